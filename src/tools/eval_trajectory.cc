// hybrid_vo_eval_trajectory: a recorded run (its ~relative_pose messages and /tf) against the
// ground truth written by the renderer or a converter; or two TUM trajectory files.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <geometry_msgs/PoseStamped.h>
#include <hybrid_vo/MotionEstimate.h>
#include <hybrid_vo/VanishingPoints.h>
#include <nav_msgs/Odometry.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <tf2_msgs/TFMessage.h>

#include "hybrid_vo/evaluation/consistency.h"
#include "hybrid_vo/evaluation/plot.h"
#include "hybrid_vo/evaluation/statistics.h"
#include "hybrid_vo/evaluation/trajectory.h"
#include "hybrid_vo/geometry/pose_error.h"

namespace {

namespace evaluation = hybrid_vo::evaluation;
using evaluation::StampedPose;
using evaluation::Trajectory;
constexpr double kDeg = 180.0 / M_PI;

void usage(const char* program) {
  std::cerr << "Usage: " << program
            << " --bag RUN.bag --gt GT.bag [--gt-topic /ground_truth/pose] [--plot OUT.png]"
               " [--window S]\n"
               "         [--truth-rotation-sigma-deg S] [--truth-direction-sigma-deg S]"
               " [--truth-orientation-sigma-deg S] [--truth-position-sigma-m S]\n"
               "       " << program << " --tum EST.txt GT.txt [--plot OUT.png] [--window S]\n"
               "  Per-pair rotation and translation-direction errors with AUC@5/10/20, RPE, ATE\n"
               "  after alignment (similarity without metric scale), KITTI-style drift, and a plot.\n"
               "  Rotation in degrees: median per pair (the node's estimates with status OK, else\n"
               "  consecutive poses), median over windows of S seconds (default 1), orientation\n"
               "  against the first frame at the last frame and at most; the median translation\n"
               "  direction error.\n"
               "  From a bag, '# consistency:' lines: whether the reported covariances hold the\n"
               "  errors (NEES, chi-square with 3 dof for rotations and 2 for directions when\n"
               "  honest): per pair the rotation and the translation direction (~relative_pose's\n"
               "  covariance), and the orientation against the first frame (~odometry's pose\n"
               "  covariance). The truth's own noise, degrees per axis, is added to the\n"
               "  covariance: --truth-rotation-sigma-deg to each pair's rotation,\n"
               "  --truth-direction-sigma-deg to each pair's direction,\n"
               "  --truth-orientation-sigma-deg to the orientation against the first frame\n"
               "  (default 0 each); --truth-position-sigma-m, metres per axis, moves each pair's\n"
               "  true direction by sqrt(2) S / its baseline, added to the direction's.\n"
               "  Last line: summary: pairs=N auc5=X auc10=X auc20=X rpe_trans=X rpe_rot_deg=X ate=X\n"
               "  rot_pair_deg=X rot_window_deg=X window_s=S orient_last_deg=X orient_max_deg=X\n"
               "  dir_deg=X nees_rot_pair=X in95_rot_pair=P nees_orient=X in95_orient=P\n"
               "  (median NEES and percent inside the 95 % ellipsoid; nan without covariances)\n";
}

using evaluation::median;

StampedPose from_transform(double stamp, const geometry_msgs::Transform& t) {
  StampedPose p;
  p.stamp = stamp;
  p.R = Eigen::Quaterniond(t.rotation.w, t.rotation.x, t.rotation.y, t.rotation.z)
            .normalized()
            .toRotationMatrix();
  p.c = Eigen::Vector3d(t.translation.x, t.translation.y, t.translation.z);
  return p;
}

// A ~odometry message: the camera's pose in the odometry frame and the covariances as published.
// The pose covariance needs no mapping to the camera: a left increment about the odom frame's
// fixed axes is the same for every frame rigidly attached to the body.
struct OdometrySample {
  StampedPose camera;
  nav_msgs::Odometry::_pose_type::_covariance_type pose_covariance;
  bool twist_covariance = false;  // any non-zero entry
};

// The pose of a frame through its static transform to another, e.g. base_link -> camera.
StampedPose through(StampedPose p, const geometry_msgs::Transform& link) {
  const StampedPose l = from_transform(0.0, link);
  p.c = p.c + p.R * l.c;
  p.R = p.R * l.R;
  return p;
}

struct Run {
  Trajectory trajectory;  // camera poses in the odometry frame
  std::vector<hybrid_vo::MotionEstimate> motions;
  int scale_known = 0;
  std::vector<OdometrySample> odometry;
  std::vector<hybrid_vo::VanishingPoints> vanishing_points;  // ~vanishing_points, one a frame
};

bool any_nonzero(const boost::array<double, 36>& values) {
  return std::any_of(values.begin(), values.end(), [](double v) { return v != 0.0; });
}

bool read_run(const std::string& path, Run* run, std::string* error) {
  rosbag::Bag bag;
  try {
    bag.open(path, rosbag::bagmode::Read);
  } catch (const rosbag::BagException& e) {
    *error = path + ": " + e.what();
    return false;
  }
  // odom -> child poses over time, and static transforms (e.g. base_link -> camera), to the
  // camera frame of the ~relative_pose messages.
  std::map<std::string, Trajectory> by_child;
  std::map<std::pair<std::string, std::string>, geometry_msgs::Transform> statics;
  std::vector<nav_msgs::Odometry> odometry;
  for (const rosbag::MessageInstance& m : rosbag::View(bag)) {
    if (const auto tf = m.instantiate<tf2_msgs::TFMessage>()) {
      for (const auto& t : tf->transforms) {
        if (m.getTopic() == "/tf_static") statics[{t.header.frame_id, t.child_frame_id}] = t.transform;
        else if (t.header.frame_id == "odom")
          by_child[t.child_frame_id].push_back(from_transform(t.header.stamp.toSec(), t.transform));
      }
    } else if (const auto motion = m.instantiate<hybrid_vo::MotionEstimate>()) {
      run->motions.push_back(*motion);
      run->scale_known += motion->scale_known;
    } else if (const auto o = m.instantiate<nav_msgs::Odometry>()) {
      odometry.push_back(*o);
    } else if (const auto v = m.instantiate<hybrid_vo::VanishingPoints>()) {
      run->vanishing_points.push_back(*v);
    }
  }
  bag.close();
  if (by_child.empty() && run->motions.empty()) {
    *error = path + ": no odom transforms and no hybrid_vo/MotionEstimate messages";
    return false;
  }
  const std::string camera_frame = run->motions.empty() ? "" : run->motions.front().header.frame_id;
  if (!by_child.empty()) {
    // The longest odom -> child track; through a static child -> camera transform when one is
    // known, so that the poses are camera poses like the ground truth.
    auto best = by_child.begin();
    for (auto it = by_child.begin(); it != by_child.end(); ++it)
      if (it->second.size() > best->second.size()) best = it;
    const auto link = statics.find({best->first, camera_frame});
    for (const StampedPose& p : best->second)
      run->trajectory.push_back(link != statics.end() ? through(p, link->second) : p);
    std::sort(run->trajectory.begin(), run->trajectory.end(),
              [](const StampedPose& a, const StampedPose& b) { return a.stamp < b.stamp; });
  }
  for (const nav_msgs::Odometry& o : odometry) {
    geometry_msgs::Transform pose;
    pose.translation.x = o.pose.pose.position.x;
    pose.translation.y = o.pose.pose.position.y;
    pose.translation.z = o.pose.pose.position.z;
    pose.rotation = o.pose.pose.orientation;
    OdometrySample sample;
    sample.camera = from_transform(o.header.stamp.toSec(), pose);
    const auto link = statics.find({o.child_frame_id, camera_frame});
    if (link != statics.end()) sample.camera = through(sample.camera, link->second);
    sample.pose_covariance = o.pose.covariance;
    sample.twist_covariance = any_nonzero(o.twist.covariance);
    run->odometry.push_back(sample);
  }
  std::sort(run->odometry.begin(), run->odometry.end(),
            [](const OdometrySample& a, const OdometrySample& b) {
              return a.camera.stamp < b.camera.stamp;
            });
  return true;
}

bool read_gt(const std::string& path, const std::string& topic, Trajectory* gt, std::string* error) {
  rosbag::Bag bag;
  try {
    bag.open(path, rosbag::bagmode::Read);
  } catch (const rosbag::BagException& e) {
    *error = path + ": " + e.what();
    return false;
  }
  for (const rosbag::MessageInstance& m : rosbag::View(bag, rosbag::TopicQuery(topic))) {
    if (const auto pose = m.instantiate<geometry_msgs::PoseStamped>()) {
      StampedPose p;
      p.stamp = pose->header.stamp.toSec();
      const auto& q = pose->pose.orientation;
      p.R = Eigen::Quaterniond(q.w, q.x, q.y, q.z).normalized().toRotationMatrix();
      p.c = Eigen::Vector3d(pose->pose.position.x, pose->pose.position.y, pose->pose.position.z);
      gt->push_back(p);
    }
  }
  bag.close();
  if (gt->empty()) {
    *error = path + ": no geometry_msgs/PoseStamped on " + topic;
    return false;
  }
  std::sort(gt->begin(), gt->end(),
            [](const StampedPose& a, const StampedPose& b) { return a.stamp < b.stamp; });
  return true;
}

// How the map of world directions served the estimated frames, as bench_frontend prints it.
void print_map_summary(const std::vector<hybrid_vo::MotionEstimate>& motions) {
  using M = hybrid_vo::MotionEstimate;
  int estimated = 0, held = 0, reacquired = 0, rejected = 0, blank = 0, coasted = 0,
      overruled = 0, directions = 0;
  for (const M& m : motions) {
    if (m.status != M::STATUS_OK) continue;
    ++estimated;
    held += m.orientation_source == M::ORIENTATION_MAP ||
            m.orientation_source == M::ORIENTATION_REACQUIRED;
    reacquired += m.orientation_source == M::ORIENTATION_REACQUIRED;
    coasted += m.orientation_source == M::ORIENTATION_COASTED;
    overruled += m.orientation_source == M::ORIENTATION_PAIR_REJECTED;
    rejected += m.map_correction_rejected;
    blank += m.blank_wall;
    directions = m.map_directions;
  }
  std::printf("# map of directions: %d confirmed directions at the end; of %d estimated frames "
              "%d held by the map, %d re-acquisitions, %d corrections rejected, %d blank walls "
              "(%d coasted), %d pairs overruled\n",
              directions, estimated, held, reacquired, rejected, blank, coasted, overruled);
}

// One `# consistency:` line.
void print_consistency(const char* what, double truth_sigma, const evaluation::NeesSummary& nees,
                       const char* items, const std::string& more) {
  std::printf("# consistency: %s (%d dof, truth sigma %g deg): %s%s\n", what, nees.dof,
              truth_sigma * kDeg, evaluation::describe_nees(nees, items).c_str(), more.c_str());
}

// The orientation against the first frame from ~odometry's pose covariance (ROS order: x y z,
// then the rotation), the first odometry pose with a true pose being the reference; and how
// many messages carry a pose and a twist covariance at all.
evaluation::NeesSummary orientation_consistency(const std::vector<OdometrySample>& odometry,
                                                const Trajectory& gt, double tolerance,
                                                double truth_sigma) {
  const char* what = "orientation against the first frame";
  if (odometry.empty()) {
    std::printf("# consistency: %s: no nav_msgs/Odometry recorded\n", what);
    return evaluation::summarize_nees({}, 3);
  }
  std::vector<double> nees;
  int with_pose = 0, with_twist = 0;
  const OdometrySample* first = nullptr;
  StampedPose first_truth;
  for (const OdometrySample& o : odometry) {
    with_pose += any_nonzero(o.pose_covariance);
    with_twist += o.twist_covariance;
    StampedPose truth;
    if (!evaluation::pose_at(gt, o.camera.stamp, tolerance, &truth)) continue;
    if (!first) {
      first = &o;
      first_truth = truth;
      continue;
    }
    nees.push_back(evaluation::orientation_nees(
        first->camera.R, o.camera.R, first_truth.R, truth.R,
        evaluation::covariance_block(o.pose_covariance.data(), 3), truth_sigma));
  }
  const evaluation::NeesSummary summary = evaluation::summarize_nees(nees, 3);
  char more[160];
  std::snprintf(more, sizeof(more),
                "; %.1f %% of %zu odometry messages with a pose covariance, %.1f %% with a twist "
                "covariance",
                100.0 * with_pose / odometry.size(), odometry.size(),
                100.0 * with_twist / odometry.size());
  print_consistency(what, truth_sigma, summary, "poses", more);
  return summary;
}

// The VP observations on ~vanishing_points (each direction seen, with its covariance) against
// the truth: a sighting against the same direction's at least 5 messages before, under the true
// rotation between the two frames (evaluation::DirectionSightings). Runs recorded before the
// observations were published carry none: no line.
void vp_observation_consistency(const std::vector<hybrid_vo::VanishingPoints>& messages,
                                const Trajectory& gt, double tolerance) {
  evaluation::DirectionSightings sightings;
  int observed = 0;
  for (size_t i = 0; i < messages.size(); ++i) {
    StampedPose truth;
    if (!evaluation::pose_at(gt, messages[i].header.stamp.toSec(), tolerance, &truth)) continue;
    for (const hybrid_vo::VanishingPoint& vp : messages[i].vps) {
      const Eigen::Vector3d d(vp.observation_camera.x, vp.observation_camera.y,
                              vp.observation_camera.z);
      if (!vp.seen || !(d.norm() > 0.0)) continue;
      ++observed;
      sightings.add(static_cast<int>(i), vp.id, d,
                    Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(
                        vp.observation_covariance.data()),
                    truth.R);
    }
  }
  if (observed > 0)
    print_consistency("VP observation against the same direction's earlier one", 0.0,
                      evaluation::summarize_nees(sightings.nees(), 2), "sightings compared", "");
}

}  // namespace

int main(int argc, char** argv) {
  std::string bag, gt_bag, gt_topic = "/ground_truth/pose", tum_est, tum_gt, plot;
  double window_s = evaluation::kDefaultRotationWindowSeconds;
  // The truth's own noise (radians per axis) for the NEES.
  double truth_rotation_sigma = 0.0, truth_direction_sigma = 0.0, truth_orientation_sigma = 0.0;
  double truth_position_sigma = 0.0;  // metres per axis
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::cerr << "error: " << a << " needs a value\n";
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--bag") bag = next();
    else if (a == "--gt") gt_bag = next();
    else if (a == "--gt-topic") gt_topic = next();
    else if (a == "--plot") plot = next();
    else if (a == "--window") {
      const std::string v = next();
      char* end = nullptr;
      window_s = std::strtod(v.c_str(), &end);
      if (v.empty() || *end || !std::isfinite(window_s) || !(window_s > 0.0)) {
        std::cerr << "error: --window: expected a positive number of seconds, got '" << v
                  << "'\n";
        return 2;
      }
    }
    else if (a == "--truth-rotation-sigma-deg" || a == "--truth-direction-sigma-deg" ||
             a == "--truth-orientation-sigma-deg") {
      const std::string v = next();
      char* end = nullptr;
      const double degrees = std::strtod(v.c_str(), &end);
      if (v.empty() || *end || !std::isfinite(degrees) || degrees < 0.0) {
        std::cerr << "error: " << a << ": expected a number of degrees >= 0, got '" << v << "'\n";
        return 2;
      }
      (a == "--truth-rotation-sigma-deg"    ? truth_rotation_sigma
       : a == "--truth-direction-sigma-deg" ? truth_direction_sigma
                                            : truth_orientation_sigma) = degrees / kDeg;
    }
    else if (a == "--truth-position-sigma-m") {
      const std::string v = next();
      char* end = nullptr;
      truth_position_sigma = std::strtod(v.c_str(), &end);
      if (v.empty() || *end || !std::isfinite(truth_position_sigma) || truth_position_sigma < 0.0) {
        std::cerr << "error: " << a << ": expected metres >= 0, got '" << v << "'\n";
        return 2;
      }
    }
    else if (a == "--tum") {
      tum_est = next();
      tum_gt = next();
    } else if (a == "--help" || a == "-h") {
      usage(argv[0]);
      return 0;
    } else {
      std::cerr << "error: unknown argument '" << a << "'\n";
      usage(argv[0]);
      return 2;
    }
  }
  Run run;
  Trajectory gt;
  std::string error;
  if (!tum_est.empty()) {
    if (!evaluation::read_tum_trajectory(tum_est, &run.trajectory, &error) ||
        !evaluation::read_tum_trajectory(tum_gt, &gt, &error)) {
      std::cerr << "error: " << error << "\n";
      return 1;
    }
  } else if (!bag.empty() && !gt_bag.empty()) {
    if (!read_run(bag, &run, &error) || !read_gt(gt_bag, gt_topic, &gt, &error)) {
      std::cerr << "error: " << error << "\n";
      return 1;
    }
  } else {
    usage(argv[0]);
    return 2;
  }
  const double tolerance = 1e-3;

  // Per-pair errors: the node's own relative poses when recorded, else consecutive poses.
  std::vector<double> errors;
  // The rotation and translation direction errors of the estimated pairs (status OK).
  std::vector<double> pair_rot, pair_dir;
  int failures = 0, skipped = 0;
  // With a metric scale, the ratio of the estimated to the true translation length per pair: a
  // scale bias shows at a glance, not only through the drift.
  std::vector<double> scale_ratios;
  // NEES of the estimated pairs' rotation and translation direction; NaN without a covariance.
  std::vector<double> pair_rot_nees, pair_dir_nees;
  // Stereo: the metric translation's NEES (3 dof). Rotation-only pairs and pairs without a
  // baseline: their rotation is compared, they have no direction and stay out of the pose AUC.
  std::vector<double> pair_t_nees;
  int rotation_only = 0;
  std::printf("pair,stamp_ref,stamp,status,rot_err_deg,dir_err_deg,scale_ratio\n");
  if (!run.motions.empty()) {
    for (const hybrid_vo::MotionEstimate& m : run.motions) {
      if (m.status == hybrid_vo::MotionEstimate::STATUS_SKIPPED) {
        ++skipped;
        continue;
      }
      StampedPose a, b;
      if (!evaluation::pose_at(gt, m.reference_stamp.toSec(), tolerance, &a) ||
          !evaluation::pose_at(gt, m.header.stamp.toSec(), tolerance, &b))
        continue;
      double rot = 180.0, dir = 180.0, ratio = NAN;
      if (m.status == hybrid_vo::MotionEstimate::STATUS_OK) {
        const auto& q = m.transform.rotation;
        const Eigen::Matrix3d R = Eigen::Quaterniond(q.w, q.x, q.y, q.z).normalized().toRotationMatrix();
        const Eigen::Vector3d t(m.transform.translation.x, m.transform.translation.y,
                                m.transform.translation.z);
        const Eigen::Matrix3d R_gt = b.R.transpose() * a.R;
        const Eigen::Vector3d t_gt = b.R.transpose() * (a.c - b.c);
        rot = hybrid_vo::rotation_error(R, R_gt) * kDeg;
        pair_rot.push_back(rot);
        pair_rot_nees.push_back(evaluation::rotation_nees(
            R, R_gt, evaluation::covariance_block(m.covariance.data(), 0), truth_rotation_sigma));
        if (m.scale_known)
          pair_t_nees.push_back(evaluation::translation_nees(
              t, t_gt, evaluation::covariance_block(m.covariance.data(), 3)));
        if (m.rotation_only || !m.baseline) {
          rotation_only += m.rotation_only;
          std::printf("r,%.6f,%.6f,%d,%.4f,,\n", m.reference_stamp.toSec(),
                      m.header.stamp.toSec(), m.status, rot);
          continue;
        }
        dir = hybrid_vo::translation_error(t, t_gt) * kDeg;
        pair_dir.push_back(dir);
        // The truth's position noise moves its direction by sqrt(2) sigma / baseline.
        const double position_part =
            t_gt.norm() > 0.0 ? std::sqrt(2.0) * truth_position_sigma / t_gt.norm() : 0.0;
        pair_dir_nees.push_back(evaluation::direction_nees(
            t, t_gt, evaluation::covariance_block(m.covariance.data(), 3),
            std::hypot(truth_direction_sigma, position_part)));
        if (m.scale_known && t_gt.norm() > 1e-9) {
          ratio = t.norm() / t_gt.norm();
          scale_ratios.push_back(ratio);
        }
      } else {
        ++failures;
      }
      errors.push_back(std::max(rot, dir));
      std::printf("%zu,%.6f,%.6f,%d,%.4f,%.4f,", errors.size() - 1, m.reference_stamp.toSec(),
                  m.header.stamp.toSec(), m.status, rot, dir);
      if (std::isfinite(ratio)) std::printf("%.4f", ratio);
      std::printf("\n");
    }
  }
  const bool with_scale = run.scale_known * 2 < static_cast<int>(run.motions.size()) || run.motions.empty();
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> aligned;
  const evaluation::TrajectoryErrors te =
      evaluation::compare_trajectories(run.trajectory, gt, with_scale, tolerance, &aligned,
                                       window_s);
  if (run.motions.empty()) {
    pair_rot = te.rot_err_deg;
    pair_dir = te.dir_err_deg;
    for (size_t i = 0; i < te.rot_err_deg.size(); ++i) {
      errors.push_back(std::max(te.rot_err_deg[i], te.dir_err_deg[i]));
      std::printf("%zu,,,0,%.4f,%.4f,\n", i, te.rot_err_deg[i], te.dir_err_deg[i]);
    }
  }
  if (!plot.empty() && !aligned.empty()) {
    // Top-down view: the two axes along which the ground truth moves most.
    Eigen::Vector3d lo = aligned[0].second, hi = lo;
    for (const auto& p : aligned) lo = lo.cwiseMin(p.second), hi = hi.cwiseMax(p.second);
    const Eigen::Vector3d extent = hi - lo;
    int a0 = 0, a1 = 1;
    if (extent(2) > extent(a0) && extent(2) > extent(a1)) (extent(0) < extent(1) ? a0 : a1) = 2;
    else if (extent(2) > std::min(extent(0), extent(1))) (extent(0) < extent(1) ? a0 : a1) = 2;
    if (a0 > a1) std::swap(a0, a1);
    evaluation::PlotSeries est{"estimate (aligned)", {}, {}}, truth{"ground truth", {}, {}};
    for (const auto& p : aligned) {
      est.x.push_back(p.first(a0));
      est.y.push_back(p.first(a1));
      truth.x.push_back(p.second(a0));
      truth.y.push_back(p.second(a1));
    }
    evaluation::PlotOptions options;
    options.title = "Trajectory, top view";
    options.x_label = std::string("axis ") + "xyz"[a0] + " [m]";
    options.y_label = std::string("axis ") + "xyz"[a1] + " [m]";
    if (!evaluation::write_line_plot(plot, {truth, est}, options))
      std::cerr << "warning: cannot write " << plot << "\n";
  }
  std::printf("# %d failed, %d skipped frames; trajectory: %d poses compared, scale %s %.4f; "
              "drift %.2f %% and %.3f deg/100 m over %d segments\n",
              failures, skipped, te.pairs + 1, with_scale ? "aligned" : "metric", te.scale,
              te.drift_trans_percent, te.drift_rot_deg_per_100m, te.drift_segments);
  if (!run.motions.empty()) {
    // An odometry for a robot answers every frame, at rest and turning in place too.
    double farthest = 0.0;
    for (const OdometrySample& o : run.odometry)
      farthest = std::max(farthest, (o.camera.c - run.odometry.front().camera.c).norm());
    std::printf("# answers: %zu odometry messages for %zu frames, %d rotation-only pairs; the "
                "position at most %.4f from the first\n",
                run.odometry.size(), run.motions.size(), rotation_only, farthest);
  }
  if (!scale_ratios.empty())
    std::printf("# scale ratio (estimated / true translation length): median %.4f (p10 %.4f, "
                "p90 %.4f) over %zu metric pairs\n",
                median(scale_ratios), evaluation::percentile(scale_ratios, 0.1),
                evaluation::percentile(scale_ratios, 0.9), scale_ratios.size());
  // Whether the covariances hold the errors; not last: scripts/demo shows the last three lines.
  evaluation::NeesSummary rot_nees, orient_nees;
  if (!bag.empty()) {
    rot_nees = evaluation::summarize_nees(pair_rot_nees, 3);
    print_consistency("rotation per pair", truth_rotation_sigma, rot_nees, "estimated pairs", "");
    if (!pair_t_nees.empty())
      print_consistency("metric translation per pair", 0.0, evaluation::summarize_nees(pair_t_nees, 3),
                        "pairs with a scale", "");
    print_consistency("translation direction per pair", truth_direction_sigma,
                      evaluation::summarize_nees(pair_dir_nees, 2), "estimated pairs", "");
    orient_nees = orientation_consistency(run.odometry, gt, tolerance, truth_orientation_sigma);
    vp_observation_consistency(run.vanishing_points, gt, tolerance);
  }
  // Processing time per frame as the node measured it (MotionEstimate), skipped frames included:
  // what bounds the frame rate through the node. Then where it goes, stage by stage (the stages
  // overlap: the segments and the stereo matching run on a second thread), and the matches.
  if (!run.motions.empty()) {
    std::vector<double> frontend, estimator, total, points, redetect, lines, line_matching, vps,
        ransac, stereo, point_matches, point_inliers, line_matches, line_inliers, junctions,
        junction_inliers, vp_matches, vp_inliers;
    double lines_sum = 0.0, line_inliers_sum = 0.0;
    for (const hybrid_vo::MotionEstimate& m : run.motions) {
      frontend.push_back(m.frontend_ms);
      estimator.push_back(m.estimator_ms);
      total.push_back(m.total_ms);
      points.push_back(m.points_ms);
      redetect.push_back(m.redetect_ms);
      lines.push_back(m.lines_ms);
      line_matching.push_back(m.line_matching_ms);
      vps.push_back(m.vps_ms);
      ransac.push_back(m.ransac_ms);
      stereo.push_back(m.stereo_ms);
      if (m.status != hybrid_vo::MotionEstimate::STATUS_OK) continue;
      point_matches.push_back(m.points);
      point_inliers.push_back(m.point_inliers);
      line_matches.push_back(m.lines);
      line_inliers.push_back(m.line_inliers);
      junctions.push_back(m.junctions);
      junction_inliers.push_back(m.junction_inliers);
      vp_matches.push_back(m.vps);
      vp_inliers.push_back(m.vp_inliers);
      lines_sum += m.lines;
      line_inliers_sum += m.line_inliers;
    }
    std::printf("# frames answered: %zu, of %zu ground-truth poses\n", run.motions.size(),
                gt.size());
    print_map_summary(run.motions);
    std::printf("# per frame (median): front end %.1f ms, estimator %.1f ms, total %.1f ms = %.1f "
                "frames/s; total p95 %.1f ms, max %.1f ms\n",
                median(frontend), median(estimator), median(total),
                1000.0 / std::max(1e-3, median(total)), evaluation::percentile(total, 0.95),
                total.empty() ? NAN : *std::max_element(total.begin(), total.end()));
    std::printf("# per stage (median ms): points %.1f, re-detection %.1f, lines %.1f, line "
                "matching %.1f, VPs %.1f, RANSAC %.1f, stereo %.1f\n",
                median(points), median(redetect), median(lines), median(line_matching), median(vps),
                median(ransac), median(stereo));
    if (!point_matches.empty())
      std::printf("# matches per estimated frame (median): points %.0f (%.0f inliers), lines %.0f "
                  "(%.0f inliers), junctions %.0f (%.0f inliers), VPs %.0f (%.0f inliers); line "
                  "inlier ratio %.3f (all frames pooled)\n",
                  median(point_matches), median(point_inliers), median(line_matches),
                  median(line_inliers), median(junctions), median(junction_inliers),
                  median(vp_matches), median(vp_inliers),
                  lines_sum > 0.0 ? line_inliers_sum / lines_sum : 0.0);
  }
  const double rot_pair = median(pair_rot), dir = median(pair_dir);
  std::printf("# rotation error (deg): median %.3f per pair (%zu %s), %.3f over %g s windows (%zu), "
              "orientation against the first frame %.3f at the last frame and %.3f at most; "
              "median translation direction error %.2f deg\n",
              rot_pair, pair_rot.size(),
              run.motions.empty() ? "pairs of consecutive poses" : "estimated pairs",
              te.rot_window_median_deg, window_s, te.rot_window_err_deg.size(),
              te.orientation_last_deg, te.orientation_max_deg, dir);
  std::printf("summary: pairs=%zu auc5=%.2f auc10=%.2f auc20=%.2f rpe_trans=%.4f rpe_rot_deg=%.4f "
              "ate=%.4f rot_pair_deg=%.4f rot_window_deg=%.4f window_s=%g orient_last_deg=%.4f "
              "orient_max_deg=%.4f dir_deg=%.3f nees_rot_pair=%.3f in95_rot_pair=%.1f "
              "nees_orient=%.3f in95_orient=%.1f\n",
              errors.size(), 100.0 * hybrid_vo::pose_auc(errors, 5.0),
              100.0 * hybrid_vo::pose_auc(errors, 10.0), 100.0 * hybrid_vo::pose_auc(errors, 20.0),
              te.rpe_trans, te.rpe_rot_deg, te.ate, rot_pair, te.rot_window_median_deg, window_s,
              te.orientation_last_deg, te.orientation_max_deg, dir, rot_nees.median,
              100.0 * rot_nees.inside95, orient_nees.median, 100.0 * orient_nees.inside95);
  return 0;
}
