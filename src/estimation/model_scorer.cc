#include "model_scorer.h"

#include <algorithm>
#include <cmath>

#include "hybrid_vo/geometry/homogeneous.h"

namespace hybrid_vo {
namespace {

// The squared Sampson error, inlined into the scoring loops (millions of calls a sequence).
inline double sampson_squared(const Eigen::Matrix3d& F, const Eigen::Vector2d& a,
                              const Eigen::Vector2d& b) {
  const double f0 = F(0, 0) * a.x() + F(0, 1) * a.y() + F(0, 2);
  const double f1 = F(1, 0) * a.x() + F(1, 1) * a.y() + F(1, 2);
  const double f2 = F(2, 0) * a.x() + F(2, 1) * a.y() + F(2, 2);
  const double g0 = F(0, 0) * b.x() + F(1, 0) * b.y() + F(2, 0);
  const double g1 = F(0, 1) * b.x() + F(1, 1) * b.y() + F(2, 1);
  const double c = b.x() * f0 + b.y() * f1 + f2;
  const double d = f0 * f0 + f1 * f1 + g0 * g0 + g1 * g1;
  return d > 0.0 ? c * c / d : (c == 0.0 ? 0.0 : INFINITY);
}

}  // namespace

ModelScorer::ModelScorer(const HybridProblem& problem, double point_threshold_px,
                         double vp_threshold_rad)
    : problem_(problem),
      point_threshold_sq_(point_threshold_px * point_threshold_px),
      vp_threshold_sq_(vp_threshold_rad * vp_threshold_rad),
      K1_inverse_(problem.camera1.K_inverse()),
      K2_inverse_transpose_(problem.camera2.K_inverse().transpose()) {}

Eigen::Matrix3d ModelScorer::fundamental(const RelativePose& pose) const {
  return K2_inverse_transpose_ * pose.essential() * K1_inverse_;
}

double ModelScorer::squared_sampson(const Eigen::Matrix3d& F, int i) const {
  return sampson_squared(F, problem_.px1[i], problem_.px2[i]);
}

double ModelScorer::squared_sampson(const Eigen::Matrix3d& F, const Eigen::Vector2d& a,
                                    const Eigen::Vector2d& b) const {
  return sampson_squared(F, a, b);
}

double ModelScorer::vp_angle(const Eigen::Matrix3d& R, int k) const {
  const Eigen::Vector3d a = R * problem_.d1[k];
  const Eigen::Vector3d& b = problem_.d2[k];
  const double c = a.dot(b);
  return std::atan2(a.cross(b).norm(), problem_.vp_sign_known[k] ? c : std::abs(c));
}

double ModelScorer::cost(const RelativePose& pose, double bound) const {
  if (!(pose.t.squaredNorm() > 0.0)) return INFINITY;
  double total = 0.0;
  for (int k = 0; k < problem_.num_vps(); ++k) {
    const double a = vp_angle(pose.R, k);
    total += kVpRows * std::min(a * a / vp_threshold_sq_, 1.0);
  }
  const Eigen::Matrix3d F = fundamental(pose);
  const int n = problem_.num_pool();
  // Check the bound every 64 points: cheap enough, and most bad models stop after a few blocks.
  for (int start = 0; start < n && total <= bound; start += 64) {
    const int end = std::min(n, start + 64);
    for (int i = start; i < end; ++i)
      total += std::min(sampson_squared(F, problem_.px1[i], problem_.px2[i]) /
                            point_threshold_sq_, 1.0);
  }
  return total;
}

int ModelScorer::pool_inliers(const RelativePose& pose, std::vector<char>* mask,
                              double widen) const {
  mask->assign(problem_.num_pool(), 0);
  if (!(pose.t.squaredNorm() > 0.0)) return 0;
  const Eigen::Matrix3d F = fundamental(pose);
  const double threshold_sq = widen * widen * point_threshold_sq_;
  int count = 0;
  for (int i = 0; i < problem_.num_pool(); ++i) {
    (*mask)[i] = sampson_squared(F, problem_.px1[i], problem_.px2[i]) <= threshold_sq;
    count += (*mask)[i];
  }
  return count;
}

int ModelScorer::vp_inliers(const RelativePose& pose, std::vector<char>* mask) const {
  mask->assign(problem_.num_vps(), 0);
  int count = 0;
  for (int k = 0; k < problem_.num_vps(); ++k) {
    const double a = vp_angle(pose.R, k);
    (*mask)[k] = a * a <= vp_threshold_sq_;
    count += (*mask)[k];
  }
  return count;
}

int ModelScorer::line_support(const RelativePose& pose, std::vector<char>* mask) const {
  std::vector<char> local;
  std::vector<char>& supported = mask ? *mask : local;
  supported.assign(problem_.num_lines(), 0);
  if (pose.t.squaredNorm() > 0.0) {
    const Eigen::Matrix3d F = fundamental(pose);
    for (size_t j = 0; j < problem_.junction_lines.size(); ++j) {
      if (sampson_squared(F, problem_.junction_px1[j], problem_.junction_px2[j]) >
          point_threshold_sq_)
        continue;
      supported[problem_.junction_lines[j].first] = 1;
      supported[problem_.junction_lines[j].second] = 1;
    }
  }
  const double max_sin_sq = std::sin(std::sqrt(vp_threshold_sq_)) * std::sin(std::sqrt(vp_threshold_sq_));
  for (int i = 0; i < problem_.num_lines(); ++i) {
    const int k = problem_.line_vp[i];
    if (supported[i] || k < 0) continue;
    // The image-2 line passes through R d1 and the image-1 line through R^T d2.
    const Eigen::Vector3d l1 = problem_.s1[i].line(), l2 = problem_.s2[i].line();
    const double a = l2.dot(pose.R * problem_.d1[k]), b = l1.dot(pose.R.transpose() * problem_.d2[k]);
    supported[i] = a * a <= max_sin_sq * l2.squaredNorm() && b * b <= max_sin_sq * l1.squaredNorm();
  }
  int count = 0;
  for (char c : supported) count += c;
  return count;
}

}  // namespace hybrid_vo
