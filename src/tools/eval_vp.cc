// hybrid_vo_eval_vp: single-image VP detection against the York Urban ground truth.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "hybrid_vo/frontend/line_detection.h"
#include "hybrid_vo/lines/vp_detection.h"
#include "statistics.h"

namespace {

using hybrid_vo::LineSegment;

void usage(const char* program) {
  std::cerr << "Usage: " << program
            << " --york DIR [--segments gt|lsd] [--threshold PX] [--max-vps N] [--no-refine]\n"
               "  DIR holds camera.txt and images/NAME/{NAME.jpg, lines.txt, vp_directions.txt}\n"
               "  (the York Urban layout). Prints, per image, the angle between each ground-truth\n"
               "  direction and its closest detected VP, then a summary line.\n";
}

bool read_camera(const std::string& path, hybrid_vo::PinholeCamera* camera) {
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
  *camera = hybrid_vo::PinholeCamera(values["fx"], values["fy"], values["cx"], values["cy"],
                                     static_cast<int>(values["width"]),
                                     static_cast<int>(values["height"]));
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

using hybrid_vo::tools::median;

}  // namespace

int main(int argc, char** argv) {
  std::string dir, segments_mode = "gt";
  hybrid_vo::VpDetectionOptions options;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::cerr << "error: " << a << " needs a value\n";
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--york") {
      dir = value();
    } else if (a == "--segments") {
      segments_mode = value();
    } else if (a == "--threshold") {
      options.inlier_threshold_px = std::atof(value().c_str());
    } else if (a == "--max-vps") {
      options.max_vps = std::atoi(value().c_str());
    } else if (a == "--no-refine") {
      options.refine = false;
    } else if (a == "--help" || a == "-h") {
      usage(argv[0]);
      return 0;
    } else {
      std::cerr << "error: unknown argument '" << a << "'\n";
      usage(argv[0]);
      return 2;
    }
  }
  if (dir.empty() || (segments_mode != "gt" && segments_mode != "lsd") ||
      !(options.inlier_threshold_px > 0.0) || options.max_vps < 1) {
    usage(argv[0]);
    return 2;
  }
  hybrid_vo::PinholeCamera camera;
  if (!read_camera(dir + "/camera.txt", &camera)) {
    std::cerr << "error: cannot read a valid camera from " << dir << "/camera.txt\n";
    return 1;
  }
  // York's coordinates are MATLAB's, 1-based, like its principal point; OpenCV's LSD works in
  // 0-based pixels, so its segments are shifted by one to match.
  std::vector<std::string> names;
  {
    std::ifstream split(dir + "/splits.txt");
    std::string word;
    while (split >> word)
      if (word != "train" && word != "test") names.push_back(word);
  }
  if (names.empty()) {
    std::cerr << "error: no image names in " << dir << "/splits.txt\n";
    return 1;
  }

  std::vector<double> errors, times;
  int images = 0;
  std::printf("image,err1_deg,err2_deg,err3_deg,segments,vps,ms\n");
  for (const std::string& name : names) {
    const std::string base = dir + "/images/" + name + "/";
    std::string error;
    std::vector<std::vector<double>> gt;
    if (!read_rows(base + "vp_directions.txt", 3, &gt, &error)) {
      std::cerr << "error: " << error << "\n";
      return 1;
    }
    std::vector<LineSegment> segments;
    if (segments_mode == "gt") {
      std::vector<std::vector<double>> rows;
      if (!read_rows(base + "lines.txt", 4, &rows, &error)) {
        std::cerr << "error: " << error << "\n";
        return 1;
      }
      for (const auto& r : rows) segments.push_back(LineSegment({r[0], r[1]}, {r[2], r[3]}));
    }
    const auto start = std::chrono::steady_clock::now();
    if (segments_mode == "lsd") {
      const cv::Mat image = cv::imread(base + name + ".jpg", cv::IMREAD_GRAYSCALE);
      if (image.empty()) {
        std::cerr << "error: cannot read " << base + name + ".jpg\n";
        return 1;
      }
      segments = hybrid_vo::detect_line_segments(image);
      for (LineSegment& s : segments) {
        s.p1 += Eigen::Vector2d::Ones();
        s.p2 += Eigen::Vector2d::Ones();
      }
    }
    const hybrid_vo::SingleImageVps vps =
        hybrid_vo::detect_vanishing_points(camera, segments, options);
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    times.push_back(ms);
    ++images;
    std::printf("%s", name.c_str());
    for (const auto& row : gt) {
      // York's directions have y up: the camera-frame direction is diag(1, -1, 1) d (MANIFEST).
      const Eigen::Vector3d d = Eigen::Vector3d(row[0], -row[1], row[2]).normalized();
      double best = 90.0;
      for (const hybrid_vo::ImageVp& vp : vps.vps)
        best = std::min(best, std::acos(std::min(1.0, std::abs(vp.direction.dot(d)))) * 180.0 / M_PI);
      errors.push_back(best);
      std::printf(",%.3f", best);
    }
    std::printf(",%zu,%zu,%.2f\n", segments.size(), vps.vps.size(), ms);
  }
  auto within = [&](double limit) {
    return static_cast<double>(std::count_if(errors.begin(), errors.end(),
                                             [limit](double e) { return e <= limit; })) /
           errors.size();
  };
  std::printf("summary: images=%d median_deg=%.3f within2=%.3f within5=%.3f within10=%.3f "
              "ms_per_image=%.2f\n",
              images, median(errors), within(2.0), within(5.0), within(10.0), median(times));
  return 0;
}
