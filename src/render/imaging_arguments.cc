#include "imaging_arguments.h"

#include <algorithm>
#include <cstdio>

#include "number_arguments.h"

namespace hybrid_vo {
namespace render {

bool is_imaging_option(const std::string& arg) {
  static const char* kNames[] = {"--imaging",        "--exposure-ms",     "--exposure-samples",
                                 "--vignetting",     "--shot-noise-gain", "--exposure-drift",
                                 "--jpeg-artefacts"};
  return std::find(std::begin(kNames), std::end(kNames), arg) != std::end(kNames);
}

bool parse_imaging_option(const std::string& arg, const std::string& v, ImagingArguments* a) {
  ImagingOptions& o = a->given;
  bool ok = false;
  if (arg == "--imaging") {
    ok = v == "clean" || v == "realistic";
    a->realistic = v == "realistic";
    return ok;
  }
  if (arg == "--exposure-ms") {
    ok = parse_double(v, 0.0, 1000.0, false, &o.exposure_ms);
  } else if (arg == "--exposure-samples") {
    ok = parse_int(v, 1, 31, &o.max_exposure_samples) && o.max_exposure_samples % 2 == 1;
  } else if (arg == "--vignetting") {
    ok = parse_double(v, 0.0, 0.95, false, &o.vignetting);
  } else if (arg == "--shot-noise-gain") {
    ok = parse_double(v, 0.0, 10.0, false, &o.shot_noise_gain);
  } else if (arg == "--exposure-drift") {
    ok = parse_double(v, 0.0, 0.9, false, &o.exposure_drift);
  } else if (arg == "--jpeg-artefacts") {
    ok = parse_int(v, 0, 100, &o.jpeg_quality);
  }
  if (ok) a->named.push_back(arg);
  return ok;
}

ImagingOptions resolve_imaging(const ImagingArguments& a, bool noise_given, double* noise) {
  ImagingOptions o = a.realistic ? realistic_imaging() : ImagingOptions();
  if (a.realistic && !noise_given) *noise = kRealisticReadNoise;
  const ImagingOptions& g = a.given;
  for (const std::string& name : a.named) {
    if (name == "--exposure-ms") o.exposure_ms = g.exposure_ms;
    if (name == "--exposure-samples") o.max_exposure_samples = g.max_exposure_samples;
    if (name == "--vignetting") o.vignetting = g.vignetting;
    if (name == "--shot-noise-gain") o.shot_noise_gain = g.shot_noise_gain;
    if (name == "--exposure-drift") o.exposure_drift = g.exposure_drift;
    if (name == "--jpeg-artefacts") o.jpeg_quality = g.jpeg_quality;
  }
  return o;
}

std::string imaging_rate_problem(const ImagingOptions& imaging, double rate_hz) {
  const double frame_ms = 1000.0 / rate_hz;
  if (imaging.exposure_ms <= frame_ms) return "";
  char text[160];
  std::snprintf(text, sizeof(text), "--exposure-ms %g is longer than a frame at %g Hz (%.4g ms)",
                imaging.exposure_ms, rate_hz, frame_ms);
  return text;
}

std::string imaging_usage() {
  return "  --imaging clean|realistic  how the camera makes its images (default clean: a slight\n"
         "                     blur and constant noise); realistic: a real camera's, the\n"
         "                     knobs below at their 'realistic' values; each knob may also be\n"
         "                     given alone, or after --imaging realistic to change it\n"
         "  --exposure-ms MS   motion blur: the views over an exposure of MS ms around each\n"
         "                     frame's stamp, averaged (realistic 10; the ground truth is the\n"
         "                     middle of the exposure)\n"
         "  --exposure-samples N  at most N views per exposure (odd; default 7), fewer when the\n"
         "                     image moves less than N pixels; one at rest\n"
         "  --vignetting F     the image corners F darker than the centre (realistic 0.35)\n"
         "  --noise SIGMA      the read noise, grey levels (default 1; realistic 1.5)\n"
         "  --shot-noise-gain G  shot noise: variance G per grey level of signal, beside the\n"
         "                     read noise's (realistic 0.05: 2.5 grey levels at mid-grey)\n"
         "  --exposure-drift F  auto exposure: the brightness wanders within +-F over seconds,\n"
         "                     with small steps (realistic 0.15)\n"
         "  --jpeg-artefacts Q  every image JPEG-coded at quality Q and decoded, also the\n"
         "                     KITTI layout's PNGs (realistic 85; 0: none)\n";
}

}  // namespace render
}  // namespace hybrid_vo
