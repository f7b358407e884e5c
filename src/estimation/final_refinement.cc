#include "hybrid_vo/estimation/final_refinement.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <utility>

#include <Eigen/Dense>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <ceres/ceres.h>

#include "hybrid_vo/geometry/homogeneous.h"
#include "hybrid_vo/geometry/vp_covariance.h"
#include "hybrid_vo/geometry/vp_distance.h"

namespace hybrid_vo {
namespace {

using Matrix43 = Eigen::Matrix<double, 4, 3>;
using RowVector4d = Eigen::Matrix<double, 1, 4>;

constexpr double kDegree = M_PI / 180.0;

Eigen::Matrix3d rotation_of(const double* q) {
  return Eigen::Map<const Eigen::Quaterniond>(q).normalized().toRotationMatrix();
}

// Ceres' EigenQuaternionManifold (memory x, y, z, w) has Plus(q, d) = [cos|d|, sin|d| d / |d|] q,
// a left rotation by 2|d|, so the left increment R <- exp([w]x) R has w = 2 d. Its Jacobian at
// d = 0 is P = [s I - [v]x; -v^T] for q = (v, s), with orthonormal columns orthogonal to q: the
// ambient Jacobian J_q = 2 J_w P^T (nothing along q) gives J_q P = dr/dd exactly.
Matrix43 quaternion_plus_jacobian(const double* q) {
  const Eigen::Vector3d v(q[0], q[1], q[2]);
  Matrix43 P;
  P.topRows<3>() = q[3] * Eigen::Matrix3d::Identity() - skew(v);
  P.row(3) = -v.transpose();
  return P;
}

// Sampson error in pixels (paper Sec. 4, "reprojection error on the point correspondences"):
// with F = K2^-T E K1^-1 and x1, x2 in pixels, r = x2^T F x1 / |grad|, where the gradient of
// x2^T F x1 with respect to the four pixel coordinates is (Ep / f2, E^T q / f1) per axis for the
// normalised p = K1^-1 x1, q = K2^-1 x2, each divided by its match's sigma. Analytic Jacobian.
// One block holds many matches: R is computed once per block, and Ceres' per-block overhead
// (which dominated the refinement with one block per match) is paid once. The Cauchy loss is
// therefore applied inside, as the residual sign(r) sqrt(rho(r^2)) with rho(s) = a^2 log(1 +
// s / a^2): the sum of squares is the robust cost Ceres would minimise, so the optimum is the
// same; Gauss-Newton sees the loss's slope through the chain rule instead of Triggs' correction.
class PointBlockSampsonCost final : public ceres::CostFunction {
 public:
  struct Match {
    Eigen::Vector3d p, q;  // K1^-1 x1, K2^-1 x2
    double scale;          // 1 / sigma in pixels
    double loss;           // Cauchy scale a in sigmas; <= 0: none
  };

  PointBlockSampsonCost(std::vector<Match> matches, const Eigen::Vector2d& w1,
                        const Eigen::Vector2d& w2)
      : matches_(std::move(matches)), w1_(w1), w2_(w2) {
    set_num_residuals(static_cast<int>(matches_.size()));
    *mutable_parameter_block_sizes() = {4, 3};
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const Eigen::Matrix3d R = rotation_of(parameters[0]);
    const Eigen::Map<const Eigen::Vector3d> t(parameters[1]);
    Matrix43 P_t;
    if (jacobians && jacobians[0]) P_t = quaternion_plus_jacobian(parameters[0]);
    for (size_t i = 0; i < matches_.size(); ++i) {
      const Match& m = matches_[i];
      double* J_q = jacobians && jacobians[0] ? jacobians[0] + 4 * i : nullptr;
      double* J_t = jacobians && jacobians[1] ? jacobians[1] + 3 * i : nullptr;
      // E p = t x R p and E^T q = R^T (q x t) for E = [t]x R.
      const Eigen::Vector3d Rp = R * m.p, q_x_t = m.q.cross(t);
      const Eigen::Vector3d a = t.cross(Rp), b = R.transpose() * q_x_t;
      const Eigen::Vector3d wa(w2_.x() * a.x(), w2_.y() * a.y(), 0.0);
      const Eigen::Vector3d wb(w1_.x() * b.x(), w1_.y() * b.y(), 0.0);
      const double C = m.q.dot(a);
      const double D = wa.dot(a) + wb.dot(b);
      if (!(D > 0.0) || !std::isfinite(D) || !std::isfinite(C)) {
        // Both epipolar lines degenerate at this match: it carries no information here.
        residuals[i] = 0.0;
        if (J_q) Eigen::Map<RowVector4d>(J_q).setZero();
        if (J_t) Eigen::Map<Eigen::RowVector3d>(J_t).setZero();
        continue;
      }
      const double sqrt_D = std::sqrt(D) / m.scale;  // the scale folds into the normaliser
      const double r = C / sqrt_D;
      // The robust residual and its slope dr'/dr (1 at r = 0).
      double slope = 1.0;
      residuals[i] = r;
      if (m.loss > 0.0) {
        const double a2 = m.loss * m.loss, s = r * r;
        const double rho = a2 * std::log1p(s / a2);
        const double robust = std::sqrt(rho);
        residuals[i] = r < 0.0 ? -robust : robust;
        if (robust > 1e-150) slope = std::abs(r) / (1.0 + s / a2) / robust;
      }
      if (!J_q && !J_t) continue;
      // dr/dE = G = (dC/dE - C / (2 D) dD/dE) / sqrt(D) with dC/dE = q p^T and
      // dD/dE = 2 (W2 a p^T + q (W1 b)^T), i.e. G = u p^T + q v^T.
      const double k = C / D;  // D unscaled: C / D is scale-free
      const Eigen::Vector3d u = slope * (m.q - k * wa) / sqrt_D, v = (-slope * k / sqrt_D) * wb;
      // <G, [e]x R> = e . vee(G R^T) with vee(M) = (M21 - M12, M02 - M20, M10 - M01) and
      // vee(a b^T) = b x a. With G R^T = u (R p)^T + q (R v)^T: dE = [dt]x R gives dr/dt, and
      // dE = [t]x [dw]x R gives dr/dw = vee(-[t]x G R^T).
      const Eigen::Vector3d Rv = R * v;
      if (J_q) {
        const Eigen::Vector3d dr_dw = Rp.cross(u.cross(t)) + Rv.cross(q_x_t);
        Eigen::Map<RowVector4d> dq(J_q);
        dq = 2.0 * dr_dw.transpose() * P_t.transpose();
      }
      if (J_t) {
        Eigen::Map<Eigen::RowVector3d> dt(J_t);
        dt = (Rp.cross(u) + Rv.cross(m.q)).transpose();
      }
    }
    return true;
  }

 private:
  std::vector<Match> matches_;
  Eigen::Vector2d w1_, w2_;  // (1 / fx^2, 1 / fy^2) of each camera
};

// VP error given the rotation (paper Sec. 4): s (R d1 - d2) when the sign is known, else
// s (d2 x R d1), sign-invariant; for unit d1, d2 both are the angle to first order, times s.
class VpAngleCost final : public ceres::SizedCostFunction<3, 4> {
 public:
  VpAngleCost(const Eigen::Vector3d& d1, const Eigen::Vector3d& d2, bool sign_known, double scale)
      : d1_(d1), d2_(d2), sign_known_(sign_known), scale_(scale) {}

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const Eigen::Vector3d Rd1 = rotation_of(parameters[0]) * d1_;
    Eigen::Map<Eigen::Vector3d> r(residuals);
    r = scale_ * (sign_known_ ? Eigen::Vector3d(Rd1 - d2_) : Eigen::Vector3d(d2_.cross(Rd1)));
    if (!jacobians || !jacobians[0]) return true;
    // d(R d1)/dw = -[R d1]x for the left increment.
    const Eigen::Matrix3d dRd1 = -skew(Rd1);
    const Eigen::Matrix3d dr_dw = scale_ * (sign_known_ ? dRd1 : Eigen::Matrix3d(skew(d2_) * dRd1));
    Eigen::Map<Eigen::Matrix<double, 3, 4, Eigen::RowMajor>> J_q(jacobians[0]);
    J_q = 2.0 * dr_dw * quaternion_plus_jacobian(parameters[0]).transpose();
    return true;
  }

 private:
  Eigen::Vector3d d1_, d2_;  // unit
  bool sign_known_;
  double scale_;
};

// Tardif's distance (geometry/vp_distance.h) times a weight, with its gradient.
bool tardif_distance(const Eigen::Vector3d& l, const Eigen::Vector2d& m, const Eigen::Vector3d& v,
                     double weight, double* r, Eigen::Vector3d* dr_dv) {
  if (!hybrid_vo::tardif_distance(l, m, v, r, dr_dv)) return false;
  *r *= weight;
  if (dr_dv) *dr_dv *= weight;
  return true;
}

// Line-to-VP consistency with the VP direction fixed: a segment against the VP predicted from
// the other image, v = K R d1 (segment in image 2) or v = K R^T d2 (segment in image 1).
class LineVpCost final : public ceres::SizedCostFunction<1, 4> {
 public:
  LineVpCost(const Eigen::Matrix3d& K, const LineSegment& segment, const Eigen::Vector3d& direction,
             bool inverse_rotation, double weight)
      : K_(K),
        l_(homogeneous(segment.p1).cross(homogeneous(segment.p2))),
        m_(segment.midpoint()),
        d_(direction),
        inverse_rotation_(inverse_rotation),
        weight_(weight) {}

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const Eigen::Matrix3d R = rotation_of(parameters[0]);
    const Eigen::Vector3d u =
        inverse_rotation_ ? Eigen::Vector3d(R.transpose() * d_) : Eigen::Vector3d(R * d_);
    Eigen::Vector3d dr_dv;
    if (!tardif_distance(l_, m_, K_ * u, weight_, residuals, jacobians ? &dr_dv : nullptr)) {
      residuals[0] = 0.0;
      if (jacobians && jacobians[0]) Eigen::Map<RowVector4d>(jacobians[0]).setZero();
      return true;
    }
    if (!jacobians || !jacobians[0]) return true;
    // Left increment: d(R d)/dw = -[R d]x, d(R^T d)/dw = R^T [d]x.
    const Eigen::Matrix3d du_dw =
        inverse_rotation_ ? Eigen::Matrix3d(R.transpose() * skew(d_)) : Eigen::Matrix3d(-skew(u));
    const Eigen::RowVector3d dr_dw = dr_dv.transpose() * K_ * du_dw;
    Eigen::Map<RowVector4d> J_q(jacobians[0]);
    J_q = 2.0 * dr_dw * quaternion_plus_jacobian(parameters[0]).transpose();
    return true;
  }

 private:
  Eigen::Matrix3d K_;  // of the segment's image
  Eigen::Vector3d l_;  // p1 x p2 in pixels
  Eigen::Vector2d m_;  // midpoint in pixels
  Eigen::Vector3d d_;  // unit VP direction in the other camera
  bool inverse_rotation_;
  double weight_;
};

// Line-to-VP consistency with the VP's 3D direction d (camera 1) a parameter: segments of image 1
// against K1 d, segments of image 2 against K2 R d. The VP is then estimated jointly from all its
// lines in both views instead of being trusted as detected, so the lines constrain R directly.
class LineFreeVpCost final : public ceres::SizedCostFunction<1, 4, 3> {
 public:
  LineFreeVpCost(const Eigen::Matrix3d& K, const LineSegment& segment, bool second_image,
                 double weight)
      : K_(K),
        l_(homogeneous(segment.p1).cross(homogeneous(segment.p2))),
        m_(segment.midpoint()),
        second_image_(second_image),
        weight_(weight) {}

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const Eigen::Matrix3d R = rotation_of(parameters[0]);
    const Eigen::Map<const Eigen::Vector3d> d(parameters[1]);
    const Eigen::Vector3d u = second_image_ ? Eigen::Vector3d(R * d) : Eigen::Vector3d(d);
    Eigen::Vector3d dr_dv;
    const bool informative =
        tardif_distance(l_, m_, K_ * u, weight_, residuals, jacobians ? &dr_dv : nullptr);
    if (!informative) residuals[0] = 0.0;
    if (!jacobians) return true;
    if (jacobians[0]) {
      Eigen::Map<RowVector4d> J_q(jacobians[0]);
      if (!informative || !second_image_) {
        J_q.setZero();
      } else {
        const Eigen::RowVector3d dr_dw = dr_dv.transpose() * K_ * (-skew(u));
        J_q = 2.0 * dr_dw * quaternion_plus_jacobian(parameters[0]).transpose();
      }
    }
    if (jacobians[1]) {
      Eigen::Map<Eigen::RowVector3d> J_d(jacobians[1]);
      if (!informative)
        J_d.setZero();
      else
        J_d = second_image_ ? Eigen::RowVector3d(dr_dv.transpose() * K_ * R)
                            : Eigen::RowVector3d(dr_dv.transpose() * K_);
    }
    return true;
  }

 private:
  Eigen::Matrix3d K_;
  Eigen::Vector3d l_;
  Eigen::Vector2d m_;
  bool second_image_;
  double weight_;
};

// A prior on a VP's free direction d (camera 1): its gnomonic coordinates y = B^T d / (p^T d)
// around the prior direction p, whitened by the prior's covariance in that tangent plane
// (r = L y with L^T L = (B^T S B)^-1), so that |r|^2 is the Mahalanobis distance.
class VpPriorCost final : public ceres::SizedCostFunction<2, 3> {
 public:
  VpPriorCost(const Eigen::Vector3d& p, const Eigen::Matrix<double, 3, 2>& B,
              const Eigen::Matrix2d& L)
      : p_(p), B_(B), L_(L) {}

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const Eigen::Map<const Eigen::Vector3d> d(parameters[0]);
    const double c = p_.dot(d);
    Eigen::Map<Eigen::Vector2d> r(residuals);
    if (!(std::abs(c) > 1e-12)) {  // 90 degrees off: no pull, rather than an infinite one
      r.setZero();
      if (jacobians && jacobians[0])
        Eigen::Map<Eigen::Matrix<double, 2, 3, Eigen::RowMajor>>(jacobians[0]).setZero();
      return true;
    }
    const Eigen::Vector2d y = B_.transpose() * d / c;
    r = L_ * y;
    if (jacobians && jacobians[0]) {
      Eigen::Map<Eigen::Matrix<double, 2, 3, Eigen::RowMajor>> J(jacobians[0]);
      J = L_ * (B_.transpose() / c - y * p_.transpose() / c);
    }
    return true;
  }

 private:
  Eigen::Vector3d p_;
  Eigen::Matrix<double, 3, 2> B_;
  Eigen::Matrix2d L_;
};

// Whitening of a prior's covariance in the tangent plane of its direction: false when it is not
// positive definite there.
bool prior_whitening(const VpPrior& prior, Eigen::Vector3d* p, Eigen::Matrix<double, 3, 2>* B,
                     Eigen::Matrix2d* L) {
  if (!prior.valid || !all_finite(prior.direction) || !all_finite(prior.covariance) ||
      !(prior.direction.norm() > 0.0))
    return false;
  *p = prior.direction.normalized();
  *B = tangent_basis(*p);
  const Eigen::Matrix2d S = B->transpose() * prior.covariance * *B;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eigen(0.5 * (S + S.transpose()));
  if (eigen.info() != Eigen::Success || !(eigen.eigenvalues()(0) > 0.0)) return false;
  // L = D^-1/2 V^T: L^T L = V D^-1 V^T = S^-1.
  *L = eigen.eigenvalues().cwiseSqrt().cwiseInverse().asDiagonal() *
       eigen.eigenvectors().transpose();
  return all_finite(*L);
}

bool usable_sigma(double sigma) { return sigma > 0.0 && std::isfinite(sigma); }

// J^T J of each kind of residual, in Ceres' tangent [d (quaternion), u, VP directions], as an
// InformationSplit in [w = 2 d, u, ...], the points' and the segments' with their own variance
// factors.
InformationSplit split_information(const Eigen::MatrixXd& points, const Eigen::MatrixXd& segments,
                                   const Eigen::MatrixXd& priors, double point_factor,
                                   double segment_factor,
                                   const Eigen::Matrix<double, 3, 2, Eigen::RowMajor>& t_basis) {
  InformationSplit split;
  const int n = static_cast<int>(points.rows());
  if (n < 5 || !(point_factor > 0.0) || !(segment_factor > 0.0)) return split;
  Eigen::VectorXd scale = Eigen::VectorXd::Ones(n);
  scale.head<3>().setConstant(0.5);  // d = w / 2
  const Eigen::MatrixXd S = scale.asDiagonal();
  const Eigen::Matrix<double, 5, 5> pose_points = (S * points * S).topLeftCorner<5, 5>();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 5, 5>> eigen(pose_points);
  if (eigen.info() != Eigen::Success ||
      !(eigen.eigenvalues()(0) > 1e-10 * eigen.eigenvalues()(4)))
    return split;
  split.points_covariance = point_factor * eigen.eigenvectors() *
                            eigen.eigenvalues().cwiseInverse().asDiagonal() *
                            eigen.eigenvectors().transpose();
  split.segment_information = S * segments * S / segment_factor;
  split.prior_information = S * priors * S;
  split.to_pose.topLeftCorner<3, 3>().setIdentity();
  split.to_pose.bottomRightCorner<3, 2>() = t_basis;
  split.valid = all_finite(split.points_covariance) && all_finite(split.segment_information) &&
                all_finite(split.prior_information);
  return split;
}

bool is_rotation(const Eigen::Matrix3d& R) {
  return all_finite(R) && (R.transpose() * R - Eigen::Matrix3d::Identity()).norm() < 1e-6 &&
         R.determinant() > 0.0;
}

bool usable_segment(const LineSegment& s) {
  return all_finite(s.p1) && all_finite(s.p2) && s.length() > 1e-9;
}

}  // namespace

FinalRefinementResult refine_relative_pose_ceres(
    const PinholeCamera& camera1, const PinholeCamera& camera2,
    const std::vector<PointMatch>& points, const std::vector<VpMatch>& vps,
    const std::vector<LineMatch>& lines, const std::vector<int>& line_vp,
    const RelativePose& initial, const FinalRefinementOptions& options) {
  RefinementData data;
  data.points = points;
  data.vps = vps;
  data.lines = lines;
  data.line_vp = line_vp;
  return refine_relative_pose_ceres(camera1, camera2, data, initial, options);
}

FinalRefinementResult refine_relative_pose_ceres(const PinholeCamera& camera1,
                                                 const PinholeCamera& camera2,
                                                 const RefinementData& data,
                                                 const RelativePose& initial,
                                                 const FinalRefinementOptions& options) {
  const std::vector<PointMatch>& points = data.points;
  const std::vector<VpMatch>& vps = data.vps;
  const std::vector<LineMatch>& lines = data.lines;
  const std::vector<int>& line_vp = data.line_vp;
  FinalRefinementResult result;
  result.pose = initial;
  const double t_norm = initial.t.norm();
  if (t_norm > 0.0 && std::isfinite(t_norm)) result.pose.t /= t_norm;
  if (!camera1.valid() || !camera2.valid() || !is_rotation(initial.R) || !all_finite(initial.t))
    return result;
  // A NaN sigma or scale is a caller's mistake, unlike an infinite sigma (the modality left out).
  const double values[] = {options.point_sigma_px, options.line_vp_sigma_px, options.vp_sigma_deg,
                           options.point_loss_px,  options.line_vp_loss_px,  options.vp_loss_deg};
  for (double value : values)
    if (std::isnan(value)) return result;
  for (double value : data.vp_sigma_scale)
    if (!(value > 0.0) || !std::isfinite(value)) return result;
  // Points need a direction to start t from.
  if (!points.empty() && !(t_norm > 0.0 && std::isfinite(t_norm))) return result;

  // Parameters: Eigen quaternion (x, y, z, w) and the unit t.
  Eigen::Quaterniond rotation(initial.R);
  rotation.normalize();
  double q[4] = {rotation.x(), rotation.y(), rotation.z(), rotation.w()};
  double t[3] = {result.pose.t.x(), result.pose.t.y(), result.pose.t.z()};

  const bool use_vps = usable_sigma(options.vp_sigma_deg);
  const bool use_lines = usable_sigma(options.line_vp_sigma_px);
  const double vp_scale = use_vps ? 1.0 / (options.vp_sigma_deg * kDegree) : 0.0;
  const double line_scale = use_lines ? 1.0 / options.line_vp_sigma_px : 0.0;
  // Losses on whitened residuals, at each modality's threshold in its sigmas; shared by the
  // modality's residuals (points: per point sigma, so per distinct sigma), outliving the problem.
  std::vector<std::unique_ptr<ceres::LossFunction>> losses;
  auto cauchy = [&](double threshold, double sigma) -> ceres::LossFunction* {
    if (!(threshold > 0.0) || !std::isfinite(threshold) || !usable_sigma(sigma)) return nullptr;
    losses.emplace_back(new ceres::CauchyLoss(threshold / sigma));
    return losses.back().get();
  };
  ceres::LossFunction* line_loss = cauchy(options.line_vp_loss_px, options.line_vp_sigma_px);
  ceres::LossFunction* vp_loss = cauchy(options.vp_loss_deg, options.vp_sigma_deg);
  ceres::Problem::Options problem_options;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_options.disable_all_safety_checks = true;  // we add each block once, with its sizes
  ceres::Problem problem(problem_options);
  problem.AddParameterBlock(q, 4, new ceres::EigenQuaternionManifold);

  const Eigen::Vector2d w1(1.0 / (camera1.fx * camera1.fx), 1.0 / (camera1.fy * camera1.fy));
  const Eigen::Vector2d w2(1.0 / (camera2.fx * camera2.fx), 1.0 / (camera2.fy * camera2.fy));
  const bool per_point = data.point_sigma_px.size() == points.size();
  const bool point_loss = options.point_loss_px > 0.0 && std::isfinite(options.point_loss_px);
  // Blocks of this many matches: large enough that Ceres' per-block cost vanishes, small enough
  // that a block's Jacobian stays in the cache.
  constexpr size_t kBlock = 64;
  std::vector<PointBlockSampsonCost::Match> block;
  // What each residual row measures, in the order the rows are added (= Ceres' row order).
  enum RowKind : char { kPointRow, kSegmentRow, kPriorRow };
  std::vector<char> row_kind;
  auto flush = [&] {
    if (block.empty()) return;
    if (result.num_point_residuals == static_cast<int>(block.size()))
      problem.AddParameterBlock(t, 3, new ceres::SphereManifold<3>);
    problem.AddResidualBlock(new PointBlockSampsonCost(std::move(block), w1, w2), nullptr, q, t);
    block.clear();
  };
  for (size_t i = 0; i < points.size(); ++i) {
    const PointMatch& m = points[i];
    const double sigma = per_point ? data.point_sigma_px[i] : options.point_sigma_px;
    if (!all_finite(m.x1) || !all_finite(m.x2) || !usable_sigma(sigma)) continue;
    block.push_back({homogeneous(camera1.normalize(m.x1)), homogeneous(camera2.normalize(m.x2)),
                     1.0 / sigma, point_loss ? options.point_loss_px / sigma : 0.0});
    ++result.num_point_residuals;
    row_kind.push_back(kPointRow);
    if (block.size() == kBlock) flush();
  }
  flush();

  // VPs with a usable direction; lines may only name these (also when VPs are weighted out).
  std::vector<char> vp_ok(vps.size(), 0);
  for (size_t k = 0; k < vps.size(); ++k)
    vp_ok[k] = all_finite(vps[k].d1) && all_finite(vps[k].d2) && vps[k].d1.norm() > 0.0 &&
               vps[k].d2.norm() > 0.0;
  // Labelled segments per VP and image; a VP with two or more in each image gets its direction
  // refined from them (its detected directions were fitted on the same segments, so its VP
  // residual would count them twice and is dropped).
  std::vector<std::vector<int>> labelled(vps.size());
  std::vector<int> count1(vps.size(), 0), count2(vps.size(), 0);
  if (use_lines) {
    for (size_t i = 0; i < lines.size() && i < line_vp.size(); ++i) {
      const int k = line_vp[i];
      if (k < 0 || k >= static_cast<int>(vps.size()) || !vp_ok[k]) continue;
      labelled[k].push_back(static_cast<int>(i));
      count1[k] += usable_segment(lines[i].s1);
      count2[k] += usable_segment(lines[i].s2);
    }
  }
  std::vector<Eigen::Vector3d> directions(vps.size());
  int free_vps = 0, prior_rows = 0;
  const Eigen::Matrix3d K1 = camera1.K(), K2 = camera2.K();
  for (size_t k = 0; k < vps.size(); ++k) {
    if (!vp_ok[k]) continue;
    const Eigen::Vector3d d1 = vps[k].d1.normalized(), d2 = vps[k].d2.normalized();
    const double scale = k < data.vp_sigma_scale.size() ? data.vp_sigma_scale[k] : 1.0;
    ceres::LossFunction* line_loss_k =
        scale == 1.0 ? line_loss
                     : cauchy(options.line_vp_loss_px, options.line_vp_sigma_px * scale);
    const double line_scale_k = line_scale / scale;
    // A prior needs image 2's segments to carry it to R; camera 1's are in it already or not.
    Eigen::Vector3d prior_direction;
    Eigen::Matrix<double, 3, 2> prior_basis;
    Eigen::Matrix2d prior_whitener;
    const bool prior = k < data.vp_priors.size() && count2[k] >= 2 &&
                       prior_whitening(data.vp_priors[k], &prior_direction, &prior_basis,
                                       &prior_whitener);
    if (prior || (options.refine_vp_directions && count1[k] >= 2 && count2[k] >= 2)) {
      directions[k] = prior ? prior_direction : d1;
      problem.AddParameterBlock(directions[k].data(), 3, new ceres::SphereManifold<3>);
      ++free_vps;
      if (prior) {
        problem.AddResidualBlock(new VpPriorCost(prior_direction, prior_basis, prior_whitener),
                                 nullptr, directions[k].data());
        ++result.num_vp_priors;
        prior_rows += 2;
        row_kind.insert(row_kind.end(), 2, kPriorRow);
      }
      const bool skip_view1 = prior && data.vp_priors[k].includes_view1;
      for (int i : labelled[k]) {
        for (const bool second : {false, true}) {
          if (!second && skip_view1) continue;
          const LineSegment& segment = second ? lines[i].s2 : lines[i].s1;
          if (!usable_segment(segment)) continue;
          problem.AddResidualBlock(
              new LineFreeVpCost(second ? K2 : K1, segment, second, line_scale_k), line_loss_k, q,
              directions[k].data());
          ++result.num_line_residuals;
          row_kind.push_back(kSegmentRow);
        }
      }
      continue;
    }
    if (use_vps) {
      problem.AddResidualBlock(
          new VpAngleCost(d1, d2, vps[k].sign_known, vp_scale / scale),
          scale == 1.0 ? vp_loss : cauchy(options.vp_loss_deg, options.vp_sigma_deg * scale), q);
      ++result.num_vp_residuals;
      row_kind.insert(row_kind.end(), 3, kSegmentRow);
    }
    for (int i : labelled[k]) {
      if (usable_segment(lines[i].s2)) {
        problem.AddResidualBlock(new LineVpCost(K2, lines[i].s2, d1, false, line_scale_k),
                                 line_loss_k, q);
        ++result.num_line_residuals;
        row_kind.push_back(kSegmentRow);
      }
      if (usable_segment(lines[i].s1)) {
        problem.AddResidualBlock(new LineVpCost(K1, lines[i].s1, d2, true, line_scale_k),
                                 line_loss_k, q);
        ++result.num_line_residuals;
        row_kind.push_back(kSegmentRow);
      }
    }
  }
  result.num_refined_vps = free_vps;

  // At least five residual rows, and no fewer independent ones (a VP's three rows have rank two)
  // than free parameters: three for R, two more for t when points are used, two per free VP.
  const int parameters = (result.num_point_residuals > 0 ? 5 : 3) + 2 * free_vps;
  const int ceres_rows = result.num_point_residuals + 3 * result.num_vp_residuals +
                         result.num_line_residuals + prior_rows;
  const int rows = ceres_rows - result.num_vp_residuals;
  if (ceres_rows < 5 || rows < parameters) return result;

  ceres::Solver::Options solver_options;
  solver_options.linear_solver_type = ceres::DENSE_QR;
  solver_options.num_threads = 1;
  solver_options.max_num_iterations = std::max(0, options.max_iterations);
  solver_options.function_tolerance = options.function_tolerance;
  solver_options.parameter_tolerance = options.parameter_tolerance;
  solver_options.gradient_tolerance = 1e-16;
  solver_options.logging_type = ceres::SILENT;
  solver_options.minimizer_progress_to_stdout = false;
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, &problem, &summary);

  RelativePose refined;
  refined.R = rotation_of(q);
  refined.t = result.num_point_residuals > 0 ? Eigen::Vector3d(t[0], t[1], t[2]).normalized()
                                             : result.pose.t;
  if (!summary.IsSolutionUsable() || !all_finite(refined.R) || !all_finite(refined.t) ||
      !std::isfinite(summary.final_cost))
    return result;
  result.success = true;
  result.pose = refined;
  result.iterations = summary.num_successful_steps + summary.num_unsuccessful_steps;
  result.initial_cost = summary.initial_cost;
  result.final_cost = summary.final_cost;

  // Covariance: needs t in the problem and redundancy to estimate sigma^2.
  if (!options.compute_covariance || result.num_point_residuals == 0 || rows <= parameters)
    return result;
  // (J^T J)^-1 in the tangent spaces of all parameter blocks, from the robustified Jacobian at the
  // optimum (what ceres::Covariance computes, without its setup cost: 40 % of a refinement of
  // 1500 points). Its [q, t] block marginalises the free VP directions. A pose block that is rank
  // deficient (an eigenvalue below 1e-10 of the largest): no covariance.
  std::vector<double*> blocks = {q, t};
  for (size_t k = 0; k < vps.size(); ++k)
    if (problem.HasParameterBlock(directions[k].data())) blocks.push_back(directions[k].data());
  ceres::Problem::EvaluateOptions evaluate_options;
  evaluate_options.parameter_blocks = blocks;
  evaluate_options.apply_loss_function = true;
  evaluate_options.num_threads = 1;
  ceres::CRSMatrix crs;
  std::vector<double> residuals;
  if (!problem.Evaluate(evaluate_options, nullptr, &residuals, nullptr, &crs)) return result;
  // J^T J by the kind of row (upper triangles), and their sum.
  const bool kinds_known = static_cast<int>(row_kind.size()) == crs.num_rows;
  std::array<Eigen::MatrixXd, 3> by_kind;
  for (Eigen::MatrixXd& part : by_kind) part = Eigen::MatrixXd::Zero(crs.num_cols, crs.num_cols);
  for (int row = 0; row < crs.num_rows; ++row) {
    Eigen::MatrixXd& part = by_kind[kinds_known ? row_kind[row] : kSegmentRow];
    for (int a = crs.rows[row]; a < crs.rows[row + 1]; ++a)
      for (int b = a; b < crs.rows[row + 1]; ++b)
        part(crs.cols[a], crs.cols[b]) += crs.values[a] * crs.values[b];
  }
  for (Eigen::MatrixXd& part : by_kind) part = part.selfadjointView<Eigen::Upper>();
  const Eigen::MatrixXd H = by_kind[kPointRow] + by_kind[kSegmentRow] + by_kind[kPriorRow];
  // The pose's block of the inverse: the Schur complement of the VP directions, which may be
  // unfixed themselves (a direction seen along one segment) without the pose being so.
  if (crs.num_cols < 5) return result;
  Eigen::Matrix<double, 5, 5> schur = H.topLeftCorner<5, 5>();
  if (crs.num_cols > 5) {
    const int m = crs.num_cols - 5;
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> directions(H.bottomRightCorner(m, m));
    if (directions.info() != Eigen::Success) return result;
    Eigen::VectorXd inverse = directions.eigenvalues();
    const double largest = std::max(0.0, inverse.maxCoeff());
    for (int k = 0; k < m; ++k)
      inverse(k) = inverse(k) > 1e-10 * largest && inverse(k) > 0.0 ? 1.0 / inverse(k) : 0.0;
    const Eigen::MatrixXd B = H.topRightCorner(5, m);
    schur -= B * directions.eigenvectors() * inverse.asDiagonal() *
             directions.eigenvectors().transpose() * B.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 5, 5>> eigen(
      0.5 * (schur + schur.transpose()));
  if (eigen.info() != Eigen::Success ||
      !(eigen.eigenvalues()(0) > 1e-10 * eigen.eigenvalues()(4)))
    return result;
  const Eigen::Matrix<double, 5, 5> symmetric = eigen.eigenvectors() *
                                                eigen.eigenvalues().cwiseInverse().asDiagonal() *
                                                eigen.eigenvectors().transpose();
  if (!all_finite(symmetric)) return result;
  // Tangent [d (quaternion), 2 sphere coordinates] to [w = 2 d, t]: t's tangent basis is the
  // sphere manifold's Plus Jacobian at t.
  Eigen::Matrix<double, 3, 2, Eigen::RowMajor> t_basis;
  ceres::SphereManifold<3>().PlusJacobian(t, t_basis.data());
  Eigen::Matrix<double, 6, 5> J = Eigen::Matrix<double, 6, 5>::Zero();
  J.topLeftCorner<3, 3>() = 2.0 * Eigen::Matrix3d::Identity();
  J.bottomRightCorner<3, 2>() = t_basis;
  result.sigma2 = 2.0 * result.final_cost / (rows - parameters);
  const Eigen::Matrix<double, 6, 6> full = result.sigma2 * J * symmetric * J.transpose();
  if (!all_finite(full)) return result;
  result.covariance = 0.5 * (full + full.transpose());
  result.covariance_valid = true;
  if (kinds_known && static_cast<int>(residuals.size()) == crs.num_rows) {
    // Each source's own variance factor (variance component estimation): the points' residuals
    // tell the points' noise, the segments' theirs; a prior's covariance is given, not measured.
    std::array<double, 3> squares{}, rows_of{};
    for (int row = 0; row < crs.num_rows; ++row) {
      squares[row_kind[row]] += residuals[row] * residuals[row];
      rows_of[row_kind[row]] += 1.0;
    }
    const double point_factor = squares[kPointRow] / std::max(1.0, rows_of[kPointRow] - 5.0);
    const double segment_factor =
        rows_of[kSegmentRow] > 2.0 * free_vps
            ? squares[kSegmentRow] / (rows_of[kSegmentRow] - 2.0 * free_vps)
            : 1.0;
    result.split = split_information(by_kind[kPointRow], by_kind[kSegmentRow],
                                     by_kind[kPriorRow], point_factor, segment_factor, t_basis);
  }
  return result;
}

}  // namespace hybrid_vo
