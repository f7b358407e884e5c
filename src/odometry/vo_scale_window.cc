// VisualOdometry's one scale across keyframes in mono (issue 58): the last keyframes' points and
// the links between them, and the window's fit (estimation/window_scale.h) of the link a frame
// adds as it becomes the keyframe, before it is integrated. A pair's own length comes from its
// keyframe's depths, which are in turn triangulated with the length before: handed on pair by
// pair, the length wandered (KITTI 01 mono: 0.92 to 1.05 of the truth in 50 frames). The points
// tracked over several keyframes tie their lengths together.
#include <algorithm>
#include <cmath>

#include "hybrid_vo/estimation/window_scale.h"
#include "vo_frame.h"

namespace hybrid_vo {

std::map<int64_t, Eigen::Vector2d> VisualOdometry::keyframe_rays() const {
  std::map<int64_t, Eigen::Vector2d> rays;
  const CameraModel& camera = keyframe_.camera;
  const bool undistort = !keyframe_.points_undistorted && camera.has_distortion();
  for (const auto& [id, pixel] : keyframe_.points) {
    const Eigen::Vector2d x = camera.pinhole.normalize(undistort ? camera.undistort(pixel) : pixel);
    if (all_finite(x)) rays[id] = x;
  }
  return rays;
}

void VisualOdometry::remember_window_keyframe(const Frame& f) {
  const VisualOdometryResult& r = f.result;
  if (f.stereo || options_.mono_window_keyframes < 3) {
    window_.clear();
    return;
  }
  // A keyframe that starts a chain (the first frame, a reset, too few matches) has no link to the
  // one before, and the window starts again at it.
  WindowKeyframe k;
  const bool linked = r.became_keyframe && !window_.empty();
  if (!linked) window_.clear();
  if (linked) {
    k.sure =
        r.baseline && translation_direction_sigma(r) <= options_.mono_depth_max_direction_sigma;
    // The pose that explains the pair's points, with the length as integrated.
    const RelativePose& own = f.oriented.scale_pose;
    const double length = r.motion.t.norm();
    k.link = RelativePose(own.R, own.t.norm() > 0.0 && length > 0.0
                                     ? Eigen::Vector3d(own.t.normalized() * length)
                                     : Eigen::Vector3d::Zero());
  }
  k.rays = keyframe_rays();
  window_.push_back(std::move(k));
  while (static_cast<int>(window_.size()) > options_.mono_window_keyframes - 1) window_.pop_front();
}

void VisualOdometry::fit_window_scale(Frame& f) {
  VisualOdometryResult& r = f.result;
  const int cameras = static_cast<int>(window_.size()) + 1;  // this frame last
  if (f.stereo || options_.mono_window_keyframes < 3 || cameras < 3 || !r.baseline ||
      !(r.motion.t.norm() > 0.0) || !(f.length > 0.0))
    return;
  // Every link's direction must be known to a few degrees, as for the depths a pair triangulates:
  // a blank wall's (the white panels: 57 degrees) places the points anywhere, and the few points
  // of the window then gave lengths two or three times the pair's.
  if (translation_direction_sigma(r) > options_.mono_depth_max_direction_sigma) return;
  for (size_t k = 1; k < window_.size(); ++k)
    if (!window_[k].sure) return;
  // The links: the window's, then this pair's (its own pose, its length as fitted). A link
  // without a length (a keyframe turned in place) has nothing to scale and is held; the oldest
  // link is the gauge: the scale carried into the window.
  const int links = cameras - 1;
  std::vector<RelativePose> chain;
  std::vector<char> fixed;
  for (size_t k = 1; k < window_.size(); ++k) {
    chain.push_back(window_[k].link);
    fixed.push_back(chain.size() == 1 || !(window_[k].link.t.norm() > 0.0));
  }
  const RelativePose& own = f.oriented.scale_pose;
  if (!(own.t.norm() > 0.0)) return;
  chain.emplace_back(own.R, own.t.normalized() * r.motion.t.norm());
  fixed.push_back(chain.size() == 1);
  if (static_cast<int>(chain.size()) != links || fixed.back()) return;

  // This frame's sightings: the pair's inlier points.
  std::map<int64_t, Eigen::Vector2d> current;
  const TwoViewMatches& m = r.matches;
  const std::vector<char>& inliers = r.estimate.estimate.point_inliers;
  const PinholeCamera& camera = f.input.camera.pinhole;
  for (size_t i = 0; i < m.points.size() && i < f.point_ids.size(); ++i)
    if (i < inliers.size() && inliers[i])
      current[f.point_ids[i]] = camera.normalize(m.points[i].x2);
  // Every point seen across two links or more: a point seen by two cameras only fixes its own
  // depth. Each is anchored where the window first saw it.
  std::map<int64_t, WindowPoint> by_id;
  for (int c = 0; c < cameras; ++c) {
    const std::map<int64_t, Eigen::Vector2d>& rays = c < links ? window_[c].rays : current;
    for (const auto& [id, x] : rays) {
      auto it = by_id.find(id);
      if (it == by_id.end()) {
        if (c >= links - 1) continue;  // first seen in the last two cameras: ties nothing
        WindowPoint p;
        p.anchor = c;
        p.x_anchor = x;
        by_id.emplace(id, std::move(p));
      } else {
        it->second.seen.emplace_back(c, x);
      }
    }
  }
  std::vector<WindowPoint> points;
  for (auto& [id, p] : by_id)
    if (!p.seen.empty() && p.seen.back().first - p.anchor >= 2) points.push_back(std::move(p));
  // A few hundred points fix the lengths to a fraction of a percent (their errors are shared).
  constexpr size_t kMaxPoints = 300;
  if (points.size() > kMaxPoints) {
    std::vector<WindowPoint> every;
    const double step = static_cast<double>(points.size()) / kMaxPoints;
    for (size_t k = 0; k < kMaxPoints; ++k) every.push_back(points[static_cast<size_t>(k * step)]);
    points = std::move(every);
  }

  WindowScaleOptions options;
  options.point_sigma = options_.stereo_scale.point_sigma_px / camera.fx;
  options.loss_scale = options_.stereo_scale.loss_scale;
  options.min_tying_points = options_.mono_min_depth_points;
  const WindowScaleEstimate e = estimate_window_scales(chain, fixed, points, options);
  r.window_scale_points = e.ok ? e.inliers : 0;
  if (!e.ok) return;
  // The older links keep their lengths in the window as fitted now (the path keeps them as they
  // were integrated); the next fit starts from them.
  for (int j = 1; j + 1 < links; ++j) window_[j + 1].link.t *= e.scales[j];
  // The length changes from the link before by a factor as sure as the fit says; the points
  // share their errors and count as at most the translation's independent points, as for a
  // pair's length.
  const int last = links - 1;
  const double var = e.log_covariance(last, last) - 2.0 * e.log_covariance(last, last - 1) +
                     e.log_covariance(last - 1, last - 1);
  const double inflation =
      std::max(1.0, e.points_used / pair_options().covariance.independent_translation_points);
  const double scale = f.length * e.scales[last];
  set_length(f, scale, scale * std::sqrt(std::max(0.0, var) * inflation));
}

}  // namespace hybrid_vo
