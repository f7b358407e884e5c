#include "hybrid_vo/estimation/stereo_scale.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>

#include "hybrid_vo/geometry/homogeneous.h"
#include "hybrid_vo/geometry/rotation.h"

namespace hybrid_vo {
namespace {

// The global parameters: a left rotation increment w, a translation direction increment tau in
// the tangent plane of t, the scale s and the disparity offset delta.
constexpr int kW = 0, kTau = 3, kS = 5, kDelta = 6, kGlobals = 7;
using Vector7d = Eigen::Matrix<double, kGlobals, 1>;
using Matrix7d = Eigen::Matrix<double, kGlobals, kGlobals>;
constexpr int kMaxRows = 4;

struct State {
  Eigen::Matrix3d R;
  Eigen::Vector3d t;  // unit
  double s = 0.0, delta = 0.0;
  std::vector<double> rho;  // inverse depth of each point in the keyframe
};

// Two unit vectors spanning the tangent plane of the sphere at unit t.
Eigen::Matrix<double, 3, 2> tangent_basis(const Eigen::Vector3d& t) {
  Eigen::Matrix<double, 3, 2> B;
  B.col(0) = t.unitOrthogonal();
  B.col(1) = t.cross(B.col(0));
  return B;
}

// A point's whitened residual rows with their derivatives by its rho and by the globals.
struct PointRows {
  int rows = 0;
  double r[kMaxRows], j_rho[kMaxRows];
  Vector7d j[kMaxRows];
  double chi2() const {
    double sum = 0.0;
    for (int k = 0; k < rows; ++k) sum += r[k] * r[k];
    return sum;
  }
};

class ScaleModel {
 public:
  ScaleModel(const StereoRig& rig, const StereoScaleOptions& options)
      : rig_(rig), c_(rig.fx * rig.baseline_m), sd_(options.disparity_sigma_px),
        sp_(options.point_sigma_px) {}

  double fx_baseline() const { return c_; }

  // False when the point falls behind the current camera.
  bool rows(const State& x, double rho, const StereoScaleObservation& o, PointRows* p) const {
    p->rows = 0;
    Vector7d j = Vector7d::Zero();
    const double sd_ref = o.disparity_ref_sigma_px > 0.0 ? o.disparity_ref_sigma_px : sd_;
    j(kDelta) = 1.0 / sd_ref;
    add(p, (c_ * rho + x.delta - o.disparity_ref) / sd_ref, c_ / sd_ref, j);

    const Eigen::Vector3d Rn = x.R * homogeneous(o.x_ref);
    const Eigen::Vector3d P = Rn + x.s * rho * x.t;  // the current point times rho
    if (!(P.z() > 1e-9 * (1.0 + std::abs(P.x()) + std::abs(P.y())))) return false;
    // dP by rho, by the globals (w: -[Rn]x, tau: s rho B, s: rho t, delta: 0).
    Eigen::Matrix<double, 3, kGlobals> dP = Eigen::Matrix<double, 3, kGlobals>::Zero();
    dP.block<3, 3>(0, kW) << 0.0, Rn.z(), -Rn.y(), -Rn.z(), 0.0, Rn.x(), Rn.y(), -Rn.x(), 0.0;
    dP.block<3, 2>(0, kTau) = x.s * rho * tangent_basis(x.t);
    dP.col(kS) = rho * x.t;
    const Eigen::Vector3d dP_rho = x.s * x.t;
    const double iz = 1.0 / P.z(), u = P.x() * iz, v = P.y() * iz;
    const Eigen::RowVector3d du(iz, 0.0, -u * iz), dv(0.0, iz, -v * iz);
    const double ku = rig_.fx / sp_, kv = rig_.fy / sp_;
    add(p, ku * (u - o.x_cur.x()), ku * du.dot(dP_rho), ku * (du * dP).transpose());
    add(p, kv * (v - o.x_cur.y()), kv * dv.dot(dP_rho), kv * (dv * dP).transpose());
    if (o.disparity_cur > 0.0) {
      // This frame's disparity: the inverse depth rho / P_z.
      const double q = rho * iz, kd = c_ / sd_;
      Vector7d jq = (-rho * iz * iz * dP.row(2)).transpose();
      jq(kDelta) = 1.0 / c_;
      add(p, kd * (q - o.disparity_cur / c_) + x.delta / sd_,
          kd * (iz - rho * iz * iz * dP_rho.z()), kd * jq);
    }
    return true;
  }

 private:
  static void add(PointRows* p, double r, double j_rho, const Vector7d& j) {
    p->r[p->rows] = r;
    p->j_rho[p->rows] = j_rho;
    p->j[p->rows] = j;
    ++p->rows;
  }

  StereoRig rig_;
  double c_, sd_, sp_;
};

double cauchy_cost(double chi2, double k) { return k * k * std::log1p(chi2 / (k * k)); }
double cauchy_weight(double chi2, double k) { return 1.0 / (1.0 + chi2 / (k * k)); }

// The scale that puts x_cur on the ray of X = [x_ref; 1] / rho moved by s t (least squares in
// the cross product x_cur x (R X + s t) = 0); NaN when the point lies along t.
double point_scale(const RelativePose& motion, const StereoScaleObservation& o, double rho) {
  const Eigen::Vector3d x = homogeneous(o.x_cur);
  const Eigen::Vector3d a = x.cross(motion.R * homogeneous(o.x_ref) / rho), b = x.cross(motion.t);
  const double bb = b.squaredNorm();
  if (!(bb > 1e-6 * motion.t.squaredNorm() * x.squaredNorm())) return NAN;
  return -a.dot(b) / bb;
}

}  // namespace

bool StereoRig::valid() const {
  return std::isfinite(fx) && std::isfinite(fy) && std::isfinite(baseline_m) && fx > 0.0 &&
         fy > 0.0 && baseline_m > 0.0;
}

const char* to_string(StereoScaleStatus status) {
  switch (status) {
    case StereoScaleStatus::kOk:
      return "ok";
    case StereoScaleStatus::kInvalidInput:
      return "invalid input";
    case StereoScaleStatus::kTooFewNearPoints:
      return "too few near stereo points";
    case StereoScaleStatus::kNoConvergence:
      return "no convergence";
  }
  return "unknown";
}

StereoScaleEstimate estimate_stereo_scale(const RelativePose& unit_motion, const StereoRig& rig,
                                          const std::vector<StereoScaleObservation>& observations,
                                          const StereoScaleOptions& options) {
  StereoScaleEstimate result;
  if (!rig.valid() || !all_finite(unit_motion.R) || !all_finite(unit_motion.t) ||
      !(unit_motion.t.norm() > 1e-12) || !(options.disparity_sigma_px > 0.0) ||
      !(options.point_sigma_px > 0.0) || !std::isfinite(options.disparity_offset_px) ||
      !(options.disparity_offset_sigma_px >= 0.0))
    return result;
  const RelativePose motion(unit_motion.R, unit_motion.t.normalized());
  const ScaleModel model(rig, options);
  const double c = model.fx_baseline();

  // Near points: Z = fx b / (d - delta) below max_depth_baselines * b.
  const double min_disparity =
      options.max_depth_baselines > 0.0 ? rig.fx / options.max_depth_baselines : 0.0;
  const double delta0 = options.disparity_offset_px;
  State x;
  x.R = motion.R;
  x.t = motion.t;
  x.delta = delta0;
  std::vector<const StereoScaleObservation*> near;
  std::vector<double> initial;
  for (const StereoScaleObservation& o : observations) {
    const double d = o.disparity_ref - delta0;
    if (!all_finite(o.x_ref) || !all_finite(o.x_cur) || !std::isfinite(d) || !(d > 0.0) ||
        d < min_disparity || !std::isfinite(o.disparity_cur))
      continue;
    near.push_back(&o);
    x.rho.push_back(d / c);
    const double s = point_scale(motion, o, x.rho.back());
    if (std::isfinite(s) && s > 0.0) initial.push_back(s);
  }
  result.near_points = static_cast<int>(near.size());
  if (result.near_points < std::max(1, options.min_near_points) || initial.empty()) {
    result.status = StereoScaleStatus::kTooFewNearPoints;
    return result;
  }
  std::nth_element(initial.begin(), initial.begin() + initial.size() / 2, initial.end());
  x.s = initial[initial.size() / 2];

  // Which globals move: the scale always; the motion and the offset on request. delta has a
  // Gaussian prior (delta0, sigma), which with sigma = infinity is no prior at all.
  Vector7d active = Vector7d::Zero();
  active(kS) = 1.0;
  if (options.refine_motion) active.segment<5>(kW).setOnes();
  const double delta_sigma = options.disparity_offset_sigma_px;
  if (delta_sigma > 0.0) active(kDelta) = 1.0;
  const double prior_weight =
      delta_sigma > 0.0 && std::isfinite(delta_sigma) ? 1.0 / (delta_sigma * delta_sigma) : 0.0;

  const double k = options.loss_scale > 0.0 ? options.loss_scale : 1e300;
  const double kBehind = 1e6;  // a point's chi2 when it falls behind the current camera
  auto cost_of = [&](const State& state) {
    double cost = prior_weight * (state.delta - delta0) * (state.delta - delta0);
    PointRows p;
    for (size_t i = 0; i < near.size(); ++i)
      cost += cauchy_cost(model.rows(state, state.rho[i], *near[i], &p) ? p.chi2() : kBehind, k);
    return cost;
  };

  // Gauss-Newton on (globals, rho_1..n) with the rho_i eliminated per point: a point's normal
  // equations are [h_rr h_rg^T; h_rg H_gg] [d_rho; d_g] = -[b_r; b_g], and its Schur complement
  // H_gg - h_rg h_rg^T / h_rr adds to the global one (a 7x7 system, whatever the number of
  // points). Cauchy weights are refreshed each step (IRLS) and a step is halved until the robust
  // cost decreases.
  const size_t n = near.size();
  std::vector<double> h_rr(n), b_r(n), weight(n);
  std::vector<Vector7d> h_rg(n);
  Matrix7d H;
  double weighted_chi2 = 0.0;
  int rows = 0;
  auto linearise = [&]() -> Vector7d {
    H.setZero();
    Vector7d b = Vector7d::Zero();
    weighted_chi2 = 0.0;
    rows = 0;
    PointRows p;
    for (size_t i = 0; i < n; ++i) {
      weight[i] = 0.0;
      h_rr[i] = 1.0;
      b_r[i] = 0.0;
      h_rg[i].setZero();
      if (!model.rows(x, x.rho[i], *near[i], &p)) continue;
      double rr = 0.0, br = 0.0;
      Vector7d rg = Vector7d::Zero(), bg = Vector7d::Zero();
      Matrix7d gg = Matrix7d::Zero();
      for (int row = 0; row < p.rows; ++row) {
        const Vector7d jg = p.j[row].cwiseProduct(active);
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
      b += w * (bg - rg * br / rr);
      weighted_chi2 += w * chi2;
      rows += p.rows;
    }
    H(kDelta, kDelta) += prior_weight;
    b(kDelta) += prior_weight * (x.delta - delta0);
    for (int g = 0; g < kGlobals; ++g)
      if (active(g) == 0.0) H(g, g) = 1.0;  // fixed: its row and column are zero
    return -H.ldlt().solve(b);
  };
  auto apply = [&](const Vector7d& step, double lambda, State* to) {
    to->R = x.R;
    const Eigen::Vector3d w = lambda * step.segment<3>(kW);
    if (w.norm() > 0.0) to->R = rotation_about(w.normalized(), w.norm()) * x.R;
    to->t = (x.t + tangent_basis(x.t) * (lambda * step.segment<2>(kTau))).normalized();
    to->s = x.s + lambda * step(kS);
    to->delta = x.delta + lambda * step(kDelta);
    to->rho.resize(n);
    for (size_t i = 0; i < n; ++i)
      to->rho[i] = std::max(1e-12, x.rho[i] - lambda * (b_r[i] + h_rg[i].dot(step)) / h_rr[i]);
  };

  double cost = cost_of(x);
  State trial;
  for (result.iterations = 0; result.iterations < options.max_iterations; ++result.iterations) {
    const Vector7d step = linearise();
    if (!(H(kS, kS) > 0.0) || !all_finite(step)) break;
    double lambda = 1.0, trial_cost = cost;
    for (int halvings = 0; halvings < 20; ++halvings, lambda *= 0.5) {
      if (!(x.s + lambda * step(kS) > 0.0)) continue;
      apply(step, lambda, &trial);
      trial_cost = cost_of(trial);
      if (trial_cost <= cost) break;
    }
    if (!(trial_cost <= cost) || !(x.s + lambda * step(kS) > 0.0)) break;  // no descent left
    std::swap(x, trial);
    cost = trial_cost;
    if (std::abs(lambda * step(kS)) < 1e-9 * x.s &&
        (lambda * step.segment<5>(kW)).norm() < 1e-10)
      break;
  }
  linearise();
  const Eigen::LDLT<Matrix7d> ldlt(H);
  if (!(x.s > 0.0) || !std::isfinite(x.s) || ldlt.info() != Eigen::Success ||
      !ldlt.isPositive()) {
    result.status = StereoScaleStatus::kNoConvergence;
    return result;
  }
  // Residual variance over the model's: rows minus one rho per point and the active globals.
  const int redundancy = rows - static_cast<int>(n) - static_cast<int>(active.sum());
  result.variance_factor = redundancy > 0 ? weighted_chi2 / redundancy : 1.0;
  const Matrix7d covariance = result.variance_factor * ldlt.solve(Matrix7d::Identity());
  if (!(covariance(kS, kS) > 0.0) || !all_finite(covariance)) {
    result.status = StereoScaleStatus::kNoConvergence;
    return result;
  }
  result.scale = x.s;
  result.sigma = std::sqrt(covariance(kS, kS));
  result.disparity_offset = x.delta;
  result.offset_sigma = active(kDelta) > 0.0 ? std::sqrt(covariance(kDelta, kDelta)) : 0.0;
  result.motion = RelativePose(x.R, x.t);
  result.inliers = static_cast<int>(
      std::count_if(weight.begin(), weight.end(), [](double w) { return w > 0.5; }));
  result.status = StereoScaleStatus::kOk;
  return result;
}

Eigen::Matrix<double, 6, 6> metric_motion_covariance(const Eigen::Matrix<double, 6, 6>& unit,
                                                     const Eigen::Vector3d& unit_t, double scale,
                                                     double sigma_scale) {
  Eigen::Matrix<double, 6, 6> cov = unit;
  cov.block<3, 3>(3, 3) *= scale * scale;
  cov.block<3, 3>(3, 3) += sigma_scale * sigma_scale * unit_t * unit_t.transpose();
  cov.block<3, 3>(0, 3) *= scale;
  cov.block<3, 3>(3, 0) *= scale;
  return cov;
}

double median_of_point_scales(const RelativePose& unit_motion, const StereoRig& rig,
                              const std::vector<StereoScaleObservation>& observations,
                              double max_depth_baselines) {
  if (!rig.valid() || !(unit_motion.t.norm() > 1e-12)) return NAN;
  const RelativePose motion(unit_motion.R, unit_motion.t.normalized());
  const double fb = rig.fx * rig.baseline_m;
  std::vector<double> scales;
  for (const StereoScaleObservation& o : observations) {
    if (!(o.disparity_ref > 0.0)) continue;
    if (max_depth_baselines > 0.0 && o.disparity_ref < rig.fx / max_depth_baselines) continue;
    const double s = point_scale(motion, o, o.disparity_ref / fb);
    if (std::isfinite(s) && s > 0.0) scales.push_back(s);
  }
  if (scales.size() < 5) return NAN;
  std::nth_element(scales.begin(), scales.begin() + scales.size() / 2, scales.end());
  return scales[scales.size() / 2];
}

bool DisparityOffsetFilter::update(const RelativePose& unit_motion, const StereoRig& rig,
                                   const std::vector<StereoScaleObservation>& observations,
                                   const StereoScaleOptions& scale_options) {
  if (!options_.enabled) return false;
  // The free-offset fit needs far points too (their disparity change is what separates an
  // offset from the scale) and a free motion (a fixed, slightly wrong one would bend delta).
  StereoScaleOptions o = scale_options;
  o.max_depth_baselines = 0.0;
  o.disparity_offset_px = 0.0;
  o.disparity_offset_sigma_px = std::numeric_limits<double>::infinity();
  o.refine_motion = true;
  const StereoScaleEstimate e = estimate_stereo_scale(unit_motion, rig, observations, o);
  if (e.status != StereoScaleStatus::kOk || !(e.offset_sigma > 0.0) ||
      !std::isfinite(e.disparity_offset))
    return false;
  const double w = 1.0 / (e.offset_sigma * e.offset_sigma +
                          options_.pair_spread_px * options_.pair_spread_px);
  sum_w_ = options_.forgetting * sum_w_ + w;
  sum_wd_ = options_.forgetting * sum_wd_ + w * e.disparity_offset;
  ++pairs_;
  return true;
}

double DisparityOffsetFilter::sigma() const {
  return sum_w_ > 0.0 ? 1.0 / std::sqrt(sum_w_) : std::numeric_limits<double>::infinity();
}

double DisparityOffsetFilter::offset() const {
  if (!options_.enabled || !(sum_w_ > 0.0)) return 0.0;
  const double m = mean();
  return std::abs(m) > options_.dead_band_px && std::abs(m) > options_.significance * sigma() ? m
                                                                                            : 0.0;
}

}  // namespace hybrid_vo
