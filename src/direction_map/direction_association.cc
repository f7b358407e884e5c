#include "hybrid_vo/direction_map/direction_association.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include <Eigen/Geometry>
#include <Eigen/LU>

#include "hybrid_vo/geometry/homogeneous.h"
#include "hybrid_vo/geometry/rotation.h"
#include "hybrid_vo/geometry/vp_covariance.h"

namespace hybrid_vo {
namespace {

constexpr double kDeg = M_PI / 180.0;

Eigen::Matrix3d exp_so3(const Eigen::Vector3d& w) {
  const double angle = w.norm();
  return angle > 0.0 ? rotation_about(w / angle, angle) : Eigen::Matrix3d::Identity();
}

// The residual of one pair at a rotation: the observation's direction in azimuthal equidistant
// coordinates of the landmark's tangent plane (the angle between them along the tangent towards
// the observation; zero when they agree, either sign), its Jacobian with respect to a left
// increment of the rotation, and the pair's noise there. Unlike gnomonic coordinates these stay
// proportional to the angle at the tens of degrees a re-acquisition corrects.
struct PairResidual {
  Eigen::Vector2d r;
  Eigen::Matrix<double, 2, 3> H;
  Eigen::Matrix2d S;
};

bool tangent_angle(const Eigen::Vector3d& world, const Eigen::Vector3d& m,
                   const Eigen::Matrix<double, 3, 2>& B, Eigen::Vector2d* r) {
  const Eigen::Vector3d p = m.dot(world) >= 0.0 ? world : Eigen::Vector3d(-world);
  const Eigen::Vector2d x = B.transpose() * p;
  const double s = x.norm(), c = m.dot(p);
  if (!(c > 1e-3)) return false;  // beyond 90 degrees: not this direction
  *r = s > 1e-15 ? Eigen::Vector2d(x * (std::atan2(s, c) / s)) : Eigen::Vector2d(x / c);
  return true;
}

bool residual_and_jacobian(const Eigen::Vector3d& world, const Eigen::Vector3d& m,
                           Eigen::Vector2d* r, Eigen::Matrix<double, 2, 3>* H) {
  const Eigen::Matrix<double, 3, 2> B = tangent_basis(m);
  if (!tangent_angle(world, m, B, r)) return false;
  // Central differences: the map is smooth away from 90 degrees, and a few pairs are cheap.
  constexpr double h = 1e-6;
  for (int a = 0; a < 3; ++a) {
    Eigen::Vector2d plus, minus;
    if (!tangent_angle(rotation_about(Eigen::Vector3d::Unit(a), h) * world, m, B, &plus) ||
        !tangent_angle(rotation_about(Eigen::Vector3d::Unit(a), -h) * world, m, B, &minus))
      return false;
    H->col(a) = (plus - minus) / (2.0 * h);
  }
  return true;
}

bool pair_residual(const Eigen::Vector3d& world, const Eigen::Matrix3d& world_covariance,
                   const MapLandmark& landmark, PairResidual* out) {
  if (!residual_and_jacobian(world, landmark.direction, &out->r, &out->H)) return false;
  const Eigen::Matrix<double, 3, 2> B = tangent_basis(landmark.direction);
  out->S = B.transpose() * (landmark.covariance + world_covariance) * B;
  return true;
}

// An evaluated hypothesis.
struct Fit {
  bool valid = false;
  Eigen::Vector3d delta = Eigen::Vector3d::Zero();
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  double chi2 = std::numeric_limits<double>::infinity();
};

// Iterated Kalman update of the rotation by the pairs (observation i, landmark j): minimises
// delta^T P^-1 delta + sum r^T S^-1 r, relinearising at each step, as a large correction (tens
// of degrees after a blank wall) leaves the prediction's linearisation behind.
Fit fit_pairs(const Eigen::Matrix3d& R, const Eigen::Matrix3d& P,
              const std::vector<Eigen::Vector3d>& camera,
              const std::vector<Eigen::Matrix3d>& world_covariance,
              const std::vector<MapLandmark>& landmarks,
              const std::vector<std::pair<int, int>>& pairs) {
  Fit fit;
  const int n = static_cast<int>(pairs.size());
  Eigen::VectorXd y(2 * n);
  Eigen::MatrixXd H(2 * n, 3), S = Eigen::MatrixXd::Zero(2 * n, 2 * n);
  Eigen::Vector3d delta = Eigen::Vector3d::Zero();
  for (int iteration = 0; iteration < 8; ++iteration) {
    const Eigen::Matrix3d R_now = exp_so3(delta) * R;
    for (int k = 0; k < n; ++k) {
      const auto [i, j] = pairs[k];
      PairResidual pr;
      if (!pair_residual((R_now * camera[i]).normalized(), world_covariance[i], landmarks[j], &pr))
        return fit;
      // Linearised at delta: r(d) ~ r + H (d - delta); the innovation of the prior at 0.
      y.segment<2>(2 * k) = pr.H * delta - pr.r;
      H.block<2, 3>(2 * k, 0) = pr.H;
      S.block<2, 2>(2 * k, 2 * k) = pr.S;
    }
    const Eigen::MatrixXd innovation_covariance = H * P * H.transpose() + S;
    const Eigen::FullPivLU<Eigen::MatrixXd> lu(innovation_covariance);
    if (!lu.isInvertible()) return fit;
    const Eigen::MatrixXd S_inv = lu.inverse();
    const Eigen::Matrix<double, 3, Eigen::Dynamic> K = P * H.transpose() * S_inv;
    const Eigen::Vector3d next = K * y;
    if (!all_finite(next)) return fit;
    const double step = (next - delta).norm();
    delta = next;
    fit.chi2 = y.dot(S_inv * y);
    fit.covariance = (Eigen::Matrix3d::Identity() - K * H) * P;
    if (step < 1e-10) break;
  }
  fit.covariance = 0.5 * (fit.covariance + fit.covariance.transpose());
  fit.delta = delta;
  fit.valid = all_finite(fit.covariance) && std::isfinite(fit.chi2);
  return fit;
}

// Depth-first enumeration of the hypotheses: observation `i` either stays unpaired or takes one
// of its candidates not yet taken. A partial hypothesis is extended while its chi-square could
// still pass the gate of its largest extension (each pair adds to it, and to the degrees of
// freedom: one pair's 3 sigma of prior may be plausible among three pairs).
class Search {
 public:
  Search(const Eigen::Matrix3d& R, const Eigen::Matrix3d& P,
         const std::vector<Eigen::Vector3d>& camera,
         const std::vector<Eigen::Matrix3d>& world_covariance,
         const std::vector<MapLandmark>& landmarks,
         const std::vector<std::vector<int>>& candidates, int max_hypotheses)
      : R_(R), P_(P), camera_(camera), world_covariance_(world_covariance),
        landmarks_(landmarks), candidates_(candidates), taken_(landmarks.size(), 0),
        max_hypotheses_(max_hypotheses) {}

  void run(size_t i) {
    if (i == candidates_.size() || exhausted()) return;
    run(i + 1);  // i unpaired
    for (const int j : candidates_[i]) {
      if (taken_[j] || exhausted()) continue;
      pairs_.emplace_back(static_cast<int>(i), j);
      const Fit fit = fit_pairs(R_, P_, camera_, world_covariance_, landmarks_, pairs_);
      ++evaluated;
      const int k = static_cast<int>(pairs_.size());
      if (fit.valid && fit.chi2 <= chi2_quantile_99(2 * k)) found.push_back({pairs_, fit});
      if (fit.valid && fit.chi2 <= chi2_quantile_99(2 * (k + remaining(i + 1)))) {
        taken_[j] = 1;
        run(i + 1);
        taken_[j] = 0;
      }
      pairs_.pop_back();
    }
  }

  // Observations from i on that have candidates.
  int remaining(size_t i) const {
    int n = 0;
    for (; i < candidates_.size(); ++i) n += !candidates_[i].empty();
    return n;
  }

  bool exhausted() const { return evaluated >= max_hypotheses_; }

  struct Hypothesis {
    std::vector<std::pair<int, int>> pairs;
    Fit fit;
  };
  std::vector<Hypothesis> found;
  int evaluated = 0;

 private:
  const Eigen::Matrix3d& R_;
  const Eigen::Matrix3d& P_;
  const std::vector<Eigen::Vector3d>& camera_;
  const std::vector<Eigen::Matrix3d>& world_covariance_;
  const std::vector<MapLandmark>& landmarks_;
  const std::vector<std::vector<int>>& candidates_;
  std::vector<char> taken_;
  std::vector<std::pair<int, int>> pairs_;
  const int max_hypotheses_;
};

// Candidates of each observation: the landmarks whose linearised chi-square at the prediction is
// within the gate, nearest first.
std::vector<std::vector<int>> candidates_of(const Eigen::Matrix3d& R, const Eigen::Matrix3d& P,
                                            const std::vector<Eigen::Vector3d>& camera,
                                            const std::vector<Eigen::Matrix3d>& world_covariance,
                                            const std::vector<MapLandmark>& landmarks,
                                            const DirectionAssociationOptions& options) {
  std::vector<std::vector<int>> candidates(camera.size());
  for (size_t i = 0; i < camera.size(); ++i) {
    std::vector<std::pair<double, int>> scored;
    for (size_t j = 0; j < landmarks.size(); ++j) {
      PairResidual pr;
      if (!pair_residual((R * camera[i]).normalized(), world_covariance[i], landmarks[j], &pr))
        continue;
      const Eigen::Matrix2d S = pr.H * P * pr.H.transpose() + pr.S;
      const Eigen::FullPivLU<Eigen::Matrix2d> lu(S);
      if (!lu.isInvertible()) continue;
      const double chi2 = pr.r.dot(lu.inverse() * pr.r);
      if (chi2 <= options.candidate_chi2) scored.emplace_back(chi2, static_cast<int>(j));
    }
    std::sort(scored.begin(), scored.end());
    for (size_t k = 0; k < scored.size() && static_cast<int>(k) < options.max_candidates; ++k)
      candidates[i].push_back(scored[k].second);
  }
  return candidates;
}

}  // namespace

bool direction_residual(const Eigen::Vector3d& world, const Eigen::Vector3d& direction,
                        Eigen::Vector2d* r, Eigen::Matrix<double, 2, 3>* H) {
  return all_finite(world) && all_finite(direction) && residual_and_jacobian(world, direction, r, H);
}

double chi2_quantile_99(int dof) {
  static constexpr double kTable[] = {6.635,  9.210,  11.345, 13.277, 15.086, 16.812,
                                      18.475, 20.090, 21.666, 23.209, 24.725, 26.217,
                                      27.688, 29.141, 30.578, 32.000};
  if (dof <= 0) return 0.0;
  if (dof <= 16) return kTable[dof - 1];
  // Wilson and Hilferty: (chi2 / k)^(1/3) is nearly normal; z(0.99) = 2.3263.
  const double k = dof, a = 2.0 / (9.0 * k);
  return k * std::pow(1.0 - a + 2.3263 * std::sqrt(a), 3);
}

namespace {

// The usable observations (finite, non-zero) as unit directions with world-frame covariances,
// at most `max` of them, most certain first (the detector's order is arbitrary); `index` maps
// back to the input.
struct Prepared {
  std::vector<int> index;
  std::vector<Eigen::Vector3d> camera;
  std::vector<Eigen::Matrix3d> world_covariance;
};

Prepared prepare(const Eigen::Matrix3d& R, const std::vector<VpObservation>& observations,
                 int max) {
  Prepared p;
  for (size_t i = 0; i < observations.size(); ++i) {
    const Eigen::Vector3d& d = observations[i].direction;
    if (all_finite(d) && d.norm() > 0.0 && all_finite(observations[i].covariance))
      p.index.push_back(static_cast<int>(i));
  }
  std::stable_sort(p.index.begin(), p.index.end(), [&](int a, int b) {
    return observations[a].covariance.trace() < observations[b].covariance.trace();
  });
  if (static_cast<int>(p.index.size()) > max) p.index.resize(std::max(max, 0));
  for (const int i : p.index) {
    p.camera.push_back(observations[i].direction.normalized());
    p.world_covariance.push_back(R * observations[i].covariance * R.transpose());
  }
  return p;
}

DirectionAssociation unchanged(const Eigen::Matrix3d& R, const Eigen::Matrix3d& P, size_t n) {
  DirectionAssociation out;
  out.landmark.assign(n, -1);
  out.R_world_from_camera = R;
  out.covariance = P;
  return out;
}

// The result of an accepted hypothesis.
void accept(const Eigen::Matrix3d& R, const Prepared& p,
            const std::vector<std::pair<int, int>>& pairs, const Fit& fit,
            DirectionAssociation* out) {
  for (const auto& [i, j] : pairs) out->landmark[p.index[i]] = j;
  out->paired = static_cast<int>(pairs.size());
  out->R_world_from_camera = nearest_rotation(exp_so3(fit.delta) * R);
  out->covariance = fit.covariance;
  out->joint_chi2 = fit.chi2;
}

}  // namespace

DirectionAssociation fit_directions(const Eigen::Matrix3d& R, const Eigen::Matrix3d& P,
                                    const std::vector<VpObservation>& observations,
                                    const std::vector<MapLandmark>& landmarks,
                                    const std::vector<int>& pairing) {
  DirectionAssociation out = unchanged(R, P, observations.size());
  if (!all_finite(R) || !all_finite(P)) return out;
  const Prepared p = prepare(R, observations, static_cast<int>(observations.size()));
  std::vector<std::pair<int, int>> pairs;
  for (size_t k = 0; k < p.index.size(); ++k) {
    const int i = p.index[k];
    if (static_cast<size_t>(i) < pairing.size() && pairing[i] >= 0 &&
        pairing[i] < static_cast<int>(landmarks.size()))
      pairs.emplace_back(static_cast<int>(k), pairing[i]);
  }
  if (pairs.empty()) return out;
  const Fit fit = fit_pairs(R, P, p.camera, p.world_covariance, landmarks, pairs);
  if (fit.valid && fit.chi2 <= chi2_quantile_99(2 * static_cast<int>(pairs.size())))
    accept(R, p, pairs, fit, &out);
  return out;
}

DirectionAssociation associate_directions(const Eigen::Matrix3d& R, const Eigen::Matrix3d& P,
                                          const std::vector<VpObservation>& observations,
                                          const std::vector<MapLandmark>& landmarks,
                                          const DirectionAssociationOptions& options) {
  DirectionAssociation out = unchanged(R, P, observations.size());
  if (!all_finite(R) || !all_finite(P) || landmarks.empty()) return out;
  const Prepared p = prepare(R, observations, options.max_observations);
  const std::vector<std::vector<int>> candidates =
      candidates_of(R, P, p.camera, p.world_covariance, landmarks, options);
  for (const std::vector<int>& c : candidates) out.candidates += !c.empty();
  Search search(R, P, p.camera, p.world_covariance, landmarks, candidates,
                options.max_hypotheses);
  search.run(0);
  out.hypotheses = search.evaluated;
  if (search.exhausted()) {
    out.ambiguous = true;
    return out;
  }
  if (search.found.empty()) return out;

  // The most pairs, then the lowest joint chi-square.
  auto better = [](const Search::Hypothesis& a, const Search::Hypothesis& b) {
    if (a.pairs.size() != b.pairs.size()) return a.pairs.size() > b.pairs.size();
    return a.fit.chi2 < b.fit.chi2;
  };
  const Search::Hypothesis& best =
      *std::min_element(search.found.begin(), search.found.end(), better);
  const Eigen::Matrix3d R_best = exp_so3(best.fit.delta) * R;
  for (const Search::Hypothesis& h : search.found) {
    if (h.pairs.size() != best.pairs.size() || &h == &best) continue;
    const Eigen::AngleAxisd apart(exp_so3(h.fit.delta) * R * R_best.transpose());
    if (apart.angle() > options.ambiguity_min_deg * kDeg &&
        h.fit.chi2 - best.fit.chi2 < options.ambiguity_chi2) {
      out.ambiguous = true;
      return out;
    }
  }
  accept(R, p, best.pairs, best.fit, &out);
  return out;
}

}  // namespace hybrid_vo
