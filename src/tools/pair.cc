// hybrid_vo_pair: relative pose between two images from points, lines and vanishing points.
#include <cstdio>
#include <iostream>
#include <string>

#include <opencv2/imgcodecs.hpp>

#include "hybrid_vo/evaluation/command_line.h"
#include "hybrid_vo/features/frontend.h"
#include "hybrid_vo/features/visualization.h"
#include "hybrid_vo/lines/two_view.h"

namespace {

void usage(const char* program) {
  std::cerr
      << "Usage: " << program << " IMG1 IMG2 --camera fx,fy,cx,cy[,k1,k2,p1,p2,k3]\n"
      << "         [--camera2 ...] [--preset P] [--points sift|orb] [--lines lsd|fld|none]\n"
      << "         [--seed S] [--vis out.png]\n"
      << "  Prints the relative pose (X2 = R X1 + t, unit t), the inliers per modality, the\n"
      << "  solvers used and the timings. Presets: 5pc, 5pc+junc, 5pc+4pc, 5pc+4pc+junc,\n"
      << "  hybrid (default), hybrid+junc. --vis draws inlier points, inlier segments coloured\n"
      << "  by VP, and the VPs.\n";
}

int fail(const std::string& message, int code = 1) {
  std::cerr << "error: " << message << "\n";
  return code;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace hybrid_vo;
  std::vector<std::string> positional;
  std::string camera_text, camera2_text, preset = "hybrid", vis, points = "sift", lines = "lsd";
  uint64_t seed = 0;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--help" || a == "-h") {
      usage(argv[0]);
      return 0;
    }
    if (a.rfind("--", 0) == 0) {
      if (i + 1 >= argc) return fail(a + " needs a value", 2);
      const std::string value = argv[++i];
      if (a == "--camera") camera_text = value;
      else if (a == "--camera2") camera2_text = value;
      else if (a == "--preset") preset = value;
      else if (a == "--vis") vis = value;
      else if (a == "--points") points = value;
      else if (a == "--lines") lines = value;
      else if (a == "--seed") seed = std::strtoull(value.c_str(), nullptr, 10);
      else return usage(argv[0]), fail("unknown option " + a, 2);
    } else {
      positional.push_back(a);
    }
  }
  if (positional.size() != 2 || camera_text.empty()) return usage(argv[0]), 2;
  CameraModel camera1, camera2;
  std::string error;
  if (!evaluation::parse_camera(camera_text, &camera1, &error)) return fail(error, 2);
  camera2 = camera1;
  if (!camera2_text.empty() && !evaluation::parse_camera(camera2_text, &camera2, &error))
    return fail(error, 2);
  TwoViewOptions options;
  if (!preset_options(preset, &options)) return fail("unknown preset '" + preset + "'", 2);
  options.ransac.seed = seed;
  FrontendOptions frontend;
  if (points == "orb") frontend.points.type = PointFeatureType::kOrb;
  else if (points != "sift") return fail("--points must be sift or orb", 2);
  if (lines == "fld") frontend.lines.detection.detector = LineDetector::kFld;
  else if (lines == "none") frontend.use_lines = false;
  else if (lines != "lsd") return fail("--lines must be lsd, fld or none", 2);

  const cv::Mat image1 = cv::imread(positional[0], cv::IMREAD_GRAYSCALE);
  if (image1.empty()) return fail("cannot read image '" + positional[0] + "'");
  const cv::Mat image2 = cv::imread(positional[1], cv::IMREAD_GRAYSCALE);
  if (image2.empty()) return fail("cannot read image '" + positional[1] + "'");
  camera1.pinhole.width = image1.cols;
  camera1.pinhole.height = image1.rows;
  camera2.pinhole.width = image2.cols;
  camera2.pinhole.height = image2.rows;

  const ImageFeatures f1 = extract_features(image1, frontend);
  const ImageFeatures f2 = extract_features(image2, frontend);
  double match_ms = 0.0;
  TwoViewMatches matches = match_features(f1, f2, camera1, camera2, frontend, &match_ms);
  if (matches.points.size() < 5 && matches.lines.size() < 4)
    return fail("too few features matched: " + std::to_string(matches.points.size()) +
                " points, " + std::to_string(matches.lines.size()) +
                " segments (textureless images, or the wrong pair?)");

  const TwoViewEstimate result =
      estimate_two_view(camera1.pinhole, camera2.pinhole, matches, options);
  const RelativePoseEstimate& est = result.estimate;
  std::printf("status: %s\n", to_string(est.status));
  if (est.status == EstimationStatus::kOk) {
    const Eigen::Matrix3d& R = est.pose.R;
    std::printf("R: [%.6f %.6f %.6f; %.6f %.6f %.6f; %.6f %.6f %.6f]\n", R(0, 0), R(0, 1), R(0, 2),
                R(1, 0), R(1, 1), R(1, 2), R(2, 0), R(2, 1), R(2, 2));
    std::printf("t: [%.6f %.6f %.6f]\n", est.pose.t.x(), est.pose.t.y(), est.pose.t.z());
  }
  std::printf("matches: %zu points, %zu segments, %zu junctions, %zu VPs%s\n",
              matches.points.size(), matches.lines.size(), est.junctions.size(),
              result.vps_detected ? result.vps.matches.size() : matches.vps.size(),
              result.vps_detected ? " (detected jointly)" : "");
  std::printf("inliers: %d points, %d junctions, %d segments, %d VPs\n", est.num_point_inliers,
              est.num_junction_inliers, est.num_line_inliers, est.num_vp_inliers);
  std::printf("best solver: %s; drawn/models/best per solver:",
              solver_info(est.best_solver).code);
  for (const SolverInfo& info : solver_table()) {
    const SolverStatistics& s = est.solvers[static_cast<int>(info.id)];
    if (s.sampled > 0) std::printf(" %s %d/%d/%d", info.code, s.sampled, s.models, s.best);
  }
  std::printf("\niterations: %d\n", est.iterations);
  std::printf("timings: frontend %.1f ms (points %.1f, lines %.1f, matching %.1f), VPs %.1f ms, "
              "estimator %.1f ms\n",
              f1.points_ms + f2.points_ms + f1.lines_ms + f2.lines_ms + match_ms,
              f1.points_ms + f2.points_ms, f1.lines_ms + f2.lines_ms, match_ms, result.vp_ms,
              est.total_ms);
  if (!vis.empty()) {
    if (result.vps_detected) {
      matches.vps = result.vps.matches;
      matches.line_vp = result.vps.labels;
    }
    const cv::Mat canvas = draw_two_view(image1, image2, matches, est.point_inliers,
                                         est.line_inliers, camera1.pinhole, camera2.pinhole);
    bool written = false;
    try {
      written = !canvas.empty() && cv::imwrite(vis, canvas);
    } catch (const cv::Exception&) {
      written = false;
    }
    if (!written) return fail("cannot write '" + vis + "'");
    std::printf("picture: %s\n", vis.c_str());
  }
  return est.status == EstimationStatus::kOk ? 0 : 3;
}
