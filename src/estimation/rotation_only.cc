#include "hybrid_vo/estimation/rotation_only.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include "hybrid_vo/estimation/modality_scales.h"
#include "hybrid_vo/geometry/homogeneous.h"
#include "hybrid_vo/geometry/rotation.h"

namespace hybrid_vo {
namespace {

constexpr double kDegree = M_PI / 180.0;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// The data in the form the rotation acts on: bearings and plane normals of camera 1, pixels and
// VP directions of camera 2.
struct RotationData {
  std::vector<int> point_index;  // into the matches, per bearing
  std::vector<Eigen::Vector3d> bearings1;
  std::vector<Eigen::Vector2d> pixels2;
  std::vector<int> line_index;
  std::vector<Eigen::Vector3d> normals1;  // of the plane through camera 1's centre and segment
  std::vector<Eigen::Vector3d> normals2;  // the same of camera 2: +-R normals1 exactly
  std::vector<LineSegment> segments2;
  std::vector<int> vp_index;
  std::vector<Eigen::Vector3d> vps1, vps2;
  std::vector<bool> vp_sign_known;
};

RotationData prepare(const PinholeCamera& camera1, const PinholeCamera& camera2,
                     const TwoViewMatches& matches, const RotationOnlyOptions& options) {
  RotationData d;
  const Eigen::Matrix3d K1_inverse = camera1.K_inverse();
  for (size_t i = 0; i < matches.points.size(); ++i) {
    const PointMatch& m = matches.points[i];
    if (!all_finite(m.x1) || !all_finite(m.x2)) continue;
    d.point_index.push_back(static_cast<int>(i));
    d.bearings1.push_back((K1_inverse * homogeneous(m.x1)).normalized());
    d.pixels2.push_back(m.x2);
  }
  if (options.use_lines) {
    const Eigen::Matrix3d K1t = camera1.K().transpose();
    for (size_t i = 0; i < matches.lines.size(); ++i) {
      const LineMatch& m = matches.lines[i];
      const Eigen::Vector3d n = K1t * m.s1.line();
      if (!all_finite(n) || !all_finite(m.s2.p1) || !all_finite(m.s2.p2) ||
          !(n.norm() > 0.0) || !(m.s2.length() > 1.0) || !(m.s1.length() > 1.0))
        continue;
      d.line_index.push_back(static_cast<int>(i));
      d.normals1.push_back(n.normalized());
      d.normals2.push_back((camera2.K().transpose() * m.s2.line()).normalized());
      d.segments2.push_back(m.s2);
    }
  }
  if (options.use_vps) {
    for (size_t i = 0; i < matches.vps.size(); ++i) {
      const VpMatch& v = matches.vps[i];
      if (!all_finite(v.d1) || !all_finite(v.d2) || !(v.d1.norm() > 0.0) || !(v.d2.norm() > 0.0))
        continue;
      d.vp_index.push_back(static_cast<int>(i));
      d.vps1.push_back(v.d1.normalized());
      d.vps2.push_back(v.d2.normalized());
      d.vp_sign_known.push_back(v.sign_known);
    }
  }
  return d;
}

// Residual (pixels) of a point under R and its derivative by the left increment w.
bool point_residual(const PinholeCamera& camera2, const Eigen::Matrix3d& R,
                    const Eigen::Vector3d& b1, const Eigen::Vector2d& x2, Eigen::Vector2d* r,
                    Eigen::Matrix<double, 2, 3>* J = nullptr) {
  const Eigen::Vector3d y = R * b1;
  if (!(y.z() > 1e-9)) return false;
  const double iz = 1.0 / y.z();
  *r = Eigen::Vector2d(camera2.fx * y.x() * iz + camera2.cx - x2.x(),
                       camera2.fy * y.y() * iz + camera2.cy - x2.y());
  if (J) {
    Eigen::Matrix<double, 2, 3> projection;
    projection << camera2.fx * iz, 0.0, -camera2.fx * y.x() * iz * iz, 0.0, camera2.fy * iz,
        -camera2.fy * y.y() * iz * iz;
    *J = -projection * skew(y);  // exp([w]x) y = y + w x y = y - [y]x w
  }
  return all_finite(*r);
}

// Distances (pixels) of segment 2's endpoints to segment 1's line carried by R.
bool line_residual(const Eigen::Matrix3d& K2_inverse_t, const Eigen::Matrix3d& R,
                   const Eigen::Vector3d& n1, const LineSegment& s2, Eigen::Vector2d* r) {
  const Eigen::Vector3d l = K2_inverse_t * (R * n1);
  const double norm = l.head<2>().norm();
  if (!(norm > 0.0)) return false;
  *r = Eigen::Vector2d(l.dot(homogeneous(s2.p1)), l.dot(homogeneous(s2.p2))) / norm;
  return all_finite(*r);
}

bool line_residual_jacobian(const Eigen::Matrix3d& K2_inverse_t, const Eigen::Matrix3d& R,
                            const Eigen::Vector3d& n1, const LineSegment& s2, Eigen::Vector2d* r,
                            Eigen::Matrix<double, 2, 3>* J) {
  if (!line_residual(K2_inverse_t, R, n1, s2, r)) return false;
  constexpr double h = 1e-7;
  for (int k = 0; k < 3; ++k) {
    Eigen::Vector3d w = Eigen::Vector3d::Zero();
    w[k] = h;
    Eigen::Vector2d shifted;
    if (!line_residual(K2_inverse_t, rotation_about(w.normalized(), h) * R, n1, s2, &shifted))
      return false;
    J->col(k) = (shifted - *r) / h;
  }
  return true;
}

// Tangent-plane angles (rad) of d2 against +-R d1 (the sign that fits, unless known), and their
// derivative.
bool vp_residual(const Eigen::Matrix3d& R, const Eigen::Vector3d& d1, const Eigen::Vector3d& d2,
                 bool sign_known, Eigen::Vector2d* r, Eigen::Matrix<double, 2, 3>* J = nullptr) {
  Eigen::Vector3d u = R * d1;
  if (!sign_known && u.dot(d2) < 0.0) u = -u;
  if (!(u.dot(d2) > 0.0)) return false;
  const Eigen::Vector3d helper =
      std::abs(d2.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  const Eigen::Vector3d e1 = d2.cross(helper).normalized();
  const Eigen::Vector3d e2 = d2.cross(e1);
  *r = Eigen::Vector2d(e1.dot(u), e2.dot(u));
  if (J) {
    Eigen::Matrix<double, 2, 3> basis;
    basis.row(0) = e1.transpose();
    basis.row(1) = e2.transpose();
    *J = -basis * skew(u);
  }
  return all_finite(*r);
}

// MSAC cost of every modality under R (each residual capped at its threshold).
double score(const PinholeCamera& camera2, const RotationData& d, const Eigen::Matrix3d& R,
             const RotationOnlyOptions& options, int* point_inliers) {
  double cost = 0.0;
  int inliers = 0;
  const double tp2 = options.point_threshold_px * options.point_threshold_px;
  for (size_t i = 0; i < d.bearings1.size(); ++i) {
    Eigen::Vector2d r;
    const double e2 =
        point_residual(camera2, R, d.bearings1[i], d.pixels2[i], &r) ? r.squaredNorm() : tp2;
    cost += std::min(e2 / tp2, 1.0);
    inliers += e2 < tp2;
  }
  const Eigen::Matrix3d K2_inverse_t = camera2.K_inverse().transpose();
  const double tl2 = options.line_threshold_px * options.line_threshold_px;
  for (size_t i = 0; i < d.normals1.size(); ++i) {
    Eigen::Vector2d r;
    const double e2 = line_residual(K2_inverse_t, R, d.normals1[i], d.segments2[i], &r)
                          ? r.squaredNorm() / 2.0
                          : tl2;
    cost += std::min(e2 / tl2, 1.0);
  }
  const double tv = options.vp_threshold_deg * kDegree;
  for (size_t i = 0; i < d.vps1.size(); ++i) {
    Eigen::Vector2d r;
    const double e2 =
        vp_residual(R, d.vps1[i], d.vps2[i], d.vp_sign_known[i], &r) ? r.squaredNorm() : tv * tv;
    cost += std::min(e2 / (tv * tv), 1.0);
  }
  if (point_inliers) *point_inliers = inliers;
  return cost;
}

// The rotations taking directions a1, b1 onto +-a2, +-b2 (signs tried unless known).
void add_direction_pair(const Eigen::Vector3d& a1, const Eigen::Vector3d& b1,
                        const Eigen::Vector3d& a2, const Eigen::Vector3d& b2, bool a_known,
                        bool b_known, std::vector<Eigen::Matrix3d>* hypotheses) {
  for (int s = 0; s < 4; ++s) {
    if (((s & 1) && a_known) || ((s & 2) && b_known)) continue;
    Eigen::Matrix3d R;
    if (rotation_from_two_directions(a1, b1, (s & 1) ? -a2 : a2, (s & 2) ? -b2 : b2, &R))
      hypotheses->push_back(R);
  }
}

// The rotations of every pair of VP matches, in each sign case.
std::vector<Eigen::Matrix3d> vp_hypotheses(const RotationData& d) {
  std::vector<Eigen::Matrix3d> hypotheses;
  for (size_t i = 0; i < d.vps1.size(); ++i)
    for (size_t j = i + 1; j < d.vps1.size(); ++j)
      add_direction_pair(d.vps1[i], d.vps1[j], d.vps2[i], d.vps2[j], d.vp_sign_known[i],
                         d.vp_sign_known[j], &hypotheses);
  return hypotheses;
}

Eigen::Matrix3d ransac(const PinholeCamera& camera1, const PinholeCamera& camera2,
                       const RotationData& d, const RotationOnlyOptions& options,
                       const Eigen::Matrix3d* initial, int* iterations) {
  Eigen::Matrix3d best = Eigen::Matrix3d::Identity();
  double best_cost = score(camera2, d, best, options, nullptr);
  int best_inliers = 0;
  // Ties (a pair of VPs or segments is ambiguous by half turns about them) go to the rotation
  // nearest the initial one, or to the smallest: frames are close in time.
  const Eigen::Matrix3d reference = initial ? nearest_rotation(*initial) : best;
  const auto consider = [&](const Eigen::Matrix3d& R) {
    if (!all_finite(R)) return false;
    int inliers = 0;
    const double cost = score(camera2, d, R, options, &inliers) +
                        1e-6 * Eigen::AngleAxisd(Eigen::Matrix3d(R * reference.transpose())).angle();
    if (!(cost < best_cost)) return false;
    best_cost = cost;
    best = R;
    best_inliers = inliers;
    return true;
  };
  if (initial) consider(nearest_rotation(*initial));
  for (const Eigen::Matrix3d& R : vp_hypotheses(d)) consider(R);
  const int n = static_cast<int>(d.bearings1.size());
  *iterations = 0;
  std::mt19937_64 rng(options.seed);
  // Without points, pairs of segments: their planes' normals turn with the camera.
  const int num_lines = static_cast<int>(d.normals1.size());
  if (n < 2 && num_lines >= 2) {
    std::uniform_int_distribution<int> pick_line(0, num_lines - 1);
    for (int it = 0; it < options.max_iterations; ++it, ++*iterations) {
      const int a = pick_line(rng), b = pick_line(rng);
      if (a == b) continue;
      std::vector<Eigen::Matrix3d> hypotheses;
      add_direction_pair(d.normals1[a], d.normals1[b], d.normals2[a], d.normals2[b], false, false,
                         &hypotheses);
      for (const Eigen::Matrix3d& R : hypotheses) consider(R);
      if (it >= options.min_iterations && best_cost < 0.5 * num_lines) break;
    }
  }
  if (n < 2) return best;
  // Two bearings closer than this fix the rotation about their mean poorly.
  const double min_separation = 4.0 * options.point_threshold_px / camera1.mean_focal();
  std::uniform_int_distribution<int> pick(0, n - 1);
  int needed = options.max_iterations;
  const Eigen::Matrix3d K2_inverse = camera2.K_inverse();
  for (int it = 0; it < options.max_iterations && (it < options.min_iterations || it < needed);
       ++it) {
    ++*iterations;
    const int a = pick(rng), b = pick(rng);
    if (a == b || d.bearings1[a].cross(d.bearings1[b]).norm() < min_separation) continue;
    const Eigen::Vector3d b2a = (K2_inverse * homogeneous(d.pixels2[a])).normalized();
    const Eigen::Vector3d b2b = (K2_inverse * homogeneous(d.pixels2[b])).normalized();
    Eigen::Matrix3d R;
    if (!rotation_from_two_directions(d.bearings1[a], d.bearings1[b], b2a, b2b, &R)) continue;
    if (!consider(R)) continue;
    const double w = static_cast<double>(best_inliers) / n;
    const double miss = 1.0 - w * w;
    if (miss <= 0.0) {
      needed = 0;
    } else if (miss < 1.0) {
      needed = static_cast<int>(std::ceil(std::log(1.0 - options.confidence) / std::log(miss)));
    }
  }
  return best;
}

// Per-modality information under R from the inliers, the modality's sigma measured there.
struct NormalEquations {
  Eigen::Matrix3d points = Eigen::Matrix3d::Zero(), lines = Eigen::Matrix3d::Zero(),
                  vps = Eigen::Matrix3d::Zero();
  Eigen::Vector3d gradient = Eigen::Vector3d::Zero();  // of the weighted squared residuals / 2
};

}  // namespace

double rotation_transfer_error_px(const PinholeCamera& camera1, const PinholeCamera& camera2,
                                  const Eigen::Matrix3d& R, const PointMatch& match) {
  if (!all_finite(match.x1) || !all_finite(match.x2)) return kNaN;
  const Eigen::Vector3d b1 = camera1.K_inverse() * homogeneous(match.x1);
  Eigen::Vector2d r;
  return point_residual(camera2, R, b1, match.x2, &r) ? r.norm() : kNaN;
}

RotationOnlyEstimate estimate_rotation_only(const PinholeCamera& camera1,
                                            const PinholeCamera& camera2,
                                            const TwoViewMatches& matches,
                                            const RotationOnlyOptions& options,
                                            const PairCovarianceOptions& honest,
                                            const Eigen::Matrix3d* initial) {
  RotationOnlyEstimate est;
  est.point_inliers.assign(matches.points.size(), 0);
  est.line_inliers.assign(matches.lines.size(), 0);
  est.vp_inliers.assign(matches.vps.size(), 0);
  est.parallax_px = -1.0;
  if (!camera1.valid() || !camera2.valid()) return est;
  const RotationData d = prepare(camera1, camera2, matches, options);
  if (d.bearings1.size() < 2 && d.vps1.size() < 2 && d.normals1.size() < 2) return est;
  Eigen::Matrix3d R = ransac(camera1, camera2, d, options, initial, &est.iterations);

  const Eigen::Matrix3d K2_inverse_t = camera2.K_inverse().transpose();
  // Sigmas start at a third of the thresholds and follow the inliers' residuals; the inliers are
  // those within the thresholds or three sigmas (a noisier pair than the thresholds assume would
  // otherwise lose the tails of its own noise, and the estimate and its sigma with them).
  double sp = options.point_threshold_px / 3.0, sl = options.line_threshold_px / 3.0,
         sv = options.vp_threshold_deg * kDegree / 3.0;
  double tp = options.point_threshold_px, tl = options.line_threshold_px,
         tv = options.vp_threshold_deg * kDegree;
  const auto widen = [&] {
    tp = std::max(options.point_threshold_px, 3.0 * sp);
    tl = std::max(options.line_threshold_px, 3.0 * sl);
    tv = std::max(options.vp_threshold_deg * kDegree, 3.0 * sv);
  };
  NormalEquations normal;
  int np = 0, nl = 0, nv = 0;
  const auto build = [&](const Eigen::Matrix3d& rotation, bool measure) {
    normal = NormalEquations();
    np = nl = nv = 0;
    std::vector<double> point_errors, line_errors, vp_errors;
    for (size_t i = 0; i < d.bearings1.size(); ++i) {
      Eigen::Vector2d r;
      Eigen::Matrix<double, 2, 3> J;
      if (!point_residual(camera2, rotation, d.bearings1[i], d.pixels2[i], &r, &J) ||
          !(r.norm() < tp))
        continue;
      ++np;
      point_errors.push_back(r.norm());
      normal.points += J.transpose() * J;
      normal.gradient += J.transpose() * r / (sp * sp);
    }
    for (size_t i = 0; i < d.normals1.size(); ++i) {
      Eigen::Vector2d r;
      Eigen::Matrix<double, 2, 3> J;
      if (!line_residual_jacobian(K2_inverse_t, rotation, d.normals1[i], d.segments2[i], &r, &J) ||
          !(r.cwiseAbs().maxCoeff() < tl))
        continue;
      ++nl;
      line_errors.push_back(std::abs(r.x()));
      line_errors.push_back(std::abs(r.y()));
      normal.lines += J.transpose() * J;
      normal.gradient += J.transpose() * r / (sl * sl);
    }
    for (size_t i = 0; i < d.vps1.size(); ++i) {
      Eigen::Vector2d r;
      Eigen::Matrix<double, 2, 3> J;
      if (!vp_residual(rotation, d.vps1[i], d.vps2[i], d.vp_sign_known[i], &r, &J) ||
          !(r.norm() < tv))
        continue;
      ++nv;
      vp_errors.push_back(r.norm());
      normal.vps += J.transpose() * J;
      // The VPs rest on the segments: they only steer the rotation where no segment is used.
      if (d.normals1.empty()) normal.gradient += J.transpose() * r / (sv * sv);
    }
    if (!measure) return;
    ModalityScaleOptions floors;
    if (point_errors.size() >= 10) sp = std::max(floors.min_point_px, robust_sigma(&point_errors, 2));
    if (line_errors.size() >= 16) sl = std::max(floors.min_line_px, robust_sigma(&line_errors, 1));
    if (vp_errors.size() >= 3)
      sv = std::max(floors.min_vp_deg * kDegree, robust_sigma(&vp_errors, 2));
  };
  const auto information = [&](bool honest_weights) {
    const double gp = honest_weights ? std::max(1.0, np / honest.independent_points) : 1.0;
    const double gl = honest_weights ? std::max(1.0, nl / honest.independent_segments) : 1.0;
    Eigen::Matrix3d info = normal.points / (sp * sp * gp) + normal.lines / (sl * sl * gl);
    if (d.normals1.empty()) info += normal.vps / (sv * sv);
    return info;
  };
  for (int it = 0; it < options.refine_iterations; ++it) {
    build(R, true);
    widen();
    const Eigen::Matrix3d H = information(false);
    const Eigen::LDLT<Eigen::Matrix3d> ldlt(H);
    if (ldlt.info() != Eigen::Success || !(H.trace() > 0.0)) break;
    const Eigen::Vector3d step = -ldlt.solve(normal.gradient);
    if (!all_finite(step) || step.norm() > 0.5 || step.norm() < 1e-14) break;
    R = nearest_rotation(rotation_about(step.normalized(), step.norm()) * R);
  }
  build(R, true);
  widen();
  build(R, false);  // inliers under the final rotation and sigmas

  est.R = R;
  std::vector<double> transfer;
  for (size_t i = 0; i < d.bearings1.size(); ++i) {
    Eigen::Vector2d r;
    const bool ok = point_residual(camera2, R, d.bearings1[i], d.pixels2[i], &r);
    transfer.push_back(ok ? r.norm() : std::numeric_limits<double>::infinity());
    if (ok && r.norm() < tp) est.point_inliers[d.point_index[i]] = 1;
  }
  for (size_t i = 0; i < d.normals1.size(); ++i) {
    Eigen::Vector2d r;
    if (line_residual(K2_inverse_t, R, d.normals1[i], d.segments2[i], &r) &&
        r.cwiseAbs().maxCoeff() < tl)
      est.line_inliers[d.line_index[i]] = 1;
  }
  for (size_t i = 0; i < d.vps1.size(); ++i) {
    Eigen::Vector2d r;
    if (vp_residual(R, d.vps1[i], d.vps2[i], d.vp_sign_known[i], &r) && r.norm() < tv)
      est.vp_inliers[d.vp_index[i]] = 1;
  }
  est.num_point_inliers = np;
  est.num_line_inliers = nl;
  est.num_vp_inliers = nv;
  est.point_sigma_px = np >= 10 ? sp : 0.0;
  est.line_sigma_px = nl >= 8 ? sl : 0.0;
  est.vp_sigma_deg = nv >= 3 ? sv / kDegree : 0.0;
  // Over every match, not the inliers: a translation's parallax makes points outliers of the
  // rotation, and the inliers alone would always look still.
  if (transfer.size() >= 5) {
    std::nth_element(transfer.begin(), transfer.begin() + transfer.size() / 2, transfer.end());
    est.parallax_px = transfer[transfer.size() / 2];
  }

  const Eigen::Matrix3d info = information(honest.enabled);
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(info);
  const double smallest = eigen.eigenvalues().minCoeff(), largest = eigen.eigenvalues().maxCoeff();
  if (eigen.info() == Eigen::Success && smallest > 1e-9 * largest && smallest > 0.0) {
    est.covariance = eigen.eigenvectors() * eigen.eigenvalues().cwiseInverse().asDiagonal() *
                     eigen.eigenvectors().transpose();
    if (honest.enabled && np > 0) {
      const double shared = honest.shared_error_px / camera2.mean_focal();
      est.covariance += shared * shared * Eigen::Matrix3d::Identity();
    }
    est.covariance_valid = all_finite(est.covariance);
  }
  est.ok = est.covariance_valid &&
           (np >= options.min_point_inliers || np + nl >= options.min_point_inliers ||
            (np + nl == 0 && nv >= 2));
  if (!est.ok) est.covariance.setZero();
  return est;
}

}  // namespace hybrid_vo
