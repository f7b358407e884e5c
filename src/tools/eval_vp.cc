// hybrid_vo_eval_vp: single-image VP detection against the York Urban ground truth.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "hybrid_vo/datasets/york_urban.h"
#include "hybrid_vo/evaluation/statistics.h"
#include "hybrid_vo/features/line_detection.h"
#include "hybrid_vo/lines/vp_detection.h"

namespace {

using hybrid_vo::LineSegment;

void usage(const char* program) {
  std::cerr << "Usage: " << program
            << " --york DIR [--segments gt|lsd] [--threshold PX] [--max-vps N] [--no-refine]\n"
               "  DIR holds camera.txt and images/NAME/{NAME.jpg, lines.txt, vp_directions.txt}\n"
               "  (the York Urban layout). Prints, per image, the angle between each ground-truth\n"
               "  direction and its closest detected VP, then a summary line.\n";
}

using hybrid_vo::evaluation::median;

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
  hybrid_vo::datasets::YorkUrbanSet york;
  std::string error;
  if (!hybrid_vo::datasets::read_york_urban(dir, &york, &error)) {
    std::cerr << "error: " << error << "\n";
    return 1;
  }
  // York's coordinates are MATLAB's, 1-based, like its principal point; OpenCV's LSD works in
  // 0-based pixels, so its segments are shifted by one to match.
  std::vector<double> errors, times;
  int images = 0;
  std::printf("image,err1_deg,err2_deg,err3_deg,segments,vps,ms\n");
  for (const std::string& name : york.names) {
    hybrid_vo::datasets::YorkUrbanImage truth;
    if (!hybrid_vo::datasets::read_york_urban_image(york, name, segments_mode == "gt", &truth,
                                                    &error)) {
      std::cerr << "error: " << error << "\n";
      return 1;
    }
    std::vector<LineSegment> segments = truth.segments;
    const auto start = std::chrono::steady_clock::now();
    if (segments_mode == "lsd") {
      const cv::Mat image = cv::imread(truth.image_path, cv::IMREAD_GRAYSCALE);
      if (image.empty()) {
        std::cerr << "error: cannot read " << truth.image_path << "\n";
        return 1;
      }
      segments = hybrid_vo::detect_line_segments(image);
      for (LineSegment& s : segments) {
        s.p1 += Eigen::Vector2d::Ones();
        s.p2 += Eigen::Vector2d::Ones();
      }
    }
    const hybrid_vo::SingleImageVps vps =
        hybrid_vo::detect_vanishing_points(york.camera, segments, options);
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    times.push_back(ms);
    ++images;
    std::printf("%s", name.c_str());
    for (const Eigen::Vector3d& d : truth.vp_directions) {
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
