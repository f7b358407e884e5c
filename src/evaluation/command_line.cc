#include "hybrid_vo/evaluation/command_line.h"

#include <cmath>
#include <cstdlib>
#include <iostream>
#include <sstream>

namespace hybrid_vo {
namespace evaluation {

std::vector<std::string> split_list(const std::string& text) {
  std::vector<std::string> items;
  std::stringstream stream(text);
  std::string item;
  while (std::getline(stream, item, ','))
    if (!item.empty()) items.push_back(item);
  return items;
}

bool parse_camera(const std::string& text, CameraModel* camera, std::string* error) {
  std::vector<double> values;
  for (const std::string& item : split_list(text)) {
    char* end = nullptr;
    const double v = std::strtod(item.c_str(), &end);
    if (end == item.c_str() || *end != '\0' || !std::isfinite(v)) {
      *error = "camera '" + text + "': '" + item + "' is not a finite number";
      return false;
    }
    values.push_back(v);
  }
  if (values.size() != 4 && values.size() != 9) {
    *error = "camera '" + text + "': expected fx,fy,cx,cy or fx,fy,cx,cy,k1,k2,p1,p2,k3 (" +
             std::to_string(values.size()) + " values given)";
    return false;
  }
  CameraModel c;
  c.pinhole = PinholeCamera(values[0], values[1], values[2], values[3]);
  for (size_t k = 4; k < values.size(); ++k) c.distortion[k - 4] = values[k];
  if (!c.pinhole.valid()) {
    *error = "camera '" + text + "': focal lengths must be positive";
    return false;
  }
  *camera = c;
  return true;
}

std::string option_value(int argc, char** argv, int* i) {
  if (*i + 1 >= argc) {
    std::cerr << "error: " << argv[*i] << " needs a value\n";
    std::exit(2);
  }
  return argv[++*i];
}

}  // namespace evaluation
}  // namespace hybrid_vo
