// hybrid_vo_bench_frontend: the node's VisualOdometry on a KITTI sequence's left images, without
// ROS, with the KITTI configuration (config/kitti.yaml). Images are read before the clock starts.
// Prints per-stage medians, the process CPU time per frame (load-independent enough to compare
// configurations on a shared machine) and the matches; with the sequence's ground truth
// (<root>/poses/<name>.txt) also the accuracy, as hybrid_vo_eval_trajectory prints it for a
// run through the node but without dropped frames, so that it does not depend on the load. Under
// `valgrind --tool=callgrind --toggle-collect='hybrid_vo::VisualOdometry::process*'` with
// --sequential it gives instruction counts per configuration.
#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <cmath>
#include <cstdlib>
#include <ctime>
#include <iostream>
#include <string>
#include <thread>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgcodecs.hpp>

#include "hybrid_vo/datasets/kitti.h"
#include "hybrid_vo/estimation/final_refinement.h"
#include "hybrid_vo/estimation/relative_pose_estimator.h"
#include "hybrid_vo/evaluation/consistency.h"
#include "hybrid_vo/evaluation/statistics.h"
#include "hybrid_vo/evaluation/trajectory.h"
#include "hybrid_vo/features/frontend.h"
#include "hybrid_vo/geometry/epipolar_error.h"
#include "hybrid_vo/geometry/pose_error.h"
#include "hybrid_vo/node/parameters_file.h"
#include "hybrid_vo/odometry/visual_odometry.h"

namespace hybrid_vo {
namespace {

using evaluation::median;
using evaluation::percentile;

// Each half of a pair's inliers refined alone from the estimator's pose, at the scales the
// estimator measured: its rotation's distance to the truth (degrees; NAN where that half cannot
// fix a pose). Where the halves land far apart, the pair's pose is some blend of a biased half and
// a right one (doc/real_data.md, which modality is off).
struct HalvesError {
  double points = NAN, junctions = NAN, rest = NAN;  // rest: junctions, segments and VPs
};

HalvesError halves_error(const PinholeCamera& camera, const TwoViewMatches& m,
                         const RelativePoseEstimate& est, const RelativePose& truth) {
  std::vector<PointMatch> points, junctions;
  for (size_t k = 0; k < m.points.size() && k < est.point_inliers.size(); ++k)
    if (est.point_inliers[k]) points.push_back(m.points[k]);
  for (size_t k = 0; k < est.junctions.size() && k < est.junction_inliers.size(); ++k)
    if (est.junction_inliers[k]) junctions.push_back(est.junctions[k].match);
  std::vector<VpMatch> vps;
  std::vector<int> index(m.vps.size(), -1);
  for (size_t k = 0; k < m.vps.size() && k < est.vp_inliers.size(); ++k)
    if (est.vp_inliers[k]) {
      index[k] = static_cast<int>(vps.size());
      vps.push_back(m.vps[k]);
    }
  std::vector<LineMatch> lines;
  std::vector<int> line_vp;
  for (size_t i = 0; i < m.lines.size() && i < m.line_vp.size(); ++i)
    if (m.line_vp[i] >= 0 && m.line_vp[i] < static_cast<int>(index.size()) &&
        index[m.line_vp[i]] >= 0) {
      lines.push_back(m.lines[i]);
      line_vp.push_back(index[m.line_vp[i]]);
    }
  // The scales the estimator measured; a scale it could not measure keeps the default.
  FinalRefinementOptions options;
  options.compute_covariance = false;
  if (est.scales.line_vp_px > 0.0) options.line_vp_sigma_px = est.scales.line_vp_px;
  if (est.scales.vp_deg > 0.0) options.vp_sigma_deg = est.scales.vp_deg;
  const auto error = [&](const std::vector<PointMatch>& p, double sigma_px, bool with_segments) {
    if (p.size() < 5) return static_cast<double>(NAN);
    FinalRefinementOptions o = options;
    if (sigma_px > 0.0) o.point_sigma_px = sigma_px;
    const FinalRefinementResult r =
        with_segments
            ? refine_relative_pose_ceres(camera, camera, p, vps, lines, line_vp, est.pose, o)
            : refine_relative_pose_ceres(camera, camera, p, {}, {}, {}, est.pose, o);
    return r.success ? rotation_error(r.pose.R, truth.R) * 180.0 / M_PI : NAN;
  };
  HalvesError e;
  e.points = error(points, est.scales.point_px, false);
  e.junctions = error(junctions, est.scales.junction_px, false);
  e.rest = error(junctions, est.scales.junction_px, true);
  return e;
}

// The point inliers split two ways, each half refined alone from the estimator's pose with its
// own curvature covariance: how far the halves' rotations lie apart under their claimed
// covariances (NEES, 3 dof: 2.37 median if the points' errors were independent), split by image
// row (top / bottom: what a rolling shutter or a region's shading would move) and interleaved
// (every other track); and the points' own rotation against the truth under their curvature.
// Their ratio to 2.37 is how many times the points' independence overstates what they know.
struct SplitNees {
  double rows = NAN, interleaved = NAN, truth = NAN;
};

SplitNees split_nees(const PinholeCamera& camera, const TwoViewMatches& m,
                     const RelativePoseEstimate& est, const RelativePose& truth) {
  std::vector<PointMatch> points;
  for (size_t k = 0; k < m.points.size() && k < est.point_inliers.size(); ++k)
    if (est.point_inliers[k]) points.push_back(m.points[k]);
  SplitNees out;
  if (points.size() < 20 || !(est.scales.point_px > 0.0)) return out;
  FinalRefinementOptions o;
  o.compute_covariance = true;
  o.point_sigma_px = est.scales.point_px;
  struct Fit {
    bool ok = false;
    Eigen::Matrix3d R, C;
  };
  const auto fit = [&](const std::vector<PointMatch>& p) {
    Fit f;
    const FinalRefinementResult r = refine_relative_pose_ceres(camera, camera, p, {}, {}, {}, est.pose, o);
    if (!r.success || !r.covariance_valid) return f;
    f.ok = true;
    f.R = r.pose.R;
    f.C = r.covariance.topLeftCorner<3, 3>();
    return f;
  };
  const auto nees = [](const Eigen::Matrix3d& Ra, const Eigen::Matrix3d& Rb, const Eigen::Matrix3d& C) {
    const Eigen::AngleAxisd apart(Eigen::Matrix3d(Ra * Rb.transpose()));
    const Eigen::Vector3d w = apart.angle() * apart.axis();
    const Eigen::LDLT<Eigen::Matrix3d> ldlt(C);
    return ldlt.info() == Eigen::Success && ldlt.isPositive() ? w.dot(ldlt.solve(w)) : NAN;
  };
  std::vector<PointMatch> sorted = points;
  std::sort(sorted.begin(), sorted.end(),
            [](const PointMatch& a, const PointMatch& b) { return a.x2.y() < b.x2.y(); });
  const size_t half = sorted.size() / 2;
  const Fit top = fit({sorted.begin(), sorted.begin() + half});
  const Fit bottom = fit({sorted.begin() + half, sorted.end()});
  if (top.ok && bottom.ok) out.rows = nees(top.R, bottom.R, top.C + bottom.C);
  std::vector<PointMatch> even, odd;
  for (size_t k = 0; k < points.size(); ++k) (k % 2 ? odd : even).push_back(points[k]);
  const Fit a = fit(even), b = fit(odd);
  if (a.ok && b.ok) out.interleaved = nees(a.R, b.R, a.C + b.C);
  const Fit all = fit(points);
  if (all.ok) out.truth = nees(all.R, truth.R, all.C);
  return out;
}

void usage(const char* program) {
  std::cerr << "Usage: " << program
            << " SEQUENCE_DIR [--config FILE [--param NAME=VALUE]...] [--frames N] [--preset P]"
               " [--sequential] [--lbd] [--no-predict]"
               " [--stereo] [--trajectory FILE] [--direct-gap G] [--min-corner-gradient G]"
               " [--min-corner-isotropy R]"
               " [--drop-leaving] [--no-anchor] [--no-direction-map] [--seed S]"
               " [--opencv-threads N] [--truth-rotation-sigma-deg S] [--truth-direction-sigma-deg S]"
               " [--truth-orientation-sigma-deg S] [--truth-position-sigma-m S]"
               " [--max-cpu-ms B] [--work-level L]"
               " [--max-features N] [--redetect-alternate] [--rotation-calibration-sigma S]"
               " [--no-rotation-only] [--keyframe-overlap F] [--keyframe-parallax P] [--mono-window K]"
               " [--no-strongest-first] [--weak-corner-gradient G] [--weak-corner-share S]"
               " [--independent-translation-points N]\n"
               "       [--independent-points N] [--ambiguity-independent-points N]\n"
               "       [--stereo-translation-margin M] [--line-flow | --no-line-flow]\n"
               "       [--line-redetect-below F] [--line-detect-every N] [--line-reach PX]\n"
               "       [--line-young-reach PX] [--line-end-search PX] [--line-spacing PX]\n"
               "       [--line-inset PX] [--line-min-residual PX] [--line-min-share F]\n"
               "       [--line-min-correlation C] [--line-rival-ratio R] [--verbose]\n"
               "  SEQUENCE_DIR: <root>/sequences/<name> (image_0, calib.txt; image_1 for --stereo).\n"
               "  --config FILE: the node's parameters from FILE (config/*.yaml), so that the run is\n"
               "  the node's with `config:=FILE` (without it: the KITTI settings below); --preset\n"
               "  and --param NAME=VALUE (any node parameter) replace the file's before it is read,\n"
               "  the other options below change the result after.\n"
               "  --stereo: with the right images (metric scale, as kitti.launch stereo:=true).\n"
               "  --sequential: no worker thread; --lbd: full LBD matching instead of line\n"
               "  tracking; --no-predict: KLT without motion prediction; --min-corner-gradient:\n"
               "  the KLT corners' strength floor (0: every corner); --min-corner-isotropy R: a\n"
               "  corner's weaker gradient at least R times its stronger (klt_min_corner_isotropy);\n"
               "  --no-strongest-first: KLT corners cell by cell in detection order, as before issue\n"
               "  53 (default: strongest first, corners weaker than --weak-corner-gradient only\n"
               "  while fewer than --weak-corner-share of --max-features are tracked);\n"
               "  --independent-translation-points N: the points count as N independent ones in\n"
               "  the translation direction's covariance (default 30); --independent-points N: in\n"
               "  the rotation's (200); --ambiguity-independent-points N: in the weights of\n"
               "  RANSAC's competing poses, whose spread widens the pair's covariance (20);\n"
               "  --keyframe-parallax P: the keyframe stays until this parallax (px; 0: until a\n"
               "  baseline); --keyframe-overlap F: ... or fewer than F of its points remain;\n"
               "  --drop-leaving: KLT drops\n"
               "  the features predicted outside the image unsearched; --no-anchor: no orientation\n"
               "  correction by the map of directions; --no-direction-map (old name:\n"
               "  --no-vp-tracker): no map of directions at all. Default preset hybrid+junc.\n"
               "  --opencv-threads N: OpenCV's own thread pool (cv::setNumThreads), as the node's\n"
               "  opencv_threads parameter; default 1 (none: the front end splits its work over\n"
               "  its two threads itself); -1 leaves OpenCV's default.\n"
               "  --trajectory: every frame's camera pose in the odometry frame, TUM format\n"
               "  (timestamp tx ty tz qx qy qz qw; stamps from times.txt + 1 s, as kitti_to_bag\n"
               "  writes them).\n"
               "  --direct-gap G: a check without ground truth. Every frame i is also matched\n"
               "  directly with frame i+G (SIFT, the pair tools' front end) and `5pc` estimates\n"
               "  their rotation; the odometry's chained rotation over the same G frames, and the\n"
               "  truth's, are compared with it. Where the truth is much further from these\n"
               "  direct estimates than the odometry is, the drift against it is the truth's.\n"
               "  With ground truth, '# consistency:' lines: the NEES of each estimated pair's\n"
               "  rotation and translation direction under the published motion covariance, and\n"
               "  of the orientation against the first frame under the orientation's covariance,\n"
               "  as hybrid_vo_eval_trajectory prints them; --truth-rotation-sigma-deg,\n"
               "  --truth-direction-sigma-deg and --truth-orientation-sigma-deg add the truth's\n"
               "  own noise (degrees per axis) as there; --truth-position-sigma-m S the noise of\n"
               "  its positions (metres per axis), which moves a pair's true direction by\n"
               "  sqrt(2) S / baseline (a hand-held camera's millimetres matter).\n"
               "  --max-cpu-ms B: the node's max_cpu_ms, a CPU budget per frame (both threads);\n"
               "  --work-level L: its min_work_level, a fixed level 0-4 (cpu_budget.h);\n"
               "  --max-features N: the point budget (default 1500, as config/kitti.yaml);\n"
               "  --redetect-alternate: KLT re-detection in half the cells per frame, taking\n"
               "  turns (klt_redetect_alternate: true); --redetect-lost-cells: only in the cells\n"
               "  that lost tracks since the last frame (klt_redetect_lost_cells).\n"
               "  --rotation-calibration-sigma S: the node's rotation_calibration_sigma (how far\n"
               "  every rotation may be off as a share of its angle; config/kitti.yaml: 0).\n"
               "  --no-rotation-only: frames without a baseline are skipped, not answered\n"
               "  (rotation_only_pairs: false); --rotation-keyframe-overlap F: the node's\n"
               "  keyframe_overlap; --keyframe-parallax P: keyframe_parallax_px (0: every frame\n"
               "  with a baseline becomes the keyframe); --keyframe-max-turn D: keyframe_max_turn_deg.\n"
               "  --mono-window K: mono_window_keyframes (a new\n"
               "  keyframe link's length fitted with the last links over K keyframes; < 3: off).\n"
               "  --stereo-translation-margin M: a stereo pair takes\n"
               "  the stereo points' translation where its covariance is M times smaller (0:\n"
               "  never; default 2).\n"
               "  --line-flow / --no-line-flow: segments followed by their flow and detected only\n"
               "  where their tracks thin out (line_flow), or detected and described every frame;\n"
               "  --line-redetect-below F, --line-detect-every N: when the flow's tracks are\n"
               "  detected again (below F of the last detection's tracks, or N frames after it);\n"
               "  --line-detect-seconds S: ... or S seconds after it.\n"
               "  --line-reach, --line-young-reach: how far off its prediction a track is looked for\n"
               "  (px; line_flow_tracking's min_reach_px and young_reach_px); --line-end-search,\n"
               "  --line-spacing, --line-inset, --line-min-residual, --line-min-share,\n"
               "  --line-min-correlation, --line-rival-ratio: SegmentFlowOptions' end_search_px,\n"
               "  sample_spacing_px, end_inset_px, min_residual_px, min_inlier_share,\n"
               "  min_correlation and rival_ratio.\n"
               "  With ground truth it prints the matches' Sampson error under the true epipolar\n"
               "  geometry: the points', and the junctions' that the pairs' segments make.\n";
}

// The median of each coordinate.
Eigen::Vector3d median_vector(const std::vector<Eigen::Vector3d>& vectors) {
  Eigen::Vector3d m;
  for (int k = 0; k < 3; ++k) {
    std::vector<double> values;
    for (const Eigen::Vector3d& v : vectors) values.push_back(v[k]);
    m[k] = median(values);
  }
  return m;
}

void print_difference(const char* name, const std::vector<Eigen::Vector3d>& differences) {
  std::vector<double> sizes;
  for (const Eigen::Vector3d& d : differences) sizes.push_back(d.norm());
  const Eigen::Vector3d m = median_vector(differences);
  std::printf("  %s - direct: median %.4f deg, median per axis %.4f %.4f %.4f (camera)\n", name,
              median(sizes), m.x(), m.y(), m.z());
}

// --direct-gap: chained rotations over `gap` frames against one two-view estimate across them
// (independent of KLT, of the chain and of the ground truth), and the truth against the same.
void print_direct_check(const std::vector<cv::Mat>& images, const CameraModel& camera,
                        const evaluation::Trajectory& odometry,
                        const evaluation::Trajectory& truth, int gap, uint64_t seed) {
  FrontendOptions frontend;
  frontend.use_lines = false;
  RelativePoseEstimatorOptions options;
  preset_options("5pc", &options);
  options.ransac.seed = seed;
  std::vector<ImageFeatures> features;
  for (const cv::Mat& image : images) features.push_back(extract_features(image, frontend));
  std::vector<Eigen::Vector3d> chained, true_minus_direct;
  std::vector<Eigen::Matrix3d> true_rotations, direct_rotations;
  for (size_t i = 0; i + gap < images.size(); ++i) {
    const TwoViewMatches matches =
        match_features(features[i], features[i + gap], camera, camera, frontend);
    const RelativePoseEstimate direct =
        estimate_relative_pose(camera.pinhole, camera.pinhole, matches, options);
    if (direct.status != EstimationStatus::kOk) continue;
    chained.push_back(evaluation::rotation_difference_deg(
        evaluation::relative_rotation(odometry[i], odometry[i + gap]), direct.pose.R));
    if (i + gap < truth.size()) {
      true_rotations.push_back(evaluation::relative_rotation(truth[i], truth[i + gap]));
      direct_rotations.push_back(direct.pose.R);
      true_minus_direct.push_back(
          evaluation::rotation_difference_deg(true_rotations.back(), direct.pose.R));
    }
  }
  const size_t pairs = images.size() > static_cast<size_t>(gap) ? images.size() - gap : 0;
  std::printf("rotation over %d frames against a direct two-view estimate (%zu of %zu pairs "
              "estimated):\n",
              gap, chained.size(), pairs);
  if (chained.empty()) return;
  print_difference("odometry", chained);
  if (true_minus_direct.empty()) return;
  print_difference("truth", true_minus_direct);
  // A constant part of truth - direct is the truth's (or the calibration's), not estimation's.
  const evaluation::RotationOffsetFit fit =
      evaluation::fit_rotation_offset(true_rotations, direct_rotations);
  if (fit.ok)
    std::printf("  truth - direct, fitted: the truth turns %+.2f %% more, about axes tilted by "
                "%.3f %.3f %.3f deg (camera); rms %.4f -> %.4f deg over %d pairs\n",
                100.0 * fit.scale, fit.tilt_deg.x(), fit.tilt_deg.y(), fit.tilt_deg.z(),
                fit.rms_before_deg, fit.rms_after_deg, fit.pairs);
}

double cpu_ms() { return 1000.0 * static_cast<double>(std::clock()) / CLOCKS_PER_SEC; }

int run(int argc, char** argv) {
  if (argc < 2) {
    usage(argv[0]);
    return 2;
  }
  const std::string dir = argv[1];
  int frames = -1;
  std::string preset = "hybrid+junc";
  bool stereo = false;
  double period_ms = 0.0;
  int max_features = 1500;
  bool verbose = false;
  int vp_min_inliers = 6;
  std::string trajectory_path;
  int direct_gap = 0;
  int opencv_threads = 1;
  // The truth's own noise (radians per axis) for the NEES, as in hybrid_vo_eval_trajectory.
  double truth_rotation_sigma = 0.0, truth_direction_sigma = 0.0, truth_orientation_sigma = 0.0;
  double truth_position_sigma = 0.0;  // metres per axis
  VisualOdometryOptions o;
  // --config first: the file's options are the start that every other option changes.
  std::string config_path;
  std::vector<std::pair<std::string, std::string>> overrides;
  bool preset_given = false;
  for (int i = 2; i + 1 < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--config") config_path = argv[++i];
    else if (a == "--preset") preset = argv[++i], preset_given = true;
    else if (a == "--param") {
      const std::string p = argv[++i];
      const size_t eq = p.find('=');
      if (eq == std::string::npos || eq == 0) {
        std::cerr << "--param: expected NAME=VALUE, got '" << p << "'\n";
        return 2;
      }
      overrides.emplace_back(p.substr(0, eq), p.substr(eq + 1));
    }
  }
  if (!overrides.empty() && config_path.empty()) {
    std::cerr << "--param needs --config\n";
    return 2;
  }
  if (!config_path.empty()) {
    if (preset_given) overrides.insert(overrides.begin(), {"preset", preset});
    NodeParameters node;
    std::vector<std::string> warnings;
    std::string error;
    if (!read_node_parameters_file(config_path, overrides, &node, &warnings, &error)) {
      std::cerr << error << "\n";
      return 2;
    }
    for (const std::string& w : warnings) std::cerr << config_path << ": " << w << "\n";
    o = node.odometry;
    preset = node.preset;
    opencv_threads = node.opencv_threads;
    max_features = o.features.points.max_features;
    vp_min_inliers = o.estimator.vp_detection.min_inliers;
  }
  for (int i = 2; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--frames" && i + 1 < argc) frames = std::atoi(argv[++i]);
    else if ((a == "--preset" || a == "--config" || a == "--param") && i + 1 < argc) ++i;
    else if (a == "--sequential") o.concurrent = false;
    else if (a == "--lbd") o.track_lines = false;
    else if (a == "--line-flow") o.line_flow = true;
    else if (a == "--no-line-flow") o.line_flow = false;
    else if (a == "--line-redetect-below" && i + 1 < argc)
      o.line_flow_tracking.redetect_below = std::atof(argv[++i]);
    else if (a == "--line-detect-every" && i + 1 < argc)
      o.line_flow_tracking.max_frames_between_detections = std::atoi(argv[++i]);
    else if (a == "--line-detect-seconds" && i + 1 < argc)
      o.line_flow_tracking.max_seconds_between_detections = std::atof(argv[++i]);
    else if (a == "--line-reach" && i + 1 < argc)
      o.line_flow_tracking.min_reach_px = std::atof(argv[++i]);
    else if (a == "--line-young-reach" && i + 1 < argc)
      o.line_flow_tracking.young_reach_px = std::atof(argv[++i]);
    else if (a == "--line-min-correlation" && i + 1 < argc)
      o.line_flow_tracking.flow.min_correlation = std::atof(argv[++i]);
    else if (a == "--line-rival-ratio" && i + 1 < argc)
      o.line_flow_tracking.flow.rival_ratio = std::atof(argv[++i]);
    else if (a == "--line-inset" && i + 1 < argc)
      o.line_flow_tracking.flow.end_inset_px = std::atof(argv[++i]);
    else if (a == "--line-min-residual" && i + 1 < argc)
      o.line_flow_tracking.flow.min_residual_px = std::atof(argv[++i]);
    else if (a == "--line-min-share" && i + 1 < argc)
      o.line_flow_tracking.flow.min_inlier_share = std::atof(argv[++i]);
    else if (a == "--line-end-search" && i + 1 < argc)
      o.line_flow_tracking.flow.end_search_px = std::atof(argv[++i]);
    else if (a == "--line-spacing" && i + 1 < argc)
      o.line_flow_tracking.flow.sample_spacing_px = std::atof(argv[++i]);
    else if (a == "--min-corner-gradient" && i + 1 < argc)
      o.klt.min_corner_gradient = std::atof(argv[++i]);
    else if (a == "--min-corner-isotropy" && i + 1 < argc)
      o.klt.min_corner_isotropy = std::atof(argv[++i]);
    else if (a == "--no-predict") o.klt.predict_motion = false;
    else if (a == "--drop-leaving") o.klt.drop_leaving = true;
    else if (a == "--redetect-alternate") o.klt.redetect_alternate = true;
    else if (a == "--redetect-lost-cells") o.klt.redetect_lost_cells = true;
    else if (a == "--strongest-first") o.klt.strongest_first = true;
    else if (a == "--no-strongest-first") o.klt.strongest_first = false;
    else if (a == "--weak-corner-gradient" && i + 1 < argc)
      o.klt.weak_corner_gradient = std::atof(argv[++i]);
    else if (a == "--weak-corner-share" && i + 1 < argc)
      o.klt.weak_corner_share = std::atof(argv[++i]);
    else if (a == "--refill-below" && i + 1 < argc) o.klt.refill_below = std::atof(argv[++i]);
    else if (a == "--max-cpu-ms" && i + 1 < argc) o.budget.max_cpu_ms = std::atof(argv[++i]);
    else if (a == "--work-level" && i + 1 < argc) o.budget.min_work_level = std::atoi(argv[++i]);
    else if (a == "--stereo") stereo = true;
    else if (a == "--klt-window" && i + 1 < argc) o.klt.window_px = std::atoi(argv[++i]);
    else if (a == "--klt-iterations" && i + 1 < argc) o.klt.max_iterations = std::atoi(argv[++i]);
    else if (a == "--klt-levels" && i + 1 < argc) o.klt.pyramid_levels = std::atoi(argv[++i]);
    else if (a == "--max-features" && i + 1 < argc) max_features = std::atoi(argv[++i]);
    else if (a == "--no-direction-map" || a == "--no-vp-tracker") o.use_direction_map = false;
    else if (a == "--no-anchor") o.anchor_orientation = false;
    else if (a == "--coast") o.orientation.coast_blank_walls = true;
    else if (a == "--translation-given-rotation") o.orientation.translation_given_rotation = true;
    else if (a == "--drift-floor" && i + 1 < argc)
      o.orientation.drift_floor_deg = std::atof(argv[++i]);
    else if (a == "--direction-floor" && i + 1 < argc)
      o.orientation.map.min_direction_sigma_deg = std::atof(argv[++i]);
    else if (a == "--keyframe-parallax" && i + 1 < argc)
      o.keyframe_parallax_px = std::atof(argv[++i]);
    else if (a == "--mono-window" && i + 1 < argc)
      o.mono_window_keyframes = std::atoi(argv[++i]);
    else if (a == "--min-parallax" && i + 1 < argc) o.min_parallax_px = std::atof(argv[++i]);
    else if (a == "--keyframe-max-turn" && i + 1 < argc)
      o.keyframe_max_turn_deg = std::atof(argv[++i]);
    else if (a == "--verbose") verbose = true;
    else if (a == "--trajectory" && i + 1 < argc) trajectory_path = argv[++i];
    else if (a == "--direct-gap" && i + 1 < argc) {
      direct_gap = std::atoi(argv[++i]);
      if (direct_gap < 1) {
        std::cerr << "--direct-gap: expected a number of frames >= 1, got '" << argv[i] << "'\n";
        return 2;
      }
    }
    else if (a == "--opencv-threads" && i + 1 < argc) opencv_threads = std::atoi(argv[++i]);
    else if ((a == "--truth-rotation-sigma-deg" || a == "--truth-direction-sigma-deg" ||
              a == "--truth-orientation-sigma-deg") &&
             i + 1 < argc) {
      char* end = nullptr;
      const double degrees = std::strtod(argv[++i], &end);
      if (end == argv[i] || *end || !std::isfinite(degrees) || degrees < 0.0) {
        std::cerr << a << ": expected a number of degrees >= 0, got '" << argv[i] << "'\n";
        return 2;
      }
      (a == "--truth-rotation-sigma-deg"    ? truth_rotation_sigma
       : a == "--truth-direction-sigma-deg" ? truth_direction_sigma
                                            : truth_orientation_sigma) = degrees * M_PI / 180.0;
    }
    else if (a == "--truth-position-sigma-m" && i + 1 < argc) {
      char* end = nullptr;
      truth_position_sigma = std::strtod(argv[++i], &end);
      if (end == argv[i] || *end || !std::isfinite(truth_position_sigma) ||
          truth_position_sigma < 0.0) {
        std::cerr << a << ": expected metres >= 0, got '" << argv[i] << "'\n";
        return 2;
      }
    }
    else if (a == "--seed" && i + 1 < argc)
      o.estimator.ransac.seed = std::strtoull(argv[++i], nullptr, 10);
    else if (a == "--vp-min-inliers" && i + 1 < argc) vp_min_inliers = std::atoi(argv[++i]);
    else if (a == "--period-ms" && i + 1 < argc) period_ms = std::atof(argv[++i]);
    else if (a == "--stereo-window" && i + 1 < argc) o.stereo.window_px = std::atoi(argv[++i]);
    else if (a == "--stereo-levels" && i + 1 < argc) o.stereo.pyramid_levels = std::atoi(argv[++i]);
    else if (a == "--stereo-predicted-levels" && i + 1 < argc)
      o.stereo.predicted_pyramid_levels = std::atoi(argv[++i]);
    else if (a == "--stereo-iterations" && i + 1 < argc)
      o.stereo.max_iterations = std::atoi(argv[++i]);
    else if (a == "--rotation-calibration-sigma" && i + 1 < argc)
      o.rotation_calibration_sigma = std::atof(argv[++i]);
    else if (a == "--no-rotation-only")
      o.rotation_only_pairs = false;
    else if (a == "--independent-translation-points" && i + 1 < argc)
      o.estimator.covariance.independent_translation_points = std::atof(argv[++i]);
    else if (a == "--ambiguity-independent-points" && i + 1 < argc)
      o.estimator.covariance.ambiguity_independent_points = std::atof(argv[++i]);
    else if (a == "--independent-points" && i + 1 < argc)
      o.estimator.covariance.independent_points = std::atof(argv[++i]);
    else if ((a == "--keyframe-overlap" || a == "--rotation-keyframe-overlap") && i + 1 < argc)
      o.keyframe_overlap = std::atof(argv[++i]);
    else if (a == "--stereo-translation-margin" && i + 1 < argc)
      o.stereo_translation_margin = std::atof(argv[++i]);
    else {
      usage(argv[0]);
      return 2;
    }
  }
  // As the node does (its opencv_threads parameter).
  if (opencv_threads >= 0) cv::setNumThreads(opencv_threads);
  if (config_path.empty() && !preset_options(preset, &o.estimator)) {
    std::cerr << "unknown preset " << preset << "\n";
    return 2;
  }
  // As config/kitti.yaml sets the node.
  o.features.points.max_features = max_features;
  o.estimator.vp_detection.min_inliers = vp_min_inliers;

  std::string error;
  datasets::KittiCalibration calibration;
  if (!datasets::read_kitti_calibration(dir + "/calib.txt", &calibration, &error)) {
    std::cerr << error << "\n";
    return 1;
  }
  const int available = datasets::count_kitti_images(dir, 0);
  if (available <= 0) {
    std::cerr << dir << "/image_0: no images\n";
    return 1;
  }
  if (frames < 0 || frames > available) frames = available;
  if (stereo && !(calibration.baseline() > 0.0)) {
    std::cerr << dir << "/calib.txt: --stereo needs P1\n";
    return 1;
  }
  std::vector<cv::Mat> images, right_images;
  for (int i = 0; i < frames; ++i)
    for (int camera = 0; camera < (stereo ? 2 : 1); ++camera) {
      const std::string path = datasets::kitti_image_path(dir, camera, i);
      (camera == 0 ? images : right_images).push_back(cv::imread(path, cv::IMREAD_GRAYSCALE));
      if ((camera == 0 ? images : right_images).back().empty()) {
        std::cerr << path << ": unreadable\n";
        return 1;
      }
    }
  VisualOdometryInput input;
  input.camera.pinhole = calibration.P0.camera;
  input.camera.pinhole.width = images[0].cols;
  input.camera.pinhole.height = images[0].rows;
  if (stereo) input.baseline_m = calibration.baseline();

  // Ground truth: <root>/poses/<name>.txt beside <root>/sequences/<name>.
  std::vector<datasets::KittiPose> gt;
  {
    std::string trimmed = dir;
    while (trimmed.size() > 1 && trimmed.back() == '/') trimmed.pop_back();
    const size_t slash = trimmed.find_last_of('/');
    const std::string name = trimmed.substr(slash + 1);
    const std::string root = slash == std::string::npos ? "." : trimmed.substr(0, slash);
    std::string ignored;
    datasets::read_kitti_poses(root + "/../poses/" + name + ".txt", &gt, &ignored);
  }
  std::vector<double> pose_errors;
  // NEES of the estimated pairs (rotation, translation direction) and of the estimated frames'
  // orientation against the first; NaN without a covariance.
  std::vector<double> pair_rot_nees, pair_dir_nees, orientation_nees;
  // The rotation and translation direction errors of the estimated pairs (status OK), as
  // hybrid_vo_eval_trajectory takes them from the node's MotionEstimate messages.
  std::vector<double> pair_rot_deg, pair_dir_deg;
  // Mono pairs without a baseline whose translation the keyframe's depths measured.
  std::vector<double> depth_dir_deg, depth_dir_nees;
  // The position from the start under the pose covariance (mono: in the unit of the first pair
  // with a baseline, once it is known).
  std::vector<double> position_nees;
  double position_unit = 0.0;
  evaluation::Trajectory estimate, truth, odometry;
  // Stamps from times.txt (1 s added, as kitti_to_bag does), so that a sequence with frames left
  // out has the gaps a live camera's dropped frames leave; 10 Hz without the file.
  std::vector<double> stamps;
  {
    std::vector<double> times;
    std::string ignored;
    if (datasets::read_kitti_times(dir + "/times.txt", &times, &ignored) &&
        static_cast<int>(times.size()) >= frames)
      for (int i = 0; i < frames; ++i) stamps.push_back(1.0 + times[i]);
    else
      for (int i = 0; i < frames; ++i) stamps.push_back(1.0 + 0.1 * i);
  }
  auto frame_of = [&](double stamp) {
    const auto it = std::lower_bound(stamps.begin(), stamps.end(), stamp - 1e-6);
    return it != stamps.end() && std::abs(*it - stamp) < 1e-6 ? static_cast<int>(it - stamps.begin())
                                                              : -1;
  };

  VisualOdometry vo(o);
  std::array<int, kMaxWorkLevel + 1> frames_at_level{};
  std::vector<double> total, frontend, estimator, points, redetect, lines, matching, vps, ransac,
      stereo_ms, scaled, cpu, caller_cpu, worker_cpu, longest_cpu, line_matches, line_inliers,
      tracked, started, junctions, junction_inliers, vp_matches, vp_inliers;
  int ok = 0, rotation_only = 0, answered_frames = 0;
  int segment_detections = 0;  // frames whose segments were detected
  // Every estimated pair's point matches and junctions: their Sampson error under the truth.
  std::vector<double> point_truth_px, junction_truth_px;
  // Keyframes, and the answered frames a second after the first and those of them with a baseline.
  int keyframes = 1, late_answers = 0, late_baselines = 0, late_translations = 0, late_before = 0;
  int vignetting_frames = 0;  // tracked on the image less its vignetting
  std::vector<double> pair_t_nees;   // stereo: the metric translation's NEES (3 dof)
  evaluation::DirectionSightings vp_sightings;  // the VP observations' NEES (2 dof)
  double farthest = 0.0;             // of the position from the first frame's
  // How the map of world directions served the estimated frames (as eval_trajectory prints it).
  int held = 0, reacquired = 0, rejected = 0, blank = 0, coasted = 0, overruled = 0;
  double lines_sum = 0.0, inliers_sum = 0.0;
  const auto run_start = std::chrono::steady_clock::now();
  for (int i = 0; i < frames; ++i) {
    if (period_ms > 0.0)
      std::this_thread::sleep_until(run_start + std::chrono::microseconds(
                                                    static_cast<int64_t>(1000.0 * period_ms * i)));
    input.stamp = stamps[i];
    input.image = images[i];
    if (stereo) input.right_image = right_images[i];
    const double cpu_start = cpu_ms();
    const VisualOdometryResult r = vo.process(input);
    segment_detections += r.line_tracking.detected;
    {
      evaluation::StampedPose p;
      p.stamp = input.stamp;
      p.R = r.R_wc;
      p.c = r.centre;
      odometry.push_back(p);
    }
    if (static_cast<int>(gt.size()) > i) {
      evaluation::StampedPose g;
      g.stamp = input.stamp;
      g.R = gt[i].R_wc;
      g.c = gt[i].c_w;
      estimate.push_back(odometry.back());
      truth.push_back(g);
      const int reference = frame_of(r.reference_stamp);
      // A frame skipped for too little parallax is no pair, as hybrid_vo_eval_trajectory skips
      // the node's STATUS_SKIPPED; a failure to estimate counts as an error of 180 degrees. A
      // rotation-only pair has a rotation to compare, and no translation direction: it is left
      // out of the pose AUC.
      // A pair without a baseline has its rotation, and no translation direction either.
      const bool full = r.status == VoStatus::kOk && r.baseline,
                 turned = r.status == VoStatus::kRotationOnly ||
                          (r.status == VoStatus::kOk && !r.baseline);
      if (i > 0 && reference >= 0 && reference < i && r.status != VoStatus::kLowParallax) {
        double error = 180.0;
        if (full || turned) {
          const datasets::KittiPose& a = gt[reference];
          const datasets::KittiPose& b = gt[i];
          const RelativePose truth_pose{b.R_wc.transpose() * a.R_wc,
                                        b.R_wc.transpose() * (a.c_w - b.c_w)};
          pair_rot_deg.push_back(rotation_error(r.motion.R, truth_pose.R) * 180.0 / M_PI);
          // The matches' quality: their distance to the true epipolar geometry (Sampson, px).
          for (const PointMatch& m : r.matches.points) {
            const double e = sampson_error_px(input.camera.pinhole, input.camera.pinhole,
                                              truth_pose, m.x1, m.x2);
            if (std::isfinite(e)) point_truth_px.push_back(e);
          }
          for (const DerivedPoint& j : r.estimate.estimate.junctions) {
            const double e = sampson_error_px(input.camera.pinhole, input.camera.pinhole,
                                              truth_pose, j.match.x1, j.match.x2);
            if (std::isfinite(e)) junction_truth_px.push_back(e);
          }
          // The motion and covariance the node publishes on ~relative_pose.
          const Eigen::Matrix<double, 6, 6>& C = r.motion_covariance;
          const bool valid = r.motion_covariance_valid;
          pair_rot_nees.push_back(valid ? evaluation::rotation_nees(r.motion.R, truth_pose.R,
                                                                    C.topLeftCorner<3, 3>(),
                                                                    truth_rotation_sigma)
                                        : NAN);
          if (full) {
            pair_dir_deg.push_back(translation_error(r.motion.t, truth_pose.t) * 180.0 / M_PI);
            error = std::max(pair_rot_deg.back(), pair_dir_deg.back());
            // The truth's position noise moves its direction by sqrt(2) sigma / baseline.
            const double baseline = truth_pose.t.norm();
            const double position_part =
                baseline > 0.0 ? std::sqrt(2.0) * truth_position_sigma / baseline : 0.0;
            pair_dir_nees.push_back(
                valid ? evaluation::direction_nees(
                            r.motion.t, truth_pose.t, C.bottomRightCorner<3, 3>(),
                            std::hypot(truth_direction_sigma, position_part))
                      : NAN);
          }
          if (!full && r.translation_from_depths && truth_pose.t.norm() > 0.0) {
            depth_dir_deg.push_back(translation_error(r.motion.t, truth_pose.t) * 180.0 / M_PI);
            depth_dir_nees.push_back(
                valid ? evaluation::direction_nees(r.motion.t, truth_pose.t,
                                                   C.bottomRightCorner<3, 3>(),
                                                   truth_direction_sigma)
                      : NAN);
          }
          if (r.scale_known) {
            pair_t_nees.push_back(valid ? evaluation::translation_nees(
                                              r.motion.t, truth_pose.t, C.bottomRightCorner<3, 3>())
                                        : NAN);
            if (verbose) {
              // Along t (the scale) and across it (the direction), error and sigma in metres.
              const Eigen::Vector3d u = r.motion.t.norm() > 0 ? r.motion.t.normalized()
                                                              : Eigen::Vector3d::UnitZ();
              const Eigen::Vector3d e = r.motion.t - truth_pose.t;
              const Eigen::Matrix3d Ct = C.bottomRightCorner<3, 3>();
              std::printf("stereo pair %d: t %.4f m, error along %.4f (sigma %.4f), across %.4f "
                          "(sigma %.4f), NEES %.2f\n",
                          i, r.motion.t.norm(), e.dot(u), std::sqrt(u.dot(Ct * u)),
                          (e - e.dot(u) * u).norm(),
                          std::sqrt(std::max(0.0, Ct.trace() - u.dot(Ct * u))),
                          pair_t_nees.back());
            }
          }
          // The orientation's covariance as the node reports it: the pose covariance's rotation
          // block (VoOrientation::reported_covariance).
          orientation_nees.push_back(evaluation::orientation_nees(
              odometry.front().R, r.R_wc, gt[0].R_wc, gt[i].R_wc,
              Eigen::Matrix3d(r.pose_covariance.bottomRightCorner<3, 3>()),
              truth_orientation_sigma));
          // The position from the start under the pose covariance's position block, the truth in
          // the first camera's frame and, in mono, in the odometry's unit: the length of the
          // first pair with a baseline over the truth's (so that unit's drift is what is checked).
          const Eigen::Vector3d from_start = gt[0].R_wc.transpose() * (gt[i].c_w - gt[0].c_w);
          const Eigen::Vector3d moved = odometry.front().R.transpose() * (r.centre - odometry.front().c);
          if (!(position_unit > 0.0) && full && from_start.norm() > 0.0)
            position_unit = stereo ? 1.0 : moved.norm() / from_start.norm();
          if (position_unit > 0.0) {
            const Eigen::Matrix3d P = r.pose_covariance.topLeftCorner<3, 3>() +
                                      truth_position_sigma * truth_position_sigma *
                                          position_unit * position_unit * Eigen::Matrix3d::Identity();
            const Eigen::Vector3d e = moved - position_unit * from_start;
            const Eigen::LDLT<Eigen::Matrix3d> ldlt(P);
            position_nees.push_back(ldlt.info() == Eigen::Success && ldlt.isPositive() &&
                                            ldlt.vectorD().minCoeff() > 0.0
                                        ? e.dot(ldlt.solve(e))
                                        : NAN);
            if (verbose)
              std::printf("position %d: %.4f from the start, error %.4f (%.4f along the way), "
                          "sigma %.4f, NEES %.2f\n",
                          i, moved.norm(), e.norm(), e.dot(from_start.normalized()),
                          std::sqrt(P.trace()), position_nees.back());
          }
        }
        if (!turned) pose_errors.push_back(error);
        if (verbose && (full || turned)) {
          // The direction's claimed sigma: the translation's covariance across t, per axis.
          const Eigen::Vector3d u = r.motion.t.normalized();
          const Eigen::Matrix3d across = Eigen::Matrix3d::Identity() - u * u.transpose();
          const double direction_sigma =
              full ? std::sqrt(0.5 * (across * r.motion_covariance.bottomRightCorner<3, 3>() *
                                      across).trace()) / r.motion.t.norm() * 180.0 / M_PI
                   : NAN;
          std::printf("pair %d: reference %d, %s, turned %.3f deg, parallax %.2f px, rotation "
                      "error %.4f deg, NEES %.2f; direction error %.2f deg, sigma %.2f deg, NEES "
                      "%.2f%s; length %.4f (sigma %.4f, true %.4f; %d depth points, %d window "
                      "points); %s\n",
                      i, reference, to_string(r.status),
                      Eigen::AngleAxisd(r.motion.R).angle() * 180.0 / M_PI, r.parallax_px,
                      pair_rot_deg.back(), pair_rot_nees.back(),
                      full ? pair_dir_deg.back() : NAN, direction_sigma,
                      full ? pair_dir_nees.back() : NAN, r.became_keyframe ? ", keyframe" : "",
                      r.motion.t.norm(),
                      r.motion.t.norm() > 0.0
                          ? std::sqrt(std::max(0.0, r.motion.t.normalized().dot(
                                                        r.motion_covariance.bottomRightCorner<3, 3>() *
                                                        r.motion.t.normalized())))
                          : NAN,
                      (gt[i].c_w - gt[reference].c_w).norm(),
                      r.mono_scale_points, r.window_scale_points, r.message.c_str());
          // Does the estimator's pose fit its own inliers as well as the truth does? Where the
          // truth fits them better, something other than their noise moved the pose.
          const RelativePoseEstimate& est = r.estimate.estimate;
          const auto& cam = input.camera.pinhole;
          const RelativePose truth_pose{gt[i].R_wc.transpose() * gt[reference].R_wc,
                                        gt[i].R_wc.transpose() * (gt[reference].c_w - gt[i].c_w)};
          std::vector<double> pe, pt, je, jt;
          for (size_t k = 0; k < r.matches.points.size() && k < est.point_inliers.size(); ++k) {
            if (!est.point_inliers[k]) continue;
            const PointMatch& m = r.matches.points[k];
            pe.push_back(sampson_error_px(cam, cam, est.pose, m.x1, m.x2));
            pt.push_back(sampson_error_px(cam, cam, truth_pose, m.x1, m.x2));
          }
          for (size_t k = 0; k < est.junctions.size() && k < est.junction_inliers.size(); ++k) {
            if (!est.junction_inliers[k]) continue;
            const DerivedPoint& j = est.junctions[k];
            je.push_back(sampson_error_px(cam, cam, est.pose, j.match.x1, j.match.x2));
            jt.push_back(sampson_error_px(cam, cam, truth_pose, j.match.x1, j.match.x2));
          }
          std::printf("   inliers' Sampson median (px) under the estimator's pose / the truth: "
                      "points %.3f / %.3f (%zu), junctions %.3f / %.3f (%zu)%s\n",
                      median(pe), median(pt), pe.size(), median(je), median(jt), je.size(),
                      est.refined ? "" : "; not refined (the refinement lost inliers)");
          {
            // The estimator's own direction sigma (degrees), reported and from the curvature alone.
            const Eigen::Vector3d u = est.pose.t.normalized();
            const Eigen::Matrix3d across = Eigen::Matrix3d::Identity() - u * u.transpose();
            auto dir_sigma = [&](const Eigen::Matrix<double, 6, 6>& C) {
              return std::sqrt(0.5 * (across * C.bottomRightCorner<3, 3>() * across).trace()) /
                     std::max(1e-12, est.pose.t.norm()) * 180.0 / M_PI;
            };
            std::printf("   estimator: direction error %.3f deg, sigma %.3f deg (curvature %.3f), rotation "
                        "error %.4f deg, sigma %.4f deg (curvature %.4f); %d point + %d junction inliers\n",
                        translation_error(est.pose.t, truth_pose.t) * 180.0 / M_PI,
                        dir_sigma(est.covariance), dir_sigma(est.hessian_covariance),
                        rotation_error(est.pose.R, truth_pose.R) * 180.0 / M_PI,
                        std::sqrt(est.covariance.topLeftCorner<3, 3>().trace() / 3) * 180 / M_PI,
                        std::sqrt(est.hessian_covariance.topLeftCorner<3, 3>().trace() / 3) * 180 / M_PI,
                        est.num_point_inliers, est.num_junction_inliers);
          }
          const HalvesError halves = halves_error(cam, r.matches, est, truth_pose);
          std::printf("   each half alone from the estimator's pose, rotation off the truth (deg): "
                      "KLT points %.3f, junctions %.3f, junctions with segments and VPs %.3f\n",
                      halves.points, halves.junctions, halves.rest);
          const SplitNees split = split_nees(cam, r.matches, est, truth_pose);
          std::printf("   split NEES (3 dof, points): rows %.2f, interleaved %.2f, full against the truth %.2f\n",
                      split.rows, split.interleaved, split.truth);
        }
      }
    }
    // The VP observations' covariance against the truth.
    if (static_cast<int>(gt.size()) > i) {
      const std::vector<VpObservation>& seen = r.orientation.observations;
      const std::vector<int>& ids = r.orientation.location.direction_id;
      std::vector<int> index;
      const std::vector<VpObservation> used = vo.direction_map().usable(seen, &index);
      for (size_t u = 0; u < used.size(); ++u)
        if (index[u] < static_cast<int>(ids.size()) && ids[index[u]] >= 0)
          vp_sightings.add(i, ids[index[u]], used[u].direction, used[u].covariance, gt[i].R_wc);
    }
    if (verbose) {
      // Per frame: status, VPs and what became of their priors, and the tracks.
      const RelativePoseEstimate& est = r.estimate.estimate;
      std::printf("frame %d: %s, best %s, %d points (%d inliers), %d lines, %d junctions (%d "
                  "inliers), %d VPs (%d inliers), scales: point %.3f px, line %.3f px, VP "
                  "%.4f deg (%d)",
                  i, to_string(r.status), solver_table()[static_cast<int>(est.best_solver)].code,
                  r.num_point_matches, est.num_point_inliers, r.num_line_matches,
                  static_cast<int>(est.junctions.size()), est.num_junction_inliers,
                  static_cast<int>(r.matches.vps.size()),
                  est.num_vp_inliers, est.scales.point_px, est.scales.line_vp_px,
                  est.scales.vp_deg, est.scales.num_vps);
      for (size_t k = 0; k < est.vp_prior_chi2.size(); ++k)
        if (std::isfinite(est.vp_prior_chi2[k]))
          std::printf("; prior %zu chi2 %.2f %s", k, est.vp_prior_chi2[k],
                      est.vp_prior_used[k] ? "used" : "rejected");
      // With ground truth in a Manhattan world (the rendered corridor), the error of each VP seen
      // in the current image: its angle to the nearest world axis.
      if (static_cast<int>(gt.size()) > i) {
        std::printf("\n   VP error to the nearest axis (deg):");
        for (const VpMatch& v : r.matches.vps) {
          const Eigen::Vector3d w = (gt[i].R_wc * v.d2).normalized().cwiseAbs();
          std::printf(" %.3f", std::acos(std::min(1.0, w.maxCoeff())) * 180.0 / M_PI);
        }
        // Each VP as a direction of the ground truth's world (sign: largest component positive),
        // with its segments: where the scene's directions are and how much the VPs scatter.
        std::printf("\n   VP directions in the true world:");
        for (size_t k = 0; k < r.matches.vps.size(); ++k) {
          Eigen::Vector3d w = (gt[i].R_wc * r.matches.vps[k].d2).normalized();
          int largest;
          w.cwiseAbs().maxCoeff(&largest);
          if (w[largest] < 0.0) w = -w;
          int support = 0;
          for (int label : r.matches.line_vp) support += label == static_cast<int>(k);
          std::printf(" (%.4f %.4f %.4f; %d%s)", w.x(), w.y(), w.z(), support,
                      k < r.estimate.estimate.vp_inliers.size() &&
                              !r.estimate.estimate.vp_inliers[k]
                          ? ", outlier"
                          : "");
        }
        // Anywhere: each VP match's disagreement with the true relative rotation, and its
        // number of segments.
        const int reference = frame_of(r.reference_stamp);
        if (reference >= 0 && reference < i) {
          const Eigen::Matrix3d R_true = gt[i].R_wc.transpose() * gt[reference].R_wc;
          std::printf("\n   VP match error under the true rotation (deg, segments):");
          for (size_t k = 0; k < r.matches.vps.size(); ++k) {
            const VpMatch& v = r.matches.vps[k];
            const double c = std::abs((R_true * v.d1.normalized()).dot(v.d2.normalized()));
            int support = 0;
            for (int label : r.matches.line_vp) support += label == static_cast<int>(k);
            const Eigen::Vector3d d = v.d2.normalized();
            std::printf(" %.3f (%d, d2 %.2f %.2f %.2f, track %d)",
                        std::acos(std::min(1.0, c)) * 180.0 / M_PI, support, d.x(), d.y(), d.z(),
                        k < r.vp_track_ids.size() ? r.vp_track_ids[k] : -1);
          }
        }
      }
      std::printf("\n   orientation: %s%s, %d map directions paired, correction %.3f deg%s",
                  to_string(r.orientation.source), r.orientation.blank_wall ? ", blank wall" : "",
                  r.orientation.location.paired, r.orientation.correction_deg,
                  r.orientation.location.ambiguous ? ", ambiguous" : "");
      std::printf("\n   map:");
      for (const MapDirection& t : vo.direction_map().directions()) {
        // In a Manhattan world: the direction's angle to the nearest world axis (odometry = camera 0).
        // Anywhere: the direction in the ground truth's world (compare with the VPs' there).
        double axis_error = NAN;
        Eigen::Vector3d world = Eigen::Vector3d::Constant(NAN);
        if (!gt.empty()) {
          world = (gt[0].R_wc * t.direction).normalized();
          int largest;
          const double m = world.cwiseAbs().maxCoeff(&largest);
          if (world[largest] < 0.0) world = -world;
          axis_error = std::acos(std::min(1.0, m)) * 180.0 / M_PI;
        }
        std::printf(" [%d: sigma %.4f, hits %d, chi2 %.2f%s%s, axis %.3f, true world %.4f %.4f %.4f]",
                    t.id, t.sigma_deg(), t.hits, t.last_chi2, t.confirmed ? "" : " candidate",
                    t.disagreements ? " DISAGREES" : "", axis_error, world.x(), world.y(),
                    world.z());
      }
      if (static_cast<int>(gt.size()) > i)
      {
        const Eigen::AngleAxisd aa(Eigen::Matrix3d(r.R_wc.transpose() * gt[0].R_wc.transpose() *
                                                   gt[i].R_wc));
        std::printf("\n   orientation error %.3f deg about %.2f %.2f %.2f (camera)",
                    aa.angle() * 180.0 / M_PI, aa.axis().x(), aa.axis().y(), aa.axis().z());
      }
      std::printf("\n");
    }
    if (i == 0) continue;  // the first frame only initialises
    cpu.push_back(cpu_ms() - cpu_start);
    caller_cpu.push_back(r.stages.caller_cpu_ms);
    worker_cpu.push_back(r.stages.worker_cpu_ms);
    longest_cpu.push_back(std::max(r.stages.caller_cpu_ms, r.stages.worker_cpu_ms));
    ++frames_at_level[std::clamp(r.work_level, 0, kMaxWorkLevel)];
    total.push_back(r.total_ms);
    frontend.push_back(r.frontend_ms);
    estimator.push_back(r.estimator_ms);
    points.push_back(r.stages.points_ms);
    redetect.push_back(r.stages.redetect_ms);
    lines.push_back(r.stages.lines_ms);
    matching.push_back(r.stages.line_matching_ms);
    vps.push_back(r.stages.vps_ms);
    ransac.push_back(r.stages.ransac_ms);
    stereo_ms.push_back(r.stages.stereo_ms);
    answered_frames += answered(r.status);
    keyframes += r.became_keyframe;
    vignetting_frames += r.vignetting_corrected;
    if (answered(r.status) && input.stamp - stamps[0] >= 1.0) {
      ++late_answers;
      late_baselines += r.baseline;
      late_before += r.paired_with_keyframe_before;
      // Its translation measured: by a baseline, or without one by the keyframe's depths (mono)
      // or stereo points.
      late_translations += r.baseline || r.translation_from_depths ||
                           ((r.status == VoStatus::kOk || r.status == VoStatus::kRotationOnly) &&
                            r.scale_known);
    }
    farthest = std::max(farthest, (r.centre - odometry.front().c).norm());
    rotation_only += r.status == VoStatus::kRotationOnly;
    if (r.status != VoStatus::kOk && r.status != VoStatus::kRotationOnly) continue;
    ++ok;
    const OrientationSource source = r.orientation.source;
    held += source == OrientationSource::kMap || source == OrientationSource::kReacquired;
    reacquired += source == OrientationSource::kReacquired;
    coasted += source == OrientationSource::kCoasted;
    overruled += source == OrientationSource::kPairRejected;
    rejected += r.orientation.location.ambiguous || r.orientation.location.rejected;
    blank += r.orientation.blank_wall;
    if (stereo)
      scaled.push_back(r.stereo_scale.status == StereoScaleStatus::kOk ? 1.0 : 0.0);
    line_matches.push_back(r.num_line_matches);
    line_inliers.push_back(r.estimate.estimate.num_line_inliers);
    junctions.push_back(r.estimate.estimate.junctions.size());
    junction_inliers.push_back(r.estimate.estimate.num_junction_inliers);
    vp_matches.push_back(r.matches.vps.size());
    vp_inliers.push_back(r.estimate.estimate.num_vp_inliers);
    lines_sum += r.num_line_matches;
    inliers_sum += r.estimate.estimate.num_line_inliers;
    tracked.push_back(r.line_tracking.matched);
    started.push_back(r.line_tracking.started);
  }
  std::printf("frames %d, estimated %d (%s, %s, %s)\n", frames, ok,
              o.concurrent ? "concurrent" : "sequential", o.track_lines ? "line tracking" : "LBD",
              o.klt.predict_motion ? "KLT prediction" : "KLT plain");
  // An odometry for a robot answers every frame: rotation-only ones too (the camera at rest or
  // turning in place), and its position stays where the data hold it.
  std::printf("# answers: %d of %d frames after the first have a pose (%.1f %%), %d of them "
              "rotation-only; the position at most %.4f %s from the first frame's\n",
              answered_frames, frames - 1,
              frames > 1 ? 100.0 * answered_frames / (frames - 1) : 0.0, rotation_only, farthest,
              stereo ? "m" : "per-pair units");
  std::printf("# keyframes: %d of %d frames; after the first second %d of %d answered frames have "
              "a baseline (%.1f %%; %d of them with the keyframe before), %d a measured "
              "translation (%.1f %%: with a baseline, or without one from the keyframe's depths "
              "or stereo points)\n",
              keyframes, frames, late_baselines, late_answers,
              late_answers > 0 ? 100.0 * late_baselines / late_answers : 0.0, late_before,
              late_translations, late_answers > 0 ? 100.0 * late_translations / late_answers : 0.0);
  {
    const KltTrackStats& t = vo.point_track_stats();
    const double per_frame = t.frames > 0 ? 1.0 / t.frames : 0.0;
    std::printf("# tracks: %.0f searched and %.0f new per frame, %.1f %% of the ended tracks lost at "
                "their first track, median lifetime %d frames (mean %.1f)\n",
                t.searched * per_frame, t.detected * per_frame,
                t.lost > 0 ? 100.0 * t.lost_at_first / t.lost : 0.0, t.median_lifetime(),
                t.lost > 0 ? static_cast<double>(t.lifetime_sum) / t.lost : 0.0);
    const VignettingEstimator& v = vo.point_track_vignetting();
    std::printf("# vignetting: the corners at %.3f of the centre's brightness (%d pairs, "
                "information %.1f), taken out for tracking on %d of %d frames\n",
                v.corner_gain(), v.pairs(), v.information(), vignetting_frames, frames);
  }
  // Starting to move (stereo, with a truth in the first camera's frame): where the camera went
  // from its start, once it is 5 cm or more away, against where it truly went, and its length.
  if (stereo && truth.size() == estimate.size() && !truth.empty()) {
    double worst = -1.0, first_frame = -1;
    double ratio = NAN;
    for (size_t k = 0; k < truth.size(); ++k) {
      // Both in the first camera's frame.
      const Eigen::Vector3d t_true = truth[0].R.transpose() * (truth[k].c - truth[0].c);
      const Eigen::Vector3d t_est = estimate[0].R.transpose() * (estimate[k].c - estimate[0].c);
      if (t_true.norm() < 0.05) continue;
      if (first_frame < 0) first_frame = static_cast<double>(k);
      const double angle = std::atan2(t_true.cross(t_est).norm(), t_true.dot(t_est)) * 180 / M_PI;
      worst = std::max(worst, angle);
      ratio = t_est.norm() / t_true.norm();
    }
    if (first_frame >= 0)
      std::printf("# from the start: once 5 cm away (frame %.0f on), the position's direction from "
                  "the start at most %.2f deg off; its length at the last frame %.4f of the "
                  "truth's\n",
                  first_frame, worst, ratio);
  }
  std::printf("median ms: total %.1f, front end %.1f, estimator %.1f; points %.1f, "
              "re-detection %.1f, lines %.1f, "
              "line matching %.1f, VPs %.1f, RANSAC %.1f; CPU per frame %.1f\n",
              median(total), median(frontend), median(estimator), median(points), median(redetect),
              median(lines), median(matching), median(vps), median(ransac), median(cpu));
  // What a machine's speed decides, whatever else runs on it: the frame cannot take less than
  // its longer thread's CPU time.
  std::printf("CPU ms per frame (median) by thread: calling %.1f, worker %.1f, the longer %.1f\n",
              median(caller_cpu), median(worker_cpu), median(longest_cpu));
  std::printf("CPU per frame: p95 %.1f ms; budget %.1f ms (0: none); frames at work level 0..%d:",
              percentile(cpu, 0.95), o.budget.max_cpu_ms, kMaxWorkLevel);
  for (int n : frames_at_level) std::printf(" %d", n);
  std::printf("\n");
  if (stereo) {
    double n = 0.0;
    for (double s : scaled) n += s;
    std::printf("stereo: median %.1f ms (second thread); metric scale on %.0f of %d estimated pairs\n",
                median(stereo_ms), n, ok);
  }
  std::printf("median per estimated frame: line matches %.0f, line inliers %.0f, segment tracks "
              "found %.0f, started %.0f; line inlier ratio %.3f of %.0f (pooled)\n",
              median(line_matches), median(line_inliers), median(tracked), median(started),
              lines_sum > 0.0 ? inliers_sum / lines_sum : 0.0, lines_sum);
  std::printf("segments detected in %d of %d frames\n", segment_detections, frames);
  if (!point_truth_px.empty())
    std::printf("matches under the true epipolar geometry (Sampson px, median / p90 / share "
                "beyond 2 px): points %.3f / %.3f / %.1f %% of %zu, junctions %.3f / %.3f / "
                "%.1f %% of %zu\n",
                median(point_truth_px), percentile(point_truth_px, 0.9),
                100.0 * std::count_if(point_truth_px.begin(), point_truth_px.end(),
                                      [](double e) { return e > 2.0; }) /
                    point_truth_px.size(),
                point_truth_px.size(),
                junction_truth_px.empty() ? NAN : median(junction_truth_px),
                junction_truth_px.empty() ? NAN : percentile(junction_truth_px, 0.9),
                junction_truth_px.empty()
                    ? NAN
                    : 100.0 *
                          std::count_if(junction_truth_px.begin(), junction_truth_px.end(),
                                        [](double e) { return e > 2.0; }) /
                          junction_truth_px.size(),
                junction_truth_px.size());
  std::printf("median per estimated frame: junctions %.0f (%.0f inliers), VPs %.0f (%.0f "
              "inliers)\n",
              median(junctions), median(junction_inliers), median(vp_matches),
              median(vp_inliers));
  int confirmed = 0;
  for (const MapDirection& d : vo.direction_map().directions()) confirmed += d.confirmed;
  std::printf("# map of directions: %d confirmed directions at the end; of %d estimated frames "
              "%d held by the map, %d re-acquisitions, %d corrections rejected, %d blank walls "
              "(%d coasted), %d pairs overruled\n",
              confirmed, ok, held, reacquired, rejected, blank, coasted, overruled);
  if (!pose_errors.empty() || !pair_rot_deg.empty()) {
    const evaluation::TrajectoryErrors te =
        evaluation::compare_trajectories(estimate, truth, !stereo, 0.01);
    std::printf("accuracy: pairs %zu, AUC@5/10/20 %.2f / %.2f / %.2f, drift %.2f %% and %.3f "
                "deg/100 m, ATE %.4f m (%s), RPE rotation %.4f deg\n",
                pose_errors.size(), 100.0 * pose_auc(pose_errors, 5.0),
                100.0 * pose_auc(pose_errors, 10.0), 100.0 * pose_auc(pose_errors, 20.0),
                te.drift_trans_percent, te.drift_rot_deg_per_100m, te.ate,
                stereo ? "metric" : "scale aligned", te.rpe_rot_deg);
    std::printf("rotation error (deg): median %.3f per estimated pair (%zu), %.3f over %g s "
                "windows (%zu), orientation against the first frame %.3f at the last frame and "
                "%.3f at most; median translation direction error %.2f deg\n",
                median(pair_rot_deg), pair_rot_deg.size(), te.rot_window_median_deg, te.window_s,
                te.rot_window_err_deg.size(), te.orientation_last_deg, te.orientation_max_deg,
                median(pair_dir_deg));
    auto consistency = [](const char* what, double truth_sigma, const std::vector<double>& nees,
                          int dof, const char* items) {
      std::printf("# consistency: %s (%d dof, truth sigma %g deg): %s\n", what, dof,
                  truth_sigma * 180.0 / M_PI,
                  evaluation::describe_nees(evaluation::summarize_nees(nees, dof), items).c_str());
    };
    consistency("rotation per pair", truth_rotation_sigma, pair_rot_nees, 3, "estimated pairs");
    consistency("translation direction per pair", truth_direction_sigma, pair_dir_nees, 2,
                "estimated pairs");
    if (!depth_dir_nees.empty()) {
      std::printf("median direction error of the translations without a baseline (from the "
                  "keyframe's depths) %.2f deg\n",
                  median(depth_dir_deg));
      consistency("translation direction without a baseline, from the keyframe's depths",
                  truth_direction_sigma, depth_dir_nees, 2, "pairs");
    }
    consistency("orientation against the first frame", truth_orientation_sigma, orientation_nees,
                3, "estimated frames");
    consistency(stereo ? "position from the start"
                       : "position from the start, in the unit of the first pair with a baseline",
                0.0, position_nees, 3, "estimated frames");
    if (stereo)
      consistency("metric translation per pair", 0.0, pair_t_nees, 3, "pairs with a scale");
    consistency("VP observation against the same direction's earlier one", 0.0,
                vp_sightings.nees(), 2, "sightings compared");
  }
  if (direct_gap > 0)
    print_direct_check(images, input.camera, odometry, truth, direct_gap,
                       o.estimator.ransac.seed);
  if (!trajectory_path.empty() &&
      !evaluation::write_tum_trajectory(trajectory_path, odometry, &error)) {
    std::cerr << error << "\n";
    return 1;
  }
  return 0;
}

}  // namespace
}  // namespace hybrid_vo

int main(int argc, char** argv) { return hybrid_vo::run(argc, argv); }
