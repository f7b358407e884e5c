// hybrid_vo_bench_estimator: the hybrid estimator's presets against OpenCV's USAC_MAGSAC on the
// same synthetic Manhattan scenes (points x outlier ratios), one thread, fixed seeds.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "hybrid_vo/estimation/relative_pose_estimator.h"
#include "hybrid_vo/evaluation/opencv_baseline.h"
#include "hybrid_vo/evaluation/statistics.h"
#include "hybrid_vo/geometry/pose_error.h"
#include "hybrid_vo/synthetic/manhattan_scene.h"

namespace hybrid_vo {
namespace {

struct Arguments {
  int scenes = 20;
  uint64_t seed = 7;
  std::vector<std::string> presets = preset_names();
  double noise_px = 0.5;
  double line_outlier_ratio = 0.3;
};

void usage(const char* program) {
  std::cerr << "Usage: " << program
            << " [--scenes N] [--seed S] [--presets a,b,...] [--noise PX] [--line-outliers R]\n"
               "  Synthetic Manhattan scenes with {500, 2000} points x {25 %, 50 %} outliers, 150\n"
               "  segments (30 % wrong by default) and 3 VPs; one CSV row per method and setting:\n"
               "  preset,points,outlier_ratio,median_ms,median_iterations,median_rot_err_deg,\n"
               "  median_trans_err_deg,inlier_recall\n";
}

bool parse(int argc, char** argv, Arguments* a) {
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--help" || arg == "-h") {
      usage(argv[0]);
      std::exit(0);
    }
    if (i + 1 >= argc) {
      std::cerr << "error: " << arg << " needs a value\n";
      return false;
    }
    const std::string value = argv[++i];
    char* end = nullptr;
    if (arg == "--scenes") {
      a->scenes = static_cast<int>(std::strtol(value.c_str(), &end, 10));
      if (*end || a->scenes < 1) return std::cerr << "error: bad --scenes\n", false;
    } else if (arg == "--seed") {
      a->seed = std::strtoull(value.c_str(), &end, 10);
      if (*end) return std::cerr << "error: bad --seed\n", false;
    } else if (arg == "--noise") {
      a->noise_px = std::strtod(value.c_str(), &end);
      if (*end || a->noise_px < 0) return std::cerr << "error: bad --noise\n", false;
    } else if (arg == "--line-outliers") {
      a->line_outlier_ratio = std::strtod(value.c_str(), &end);
      if (*end || a->line_outlier_ratio < 0 || a->line_outlier_ratio >= 1)
        return std::cerr << "error: bad --line-outliers\n", false;
    } else if (arg == "--presets") {
      a->presets.clear();
      std::stringstream list(value);
      std::string name;
      RelativePoseEstimatorOptions unused;
      while (std::getline(list, name, ',')) {
        if (name != "opencv_usac_magsac" && !preset_options(name, &unused))
          return std::cerr << "error: unknown preset '" << name << "'\n", false;
        if (name != "opencv_usac_magsac") a->presets.push_back(name);
      }
    } else {
      std::cerr << "error: unknown argument '" << arg << "'\n";
      usage(argv[0]);
      return false;
    }
  }
  return true;
}

using hybrid_vo::evaluation::median;

struct Samples {
  std::vector<double> ms, iterations, rot, trans, recall;
  void print(const std::string& method, int points, double outliers) const {
    std::printf("%s,%d,%.2f,%.3f,%.0f,%.4f,%.4f,%.4f\n", method.c_str(), points, outliers,
                median(ms), median(iterations), median(rot), median(trans), median(recall));
    std::fflush(stdout);
  }
};

double recall(const std::vector<char>& estimated, const std::vector<bool>& truth) {
  int inliers = 0, found = 0;
  for (size_t i = 0; i < truth.size(); ++i) {
    if (!truth[i]) continue;
    ++inliers;
    found += i < estimated.size() && estimated[i];
  }
  return inliers > 0 ? static_cast<double>(found) / inliers : 0.0;
}

// OpenCV's USAC_MAGSAC plus recoverPose (opencv_baseline.h) on the same point matches; recall is
// measured on MAGSAC's own inliers.
void run_opencv(const ManhattanScene& scene, double threshold_px, Samples* out) {
  const auto start = std::chrono::steady_clock::now();
  const evaluation::OpenCvPose result = evaluation::opencv_usac_magsac(
      scene.matches.points, scene.camera1, scene.camera2, threshold_px, 0);
  out->ms.push_back(
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
  out->iterations.push_back(NAN);
  out->rot.push_back(result.ok ? rotation_error(result.pose.R, scene.truth.R) * 180.0 / M_PI
                               : 180.0);
  out->trans.push_back(result.ok ? translation_error(result.pose.t, scene.truth.t) * 180.0 / M_PI
                                 : 180.0);
  out->recall.push_back(recall(result.inliers, scene.point_inlier));
}

}  // namespace
}  // namespace hybrid_vo

int main(int argc, char** argv) {
  using namespace hybrid_vo;
  Arguments args;
  if (!parse(argc, argv, &args)) return 2;
  cv::setNumThreads(1);
  std::printf("preset,points,outlier_ratio,median_ms,median_iterations,median_rot_err_deg,"
              "median_trans_err_deg,inlier_recall\n");
  for (int points : {500, 2000}) {
    for (double outliers : {0.25, 0.5}) {
      std::vector<ManhattanScene> scenes;
      std::mt19937_64 rng(args.seed + points + static_cast<int>(100 * outliers));
      ManhattanSceneOptions so;
      so.num_points = points;
      so.num_segments = 150;
      so.point_outlier_ratio = outliers;
      so.line_outlier_ratio = args.line_outlier_ratio;
      so.noise_px = args.noise_px;
      so.num_vps = 3;
      for (int i = 0; i < args.scenes; ++i) scenes.push_back(generate_manhattan_scene(rng, so));

      for (const std::string& preset : args.presets) {
        RelativePoseEstimatorOptions options;
        preset_options(preset, &options);
        Samples samples;
        for (size_t i = 0; i < scenes.size(); ++i) {
          const ManhattanScene& scene = scenes[i];
          options.ransac.seed = args.seed + i;
          const auto start = std::chrono::steady_clock::now();
          const RelativePoseEstimate est =
              estimate_relative_pose(scene.camera1, scene.camera2, scene.matches, options);
          samples.ms.push_back(std::chrono::duration<double, std::milli>(
                                   std::chrono::steady_clock::now() - start)
                                   .count());
          samples.iterations.push_back(est.iterations);
          const bool ok = est.status == EstimationStatus::kOk;
          samples.rot.push_back(ok ? rotation_error(est.pose.R, scene.truth.R) * 180.0 / M_PI
                                   : 180.0);
          samples.trans.push_back(ok ? translation_error(est.pose.t, scene.truth.t) * 180.0 / M_PI
                                     : 180.0);
          samples.recall.push_back(recall(est.point_inliers, scene.point_inlier));
        }
        samples.print(preset, points, outliers);
      }
      Samples opencv;
      cv::theRNG().state = args.seed;
      for (const ManhattanScene& scene : scenes) run_opencv(scene, 1.0, &opencv);
      opencv.print("opencv_usac_magsac", points, outliers);
    }
  }
  return 0;
}
