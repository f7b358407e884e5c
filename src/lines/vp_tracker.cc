#include "hybrid_vo/lines/vp_tracker.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <tuple>

#include <Eigen/Geometry>
#include <Eigen/LU>

#include "hybrid_vo/geometry/homogeneous.h"

namespace hybrid_vo {
namespace {

constexpr double kDeg = M_PI / 180.0;

// A finite proper rotation: |R^T R - I| <= 1e-6 (Frobenius) and det R > 0.
bool is_rotation(const Eigen::Matrix3d& R) {
  if (!all_finite(R)) return false;
  return (R.transpose() * R - Eigen::Matrix3d::Identity()).norm() <= 1e-6 && R.determinant() > 0.0;
}

// Unit vector of a finite, non-zero direction; false otherwise.
bool unit_direction(const Eigen::Vector3d& d, Eigen::Vector3d* unit) {
  if (!all_finite(d)) return false;
  const double n = d.norm();
  // n can overflow to inf for huge finite d; a VP of any scale is still a direction.
  if (!(n > 0.0) || !std::isfinite(n)) {
    const double m = d.cwiseAbs().maxCoeff();
    if (!(m > 0.0)) return false;
    *unit = (d / m).normalized();
    return true;
  }
  *unit = d / n;
  return true;
}

// Angle between the lines spanned by two unit vectors, in [0, pi/2]. atan2 stays accurate near 0,
// where acos of the dot product loses half the digits.
double line_angle(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), std::abs(a.dot(b)));
}

// Greedy one-to-one association by smallest angle within `gate` (radians): for the handful of
// VPs per frame this matches the optimal assignment whenever the VPs are further apart than
// twice the gate, which a VP detector guarantees. `usable[j]` marks the candidate targets.
// Returns per observation its target index or -1; `angles` gets the matched angles.
std::vector<int> associate(const std::vector<Eigen::Vector3d>& observations,
                           const std::vector<char>& valid_observation,
                           const std::vector<Eigen::Vector3d>& targets,
                           const std::vector<char>& usable, double gate,
                           std::vector<double>* angles) {
  std::vector<std::tuple<double, int, int>> pairs;  // angle, observation, target
  for (size_t i = 0; i < observations.size(); ++i) {
    if (!valid_observation[i]) continue;
    for (size_t j = 0; j < targets.size(); ++j) {
      if (!usable[j]) continue;
      const double a = line_angle(observations[i], targets[j]);
      if (a <= gate) pairs.emplace_back(a, static_cast<int>(i), static_cast<int>(j));
    }
  }
  std::sort(pairs.begin(), pairs.end());
  std::vector<int> target_of(observations.size(), -1);
  std::vector<char> taken(targets.size(), 0);
  angles->assign(observations.size(), 0.0);
  for (const auto& [a, i, j] : pairs) {
    if (target_of[i] >= 0 || taken[j]) continue;
    target_of[i] = j;
    taken[j] = 1;
    (*angles)[i] = a;
  }
  return target_of;
}

}  // namespace

VpTracker::VpTracker(const VpTrackerOptions& options) : options_(options) {}

const VpTrack* VpTracker::find(int id) const {
  for (const VpTrack& track : tracks_)
    if (track.id == id) return &track;
  return nullptr;
}

std::vector<int> VpTracker::update(const Eigen::Matrix3d& R_world_from_camera,
                                   const std::vector<Eigen::Vector3d>& directions,
                                   const std::vector<double>& weights) {
  const size_t n = directions.size();
  std::vector<int> ids(n, -1);
  if (!is_rotation(R_world_from_camera)) return ids;
  if (!weights.empty() && weights.size() != n) return ids;

  // Observations in the odometry frame.
  std::vector<Eigen::Vector3d> world(n, Eigen::Vector3d::Zero());
  std::vector<double> w(n, 1.0);
  std::vector<char> valid(n, 0);
  for (size_t i = 0; i < n; ++i) {
    if (!weights.empty()) w[i] = weights[i];
    Eigen::Vector3d unit;
    if (!(std::isfinite(w[i]) && w[i] > 0.0) || !unit_direction(directions[i], &unit)) continue;
    world[i] = (R_world_from_camera * unit).normalized();
    valid[i] = 1;
  }

  // Age and decay every track; the decay lets later detections outweigh older ones.
  const double memory = std::clamp(options_.memory, 0.0, 1.0);
  for (VpTrack& track : tracks_) {
    ++track.age;
    track.weight *= memory;
  }

  std::vector<Eigen::Vector3d> track_directions;
  for (const VpTrack& track : tracks_) track_directions.push_back(track.direction);
  const double gate = std::max(options_.association_angle_deg, 0.0) * kDeg;
  std::vector<double> angles;
  const std::vector<char> usable(tracks_.size(), 1);
  const std::vector<int> track_of =
      associate(world, valid, track_directions, usable, gate, &angles);

  std::vector<char> hit(tracks_.size(), 0);
  for (size_t i = 0; i < n; ++i) {
    if (track_of[i] < 0) continue;
    VpTrack& track = tracks_[track_of[i]];
    hit[track_of[i]] = 1;
    // Sign-aligned recursive weighted mean: d <- normalise(W d + w s x), W <- W + w.
    const double sign = track.direction.dot(world[i]) >= 0.0 ? 1.0 : -1.0;
    const Eigen::Vector3d sum = track.weight * track.direction + w[i] * sign * world[i];
    // sum . direction >= W > 0 after the sign alignment, so sum never vanishes; guard anyway
    // against weights so large that it overflows.
    if (all_finite(sum) && sum.norm() > 0.0 && std::isfinite(sum.norm())) {
      track.direction = sum.normalized();
      track.weight += w[i];
    }
    ++track.hits;
    track.misses = 0;
    track.last_angle_deg = angles[i] / kDeg;
    track.confident = track.hits >= options_.confirm_hits;
    ids[i] = track.id;
  }
  for (size_t j = 0; j < tracks_.size(); ++j)
    if (!hit[j]) ++tracks_[j].misses;

  // Unmatched observations, heaviest first, start tracks unless they duplicate a track (an
  // existing one that a closer observation took, or one started earlier in this frame).
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return w[a] > w[b]; });
  for (const int i : order) {
    if (!valid[i] || track_of[i] >= 0) continue;
    bool duplicate = false;
    for (const VpTrack& track : tracks_)
      if (line_angle(track.direction, world[i]) <= gate) duplicate = true;
    if (duplicate) continue;
    if (options_.max_tracks > 0 && static_cast<int>(tracks_.size()) >= options_.max_tracks) {
      continue;
    }
    VpTrack track;
    track.id = next_id_++;
    track.direction = world[i];
    track.hits = 1;
    track.weight = w[i];
    track.confident = track.hits >= options_.confirm_hits;
    tracks_.push_back(track);
    ids[i] = track.id;
  }

  // Drop stale tracks; remove_if keeps the rest in creation order.
  const int max_misses = options_.max_misses;
  tracks_.erase(std::remove_if(tracks_.begin(), tracks_.end(),
                               [max_misses](const VpTrack& t) { return t.misses > max_misses; }),
                tracks_.end());
  return ids;
}

std::vector<int> VpTracker::refine_matches(const Eigen::Matrix3d& R_world_from_camera1,
                                           std::vector<VpMatch>* matches) const {
  if (matches == nullptr) return {};
  const size_t n = matches->size();
  std::vector<int> ids(n, -1);
  if (!is_rotation(R_world_from_camera1)) return ids;

  std::vector<Eigen::Vector3d> world(n, Eigen::Vector3d::Zero()), d1(n, Eigen::Vector3d::Zero());
  std::vector<char> valid(n, 0);
  for (size_t i = 0; i < n; ++i) {
    if (!unit_direction((*matches)[i].d1, &d1[i])) continue;
    world[i] = (R_world_from_camera1 * d1[i]).normalized();
    valid[i] = 1;
  }
  std::vector<Eigen::Vector3d> track_directions;
  std::vector<char> confident;
  for (const VpTrack& track : tracks_) {
    track_directions.push_back(track.direction);
    confident.push_back(track.confident);
  }
  const double gate = std::max(options_.association_angle_deg, 0.0) * kDeg;
  std::vector<double> angles;
  const std::vector<int> track_of = associate(world, valid, track_directions, confident, gate,
                                              &angles);
  for (size_t i = 0; i < n; ++i) {
    if (track_of[i] < 0) continue;
    const VpTrack& track = tracks_[track_of[i]];
    Eigen::Vector3d in_camera = R_world_from_camera1.transpose() * track.direction;
    in_camera.normalize();
    // Keep the old d1's sign: with sign_known, d2 = +R d1 must still hold.
    if (in_camera.dot(d1[i]) < 0.0) in_camera = -in_camera;
    (*matches)[i].d1 = in_camera;
    ids[i] = track.id;
  }
  return ids;
}

}  // namespace hybrid_vo
