#include "hybrid_vo/lines/vp_tracker.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <tuple>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <Eigen/LU>

#include "hybrid_vo/geometry/homogeneous.h"
#include "hybrid_vo/geometry/vp_covariance.h"

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

// The projector onto the plane orthogonal to unit d.
Eigen::Matrix3d tangent_projector(const Eigen::Vector3d& d) {
  return Eigen::Matrix3d::Identity() - d * d.transpose();
}

// A detection's covariance in the odometry frame, projected onto its tangent plane and floored.
Eigen::Matrix3d observation_covariance(const VpObservation& o, const Eigen::Matrix3d& R,
                                       const Eigen::Vector3d& world,
                                       const VpTrackerOptions& options) {
  const Eigen::Matrix3d P = tangent_projector(world);
  const double floor = std::pow(std::max(options.min_sigma_deg, 0.0) * kDeg, 2);
  Eigen::Matrix3d C;
  if (o.covariance.isZero(0.0)) {
    const double sigma = std::max(options.default_sigma_deg, options.min_sigma_deg) * kDeg;
    C = sigma * sigma * P;
  } else {
    C = P * R * o.covariance * R.transpose() * P;
  }
  return 0.5 * (C + C.transpose()) + floor * P;
}

// Greedy one-to-one association by smallest angle within `gate` (radians): for the handful of
// VPs per frame this matches the optimal assignment whenever the VPs are further apart than
// twice the gate, which a VP detector guarantees. `usable[j]` marks the candidate targets.
// Returns per observation its target index or -1.
std::vector<int> associate(const std::vector<Eigen::Vector3d>& observations,
                           const std::vector<char>& valid_observation,
                           const std::vector<Eigen::Vector3d>& targets,
                           const std::vector<char>& usable, double gate) {
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
  for (const auto& [a, i, j] : pairs) {
    if (target_of[i] >= 0 || taken[j]) continue;
    target_of[i] = j;
    taken[j] = 1;
  }
  return target_of;
}

// Kalman update of a track with a detection z (unit, odometry frame) of covariance C: both in
// the tangent plane of the track's direction, where the gnomonic coordinates of z are the
// innovation. Returns false (track unchanged) when the innovation covariance is singular.
bool fuse(VpTrack* track, const Eigen::Vector3d& z, const Eigen::Matrix3d& C) {
  const Eigen::Vector3d& d = track->direction;
  const Eigen::Vector3d w = d.dot(z) >= 0.0 ? z : Eigen::Vector3d(-z);
  const Eigen::Matrix<double, 3, 2> B = tangent_basis(d);
  const Eigen::Vector2d y = B.transpose() * w / d.dot(w);
  const Eigen::Matrix2d P = B.transpose() * track->covariance * B;
  const Eigen::Matrix2d S = P + B.transpose() * C * B;
  const Eigen::FullPivLU<Eigen::Matrix2d> lu(S);
  if (!lu.isInvertible()) return false;
  const Eigen::Matrix2d K = P * lu.inverse();
  const Eigen::Vector3d next = (d + B * (K * y)).normalized();
  Eigen::Matrix2d P_next = (Eigen::Matrix2d::Identity() - K) * P;
  P_next = 0.5 * (P_next + P_next.transpose());
  if (!all_finite(next) || !all_finite(P_next)) return false;
  // The new tangent plane differs from the old by the (tiny) correction: re-project onto it.
  const Eigen::Matrix3d projector = tangent_projector(next);
  track->direction = next;
  track->covariance = projector * B * P_next * B.transpose() * projector;
  return true;
}

}  // namespace

std::vector<int> VpTracker::associate_with_tracks(const std::vector<Eigen::Vector3d>& directions,
                                                  const std::vector<char>& valid,
                                                  bool confident_only) const {
  std::vector<Eigen::Vector3d> track_directions;
  std::vector<char> usable;
  for (const VpTrack& track : tracks_) {
    track_directions.push_back(track.direction);
    usable.push_back(!confident_only || track.confident);
  }
  const double gate = std::max(options_.association_angle_deg, 0.0) * kDeg;
  return associate(directions, valid, track_directions, usable, gate);
}

double VpTrack::sigma_deg() const {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(0.5 *
                                                             (covariance + covariance.transpose()));
  return std::sqrt(std::max(0.0, eigen.eigenvalues().maxCoeff())) / kDeg;
}

VpTracker::VpTracker(const VpTrackerOptions& options) : options_(options) {}

const VpTrack* VpTracker::find(int id) const {
  for (const VpTrack& track : tracks_)
    if (track.id == id) return &track;
  return nullptr;
}

std::vector<VpAssociation> VpTracker::update(const Eigen::Matrix3d& R_world_from_camera,
                                             const std::vector<VpObservation>& observations) {
  const size_t n = observations.size();
  std::vector<VpAssociation> result(n);
  if (!is_rotation(R_world_from_camera)) return result;
  ++frame_;

  // Observations in the odometry frame with their covariances.
  std::vector<Eigen::Vector3d> world(n, Eigen::Vector3d::Zero());
  std::vector<Eigen::Matrix3d> covariance(n, Eigen::Matrix3d::Zero());
  std::vector<char> valid(n, 0);
  for (size_t i = 0; i < n; ++i) {
    Eigen::Vector3d unit;
    if (!unit_direction(observations[i].direction, &unit) ||
        !all_finite(observations[i].covariance))
      continue;
    world[i] = (R_world_from_camera * unit).normalized();
    covariance[i] = observation_covariance(observations[i], R_world_from_camera, world[i],
                                           options_);
    valid[i] = all_finite(covariance[i]);
  }

  // Predict: age, and the random walk that lets a track follow the odometry frame's drift.
  const double q = std::pow(std::max(options_.process_noise_deg, 0.0) * kDeg, 2);
  for (VpTrack& track : tracks_) {
    ++track.age;
    track.covariance += q * tangent_projector(track.direction);
  }

  const std::vector<int> track_of = associate_with_tracks(world, valid, false);

  std::vector<char> fused(tracks_.size(), 0), gated(tracks_.size(), 0);
  for (size_t i = 0; i < n; ++i) {
    if (track_of[i] < 0) continue;
    VpTrack& track = tracks_[track_of[i]];
    const double chi2 =
        direction_chi2(track.direction, world[i], track.covariance + covariance[i], false);
    result[i].track_id = track.id;
    result[i].chi2 = chi2;
    track.last_chi2 = chi2;
    if (!(chi2 <= options_.gate_chi2) || !fuse(&track, world[i], covariance[i])) {
      result[i].gated_out = true;
      track.last_gate_passed = false;
      gated[track_of[i]] = 1;
      continue;
    }
    fused[track_of[i]] = 1;
    track.last_gate_passed = true;
    track.gate_failures = 0;
    ++track.hits;
    track.misses = 0;
    track.last_update = frame_;
    track.confident = track.hits >= options_.confirm_hits;
  }
  for (size_t j = 0; j < tracks_.size(); ++j) {
    if (gated[j]) {
      ++tracks_[j].gate_failures;
      ++tracks_[j].total_gate_failures;
    }
    if (!fused[j]) ++tracks_[j].misses;
  }

  // Unmatched observations, most certain first, start tracks unless they duplicate a track (an
  // existing one, also one whose gate they failed, or one started earlier in this frame).
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return covariance[a].trace() < covariance[b].trace(); });
  const double gate = std::max(options_.association_angle_deg, 0.0) * kDeg;
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
    track.covariance = covariance[i];
    track.hits = 1;
    track.last_update = frame_;
    track.confident = track.hits >= options_.confirm_hits;
    tracks_.push_back(track);
    result[i].track_id = track.id;
  }

  // Drop stale tracks and tracks that keep failing the gate; the rest stay in creation order.
  const int max_misses = options_.max_misses, max_failures = options_.max_gate_failures;
  tracks_.erase(std::remove_if(tracks_.begin(), tracks_.end(),
                               [&](const VpTrack& t) {
                                 return t.misses > max_misses ||
                                        (max_failures > 0 && t.gate_failures >= max_failures);
                               }),
                tracks_.end());
  return result;
}

AnchoredOrientation VpTracker::anchor(const Eigen::Matrix3d& R_world_from_camera,
                                      const Eigen::Matrix3d& covariance,
                                      const std::vector<VpObservation>& observations) const {
  AnchoredOrientation out;
  out.R_world_from_camera = R_world_from_camera;
  out.covariance = covariance;
  if (!is_rotation(R_world_from_camera) || !all_finite(covariance)) return out;
  const size_t n = observations.size();
  std::vector<Eigen::Vector3d> world(n, Eigen::Vector3d::Zero()), unit(n, Eigen::Vector3d::Zero());
  std::vector<Eigen::Matrix3d> world_covariance(n, Eigen::Matrix3d::Zero());
  std::vector<char> valid(n, 0);
  for (size_t i = 0; i < n; ++i) {
    if (!unit_direction(observations[i].direction, &unit[i]) ||
        !all_finite(observations[i].covariance))
      continue;
    world[i] = (R_world_from_camera * unit[i]).normalized();
    world_covariance[i] =
        observation_covariance(observations[i], R_world_from_camera, world[i], options_);
    valid[i] = all_finite(world_covariance[i]);
  }
  const std::vector<int> track_of = associate_with_tracks(world, valid, true);
  std::vector<int> order;
  for (size_t i = 0; i < n; ++i)
    if (track_of[i] >= 0) order.push_back(static_cast<int>(i));
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    return (world_covariance[a] + tracks_[track_of[a]].covariance).trace() <
           (world_covariance[b] + tracks_[track_of[b]].covariance).trace();
  });

  Eigen::Matrix3d R = R_world_from_camera, P = 0.5 * (covariance + covariance.transpose());
  for (const int i : order) {
    const VpTrack& track = tracks_[track_of[i]];
    const Eigen::Vector3d& t = track.direction;
    Eigen::Vector3d p = (R * unit[i]).normalized();
    if (p.dot(t) < 0.0) p = -p;
    // The observation in gnomonic coordinates of the track's tangent plane; a left increment w
    // moves it by -B^T [p]x w.
    const Eigen::Matrix<double, 3, 2> B = tangent_basis(t);
    const Eigen::Vector2d y = B.transpose() * p / t.dot(p);
    const Eigen::Matrix<double, 2, 3> H = -B.transpose() * skew(p);
    const Eigen::Matrix2d S = H * P * H.transpose() +
                              B.transpose() * (track.covariance + world_covariance[i]) * B;
    const Eigen::FullPivLU<Eigen::Matrix2d> lu(S);
    if (!lu.isInvertible()) continue;
    const Eigen::Matrix2d S_inv = lu.inverse();
    if (!(y.dot(S_inv * y) <= options_.gate_chi2)) {
      ++out.rejected;
      continue;
    }
    const Eigen::Matrix<double, 3, 2> K = P * H.transpose() * S_inv;
    const Eigen::Vector3d w = -K * y;
    const Eigen::Matrix3d P_next = (Eigen::Matrix3d::Identity() - K * H) * P;
    if (!all_finite(w) || !all_finite(P_next)) continue;
    R = Eigen::AngleAxisd(w.norm(), w.norm() > 0.0 ? Eigen::Vector3d(w / w.norm())
                                                   : Eigen::Vector3d::UnitX())
            .toRotationMatrix() *
        R;
    P = 0.5 * (P_next + P_next.transpose());
    ++out.anchors;
  }
  const Eigen::AngleAxisd change(R * R_world_from_camera.transpose());
  out.R_world_from_camera = R;
  out.covariance = P;
  out.correction_deg = change.angle() / kDeg;
  return out;
}

std::vector<VpPrior> VpTracker::priors(const Eigen::Matrix3d& R_world_from_camera1,
                                       const std::vector<VpMatch>& matches) const {
  const size_t n = matches.size();
  std::vector<VpPrior> priors(n);
  if (!is_rotation(R_world_from_camera1)) return priors;

  std::vector<Eigen::Vector3d> world(n, Eigen::Vector3d::Zero()), d1(n, Eigen::Vector3d::Zero());
  std::vector<char> valid(n, 0);
  for (size_t i = 0; i < n; ++i) {
    if (!unit_direction(matches[i].d1, &d1[i])) continue;
    world[i] = (R_world_from_camera1 * d1[i]).normalized();
    valid[i] = 1;
  }
  const std::vector<int> track_of = associate_with_tracks(world, valid, true);
  const double q = std::pow(std::max(options_.process_noise_deg, 0.0) * kDeg, 2);
  for (size_t i = 0; i < n; ++i) {
    if (track_of[i] < 0) continue;
    const VpTrack& track = tracks_[track_of[i]];
    const Eigen::Matrix3d& R = R_world_from_camera1;
    Eigen::Vector3d direction = (R.transpose() * track.direction).normalized();
    // d1's sign: with sign_known, d2 = +R d1 must still hold for the prior's direction.
    if (direction.dot(d1[i]) < 0.0) direction = -direction;
    Eigen::Matrix3d covariance = R.transpose() * track.covariance * R;
    covariance += q * tangent_projector(direction);
    priors[i].valid = true;
    priors[i].direction = direction;
    priors[i].covariance = 0.5 * (covariance + covariance.transpose());
    priors[i].includes_view1 = track.last_update == frame_;
    priors[i].track_id = track.id;
  }
  return priors;
}

}  // namespace hybrid_vo
