#include "hybrid_vo/direction_map/direction_map.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <Eigen/LU>

#include "hybrid_vo/geometry/homogeneous.h"
#include "hybrid_vo/geometry/rotation.h"
#include "hybrid_vo/geometry/vp_covariance.h"

namespace hybrid_vo {
namespace {

constexpr double kDeg = M_PI / 180.0;

bool is_rotation(const Eigen::Matrix3d& R) {
  return all_finite(R) && (R.transpose() * R - Eigen::Matrix3d::Identity()).norm() <= 1e-6 &&
         R.determinant() > 0.0;
}

bool is_covariance(const Eigen::Matrix3d& P) {
  return all_finite(P) && P.diagonal().minCoeff() >= 0.0;
}

Eigen::Matrix3d tangent_projector(const Eigen::Vector3d& d) {
  return Eigen::Matrix3d::Identity() - d * d.transpose();
}

// Angle between the lines of two unit vectors, in [0, pi/2].
double line_angle(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), std::abs(a.dot(b)));
}

double largest_sigma(const Eigen::Matrix3d& covariance) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(
      0.5 * (covariance + covariance.transpose()), Eigen::EigenvaluesOnly);
  return std::sqrt(std::max(0.0, eigen.eigenvalues().maxCoeff()));
}

// The uncertainty a rotation's covariance P (left increment) gives the unit direction w.
Eigen::Matrix3d rotated_direction_covariance(const Eigen::Vector3d& w, const Eigen::Matrix3d& P) {
  const Eigen::Matrix3d W = skew(w);
  return W * P * W.transpose();
}

// Chi-square of an observation (unit w, covariance C) against a direction, sign-agnostic.
double chi2_against(const MapDirection& d, const Eigen::Vector3d& w, const Eigen::Matrix3d& C) {
  return direction_chi2(d.direction, w, d.covariance + C, false);
}

// Where the map could not place a camera: as predicted, nothing paired.
MapLocation unlocated(const Eigen::Matrix3d& R, const Eigen::Matrix3d& P, size_t observations) {
  MapLocation where;
  where.R_world_from_camera = R;
  where.covariance = P;
  where.direction_id.assign(observations, -1);
  return where;
}

}  // namespace

double MapDirection::sigma_deg() const { return largest_sigma(covariance) / kDeg; }

DirectionMap::DirectionMap(const DirectionMapOptions& options)
    : options_(options) {}

const MapDirection* DirectionMap::find(int id) const {
  for (const MapDirection& d : directions_)
    if (d.id == id) return &d;
  return nullptr;
}

void DirectionMap::reset() {
  directions_.clear();
  joint_ = JointOrientation();
  structure_ = DirectionStructure();
}

JointOrientation DirectionMap::prediction(const Eigen::Matrix3d& P) const {
  JointOrientation joint = joint_;
  if (is_covariance(P)) joint.set_orientation(P);
  return joint;
}

JointOrientation DirectionMap::prediction(const Eigen::Matrix3d& P1,
                                          const Eigen::Matrix3d& Q) const {
  JointOrientation joint = prediction(P1);
  const double drift = options_.direction_drift_deg * kDeg;
  if (all_finite(Q)) joint.predict(Q, drift * drift);
  return joint;
}

void DirectionMap::sync_covariances() {
  for (size_t j = 0; j < directions_.size(); ++j) {
    const Eigen::Matrix<double, 3, 2> B = tangent_basis(directions_[j].direction);
    const Eigen::Matrix3d C = B * joint_.direction(static_cast<int>(j)) * B.transpose();
    directions_[j].covariance = 0.5 * (C + C.transpose());
  }
}

void DirectionMap::move_direction(int j, const Eigen::Vector3d& next) {
  MapDirection& d = directions_[j];
  if (!all_finite(next) || !(next.norm() > 0.0)) return;
  const Eigen::Vector3d unit = next.normalized();
  joint_.change_basis(j, tangent_basis(unit).transpose() * tangent_basis(d.direction));
  d.direction = unit;
}

void DirectionMap::remove_direction(int j) {
  directions_.erase(directions_.begin() + j);
  joint_.remove_direction(j);
}

std::vector<VpObservation> DirectionMap::usable(const std::vector<VpObservation>& observations,
                                                std::vector<int>* index) const {
  std::vector<VpObservation> out;
  index->clear();
  const double floor = std::pow(options_.min_sigma_deg * kDeg, 2);
  for (size_t i = 0; i < observations.size(); ++i) {
    const Eigen::Vector3d& d = observations[i].direction;
    const Eigen::Matrix3d& C = observations[i].covariance;
    if (!all_finite(d) || !all_finite(C)) continue;
    const double scale = d.cwiseAbs().maxCoeff();
    if (!(scale > 0.0)) continue;
    VpObservation o;
    o.direction = (d / scale).normalized();
    const Eigen::Matrix3d P = tangent_projector(o.direction);
    if (C.isZero(0.0)) {
      const double sigma = std::max(options_.default_sigma_deg, options_.min_sigma_deg) * kDeg;
      o.covariance = sigma * sigma * P;
    } else {
      o.covariance = P * (0.5 * (C + C.transpose())) * P;
    }
    o.covariance += floor * P;
    out.push_back(o);
    index->push_back(static_cast<int>(i));
  }
  return out;
}

std::vector<MapLandmark> DirectionMap::landmarks(bool confirmed_only) const {
  std::vector<MapLandmark> out;
  for (const MapDirection& d : directions_)
    if (!confirmed_only || d.confirmed) out.push_back({d.direction, d.covariance});
  return out;
}

bool DirectionMap::spread(const DirectionAssociation& a, const std::vector<int>& confirmed) const {
  const double min_angle = options_.reacquisition_min_angle_deg * kDeg;
  for (size_t i = 0; i < a.landmark.size(); ++i)
    for (size_t j = i + 1; j < a.landmark.size(); ++j)
      if (a.landmark[i] >= 0 && a.landmark[j] >= 0 &&
          line_angle(directions_[confirmed[a.landmark[i]]].direction,
                     directions_[confirmed[a.landmark[j]]].direction) >= min_angle)
        return true;
  return false;
}

bool DirectionMap::pinnable() const {
  const double min_angle = options_.reacquisition_min_angle_deg * kDeg;
  for (size_t i = 0; i < directions_.size(); ++i)
    for (size_t j = i + 1; j < directions_.size(); ++j)
      if (directions_[i].confirmed && directions_[j].confirmed &&
          line_angle(directions_[i].direction, directions_[j].direction) >= min_angle)
        return true;
  return false;
}

MapLocation DirectionMap::locate(const Eigen::Matrix3d& R, const Eigen::Matrix3d& P,
                                 const std::vector<VpObservation>& observations) const {
  if (!is_covariance(P)) return unlocated(R, P, observations.size());
  return locate_with(R, prediction(P), observations, nullptr);
}

MapLocation DirectionMap::locate(const Eigen::Matrix3d& R, const JointOrientation& predicted,
                                 const std::vector<VpObservation>& observations,
                                 bool widen) const {
  return locate_with(R, predicted, observations, nullptr, widen);
}

MapLocation DirectionMap::locate_known(const Eigen::Matrix3d& R, const Eigen::Matrix3d& P,
                                       const std::vector<VpObservation>& observations,
                                       const std::vector<int>& direction_ids) const {
  if (!is_covariance(P)) return unlocated(R, P, observations.size());
  return locate_with(R, prediction(P), observations, &direction_ids);
}

MapLocation DirectionMap::locate_known(const Eigen::Matrix3d& R,
                                       const JointOrientation& predicted,
                                       const std::vector<VpObservation>& observations,
                                       const std::vector<int>& direction_ids) const {
  return locate_with(R, predicted, observations, &direction_ids);
}

MapLocation DirectionMap::locate_with(const Eigen::Matrix3d& R, const JointOrientation& predicted,
                                      const std::vector<VpObservation>& observations,
                                      const std::vector<int>* known_ids, bool widen) const {
  const Eigen::Matrix3d P = predicted.orientation();
  MapLocation where;
  where.R_world_from_camera = R;
  where.covariance = P;
  where.direction_id.assign(observations.size(), -1);
  if (!is_rotation(R) || !is_covariance(P) || predicted.directions() != static_cast<int>(directions_.size()))
    return where;
  where.has_joint = true;
  where.joint = predicted;
  for (const MapDirection& d : directions_) where.directions.push_back(d.direction);
  std::vector<int> index;
  const std::vector<VpObservation> seen = usable(observations, &index);
  std::vector<int> confirmed;  // landmark -> index into directions_
  for (size_t j = 0; j < directions_.size(); ++j)
    if (directions_[j].confirmed) confirmed.push_back(static_cast<int>(j));
  DirectionAssociation a;
  double widened = 0.0;  // extra orientation variance the association needed (rad^2)
  if (known_ids) {
    std::vector<int> pairing(seen.size(), -1);
    for (size_t k = 0; k < seen.size(); ++k) {
      const size_t i = index[k];
      for (size_t l = 0; i < known_ids->size() && l < confirmed.size(); ++l)
        if (directions_[confirmed[l]].id == (*known_ids)[i]) pairing[k] = static_cast<int>(l);
    }
    a = fit_directions(R, P, seen, landmarks(true), pairing);
  } else {
    a = associate_directions(R, P, seen, landmarks(true), options_.association);
    // The orientation may be off by more than its covariance admits (a pair that was wrong and
    // sure of itself): three directions that pair only under a grown uncertainty, two of them
    // well apart, unambiguously, take it back. Not two: with junk VPs and few directions, two
    // pair by chance under a wide prior (TUM's panels).
    const double sigma = (widen ? options_.reacquisition_sigma_deg : 0.0) * kDeg;
    const int needed = options_.wide_reacquisition_pairs;
    if (a.paired < needed && static_cast<int>(seen.size()) >= needed && sigma > 0.0) {
      const DirectionAssociation wide = associate_directions(
          R, P + sigma * sigma * Eigen::Matrix3d::Identity(), seen, landmarks(true),
          options_.association);
      // Only a drift of the order of that uncertainty: larger ones come with a grown covariance
      // (blank walls), and a large correction from a wide prior is more often chance than drift.
      const double wide_deg =
          Eigen::AngleAxisd(wide.R_world_from_camera * R.transpose()).angle() / kDeg;
      if (wide.paired >= needed && spread(wide, confirmed) &&
          wide_deg <= options_.reacquisition_sigma_deg) {
        a = wide;
        widened = sigma * sigma;
      }
    }
  }
  where.ambiguous = a.ambiguous;
  where.rejected = a.paired == 0 && !a.ambiguous && a.candidates > 0;
  if (a.paired == 0) return where;
  const double correction_deg =
      Eigen::AngleAxisd(a.R_world_from_camera * R.transpose()).angle() / kDeg;
  // A re-acquisition needs two directions well apart: one fixes only two degrees of freedom,
  // and after tens of degrees of drift a single VP may be any of the map's directions.
  if (correction_deg > options_.reacquisition_deg && !spread(a, confirmed)) {
    where.rejected = true;
    return where;
  }
  // The association chose the pairs on each direction's own uncertainty; the correction is the
  // joint update, which also knows how the orientation and the directions are correlated, and
  // must pass its own test: consistent with the pairs' rotation since the directions were seen.
  std::vector<std::pair<int, int>> pairs;
  for (size_t k = 0; k < seen.size(); ++k)
    if (a.landmark[k] >= 0) pairs.emplace_back(static_cast<int>(k), confirmed[a.landmark[k]]);
  MapLocation corrected = where;
  if (widened > 0.0) corrected.joint.widen_orientation(widened * Eigen::Matrix3d::Identity());
  if (!correct(R, seen, pairs, &corrected)) {
    where.rejected = true;
    return where;
  }
  where = corrected;
  for (size_t k = 0; k < seen.size(); ++k)
    if (a.landmark[k] >= 0) where.direction_id[index[k]] = directions_[confirmed[a.landmark[k]]].id;
  where.paired = a.paired;
  where.pinned = spread(a, confirmed);
  where.corrected = true;
  where.correction_deg =
      Eigen::AngleAxisd(where.R_world_from_camera * R.transpose()).angle() / kDeg;
  where.reacquired = where.correction_deg > options_.reacquisition_deg;
  return where;
}

bool DirectionMap::correct(const Eigen::Matrix3d& R, const std::vector<VpObservation>& seen,
                           const std::vector<std::pair<int, int>>& pairs,
                           MapLocation* where) const {
  const JointOrientation& prior = where->joint;
  const int n = static_cast<int>(prior.covariance().rows());
  const int m = static_cast<int>(pairs.size());
  if (m == 0) return false;
  const std::vector<char> estimated(n, 1);
  const double floor = std::pow(options_.min_direction_sigma_deg * kDeg, 2);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(n), y(2 * m);
  Eigen::MatrixXd H(2 * m, n), N(2 * m, 2 * m);
  JointOrientation::Gain gain;
  // Iterated: a correction of tens of degrees (after a blank wall) leaves the prediction's
  // linearisation behind.
  for (int iteration = 0; iteration < 8; ++iteration) {
    const Eigen::Vector3d theta = x.head<3>();
    const Eigen::Matrix3d R_now =
        theta.norm() > 0.0 ? Eigen::Matrix3d(rotation_about(theta.normalized(), theta.norm()) * R)
                           : R;
    H.setZero();
    N.setZero();
    for (int k = 0; k < m; ++k) {
      const auto [i, j] = pairs[k];
      const int row = JointOrientation::kDirections + 2 * j;
      const Eigen::Vector3d& d = directions_[j].direction;
      const Eigen::Matrix<double, 3, 2> B = tangent_basis(d);
      const Eigen::Vector3d d_now = (d + B * x.segment<2>(row)).normalized();
      const Eigen::Vector3d w = (R_now * seen[i].direction).normalized();
      Eigen::Vector2d r;
      Eigen::Matrix<double, 2, 3> H_rotation;
      if (!direction_residual(w, d_now, &r, &H_rotation)) return false;
      const Eigen::Matrix<double, 3, 2> B_now = tangent_basis(d_now);
      H.block<2, 3>(2 * k, JointOrientation::kOrientation) = H_rotation;
      H.block<2, 2>(2 * k, row) = -B_now.transpose() * B;
      N.block<2, 2>(2 * k, 2 * k) =
          B_now.transpose() * (R_now * seen[i].covariance * R_now.transpose()) * B_now +
          floor * Eigen::Matrix2d::Identity();
      y.segment<2>(2 * k) = H.middleRows<2>(2 * k) * x - r;
    }
    gain = prior.gain(H, N, estimated);
    if (!gain.valid) return false;
    const Eigen::VectorXd next = gain.K * y;
    const double step = (next - x).norm();
    x = next;
    if (!all_finite(x)) return false;
    if (step < 1e-10) break;
  }
  const double chi2 = y.dot(gain.S_inverse * y);
  if (!(chi2 <= chi2_quantile_99(2 * m))) return false;
  JointOrientation posterior = prior;
  posterior.apply(gain, H, N);
  const Eigen::Vector3d theta = x.head<3>();
  where->R_world_from_camera = nearest_rotation(
      theta.norm() > 0.0 ? Eigen::Matrix3d(rotation_about(theta.normalized(), theta.norm()) * R)
                         : R);
  where->covariance = posterior.orientation();
  where->joint = posterior;
  for (size_t j = 0; j < directions_.size(); ++j) {
    const Eigen::Vector3d& d = directions_[j].direction;
    where->directions[j] =
        (d + tangent_basis(d) * x.segment<2>(JointOrientation::kDirections + 2 * j)).normalized();
  }
  where->joint_chi2 = chi2;
  return true;
}

void DirectionMap::fuse_candidate(int j, const Eigen::Vector3d& world, const Eigen::Matrix3d& C) {
  MapDirection& d = directions_[j];
  const int n = static_cast<int>(joint_.covariance().rows());
  const int row = JointOrientation::kDirections + 2 * j;
  Eigen::Vector2d r;
  Eigen::Matrix<double, 2, 3> H_rotation;
  if (!direction_residual(world, d.direction, &r, &H_rotation)) return;
  const Eigen::Matrix<double, 3, 2> B = tangent_basis(d.direction);
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(2, n);
  H.block<2, 3>(0, JointOrientation::kOrientation) = H_rotation;
  H.block<2, 2>(0, row) = -Eigen::Matrix2d::Identity();
  const double floor = std::pow(options_.min_direction_sigma_deg * kDeg, 2);
  const Eigen::MatrixXd N = B.transpose() * C * B + floor * Eigen::Matrix2d::Identity();
  // Only the candidate moves: clutter must not correct the orientation before it is confirmed.
  std::vector<char> estimated(n, 0);
  estimated[row] = estimated[row + 1] = 1;
  const JointOrientation::Gain gain = joint_.gain(H, N, estimated);
  if (!gain.valid) return;
  const Eigen::VectorXd x = gain.K * Eigen::VectorXd(-r);
  if (!all_finite(x)) return;
  joint_.apply(gain, H, N);
  move_direction(j, d.direction + B * x.segment<2>(row));
  ++d.hits;
  d.last_seen = frame_;
  d.disagreements = 0;
}

int DirectionMap::add_direction(const Eigen::Vector3d& world, const Eigen::Matrix3d& C) {
  int evicted = -1;
  if (static_cast<int>(directions_.size()) >= options_.max_directions) {
    // Room from the least supported: a candidate before a confirmed direction, then the longest
    // unseen.
    auto weaker = [](const MapDirection& a, const MapDirection& b) {
      if (a.confirmed != b.confirmed) return !a.confirmed;
      return a.last_seen < b.last_seen;
    };
    const auto weakest = std::min_element(directions_.begin(), directions_.end(), weaker);
    evicted = static_cast<int>(weakest - directions_.begin());
    remove_direction(evicted);
    ++stats_.dropped;
  }
  // Placed where it was seen, it inherits the orientation's error: J is the observation's
  // sensitivity to it, as a pair residual has (correct()).
  Eigen::Vector2d r;
  Eigen::Matrix<double, 2, 3> J;
  if (!direction_residual(world, world, &r, &J)) return evicted;
  const Eigen::Matrix<double, 3, 2> B = tangent_basis(world);
  const double floor = std::pow(options_.min_direction_sigma_deg * kDeg, 2);
  joint_.add_direction(J, B.transpose() * C * B + floor * Eigen::Matrix2d::Identity());
  MapDirection d;
  d.id = next_id_++;
  d.direction = world;
  d.hits = 1;
  d.created = d.last_seen = frame_;
  d.confirmed = d.hits >= options_.confirm_hits && options_.confirm_frames <= 0;
  directions_.push_back(d);
  ++stats_.created;
  return evicted;
}

void DirectionMap::update(const Eigen::Matrix3d& R, const Eigen::Matrix3d& P,
                          const std::vector<VpObservation>& observations,
                          const MapLocation& location) {
  if (!is_rotation(R) || !is_covariance(P)) return;
  ++frame_;
  if (location.corrected) ++stats_.located;
  if (location.reacquired) ++stats_.reacquisitions;
  if (location.ambiguous || location.rejected) ++stats_.rejected;
  // This frame's joint state: the location's (the paired observations are in it), else the
  // last one's with the orientation's covariance set to P.
  const int n = static_cast<int>(directions_.size());
  if (location.has_joint && location.joint.directions() == n &&
      static_cast<int>(location.directions.size()) == n) {
    joint_ = location.joint;
    for (int j = 0; j < n; ++j) move_direction(j, location.directions[j]);
  } else {
    joint_ = prediction(P);
  }
  std::vector<int> index;
  const std::vector<VpObservation> seen = usable(observations, &index);
  // New directions, candidates' observations and disagreements are registered against the
  // directions the map already holds: only in a frame the map located (or while it holds no two
  // confirmed directions well apart), under a certain orientation. Else a drifted orientation
  // would place copies of the map's directions a few degrees off.
  const bool certain = largest_sigma(P) <= options_.max_orientation_sigma_deg * kDeg &&
                       (location.paired > 0 || !pinnable());
  const double gate = chi2_quantile_99(2);
  std::vector<char> disagrees(directions_.size(), 0);
  for (size_t k = 0; k < seen.size(); ++k) {
    const Eigen::Vector3d w = (R * seen[k].direction).normalized();
    // The observation's own noise in the odometry frame; with the orientation's, for the tests
    // against each direction's own uncertainty.
    const Eigen::Matrix3d C_seen = R * seen[k].covariance * R.transpose();
    const Eigen::Matrix3d C = C_seen + rotated_direction_covariance(w, P);
    const int paired_id = static_cast<size_t>(index[k]) < location.direction_id.size()
                              ? location.direction_id[index[k]]
                              : -1;
    if (paired_id >= 0) {
      for (MapDirection& d : directions_)
        if (d.id == paired_id) {
          d.last_chi2 = chi2_against(d, w, C);
          ++d.hits;
          d.last_seen = frame_;
          d.disagreements = 0;
        }
      continue;
    }
    // Unpaired: a candidate's next observation, a new direction, or a disagreement with a
    // confirmed one, all only while the orientation can place it.
    if (!certain) continue;
    int nearest = -1;
    double nearest_chi2 = gate;
    bool distinct = true;
    for (size_t j = 0; j < directions_.size(); ++j) {
      MapDirection& d = directions_[j];
      const double chi2 = chi2_against(d, w, C);
      if (line_angle(d.direction, w) <= options_.min_separation_deg * kDeg || chi2 <= gate)
        distinct = false;
      if (d.confirmed && line_angle(d.direction, w) <= options_.disagreement_angle_deg * kDeg)
        disagrees[j] = 1;
      if (!d.confirmed && chi2 <= nearest_chi2) {
        nearest = static_cast<int>(j);
        nearest_chi2 = chi2;
      }
    }
    if (nearest >= 0) {
      directions_[nearest].last_chi2 = nearest_chi2;
      fuse_candidate(nearest, w, C_seen);
    } else if (distinct) {
      const int evicted = add_direction(w, C_seen);
      if (evicted >= 0) disagrees.erase(disagrees.begin() + evicted);
      disagrees.push_back(0);
    }
  }
  for (size_t j = 0; j < disagrees.size() && j < directions_.size(); ++j) {
    MapDirection& d = directions_[j];
    if (!disagrees[j] || d.last_seen == frame_) continue;
    ++d.disagreements;
    ++d.total_disagreements;
  }
  for (int j = static_cast<int>(directions_.size()) - 1; j >= 0; --j) {
    const MapDirection& d = directions_[j];
    const bool stale = !d.confirmed && frame_ - d.last_seen > options_.max_candidate_misses;
    const bool disagreeing = d.confirmed && d.disagreements >= options_.max_disagreements;
    if (!stale && !disagreeing) continue;
    remove_direction(j);
    ++stats_.dropped;
  }
  // Confirmed once seen often enough over a baseline of motion: candidates never corrected the
  // orientation, so their observations are evidence of their own.
  for (MapDirection& d : directions_)
    d.confirmed = d.confirmed || (d.hits >= options_.confirm_hits &&
                                  d.last_seen - d.created >= options_.confirm_frames);
  sync_covariances();
  std::vector<StructureDirection> confirmed;
  for (const MapDirection& d : directions_)
    if (d.confirmed) confirmed.push_back({d.id, d.direction, d.covariance});
  structure_ = find_structure(confirmed, options_.structure);
}

std::vector<VpPrior> DirectionMap::priors(const Eigen::Matrix3d& R1, const Eigen::Matrix3d& P1,
                                          const std::vector<VpMatch>& matches) const {
  std::vector<VpPrior> priors(matches.size());
  std::vector<VpObservation> d1(matches.size());
  for (size_t i = 0; i < matches.size(); ++i) d1[i].direction = matches[i].d1;
  const MapLocation where = locate(R1, P1, d1);
  const JointOrientation joint = prediction(P1);
  for (size_t i = 0; i < matches.size(); ++i) {
    const MapDirection* d = find(where.direction_id[i]);
    if (!d) continue;
    const int j = static_cast<int>(d - directions_.data());
    Eigen::Vector3d direction = (R1.transpose() * d->direction).normalized();
    const double sign = direction.dot(matches[i].d1) < 0.0 ? -1.0 : 1.0;
    direction *= sign;
    // The direction in camera 1, c = R1^T d: moved by the orientation's error theta (R1 <- exp(
    // theta) R1) as R1^T [d]x theta, and by the direction's own as R1^T B delta. Their
    // cross-covariance counts: after a correction by d the two agree more than either is sure.
    Eigen::Matrix<double, 3, 5> J;
    J.leftCols<3>() = sign * R1.transpose() * skew(d->direction);
    J.rightCols<2>() = sign * R1.transpose() * tangent_basis(d->direction);
    const int row = JointOrientation::kDirections + 2 * j;
    Eigen::Matrix<double, 5, 5> S;
    const Eigen::MatrixXd& C = joint.covariance();
    S.topLeftCorner<3, 3>() = C.topLeftCorner<3, 3>();
    S.topRightCorner<3, 2>() = C.block<3, 2>(0, row);
    S.bottomLeftCorner<2, 3>() = C.block<2, 3>(row, 0);
    S.bottomRightCorner<2, 2>() = C.block<2, 2>(row, row);
    const Eigen::Matrix3d projector = tangent_projector(direction);
    Eigen::Matrix3d covariance = projector * J * S * J.transpose() * projector;
    priors[i].valid = all_finite(covariance);
    priors[i].direction = direction;
    priors[i].covariance = 0.5 * (covariance + covariance.transpose());
    priors[i].includes_view1 = d->last_seen == frame_;
    priors[i].track_id = d->id;
  }
  return priors;
}

}  // namespace hybrid_vo
