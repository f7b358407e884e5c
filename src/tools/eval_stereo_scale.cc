// hybrid_vo_eval_stereo_scale: the metric scale of stereo odometry, estimator by estimator, on
// one run. A stereo bag (hybrid_vo_kitti_to_bag --stereo, hybrid_vo_render_sequence --stereo)
// goes through VisualOdometry frame by frame, without ROS and without dropped frames; every
// pair's stereo observations are then scaled by each candidate estimator, so that they differ
// in the scale alone (same matches, same unit motions), and each candidate's trajectory is
// compared with the ground truth.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <iostream>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <geometry_msgs/PoseStamped.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>

#include "hybrid_vo/estimation/stereo_scale.h"
#include "hybrid_vo/evaluation/command_line.h"
#include "hybrid_vo/evaluation/statistics.h"
#include "hybrid_vo/evaluation/trajectory.h"
#include "hybrid_vo/geometry/homogeneous.h"
#include "hybrid_vo/node/conversions.h"
#include "hybrid_vo/odometry/visual_odometry.h"
#include "hybrid_vo/render/renderer.h"
#include "hybrid_vo/render/scene.h"

namespace {

using hybrid_vo::StereoScaleObservation;
namespace evaluation = hybrid_vo::evaluation;
using evaluation::StampedPose;
using evaluation::Trajectory;

void usage(const char* program) {
  std::cerr << "Usage: " << program
            << " --bag STEREO.bag [--preset P] [--max-features N] [--frames N]\n"
               "       [--scene corridor|room [--seed N]] [--dump POINTS.csv]\n"
               "       [--klt-window PX] [--klt-predict 0|1] [--klt-predicted-levels N]\n"
               "       [--refine-tracks 0|1] [--refine-window PX]\n"
               "  Runs VisualOdometry over the bag's /camera/{left,right}/{image_raw,camera_info}\n"
               "  and compares stereo scale estimators against /ground_truth/pose: per pair the\n"
               "  ratio of estimated to true translation length, then per estimator the median\n"
               "  ratio (10th-90th percentile), drift and ATE of its metric trajectory.\n"
               "  --scene: the bag was rendered (hybrid_vo_render_sequence) from this scene: every\n"
               "  observation gets its exact depth by ray casting, the errors of the measured\n"
               "  disparities and points are summarised, and candidates with true values in place\n"
               "  of measured ones show which measurement a bias comes from. --dump writes them.\n";
}

struct StereoFrame {
  sensor_msgs::ImageConstPtr left, right;
  sensor_msgs::CameraInfoConstPtr left_info, right_info;
};

// Frames by stamp (ns) with all four messages, and the ground truth.
bool read_bag(const std::string& path, std::map<uint64_t, StereoFrame>* frames, Trajectory* gt,
              std::string* error) {
  rosbag::Bag bag;
  try {
    bag.open(path, rosbag::bagmode::Read);
  } catch (const rosbag::BagException& e) {
    *error = path + ": " + e.what();
    return false;
  }
  for (const rosbag::MessageInstance& m : rosbag::View(bag)) {
    const std::string& topic = m.getTopic();
    const bool left = topic.rfind("/camera/left/", 0) == 0;
    const bool right = topic.rfind("/camera/right/", 0) == 0;
    if (!left && !right) {
      if (const auto pose = m.instantiate<geometry_msgs::PoseStamped>()) {
        if (topic != "/ground_truth/pose") continue;
        StampedPose p;
        p.stamp = pose->header.stamp.toSec();
        const auto& q = pose->pose.orientation;
        p.R = Eigen::Quaterniond(q.w, q.x, q.y, q.z).normalized().toRotationMatrix();
        p.c = Eigen::Vector3d(pose->pose.position.x, pose->pose.position.y,
                              pose->pose.position.z);
        gt->push_back(p);
      }
    } else if (const auto image = m.instantiate<sensor_msgs::Image>()) {
      StereoFrame& f = (*frames)[image->header.stamp.toNSec()];
      (right ? f.right : f.left) = image;
    } else if (const auto info = m.instantiate<sensor_msgs::CameraInfo>()) {
      StereoFrame& f = (*frames)[info->header.stamp.toNSec()];
      (right ? f.right_info : f.left_info) = info;
    }
  }
  for (auto it = frames->begin(); it != frames->end();) {
    const StereoFrame& f = it->second;
    it = f.left && f.right && f.left_info && f.right_info ? std::next(it) : frames->erase(it);
  }
  std::sort(gt->begin(), gt->end(),
            [](const StampedPose& a, const StampedPose& b) { return a.stamp < b.stamp; });
  if (frames->empty() || gt->empty()) {
    *error = path + ": needs /camera/{left,right}/{image_raw,camera_info} and /ground_truth/pose";
    return false;
  }
  return true;
}

// What a pair leaves for the candidates: its unit motion, observations and the rig.
struct Pair {
  double stamp_ref = 0.0, stamp = 0.0;
  hybrid_vo::RelativePose unit;  // unit t
  hybrid_vo::StereoRig rig;
  std::vector<StereoScaleObservation> observations;
  double true_length = 0.0;
  // With --scene: the true unit motion and, per observation, its exact values (usable where
  // `exact` is set: 1 where the point lies on one surface within 1 px and is seen in both
  // frames, 2 where its whole tracking window does).
  bool has_truth = false;
  hybrid_vo::RelativePose true_unit;
  std::vector<StereoScaleObservation> truth;
  std::vector<char> exact;
};

// Depth along the ray of normalised point x from a camera at (R, c), or NaN when nothing is hit
// or the rays `pixel` (normalised) to its four sides hit another surface (a depth edge has no
// single depth).
double exact_depth(const hybrid_vo::render::Scene& scene, const Eigen::Matrix3d& R,
                   const Eigen::Vector3d& c, const Eigen::Vector2d& x, double pixel) {
  double z = 0.0;
  const int quad = hybrid_vo::render::cast_ray(scene, c, R * hybrid_vo::homogeneous(x), &z);
  if (quad < 0) return NAN;
  for (const Eigen::Vector2d& dx : {Eigen::Vector2d(pixel, 0), Eigen::Vector2d(-pixel, 0),
                                    Eigen::Vector2d(0, pixel), Eigen::Vector2d(0, -pixel)}) {
    double zn = 0.0;
    if (hybrid_vo::render::cast_ray(scene, c, R * hybrid_vo::homogeneous(x + dx), &zn) != quad)
      return NAN;
  }
  return z;
}

// Fills the pair's truth from the ground-truth poses of its two frames (left optical cameras).
void add_truth(const hybrid_vo::render::Scene& scene, const StampedPose& a, const StampedPose& b,
               Pair* p) {
  const double fb = p->rig.fx * p->rig.baseline_m, pixel = 1.0 / p->rig.fx;
  p->has_truth = true;
  p->true_unit = hybrid_vo::RelativePose(b.R.transpose() * a.R,
                                         (b.R.transpose() * (a.c - b.c)).normalized());
  p->truth = p->observations;
  p->exact.assign(p->observations.size(), 0);
  for (size_t i = 0; i < p->observations.size(); ++i) {
    StereoScaleObservation& t = p->truth[i];
    const double z = exact_depth(scene, a.R, a.c, t.x_ref, pixel);
    if (!std::isfinite(z)) continue;
    const Eigen::Vector3d X = a.c + a.R * (z * hybrid_vo::homogeneous(t.x_ref));
    const Eigen::Vector3d Xb = b.R.transpose() * (X - b.c);
    if (!(Xb.z() > 0.05)) continue;
    // Seen in the current frame: the ray there hits the same point first.
    const double zb = exact_depth(scene, b.R, b.c, Xb.head<2>() / Xb.z(), pixel);
    if (!(std::abs(zb - Xb.z()) < 1e-6 * (1.0 + Xb.z()))) continue;
    t.disparity_ref = fb / z;
    t.x_cur = Xb.head<2>() / Xb.z();
    if (t.disparity_cur > 0.0) t.disparity_cur = fb / Xb.z();
    // 2: the tracking window around it (+-10 px) lies on that surface too.
    const bool window = std::isfinite(exact_depth(scene, a.R, a.c, t.x_ref, 10.0 * pixel)) &&
                        std::isfinite(exact_depth(scene, a.R, a.c, t.x_ref, 5.0 * pixel));
    p->exact[i] = window ? 2 : 1;
  }
}

// A scale estimator: the scale, or NaN, and optionally its sigma.
using Candidate = std::function<double(const Pair&, double* sigma)>;

// The measured values' errors on the exact points, by true keyframe disparity: a disparity's
// (pixels), and the current point's along its translational flow (pixels; positive: the point
// moved farther than it did), the ones that carry the scale.
void print_truth_errors(const std::vector<Pair>& pairs) {
  const std::vector<double> edges = {0.0, 5.0, 8.0, 11.52, 16.0, 24.0, 40.0, 1e9};
  const size_t bins = edges.size() - 1;
  std::vector<std::vector<double>> e_ref(bins), e_cur(bins), e_flow(bins), e_across(bins);
  int exact = 0, all = 0;
  for (const Pair& p : pairs) {
    if (!p.has_truth) continue;
    for (size_t i = 0; i < p.observations.size(); ++i) {
      ++all;
      if (!p.exact[i]) continue;
      ++exact;
      const StereoScaleObservation &o = p.observations[i], &t = p.truth[i];
      const size_t b = std::upper_bound(edges.begin(), edges.end(), t.disparity_ref) -
                       edges.begin() - 1;
      e_ref[b].push_back(o.disparity_ref - t.disparity_ref);
      if (o.disparity_cur > 0.0) e_cur[b].push_back(o.disparity_cur - t.disparity_cur);
      const Eigen::Vector3d r = p.true_unit.R * hybrid_vo::homogeneous(t.x_ref);
      const Eigen::Vector2d flow = t.x_cur - r.head<2>() / r.z();
      if (!(flow.norm() > 1e-9)) continue;
      const Eigen::Vector2d u = flow.normalized(), e = (o.x_cur - t.x_cur) * p.rig.fx;
      e_flow[b].push_back(e.dot(u));
      e_across[b].push_back(u.x() * e.y() - u.y() * e.x());
    }
  }
  std::printf("# truth: %d of %d observations exact (one surface, seen in both frames)\n", exact,
              all);
  std::printf("# true d_ref (px)  n  d_ref error median/mean  d_cur error median/mean  "
              "x_cur error along flow median/mean, across median\n");
  auto mean = [](const std::vector<double>& v) {
    double sum = 0.0;
    for (double x : v) sum += x;
    return v.empty() ? NAN : sum / v.size();
  };
  for (size_t b = 0; b < bins; ++b)
    std::printf("# [%5.2f, %5.2f) %6zu  %+.4f %+.4f  %+.4f %+.4f  %+.4f %+.4f  %+.4f\n",
                edges[b], std::min(edges[b + 1], 999.0), e_ref[b].size(),
                evaluation::median(e_ref[b]), mean(e_ref[b]), evaluation::median(e_cur[b]),
                mean(e_cur[b]), evaluation::median(e_flow[b]), mean(e_flow[b]),
                evaluation::median(e_across[b]));
}

// One line per pair (P: index, rig, unit and true motion) and per observation (O: measured and,
// where exact, true values) for analysis elsewhere.
bool write_dump(const std::string& path, const std::vector<Pair>& pairs) {
  FILE* f = std::fopen(path.c_str(), "w");
  if (!f) return false;
  for (size_t k = 0; k < pairs.size(); ++k) {
    const Pair& p = pairs[k];
    std::fprintf(f, "P,%zu,%.9g,%.9g,%.9g,%.9g", k, p.rig.fx, p.rig.fy, p.rig.baseline_m,
                 p.true_length);
    for (const hybrid_vo::RelativePose* m : {&p.unit, &p.true_unit}) {
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) std::fprintf(f, ",%.12g", m->R(r, c));
      for (int r = 0; r < 3; ++r) std::fprintf(f, ",%.12g", m->t(r));
    }
    std::fprintf(f, "\n");
    for (size_t i = 0; i < p.observations.size(); ++i) {
      const StereoScaleObservation& o = p.observations[i];
      const StereoScaleObservation& t = p.has_truth ? p.truth[i] : o;
      std::fprintf(f, "O,%zu,%d,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g\n", k,
                   p.has_truth ? p.exact[i] : 0, o.x_ref.x(), o.x_ref.y(), o.disparity_ref,
                   o.x_cur.x(), o.x_cur.y(), o.disparity_cur, t.disparity_ref, t.x_cur.x(),
                   t.x_cur.y(), t.disparity_cur);
    }
  }
  return std::fclose(f) == 0;
}

}  // namespace

int main(int argc, char** argv) {
  std::string bag, preset = "hybrid", scene_name, dump;
  int max_features = 1000, max_frames = 1 << 30;
  uint64_t seed = 1;
  hybrid_vo::KltTrackerOptions klt;
  bool refine_tracks = hybrid_vo::VisualOdometryOptions().stereo_refine_tracks;
  int refine_window = hybrid_vo::AffineTrackingOptions().window_px;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&] { return evaluation::option_value(argc, argv, &i); };
    if (a == "--bag") bag = next();
    else if (a == "--preset") preset = next();
    else if (a == "--max-features") max_features = std::stoi(next());
    else if (a == "--frames") max_frames = std::stoi(next());
    else if (a == "--scene") scene_name = next();
    else if (a == "--seed") seed = std::stoull(next());
    else if (a == "--dump") dump = next();
    else if (a == "--klt-window") klt.window_px = std::stoi(next());
    else if (a == "--klt-predict") klt.predict_motion = std::stoi(next()) != 0;
    else if (a == "--klt-predicted-levels") klt.predicted_pyramid_levels = std::stoi(next());
    else if (a == "--refine-tracks") refine_tracks = std::stoi(next()) != 0;
    else if (a == "--refine-window") refine_window = std::stoi(next());
    else if (a == "--help" || a == "-h") {
      usage(argv[0]);
      return 0;
    } else {
      std::cerr << "error: unknown argument '" << a << "'\n";
      usage(argv[0]);
      return 2;
    }
  }
  if (bag.empty()) {
    usage(argv[0]);
    return 2;
  }
  std::unique_ptr<hybrid_vo::render::Scene> scene;
  if (!scene_name.empty()) {
    hybrid_vo::render::SceneOptions scene_options;
    if (!hybrid_vo::render::parse_scene_type(scene_name, &scene_options.type)) {
      std::cerr << "error: unknown scene '" << scene_name << "'\n";
      return 2;
    }
    scene_options.seed = seed;
    scene = std::make_unique<hybrid_vo::render::Scene>(hybrid_vo::render::build_scene(scene_options));
  }
  std::map<uint64_t, StereoFrame> frames;
  Trajectory gt;
  std::string error;
  if (!read_bag(bag, &frames, &gt, &error)) {
    std::cerr << "error: " << error << "\n";
    return 1;
  }

  hybrid_vo::VisualOdometryOptions options;
  if (!hybrid_vo::preset_options(preset, &options.estimator)) {
    std::cerr << "error: unknown preset '" << preset << "'\n";
    return 2;
  }
  options.klt = klt;
  options.stereo_refine_tracks = refine_tracks;
  options.stereo_track_refinement.window_px = refine_window;
  options.features.points.max_features = max_features;
  options.estimator.vp_detection.min_inliers = 6;  // as the node
  hybrid_vo::VisualOdometry vo(options);

  // Run once; keep each pair's data and the rotations (the same for every candidate).
  std::vector<Pair> pairs;
  std::map<double, Eigen::Matrix3d> rotation_at;  // camera-to-odometry rotation by stamp
  std::vector<double> total_ms, scale_ms;
  int n = 0;
  for (const auto& [stamp_ns, f] : frames) {
    if (n++ >= max_frames) break;
    hybrid_vo::VisualOdometryInput input;
    input.stamp = f.left->header.stamp.toSec();
    if (!hybrid_vo::camera_from_info(*f.left_info, &input.camera, &error) ||
        !hybrid_vo::gray_from_image(f.left, &input.image, &error) ||
        !hybrid_vo::gray_from_image(f.right, &input.right_image, &error) ||
        !hybrid_vo::baseline_from_info(*f.right_info, &input.baseline_m)) {
      std::cerr << "error: frame " << input.stamp << ": " << error << "\n";
      return 1;
    }
    const hybrid_vo::VisualOdometryResult r = vo.process(input);
    total_ms.push_back(r.total_ms);
    if (r.status == hybrid_vo::VoStatus::kOk) scale_ms.push_back(r.stages.scale_ms);
    if (r.status == hybrid_vo::VoStatus::kFirstFrame) rotation_at[input.stamp] = r.R_wc;
    if (r.status != hybrid_vo::VoStatus::kOk) continue;
    rotation_at[input.stamp] = r.R_wc;
    Pair p;
    p.stamp_ref = r.reference_stamp;
    p.stamp = input.stamp;
    p.unit = r.estimate.estimate.pose;
    p.rig = {input.camera.pinhole.fx, input.camera.pinhole.fy, input.baseline_m};
    p.observations = r.scale_observations;
    StampedPose a, b;
    if (evaluation::pose_at(gt, p.stamp_ref, 1e-3, &a) &&
        evaluation::pose_at(gt, p.stamp, 1e-3, &b)) {
      p.true_length = (b.c - a.c).norm();
      if (scene) add_truth(*scene, a, b, &p);
    }
    pairs.push_back(std::move(p));
  }

  struct Named {
    std::string name;
    Candidate estimate;
  };
  auto ml = [](double max_baselines, double offset_sigma = 0.0, bool motion = false) {
    return [=](const Pair& p, double* sigma) {
      hybrid_vo::StereoScaleOptions o;
      o.max_depth_baselines = max_baselines;
      o.disparity_offset_sigma_px = offset_sigma;
      o.refine_motion = motion;
      const hybrid_vo::StereoScaleEstimate e =
          hybrid_vo::estimate_stereo_scale(p.unit, p.rig, p.observations, o);
      *sigma = e.sigma;
      return e.status == hybrid_vo::StereoScaleStatus::kOk ? e.scale : NAN;
    };
  };
  // The node's default: the depth-limited fit with the self-calibrated disparity offset
  // (DisparityOffsetFilter, updated pair by pair as VisualOdometry does).
  std::vector<std::shared_ptr<hybrid_vo::DisparityOffsetFilter>> filters;  // the default's first
  // filter_point_sigma_px > 0: the offset filter's fit weighs the current points so too.
  auto calibrated = [&filters](double max_baselines, double offset_sigma = 0.0,
                               double point_sigma_px = hybrid_vo::StereoScaleOptions().point_sigma_px,
                               double filter_point_sigma_px = 0.0) {
    auto filter = std::make_shared<hybrid_vo::DisparityOffsetFilter>();
    filters.push_back(filter);
    return [=](const Pair& p, double* sigma) {
      hybrid_vo::StereoScaleOptions o;
      if (filter_point_sigma_px > 0.0) o.point_sigma_px = filter_point_sigma_px;
      filter->update(p.unit, p.rig, p.observations, o);
      o = hybrid_vo::StereoScaleOptions();
      o.max_depth_baselines = max_baselines;
      o.disparity_offset_px = filter->offset();
      o.disparity_offset_sigma_px = offset_sigma;
      o.point_sigma_px = point_sigma_px;
      const hybrid_vo::StereoScaleEstimate e =
          hybrid_vo::estimate_stereo_scale(p.unit, p.rig, p.observations, o);
      *sigma = e.sigma;
      return e.status == hybrid_vo::StereoScaleStatus::kOk ? e.scale : NAN;
    };
  };
  std::vector<Named> candidates = {
      {"default", calibrated(40.0)},
      {"calibrated", calibrated(0.0)},
      // Softer than the hard limit: a farther one, or the offset left free in each pair's fit
      // around the calibrated one with a prior sigma (px), which discounts the far points'
      // scale information by how well the offset is known (doc/stereo_scale.md).
      {"cal<60b", calibrated(60.0)},
      {"cal+p0.1", calibrated(0.0, 0.1)},
      {"cal+p0.2", calibrated(0.0, 0.2)},
      {"cal<40b+p0.1", calibrated(40.0, 0.1)},
      // The current points' noise (pixels) in the fit, and in the offset filter's fit (f): the
      // tracker's points' weight (0.5), the refined points' measured one (0.3, as the
      // disparities'), and mixtures.
      {"pt0.5", calibrated(40.0, 0.0, 0.5, 0.5)},
      {"pt0.3", calibrated(40.0, 0.0, 0.3, 0.3)},
      {"pt0.3,f0.5", calibrated(40.0, 0.0, 0.3, 0.5)},
      {"pt0.25,f0.5", calibrated(40.0, 0.0, 0.25, 0.5)},
      {"median", [](const Pair& p, double*) { return hybrid_vo::median_of_point_scales(p.unit, p.rig, p.observations, 0.0); }},
      {"median<40b", [](const Pair& p, double*) { return hybrid_vo::median_of_point_scales(p.unit, p.rig, p.observations, 40.0); }},
      {"ml", ml(0.0)},
      {"ml<40b", ml(40.0)},
      {"ml+offset", ml(0.0, INFINITY)},
      {"ml+offset<40b", ml(40.0, INFINITY)},
      {"ml+motion<40b", ml(40.0, 0.0, true)},
      {"ml+motion+offset", ml(0.0, INFINITY, true)},
  };

  if (scene) {
    // Which measurement a bias comes from: the same fit on the exact points only, with true
    // values in place of the measured ones (all true must give 1).
    enum : int { kMotion = 1, kDref = 2, kXcur = 4, kDcur = 8, kAll = 15 };
    auto with_truth = [](int which) {
      return [=](const Pair& p, double* sigma) {
        if (!p.has_truth) return double(NAN);
        std::vector<StereoScaleObservation> obs;
        for (size_t i = 0; i < p.observations.size(); ++i) {
          if (!p.exact[i]) continue;
          StereoScaleObservation o = p.observations[i];
          const StereoScaleObservation& t = p.truth[i];
          if (which & kDref) o.disparity_ref = t.disparity_ref;
          if (which & kXcur) o.x_cur = t.x_cur;
          if ((which & kDcur) && o.disparity_cur > 0.0) o.disparity_cur = t.disparity_cur;
          obs.push_back(o);
        }
        const hybrid_vo::RelativePose& m = which & kMotion ? p.true_unit : p.unit;
        const hybrid_vo::StereoScaleEstimate e = hybrid_vo::estimate_stereo_scale(m, p.rig, obs);
        *sigma = e.sigma;
        // The scale of the true direction is comparable with the estimated one's: both unit.
        return e.status == hybrid_vo::StereoScaleStatus::kOk ? e.scale : NAN;
      };
    };
    candidates.push_back({"exact pts", with_truth(0)});
    candidates.push_back({"+motion", with_truth(kMotion)});
    candidates.push_back({"+d_ref", with_truth(kDref)});
    candidates.push_back({"+x_cur", with_truth(kXcur)});
    candidates.push_back({"+d_cur", with_truth(kDcur)});
    candidates.push_back({"+d_ref+d_cur", with_truth(kDref | kDcur)});
    candidates.push_back({"all true", with_truth(kAll)});
    candidates.push_back({"true-motion", with_truth(kAll & ~kMotion)});
    candidates.push_back({"true-d_ref", with_truth(kAll & ~kDref)});
    candidates.push_back({"true-x_cur", with_truth(kAll & ~kXcur)});
    candidates.push_back({"true-d_cur", with_truth(kAll & ~kDcur)});
  }

  std::printf("pair,stamp,true_m,observations");
  for (const Named& c : candidates) std::printf(",%s", c.name.c_str());
  std::printf("\n");
  std::vector<std::vector<double>> ratios(candidates.size()), z(candidates.size());
  std::vector<Trajectory> trajectories(candidates.size());
  std::vector<std::map<double, Eigen::Vector3d>> centres(candidates.size());
  for (size_t k = 0; k < candidates.size(); ++k) {
    const double first = rotation_at.empty() ? 0.0 : rotation_at.begin()->first;
    centres[k][first] = Eigen::Vector3d::Zero();
  }
  for (size_t i = 0; i < pairs.size(); ++i) {
    const Pair& p = pairs[i];
    std::printf("%zu,%.6f,%.4f,%zu", i, p.stamp, p.true_length, p.observations.size());
    for (size_t k = 0; k < candidates.size(); ++k) {
      double sigma = 0.0;
      double s = candidates[k].estimate(p, &sigma);
      const double ratio = p.true_length > 0.0 ? s / p.true_length : NAN;
      std::printf(",%.4f", ratio);
      if (std::isfinite(ratio)) ratios[k].push_back(ratio);
      if (std::isfinite(s) && sigma > 0.0) z[k].push_back(std::abs(s - p.true_length) / sigma);
      if (!std::isfinite(s)) s = 1.0;  // the node's fallback, mono_scale
      // Integrate as VisualOdometry does: the current centre is c_ref - R_wc,ref R^T t.
      const auto ref = centres[k].find(p.stamp_ref);
      const auto rot = rotation_at.find(p.stamp_ref);
      if (ref == centres[k].end() || rot == rotation_at.end()) continue;
      centres[k][p.stamp] = ref->second - rot->second * p.unit.R.transpose() * (s * p.unit.t);
    }
    std::printf("\n");
  }
  std::printf("# %zu frames, %zu pairs estimated; VisualOdometry median %.1f ms per frame, "
              "scale (refinement and fit) %.2f ms\n",
              frames.size(), pairs.size(), evaluation::median(total_ms),
              evaluation::median(scale_ms));
  for (size_t k = 0; k < candidates.size(); ++k) {
    Trajectory t;
    for (const auto& [stamp, c] : centres[k]) {
      StampedPose sp;
      sp.stamp = stamp;
      sp.R = rotation_at.at(stamp);
      sp.c = c;
      t.push_back(sp);
    }
    const evaluation::TrajectoryErrors te =
        evaluation::compare_trajectories(t, gt, false, 1e-3);
    double within = 0.0;
    for (double v : z[k]) within += v <= 1.0;
    std::printf("%-12s ratio median %.4f (p10 %.4f, p90 %.4f) over %zu pairs; drift %.2f %% "
                "%.3f deg/100 m; ATE %.4f m",
                candidates[k].name.c_str(), evaluation::median(ratios[k]),
                evaluation::percentile(ratios[k], 0.1), evaluation::percentile(ratios[k], 0.9),
                ratios[k].size(),
                te.drift_trans_percent, te.drift_rot_deg_per_100m, te.ate);
    if (!z[k].empty())
      std::printf("; |error| <= sigma in %.0f %% of pairs", 100.0 * within / z[k].size());
    std::printf("\n");
  }
  const hybrid_vo::DisparityOffsetFilter& filter = *filters.front();
  std::printf("# default: disparity offset %.3f px applied at the end (filter mean %.3f, sigma "
              "%.3f px, %d pairs)\n",
              filter.offset(), filter.mean(), filter.sigma(), filter.pairs());
  if (scene) print_truth_errors(pairs);
  if (!dump.empty() && !write_dump(dump, pairs)) {
    std::cerr << "error: cannot write " << dump << "\n";
    return 1;
  }
  return 0;
}
