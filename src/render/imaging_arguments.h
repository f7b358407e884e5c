#pragma once

// The imaging options of the renderers' command lines (hybrid_vo_render_sequence,
// hybrid_vo_render_pan): `--imaging clean|realistic` picks the defaults, and the knobs given
// (in any order) replace them; the tools' own --noise is the read noise.

#include <string>
#include <vector>

#include "hybrid_vo/render/imaging.h"

namespace hybrid_vo {
namespace render {

struct ImagingArguments {
  bool realistic = false;
  ImagingOptions given;            // the knobs' values where given
  std::vector<std::string> named;  // the knobs given
};

// Whether `arg` is one of the imaging options (each takes a value).
bool is_imaging_option(const std::string& arg);
// Parses one of them; false for a bad value.
bool parse_imaging_option(const std::string& arg, const std::string& value,
                          ImagingArguments* arguments);
// The imaging of the arguments; *noise becomes the realistic read noise unless noise_given.
ImagingOptions resolve_imaging(const ImagingArguments& arguments, bool noise_given,
                               double* noise);
// Why the options do not suit frames at rate_hz (an exposure longer than a frame), or "".
std::string imaging_rate_problem(const ImagingOptions& imaging, double rate_hz);
// The help lines of the imaging options.
std::string imaging_usage();

}  // namespace render
}  // namespace hybrid_vo
