#include "hybrid_vo/estimation/stereo_translation.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Cholesky>

#include "hybrid_vo/geometry/homogeneous.h"

namespace hybrid_vo {
namespace {

// A point's whitened rows: residual, derivative by its rho, by t.
struct Rows {
  int n = 0;
  double r[4], j_rho[4];
  Eigen::Vector3d j_t[4];
  double chi2() const {
    double sum = 0.0;
    for (int k = 0; k < n; ++k) sum += r[k] * r[k];
    return sum;
  }
  void add(double residual, double d_rho, const Eigen::Vector3d& d_t) {
    r[n] = residual;
    j_rho[n] = d_rho;
    j_t[n] = d_t;
    ++n;
  }
};

double cauchy_weight(double chi2, double k) { return 1.0 / (1.0 + chi2 / (k * k)); }
double cauchy_cost(double chi2, double k) { return k * k * std::log1p(chi2 / (k * k)); }

}  // namespace

StereoTranslationEstimate estimate_stereo_translation(
    const Eigen::Matrix3d& R, const StereoRig& rig,
    const std::vector<StereoScaleObservation>& observations, const StereoScaleOptions& options,
    double independent_points) {
  StereoTranslationEstimate est;
  if (!rig.valid() || !all_finite(R) || !(options.disparity_sigma_px > 0.0) ||
      !(options.point_sigma_px > 0.0) || !std::isfinite(options.disparity_offset_px) ||
      !(independent_points > 0.0))
    return est;
  const double c = rig.fx * rig.baseline_m, delta = options.disparity_offset_px;
  const double sd = options.disparity_sigma_px, ku = rig.fx / options.point_sigma_px,
               kv = rig.fy / options.point_sigma_px;
  std::vector<const StereoScaleObservation*> used;
  std::vector<double> rho;
  for (const StereoScaleObservation& o : observations) {
    const double d = o.disparity_ref - delta;
    if (!all_finite(o.x_ref) || !all_finite(o.x_cur) || !std::isfinite(d) || !(d > 0.0) ||
        !std::isfinite(o.disparity_cur))
      continue;
    used.push_back(&o);
    rho.push_back(d / c);
  }
  est.points = static_cast<int>(used.size());
  if (est.points < std::max(3, options.min_near_points)) return est;

  const auto rows = [&](const Eigen::Vector3d& t, double r, const StereoScaleObservation& o,
                        Rows* p) {
    p->n = 0;
    p->add((c * r + delta - o.disparity_ref) / sd, c / sd, Eigen::Vector3d::Zero());
    const Eigen::Vector3d P = R * homogeneous(o.x_ref) + r * t;
    if (!(P.z() > 1e-9)) return false;
    const double iz = 1.0 / P.z(), u = P.x() * iz, v = P.y() * iz;
    const Eigen::Vector3d du(iz, 0.0, -u * iz), dv(0.0, iz, -v * iz);
    p->add(ku * (u - o.x_cur.x()), ku * du.dot(t), ku * r * du);
    p->add(kv * (v - o.x_cur.y()), kv * dv.dot(t), kv * r * dv);
    if (o.disparity_cur > 0.0) {
      // The current inverse depth r / P_z.
      const double kd = c / sd;
      p->add(kd * r * iz + (delta - o.disparity_cur) / sd, kd * (iz - r * iz * iz * t.z()),
             Eigen::Vector3d(0.0, 0.0, -kd * r * r * iz * iz));
    }
    return true;
  };
  const double k = options.loss_scale > 0.0 ? options.loss_scale : 1e300;
  const double kBehind = 1e6;
  const auto cost_of = [&](const Eigen::Vector3d& t, const std::vector<double>& r) {
    double cost = 0.0;
    Rows p;
    for (size_t i = 0; i < used.size(); ++i)
      cost += cauchy_cost(rows(t, r[i], *used[i], &p) ? p.chi2() : kBehind, k);
    return cost;
  };

  // The linear start: x_cur x (R X + t) = 0 with X from the keyframe's disparity.
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < used.size(); ++i) {
    const Eigen::Matrix3d S = skew(homogeneous(used[i]->x_cur));
    const Eigen::Vector3d X = R * homogeneous(used[i]->x_ref) / rho[i];
    A += S.transpose() * S;
    b -= S.transpose() * S * X;
  }
  Eigen::Vector3d t = A.ldlt().solve(b);
  if (!all_finite(t)) t.setZero();

  // Gauss-Newton with the rho eliminated per point (as estimate_stereo_scale), Cauchy weights
  // refreshed every step, a step halved until the robust cost drops.
  const size_t n = used.size();
  std::vector<double> h_rr(n), b_r(n), weight(n);
  std::vector<Eigen::Vector3d> h_rt(n);
  Eigen::Matrix3d H;
  double weighted_chi2 = 0.0;
  int total_rows = 0;
  const auto linearise = [&]() -> Eigen::Vector3d {
    H.setZero();
    Eigen::Vector3d g = Eigen::Vector3d::Zero();
    weighted_chi2 = 0.0;
    total_rows = 0;
    Rows p;
    for (size_t i = 0; i < n; ++i) {
      weight[i] = 0.0;
      h_rr[i] = 1.0;
      b_r[i] = 0.0;
      h_rt[i].setZero();
      if (!rows(t, rho[i], *used[i], &p)) continue;
      double rr = 0.0, br = 0.0;
      Eigen::Vector3d rt = Eigen::Vector3d::Zero(), bt = Eigen::Vector3d::Zero();
      Eigen::Matrix3d tt = Eigen::Matrix3d::Zero();
      for (int row = 0; row < p.n; ++row) {
        rr += p.j_rho[row] * p.j_rho[row];
        br += p.j_rho[row] * p.r[row];
        rt += p.j_rho[row] * p.j_t[row];
        tt += p.j_t[row] * p.j_t[row].transpose();
        bt += p.j_t[row] * p.r[row];
      }
      const double chi2 = p.chi2(), w = cauchy_weight(chi2, k);
      weight[i] = w;
      h_rr[i] = rr;
      h_rt[i] = rt;
      b_r[i] = br;
      H += w * (tt - rt * rt.transpose() / rr);
      g += w * (bt - rt * br / rr);
      weighted_chi2 += w * chi2;
      total_rows += p.n;
    }
    return -H.ldlt().solve(g);
  };
  double cost = cost_of(t, rho);
  std::vector<double> trial_rho(n);
  const int max_iterations = std::max(1, options.max_iterations);
  for (est.iterations = 0; est.iterations < max_iterations; ++est.iterations) {
    const Eigen::Vector3d step = linearise();
    if (!all_finite(step)) break;
    double lambda = 1.0, trial_cost = cost;
    Eigen::Vector3d trial_t = t;
    for (int halvings = 0; halvings < 20; ++halvings, lambda *= 0.5) {
      trial_t = t + lambda * step;
      for (size_t i = 0; i < n; ++i)
        trial_rho[i] =
            std::max(1e-12, rho[i] - lambda * (b_r[i] + h_rt[i].dot(step)) / h_rr[i]);
      trial_cost = cost_of(trial_t, trial_rho);
      if (trial_cost <= cost) break;
    }
    if (!(trial_cost <= cost)) break;
    t = trial_t;
    rho.swap(trial_rho);
    cost = trial_cost;
    if ((lambda * step).norm() < 1e-9 * (1.0 + t.norm()) * rig.baseline_m) break;
  }
  linearise();
  const Eigen::LDLT<Eigen::Matrix3d> ldlt(H);
  if (ldlt.info() != Eigen::Success || !ldlt.isPositive() || !all_finite(t)) return est;
  const int redundancy = total_rows - static_cast<int>(n) - 3;
  est.variance_factor = redundancy > 0 ? weighted_chi2 / redundancy : 1.0;
  // The points share their errors (calibration, KLT's correlated ones): at most
  // independent_points of them count, as for a pair's rotation.
  const double dependence = std::max(1.0, static_cast<double>(n) / independent_points);
  est.covariance =
      std::max(1.0, est.variance_factor) * dependence * ldlt.solve(Eigen::Matrix3d::Identity());
  est.covariance = 0.5 * (est.covariance + est.covariance.transpose());
  if (!all_finite(est.covariance) || !(est.covariance.trace() > 0.0)) return est;
  est.t = t;
  est.inliers = static_cast<int>(
      std::count_if(weight.begin(), weight.end(), [](double w) { return w > 0.5; }));
  est.ok = true;
  return est;
}

}  // namespace hybrid_vo
