#include "hybrid_vo/lines/direction_map.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <Eigen/LU>

#include "hybrid_vo/geometry/homogeneous.h"
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

}  // namespace

double MapDirection::sigma_deg() const { return largest_sigma(covariance) / kDeg; }

DirectionMap::DirectionMap(const DirectionMapOptions& options) : options_(options) {}

const MapDirection* DirectionMap::find(int id) const {
  for (const MapDirection& d : directions_)
    if (d.id == id) return &d;
  return nullptr;
}

void DirectionMap::reset() {
  directions_.clear();
  structure_ = DirectionStructure();
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
  return locate_with(R, P, observations, nullptr);
}

MapLocation DirectionMap::locate_known(const Eigen::Matrix3d& R, const Eigen::Matrix3d& P,
                                       const std::vector<VpObservation>& observations,
                                       const std::vector<int>& direction_ids) const {
  return locate_with(R, P, observations, &direction_ids);
}

MapLocation DirectionMap::locate_with(const Eigen::Matrix3d& R, const Eigen::Matrix3d& P,
                                      const std::vector<VpObservation>& observations,
                                      const std::vector<int>* known_ids) const {
  MapLocation where;
  where.R_world_from_camera = R;
  where.covariance = P;
  where.direction_id.assign(observations.size(), -1);
  if (!is_rotation(R) || !is_covariance(P)) return where;
  std::vector<int> index;
  const std::vector<VpObservation> seen = usable(observations, &index);
  std::vector<int> confirmed;  // landmark -> index into directions_
  for (size_t j = 0; j < directions_.size(); ++j)
    if (directions_[j].confirmed) confirmed.push_back(static_cast<int>(j));
  DirectionAssociation a;
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
    const double sigma = options_.reacquisition_sigma_deg * kDeg;
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
          wide_deg <= options_.reacquisition_sigma_deg)
        a = wide;
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
  for (size_t k = 0; k < seen.size(); ++k)
    if (a.landmark[k] >= 0) where.direction_id[index[k]] = directions_[confirmed[a.landmark[k]]].id;
  where.paired = a.paired;
  where.pinned = spread(a, confirmed);
  where.corrected = true;
  where.R_world_from_camera = a.R_world_from_camera;
  where.covariance = a.covariance;
  where.joint_chi2 = a.joint_chi2;
  where.correction_deg = correction_deg;
  where.reacquired = where.correction_deg > options_.reacquisition_deg;
  return where;
}

void DirectionMap::fuse(MapDirection* direction, const Eigen::Vector3d& world,
                        const Eigen::Matrix3d& covariance) {
  const Eigen::Vector3d& d = direction->direction;
  const Eigen::Vector3d w = d.dot(world) >= 0.0 ? world : Eigen::Vector3d(-world);
  const Eigen::Matrix<double, 3, 2> B = tangent_basis(d);
  const Eigen::Vector2d y = B.transpose() * w / d.dot(w);
  const Eigen::Matrix2d P = B.transpose() * direction->covariance * B;
  const Eigen::Matrix2d S = P + B.transpose() * covariance * B;
  const Eigen::FullPivLU<Eigen::Matrix2d> lu(S);
  if (!lu.isInvertible()) return;
  const Eigen::Matrix2d K = P * lu.inverse();
  const Eigen::Vector3d next = (d + B * (K * y)).normalized();
  Eigen::Matrix2d P_next = (Eigen::Matrix2d::Identity() - K) * P;
  P_next = 0.5 * (P_next + P_next.transpose());
  // The floor: no direction becomes more certain than the scene's lines are straight.
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eigen(P_next);
  const double floor = std::pow(options_.min_direction_sigma_deg * kDeg, 2);
  const Eigen::Vector2d clamped = eigen.eigenvalues().cwiseMax(floor);
  P_next = eigen.eigenvectors() * clamped.asDiagonal() * eigen.eigenvectors().transpose();
  if (!all_finite(next) || !all_finite(P_next)) return;
  const Eigen::Matrix3d projector = tangent_projector(next);
  direction->direction = next;
  direction->covariance = projector * B * P_next * B.transpose() * projector;
  ++direction->hits;
  direction->last_seen = frame_;
  direction->disagreements = 0;
  direction->confirmed = direction->confirmed || direction->hits >= options_.confirm_hits;
}

int DirectionMap::add_direction(const Eigen::Vector3d& world, const Eigen::Matrix3d& covariance) {
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
    directions_.erase(weakest);
    ++stats_.dropped;
  }
  MapDirection d;
  d.id = next_id_++;
  d.direction = world;
  d.covariance = covariance;
  d.hits = 1;
  d.created = d.last_seen = frame_;
  d.confirmed = d.hits >= options_.confirm_hits;
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
  std::vector<int> index;
  const std::vector<VpObservation> seen = usable(observations, &index);
  // New directions, candidates' observations and disagreements are registered against the
  // directions the map already holds: only in a frame the map located (or while it holds no two
  // confirmed directions well apart), under a certain orientation. Else a drifted orientation
  // would place copies of the map's directions a few degrees off, which would then hold the
  // drift.
  const bool certain = largest_sigma(P) <= options_.max_orientation_sigma_deg * kDeg &&
                       (location.paired > 0 || !pinnable());
  const double gate = chi2_quantile_99(2);
  std::vector<char> disagrees(directions_.size(), 0);
  for (size_t k = 0; k < seen.size(); ++k) {
    const Eigen::Vector3d w = (R * seen[k].direction).normalized();
    const Eigen::Matrix3d C =
        R * seen[k].covariance * R.transpose() + rotated_direction_covariance(w, P);
    const int paired_id = static_cast<size_t>(index[k]) < location.direction_id.size()
                              ? location.direction_id[index[k]]
                              : -1;
    if (paired_id >= 0) {
      for (MapDirection& d : directions_)
        if (d.id == paired_id) {
          d.last_chi2 = chi2_against(d, w, C);
          fuse(&d, w, C);
        }
      continue;
    }
    // Unpaired: a candidate's next observation, a new direction, or a disagreement with a
    // confirmed one, all only while the orientation can place it.
    if (!certain) continue;
    MapDirection* nearest = nullptr;
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
        nearest = &d;
        nearest_chi2 = chi2;
      }
    }
    if (nearest) {
      nearest->last_chi2 = nearest_chi2;
      fuse(nearest, w, C);
    } else if (distinct) {
      const int evicted = add_direction(w, C);
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
  const size_t before = directions_.size();
  directions_.erase(std::remove_if(directions_.begin(), directions_.end(),
                                   [&](const MapDirection& d) {
                                     if (!d.confirmed)
                                       return frame_ - d.last_seen > options_.max_candidate_misses;
                                     return d.disagreements >= options_.max_disagreements;
                                   }),
                    directions_.end());
  stats_.dropped += static_cast<int>(before - directions_.size());
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
  for (size_t i = 0; i < matches.size(); ++i) {
    const MapDirection* d = find(where.direction_id[i]);
    if (!d) continue;
    Eigen::Vector3d direction = (R1.transpose() * d->direction).normalized();
    if (direction.dot(matches[i].d1) < 0.0) direction = -direction;
    const Eigen::Matrix3d world =
        d->covariance + rotated_direction_covariance(d->direction, P1);
    const Eigen::Matrix3d projector = tangent_projector(direction);
    Eigen::Matrix3d covariance = projector * R1.transpose() * world * R1 * projector;
    priors[i].valid = true;
    priors[i].direction = direction;
    priors[i].covariance = 0.5 * (covariance + covariance.transpose());
    priors[i].includes_view1 = d->last_seen == frame_;
    priors[i].track_id = d->id;
  }
  return priors;
}

}  // namespace hybrid_vo
