#include "hybrid_vo/estimation/window_scale.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Cholesky>

#include "hybrid_vo/estimation/two_view_depth.h"
#include "hybrid_vo/geometry/homogeneous.h"

namespace hybrid_vo {
namespace {

// The free log-scales' vectors and matrices, sized at run time up to kMaxFreeLinks without an
// allocation (the window is solved once per keyframe; allocating per residual row was most of
// its cost).
using VectorF = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxFreeLinks, 1>;
using MatrixF = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxFreeLinks, kMaxFreeLinks>;
using Matrix3F = Eigen::Matrix<double, 3, Eigen::Dynamic, 0, 3, kMaxFreeLinks>;

double cauchy_cost(double chi2, double k) { return k * k * std::log1p(chi2 / (k * k)); }
double cauchy_weight(double chi2, double k) { return 1.0 / (1.0 + chi2 / (k * k)); }

// The chain in the orientation of camera 0: Q_c = R_{c-1} ... R_0 turns camera 0's axes into
// camera c's, and link j's translation is w_j = Q_{j+1}^T t_j there. A point on the ray x_a of
// camera a at inverse depth rho is seen by camera c (times rho) at
//   P = Q_c (n_a + rho sum_{a <= j < c} s_j w_j),  n_a = Q_a^T [x_a; 1],
// which is linear in every s_j: the translation from a to c is the sum of the scaled links.
struct Chain {
  std::vector<Eigen::Matrix3d> Q;
  std::vector<Eigen::Vector3d> w;
  std::vector<int> free_index;  // per link: its column among the free ones, or -1
  int free = 0;
};

// A point is its ray in the anchor camera and its inverse depth there, q = (x, y, rho): the anchor
// sighting is a measurement like the others (taken as exact, the scales' covariance was a third
// too small in sigma on random windows).
struct State {
  Eigen::VectorXd log_s;               // per link
  std::vector<Eigen::Vector3d> point;  // per point
};

// One point's whitened residuals (two per sighting, the anchor's first) with their derivatives
// by its own parameters and by the free log-scales.
struct PointRows {
  std::vector<double> r;
  std::vector<Eigen::Vector3d> j_point;
  std::vector<VectorF> j;
  double chi2 = 0.0;
};

class WindowModel {
 public:
  WindowModel(const Chain& chain, const std::vector<WindowPoint>& points, double sigma)
      : chain_(chain), points_(points), k_(1.0 / sigma) {}

  // The point's squared whitened residual norm alone (what a step's cost needs); false as rows().
  bool chi2(const State& x, size_t i, double* out) const {
    const WindowPoint& point = points_[i];
    const Eigen::Vector3d& q = x.point[i];
    const Eigen::Vector3d n =
        chain_.Q[point.anchor].transpose() * Eigen::Vector3d(q.x(), q.y(), 1.0);
    double sum = (q.head<2>() - point.x_anchor).squaredNorm();
    for (const auto& [camera, x_seen] : point.seen) {
      Eigen::Vector3d d = Eigen::Vector3d::Zero();
      for (int link = point.anchor; link < camera; ++link)
        d += std::exp(x.log_s(link)) * chain_.w[link];
      const Eigen::Vector3d P = chain_.Q[camera] * (n + q.z() * d);
      if (!(P.z() > 1e-9 * (1.0 + std::abs(P.x()) + std::abs(P.y())))) return false;
      sum += (P.head<2>() / P.z() - x_seen).squaredNorm();
    }
    *out = k_ * k_ * sum;
    return true;
  }

  // False when a sighting falls behind its camera (or at infinity before it).
  bool rows(const State& x, size_t i, PointRows* p) const {
    const WindowPoint& point = points_[i];
    const Eigen::Vector3d& q = x.point[i];
    const double rho = q.z();
    const Eigen::Matrix3d& Qa = chain_.Q[point.anchor];
    const Eigen::Vector3d n = Qa.transpose() * Eigen::Vector3d(q.x(), q.y(), 1.0);
    p->r.clear();
    p->j_point.clear();
    p->j.clear();
    p->chi2 = 0.0;
    const VectorF none = VectorF::Zero(chain_.free);
    add(p, k_ * (q.x() - point.x_anchor.x()), Eigen::Vector3d(k_, 0.0, 0.0), none);
    add(p, k_ * (q.y() - point.x_anchor.y()), Eigen::Vector3d(0.0, k_, 0.0), none);
    for (const auto& [camera, x_seen] : point.seen) {
      Eigen::Vector3d d = Eigen::Vector3d::Zero();
      for (int link = point.anchor; link < camera; ++link)
        d += std::exp(x.log_s(link)) * chain_.w[link];
      const Eigen::Matrix3d& Q = chain_.Q[camera];
      const Eigen::Vector3d P = Q * (n + rho * d);
      if (!(P.z() > 1e-9 * (1.0 + std::abs(P.x()) + std::abs(P.y())))) return false;
      const double iz = 1.0 / P.z(), u = P.x() * iz, v = P.y() * iz;
      const Eigen::RowVector3d du(iz, 0.0, -u * iz), dv(0.0, iz, -v * iz);
      // dP by the point's (x, y, rho) and by the free log-scales.
      Eigen::Matrix3d dP_q;
      dP_q.col(0) = Q * Qa.transpose().col(0);
      dP_q.col(1) = Q * Qa.transpose().col(1);
      dP_q.col(2) = Q * d;
      Matrix3F dP_s = Matrix3F::Zero(3, chain_.free);
      for (int link = point.anchor; link < camera; ++link)
        if (chain_.free_index[link] >= 0)
          dP_s.col(chain_.free_index[link]) = rho * std::exp(x.log_s(link)) * (Q * chain_.w[link]);
      add(p, k_ * (u - x_seen.x()), k_ * (du * dP_q).transpose(), k_ * (du * dP_s).transpose());
      add(p, k_ * (v - x_seen.y()), k_ * (dv * dP_q).transpose(), k_ * (dv * dP_s).transpose());
    }
    return true;
  }

 private:
  static void add(PointRows* p, double r, const Eigen::Vector3d& j_point,
                  const VectorF& j) {
    p->r.push_back(r);
    p->j_point.push_back(j_point);
    p->j.push_back(j);
    p->chi2 += r * r;
  }

  const Chain& chain_;
  const std::vector<WindowPoint>& points_;
  double k_;
};

bool valid_input(const std::vector<RelativePose>& links, const std::vector<char>& fixed,
                 const std::vector<WindowPoint>& points, const WindowScaleOptions& options) {
  const int L = static_cast<int>(links.size());
  if (L == 0 || static_cast<int>(fixed.size()) != L ||
      std::none_of(fixed.begin(), fixed.end(), [](char f) { return f != 0; }) ||
      std::count(fixed.begin(), fixed.end(), 0) > kMaxFreeLinks)
    return false;
  if (!(options.point_sigma > 0.0) || !(options.loss_scale > 0.0) || !(options.max_log_sigma > 0.0))
    return false;
  for (const RelativePose& link : links)
    if (!all_finite(link.R) || !all_finite(link.t)) return false;
  for (const WindowPoint& p : points) {
    if (p.anchor < 0 || p.anchor >= L || !all_finite(p.x_anchor) || !std::isfinite(p.rho))
      return false;
    for (const auto& [camera, x] : p.seen)
      if (camera <= p.anchor || camera > L || !all_finite(x)) return false;
  }
  return true;
}

// The inverse depth of a point in its anchor camera from its sighting farthest along the chain
// (the longest baseline) at the given lengths; 0 when none triangulates it.
double start_inverse_depth(const Chain& chain, const WindowPoint& p) {
  for (auto it = p.seen.rbegin(); it != p.seen.rend(); ++it) {
    const int camera = it->first;
    Eigen::Vector3d d = Eigen::Vector3d::Zero();
    for (int link = p.anchor; link < camera; ++link) d += chain.w[link];
    // Anchor to camera: X_c = R X_a + t; triangulated in camera a as the second camera of the
    // inverse pair.
    const RelativePose to_camera(chain.Q[camera] * chain.Q[p.anchor].transpose(),
                                 chain.Q[camera] * d);
    const RelativePose back = to_camera.inverse();
    const InverseDepth depth =
        triangulate_inverse_depth(back.R, back.t, it->second, p.x_anchor, 1e-3);
    if (depth.ok) return depth.rho;
  }
  return 0.0;
}

}  // namespace

WindowScaleEstimate estimate_window_scales(const std::vector<RelativePose>& links,
                                           const std::vector<char>& fixed,
                                           const std::vector<WindowPoint>& points,
                                           const WindowScaleOptions& options) {
  WindowScaleEstimate result;
  if (!valid_input(links, fixed, points, options)) return result;
  const int L = static_cast<int>(links.size());
  const size_t n = points.size();

  Chain chain;
  chain.Q.assign(L + 1, Eigen::Matrix3d::Identity());
  chain.w.resize(L);
  chain.free_index.assign(L, -1);
  for (int j = 0; j < L; ++j) {
    chain.Q[j + 1] = links[j].R * chain.Q[j];
    chain.w[j] = chain.Q[j + 1].transpose() * links[j].t;
    if (!fixed[j]) chain.free_index[j] = chain.free++;
  }
  const int F = chain.free;

  // Which points take part: those with a start for their depth. A free link needs enough of them
  // spanning it and another link.
  State x;
  x.log_s = Eigen::VectorXd::Zero(L);
  x.point.assign(n, Eigen::Vector3d::Zero());
  std::vector<char> used(n, 0);
  std::vector<int> tying(L, 0);
  for (size_t i = 0; i < n; ++i) {
    const WindowPoint& p = points[i];
    if (p.seen.empty()) continue;
    const double rho = p.rho > 0.0 ? p.rho : start_inverse_depth(chain, p);
    if (!(rho > 0.0)) continue;
    x.point[i] = Eigen::Vector3d(p.x_anchor.x(), p.x_anchor.y(), rho);
    used[i] = 1;
    int span_end = p.anchor;
    for (const auto& s : p.seen) span_end = std::max(span_end, s.first);
    if (span_end - p.anchor >= 2)
      for (int link = p.anchor; link < span_end; ++link) ++tying[link];
  }
  for (int j = 0; j < L; ++j)
    if (!fixed[j] && tying[j] < options.min_tying_points) return result;
  if (std::count(used.begin(), used.end(), 1) == 0) return result;

  const WindowModel model(chain, points, options.point_sigma);
  const double k = options.loss_scale;
  // A sighting behind its camera costs as a gross outlier would.
  const double behind_cost = cauchy_cost(1e6 * k * k, k);
  auto cost_of = [&](const State& s) {
    double cost = 0.0, chi2 = 0.0;
    for (size_t i = 0; i < n; ++i) {
      if (!used[i]) continue;
      cost += model.chi2(s, i, &chi2) ? cauchy_cost(chi2, k) : behind_cost;
    }
    return cost;
  };

  // Gauss-Newton on (log-scales, q_1..n) with every point eliminated by its Schur complement:
  // a point's normal equations [H_qq H_qs; H_sq H_ss] add H_ss - H_sq H_qq^-1 H_qs to the
  // reduced system (F x F). The point's Cauchy weight is refreshed each step (IRLS).
  std::vector<Eigen::Matrix3d> h_qq_inv(n, Eigen::Matrix3d::Zero());
  std::vector<Eigen::Vector3d> b_q(n, Eigen::Vector3d::Zero());
  std::vector<Matrix3F> h_qs(n, Matrix3F::Zero(3, F));
  std::vector<double> weight(n, 0.0);
  MatrixF H(F, F);
  double weighted_chi2 = 0.0;
  int rows = 0, points_in = 0;
  auto linearise = [&]() -> VectorF {
    H.setZero();
    VectorF b = VectorF::Zero(F);
    weighted_chi2 = 0.0;
    rows = points_in = 0;
    PointRows p;
    for (size_t i = 0; i < n; ++i) {
      weight[i] = 0.0;
      h_qq_inv[i].setZero();
      b_q[i].setZero();
      h_qs[i].setZero();
      if (!used[i] || !model.rows(x, i, &p)) continue;
      Eigen::Matrix3d qq = Eigen::Matrix3d::Zero();
      Eigen::Vector3d bq = Eigen::Vector3d::Zero();
      Matrix3F qs = Matrix3F::Zero(3, F);
      VectorF bs = VectorF::Zero(F);
      MatrixF ss = MatrixF::Zero(F, F);
      for (size_t row = 0; row < p.r.size(); ++row) {
        qq += p.j_point[row] * p.j_point[row].transpose();
        bq += p.j_point[row] * p.r[row];
        qs += p.j_point[row] * p.j[row].transpose();
        ss += p.j[row] * p.j[row].transpose();
        bs += p.j[row] * p.r[row];
      }
      // Its depth must move its sightings: without parallax it says nothing, and a point whose
      // own system is nearly singular (a wrong sighting on a short baseline) would leave the
      // reduced one indefinite by round-off.
      const Eigen::LDLT<Eigen::Matrix3d> ldlt(qq);
      if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 1e-9 * qq.trace()))
        continue;
      const Eigen::Matrix3d qq_inv = ldlt.solve(Eigen::Matrix3d::Identity());
      const double w = cauchy_weight(p.chi2, k);
      weight[i] = w;
      h_qq_inv[i] = qq_inv;
      h_qs[i] = qs;
      b_q[i] = bq;
      H += w * (ss - qs.transpose() * qq_inv * qs);
      b += w * (bs - qs.transpose() * qq_inv * bq);
      weighted_chi2 += w * p.chi2;
      rows += static_cast<int>(p.r.size());
      ++points_in;
    }
    if (F == 0) return VectorF();
    return -H.ldlt().solve(b);
  };
  // The point's step follows the scales' (the weight cancels in it).
  auto apply = [&](const VectorF& step, double lambda, State* to) {
    to->log_s = x.log_s;
    for (int j = 0; j < L; ++j)
      if (chain.free_index[j] >= 0) to->log_s(j) += lambda * step(chain.free_index[j]);
    to->point.resize(n);
    for (size_t i = 0; i < n; ++i) {
      to->point[i] = x.point[i];
      if (!used[i]) continue;
      const Eigen::Vector3d coupling =
          F > 0 ? Eigen::Vector3d(h_qs[i] * step) : Eigen::Vector3d::Zero();
      to->point[i] -= lambda * h_qq_inv[i] * (b_q[i] + coupling);
      to->point[i].z() = std::max(0.0, to->point[i].z());
    }
  };

  double cost = cost_of(x);
  State trial;
  for (result.iterations = 0; result.iterations < options.max_iterations; ++result.iterations) {
    const VectorF step = linearise();
    if (points_in == 0 || (F > 0 && !all_finite(step))) break;
    double lambda = 1.0, trial_cost = cost;
    for (int halvings = 0; halvings < 20; ++halvings, lambda *= 0.5) {
      apply(step, lambda, &trial);
      trial_cost = cost_of(trial);
      if (trial_cost <= cost) break;
    }
    if (!(trial_cost <= cost)) break;  // no descent left
    double moved = 0.0;
    for (size_t i = 0; i < n; ++i)
      if (used[i])
        moved = std::max(moved,
                         std::abs(trial.point[i].z() - x.point[i].z()) / (x.point[i].z() + 1e-12));
    const double scale_moved = F > 0 ? lambda * step.cwiseAbs().maxCoeff() : 0.0;
    std::swap(x, trial);
    cost = trial_cost;
    // A millionth of the scale, a hundred-thousandth of a depth: far below their noise.
    if (scale_moved < 1e-6 && moved < 1e-5) break;
  }
  linearise();
  if (points_in == 0) return result;
  MatrixF covariance = MatrixF::Zero(F, F);
  // Residual variance over the model's: rows minus three per point and the free scales.
  const int redundancy = rows - 3 * points_in - F;
  result.variance_factor = redundancy > 0 ? weighted_chi2 / redundancy : 1.0;
  if (F > 0) {
    const Eigen::LDLT<MatrixF> ldlt(H);
    if (ldlt.info() != Eigen::Success || !ldlt.isPositive()) return result;
    covariance = result.variance_factor * ldlt.solve(MatrixF::Identity(F, F));
    if (!all_finite(covariance) || !all_finite(x.log_s)) return result;
    for (int f = 0; f < F; ++f)
      if (!(covariance(f, f) > 0.0) ||
          covariance(f, f) > options.max_log_sigma * options.max_log_sigma)
        return result;
  }

  result.ok = true;
  result.scales.resize(L);
  result.log_covariance = Eigen::MatrixXd::Zero(L, L);
  for (int j = 0; j < L; ++j) {
    result.scales[j] = std::exp(x.log_s(j));
    for (int m = 0; m < L; ++m)
      if (chain.free_index[j] >= 0 && chain.free_index[m] >= 0)
        result.log_covariance(j, m) = covariance(chain.free_index[j], chain.free_index[m]);
  }
  result.rho.assign(n, 0.0);
  result.rho_sigma.assign(n, std::numeric_limits<double>::infinity());
  result.inlier.assign(n, 0);
  for (size_t i = 0; i < n; ++i) {
    if (!used[i] || !(weight[i] > 0.0)) continue;
    // Its own information and what the scales' uncertainty adds through its coupling.
    const double own = result.variance_factor / weight[i] * h_qq_inv[i](2, 2);
    const Eigen::Vector3d g = F > 0 ? Eigen::Vector3d(h_qq_inv[i] * h_qs[i] * covariance *
                                                      h_qs[i].transpose() * h_qq_inv[i].col(2))
                                    : Eigen::Vector3d::Zero();
    result.rho[i] = x.point[i].z();
    result.rho_sigma[i] = std::sqrt(own + g.z());
    result.inlier[i] = weight[i] > 0.5;
  }
  result.points_used = points_in;
  result.inliers = static_cast<int>(std::count(result.inlier.begin(), result.inlier.end(), 1));
  return result;
}

}  // namespace hybrid_vo
