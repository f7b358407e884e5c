#pragma once

// Small helpers shared by the command-line tools.

#include <string>
#include <vector>

#include "hybrid_vo/features/camera_model.h"

namespace hybrid_vo {
namespace evaluation {

// "fx,fy,cx,cy" or "fx,fy,cx,cy,k1,k2,p1,p2,k3" (OpenCV's plumb bob). False with a message on
// anything else: wrong count, non-numbers, non-finite values, non-positive focal lengths.
bool parse_camera(const std::string& text, CameraModel* camera, std::string* error);

// Comma-separated list ("a,b,c"); empty items are dropped.
std::vector<std::string> split_list(const std::string& text);

// The value after the option argv[*i], advancing *i; a missing value prints an error and exits
// with status 2 (the tools' usage-error status).
std::string option_value(int argc, char** argv, int* i);

}  // namespace evaluation
}  // namespace hybrid_vo
