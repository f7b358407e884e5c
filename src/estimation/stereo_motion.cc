#include "hybrid_vo/estimation/stereo_motion.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Cholesky>

#include "hybrid_vo/geometry/homogeneous.h"
#include "hybrid_vo/geometry/rotation.h"

namespace hybrid_vo {
namespace {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;

// A point's whitened rows: residual, derivative by its rho, by the globals [w, t].
struct Rows {
  int n = 0;
  double r[4], j_rho[4];
  Vector6d j[4];
  double chi2() const {
    double sum = 0.0;
    for (int k = 0; k < n; ++k) sum += r[k] * r[k];
    return sum;
  }
  void add(double residual, double d_rho, const Vector6d& d_globals) {
    r[n] = residual;
    j_rho[n] = d_rho;
    j[n] = d_globals;
    ++n;
  }
};

double cauchy_weight(double chi2, double k) { return 1.0 / (1.0 + chi2 / (k * k)); }
double cauchy_cost(double chi2, double k) { return k * k * std::log1p(chi2 / (k * k)); }

struct State {
  Eigen::Matrix3d R;
  Eigen::Vector3d t;
  std::vector<double> rho;
};

}  // namespace

StereoMotionEstimate estimate_stereo_motion(const Eigen::Matrix3d& R0, const StereoRig& rig,
                                            const std::vector<StereoScaleObservation>& observations,
                                            const StereoScaleOptions& options,
                                            double independent_points, bool refine_rotation) {
  StereoMotionEstimate est;
  if (!rig.valid() || !all_finite(R0) || !(options.disparity_sigma_px > 0.0) ||
      !(options.point_sigma_px > 0.0) || !std::isfinite(options.disparity_offset_px) ||
      !(independent_points > 0.0))
    return est;
  const double c = rig.fx * rig.baseline_m, delta = options.disparity_offset_px;
  const double sd = options.disparity_sigma_px, ku = rig.fx / options.point_sigma_px,
               kv = rig.fy / options.point_sigma_px;
  std::vector<const StereoScaleObservation*> used;
  State x;
  x.R = nearest_rotation(R0);
  for (const StereoScaleObservation& o : observations) {
    const double d = o.disparity_ref - delta;
    if (!all_finite(o.x_ref) || !all_finite(o.x_cur) || !std::isfinite(d) || !(d > 0.0) ||
        !std::isfinite(o.disparity_cur))
      continue;
    used.push_back(&o);
    x.rho.push_back(d / c);
  }
  est.points = static_cast<int>(used.size());
  if (est.points < std::max(3, options.min_near_points)) return est;

  const auto rows = [&](const State& s, double r, const StereoScaleObservation& o, Rows* p) {
    p->n = 0;
    p->add((c * r + delta - o.disparity_ref) / sd, c / sd, Vector6d::Zero());
    const Eigen::Vector3d Rx = s.R * homogeneous(o.x_ref);
    const Eigen::Vector3d P = Rx + r * s.t;  // the current point times rho
    if (!(P.z() > 1e-9)) return false;
    // dP by the globals: w (the left increment turns Rx: -[Rx]x), t (rho I).
    Eigen::Matrix<double, 3, 6> dP;
    dP.leftCols<3>() = -skew(Rx);
    dP.rightCols<3>() = r * Eigen::Matrix3d::Identity();
    const double iz = 1.0 / P.z(), u = P.x() * iz, v = P.y() * iz;
    const Eigen::RowVector3d du(iz, 0.0, -u * iz), dv(0.0, iz, -v * iz);
    p->add(ku * (u - o.x_cur.x()), ku * du.dot(s.t), ku * (du * dP).transpose());
    p->add(kv * (v - o.x_cur.y()), kv * dv.dot(s.t), kv * (dv * dP).transpose());
    if (o.disparity_cur > 0.0) {
      // The current inverse depth r / P_z.
      const double kd = c / sd;
      p->add(kd * r * iz + (delta - o.disparity_cur) / sd, kd * (iz - r * iz * iz * s.t.z()),
             (-kd * r * iz * iz * dP.row(2)).transpose());
    }
    return true;
  };
  const double k = options.loss_scale > 0.0 ? options.loss_scale : 1e300;
  const double kBehind = 1e6;
  const auto cost_of = [&](const State& s) {
    double cost = 0.0;
    Rows p;
    for (size_t i = 0; i < used.size(); ++i)
      cost += cauchy_cost(rows(s, s.rho[i], *used[i], &p) ? p.chi2() : kBehind, k);
    return cost;
  };

  // The linear start for t: x_cur x (R X + t) = 0 with X from the keyframe's disparity.
  {
    Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
    Eigen::Vector3d b = Eigen::Vector3d::Zero();
    for (size_t i = 0; i < used.size(); ++i) {
      const Eigen::Matrix3d S = skew(homogeneous(used[i]->x_cur));
      const Eigen::Vector3d X = x.R * homogeneous(used[i]->x_ref) / x.rho[i];
      A += S.transpose() * S;
      b -= S.transpose() * S * X;
    }
    x.t = A.ldlt().solve(b);
    if (!all_finite(x.t)) x.t.setZero();
  }

  // Gauss-Newton with the rho eliminated per point (as estimate_stereo_scale), Cauchy weights
  // refreshed every step, a step halved until the robust cost drops.
  const size_t n = used.size();
  std::vector<double> h_rr(n), b_r(n), weight(n);
  std::vector<Vector6d> h_rg(n);
  Matrix6d H;
  // The residuals of the points the loss keeps (weight above 1/2), unweighted: the noise's
  // variance (the Cauchy weights would shrink it).
  double inlier_chi2 = 0.0;
  int inlier_rows = 0, inlier_points = 0;
  const auto linearise = [&]() -> Vector6d {
    H.setZero();
    Vector6d g = Vector6d::Zero();
    inlier_chi2 = 0.0;
    inlier_rows = inlier_points = 0;
    Rows p;
    for (size_t i = 0; i < n; ++i) {
      weight[i] = 0.0;
      h_rr[i] = 1.0;
      b_r[i] = 0.0;
      h_rg[i].setZero();
      if (!rows(x, x.rho[i], *used[i], &p)) continue;
      double rr = 0.0, br = 0.0;
      Vector6d rg = Vector6d::Zero(), bg = Vector6d::Zero();
      Matrix6d gg = Matrix6d::Zero();
      for (int row = 0; row < p.n; ++row) {
        Vector6d jg = p.j[row];
        if (!refine_rotation) jg.head<3>().setZero();
        rr += p.j_rho[row] * p.j_rho[row];
        br += p.j_rho[row] * p.r[row];
        rg += p.j_rho[row] * jg;
        gg += jg * jg.transpose();
        bg += jg * p.r[row];
      }
      const double chi2 = p.chi2(), w = cauchy_weight(chi2, k);
      weight[i] = w;
      h_rr[i] = rr;
      h_rg[i] = rg;
      b_r[i] = br;
      H += w * (gg - rg * rg.transpose() / rr);
      g += w * (bg - rg * br / rr);
      if (w > 0.5) {
        inlier_chi2 += chi2;
        inlier_rows += p.n;
        ++inlier_points;
      }
    }
    if (!refine_rotation) H.topLeftCorner<3, 3>().setIdentity();  // held: zero rows and columns
    return -H.ldlt().solve(g);
  };
  double cost = cost_of(x);
  State trial;
  const int max_iterations = std::max(1, options.max_iterations);
  for (est.iterations = 0; est.iterations < max_iterations; ++est.iterations) {
    const Vector6d step = linearise();
    if (!all_finite(step)) break;
    double lambda = 1.0, trial_cost = cost;
    for (int halvings = 0; halvings < 20; ++halvings, lambda *= 0.5) {
      const Eigen::Vector3d w = lambda * step.head<3>();
      trial.R = w.norm() > 0.0 ? Eigen::Matrix3d(rotation_about(w.normalized(), w.norm()) * x.R)
                               : x.R;
      trial.t = x.t + lambda * step.tail<3>();
      trial.rho.resize(n);
      for (size_t i = 0; i < n; ++i)
        trial.rho[i] = std::max(1e-12, x.rho[i] - lambda * (b_r[i] + h_rg[i].dot(step)) / h_rr[i]);
      trial_cost = cost_of(trial);
      if (trial_cost <= cost) break;
    }
    if (!(trial_cost <= cost)) break;
    std::swap(x, trial);
    cost = trial_cost;
    if (lambda * step.head<3>().norm() < 1e-12 &&
        lambda * step.tail<3>().norm() < 1e-9 * (1.0 + x.t.norm()) * rig.baseline_m)
      break;
  }
  linearise();
  const Eigen::LDLT<Matrix6d> ldlt(H);
  if (ldlt.info() != Eigen::Success || !ldlt.isPositive() || !all_finite(x.t) ||
      !all_finite(x.R))
    return est;
  const int redundancy = inlier_rows - inlier_points - (refine_rotation ? 6 : 3);
  est.variance_factor = redundancy > 0 ? inlier_chi2 / redundancy : 1.0;
  // The noise as the residuals measure it (the sigmas of `options` only weigh the two kinds of
  // residual); the points share their errors (calibration, KLT's correlated ones): at most
  // independent_points of them count, as for a pair's rotation.
  const double dependence = std::max(1.0, static_cast<double>(n) / independent_points);
  Matrix6d covariance = est.variance_factor * dependence * ldlt.solve(Matrix6d::Identity());
  if (!refine_rotation) {
    covariance.topRows<3>().setZero();
    covariance.leftCols<3>().setZero();
  }
  est.covariance = 0.5 * (covariance + covariance.transpose());
  if (!all_finite(est.covariance) || !(est.covariance.trace() > 0.0)) {
    est.covariance.setZero();
    return est;
  }
  est.R = x.R;
  est.t = x.t;
  est.inliers = static_cast<int>(
      std::count_if(weight.begin(), weight.end(), [](double w) { return w > 0.5; }));
  est.ok = true;
  return est;
}

}  // namespace hybrid_vo
