#include "hybrid_vo/datasets/york_urban.h"

#include <fstream>
#include <map>
#include <sstream>

namespace hybrid_vo {
namespace datasets {
namespace {

// Unknown keys are ignored, and a missing width or height is 0 (unknown).
bool read_camera(const std::string& path, PinholeCamera* camera) {
  std::ifstream in(path);
  if (!in) return false;
  std::map<std::string, double> values;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    std::string key;
    double value;
    if (fields >> key >> value) values[key] = value;
  }
  for (const char* key : {"fx", "fy", "cx", "cy"})
    if (!values.count(key)) return false;
  *camera = PinholeCamera(values["fx"], values["fy"], values["cx"], values["cy"],
                          static_cast<int>(values["width"]), static_cast<int>(values["height"]));
  return camera->valid();
}

// Rows of numbers, skipping comments; false when a row has fewer than `columns` numbers.
bool read_rows(const std::string& path, size_t columns, std::vector<std::vector<double>>* rows,
               std::string* error) {
  std::ifstream in(path);
  if (!in) {
    *error = "cannot open " + path;
    return false;
  }
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    std::vector<double> row;
    double v;
    while (fields >> v) row.push_back(v);
    if (row.size() < columns) {
      *error = path + ":" + std::to_string(number) + ": expected " + std::to_string(columns) +
               " numbers";
      return false;
    }
    rows->push_back(row);
  }
  return true;
}

}  // namespace

bool read_york_urban(const std::string& dir, YorkUrbanSet* set, std::string* error) {
  set->dir = dir;
  if (!read_camera(dir + "/camera.txt", &set->camera)) {
    *error = "cannot read a valid camera from " + dir + "/camera.txt";
    return false;
  }
  set->names.clear();
  std::ifstream split(dir + "/splits.txt");
  std::string word;
  while (split >> word)
    if (word != "train" && word != "test") set->names.push_back(word);
  if (set->names.empty()) {
    *error = "no image names in " + dir + "/splits.txt";
    return false;
  }
  return true;
}

bool read_york_urban_image(const YorkUrbanSet& set, const std::string& name, bool with_segments,
                           YorkUrbanImage* image, std::string* error) {
  const std::string base = set.dir + "/images/" + name + "/";
  image->image_path = base + name + ".jpg";
  image->vp_directions.clear();
  image->segments.clear();
  std::vector<std::vector<double>> rows;
  if (!read_rows(base + "vp_directions.txt", 3, &rows, error)) return false;
  for (const auto& r : rows)
    image->vp_directions.push_back(Eigen::Vector3d(r[0], -r[1], r[2]).normalized());
  if (!with_segments) return true;
  rows.clear();
  if (!read_rows(base + "lines.txt", 4, &rows, error)) return false;
  for (const auto& r : rows) image->segments.push_back(LineSegment({r[0], r[1]}, {r[2], r[3]}));
  return true;
}

}  // namespace datasets
}  // namespace hybrid_vo
