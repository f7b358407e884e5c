#include "hybrid_vo/estimation/translation_given_rotation.h"

#include <algorithm>
#include <cmath>
#include <random>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include "hybrid_vo/geometry/cheirality.h"
#include "hybrid_vo/geometry/epipolar_error.h"
#include "hybrid_vo/geometry/homogeneous.h"
#include "hybrid_vo/solvers/relpose_known_rotation_2pt.h"

namespace hybrid_vo {
namespace {

// MSAC score of t: the truncated squared Sampson errors; `inliers` those under the threshold.
double score(const PinholeCamera& c1, const PinholeCamera& c2, const std::vector<PointMatch>& p,
             const RelativePose& pose, double threshold, std::vector<char>* inliers) {
  const double t2 = threshold * threshold;
  double cost = 0.0;
  inliers->assign(p.size(), 0);
  for (size_t i = 0; i < p.size(); ++i) {
    const double e = sampson_error_px(c1, c2, pose, p[i].x1, p[i].x2);
    const double e2 = std::isfinite(e) ? e * e : t2;
    if (e2 < t2) (*inliers)[i] = 1;
    cost += std::min(e2, t2);
  }
  return cost;
}

// t minimising the inliers' algebraic errors t.(R x1 x x2), each over its Sampson denominator at
// the previous t (iteratively reweighted): the smallest eigenvector of their scatter.
Eigen::Vector3d refine(const std::vector<Eigen::Vector3d>& r, const std::vector<Eigen::Vector3d>& q,
                       const std::vector<char>& inliers, const Eigen::Matrix3d& R,
                       Eigen::Vector3d t) {
  for (int iteration = 0; iteration < 4; ++iteration) {
    Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
    const Eigen::Matrix3d E = skew(t) * R;
    for (size_t i = 0; i < r.size(); ++i) {
      if (!inliers[i]) continue;
      const Eigen::Vector3d n = r[i].cross(q[i]);  // r = R x1
      const Eigen::Vector3d Ex1 = E * (R.transpose() * r[i]), Etx2 = E.transpose() * q[i];
      const double d2 = Ex1.head<2>().squaredNorm() + Etx2.head<2>().squaredNorm();
      if (!(d2 > 1e-18)) continue;
      A += n * n.transpose() / d2;
    }
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(A);
    const Eigen::Vector3d next = eigen.eigenvectors().col(0);
    if (!all_finite(next)) break;
    t = next.dot(t) >= 0.0 ? next : Eigen::Vector3d(-next);
  }
  return t;
}

}  // namespace

TranslationEstimate estimate_translation_given_rotation(
    const PinholeCamera& camera1, const PinholeCamera& camera2,
    const std::vector<PointMatch>& points, const Eigen::Matrix3d& R,
    const TranslationGivenRotationOptions& options) {
  TranslationEstimate out;
  out.inliers.assign(points.size(), 0);
  const int n = static_cast<int>(points.size());
  if (n < 2 || !all_finite(R) || !camera1.valid() || !camera2.valid()) return out;
  std::vector<Eigen::Vector2d> x1(n), x2(n);
  std::vector<Eigen::Vector3d> r(n), q(n);
  for (int i = 0; i < n; ++i) {
    x1[i] = camera1.normalize(points[i].x1);
    x2[i] = camera2.normalize(points[i].x2);
    r[i] = R * homogeneous(x1[i]);
    q[i] = homogeneous(x2[i]);
  }
  std::mt19937_64 rng(options.seed);
  std::uniform_int_distribution<int> pick(0, n - 1);
  double best_cost = std::numeric_limits<double>::infinity();
  std::vector<char> inliers;
  int needed = options.max_iterations;
  for (int it = 0; it < std::min(needed, options.max_iterations); ++it) {
    ++out.iterations;
    const int a = pick(rng);
    int b = pick(rng);
    if (a == b) continue;
    RelativePoses poses;
    if (relpose_known_rotation_2pt(R, {x1[a], x1[b]}, {x2[a], x2[b]}, &poses) == 0) continue;
    const double cost =
        score(camera1, camera2, points, poses[0], options.point_threshold_px, &inliers);
    if (cost >= best_cost) continue;
    best_cost = cost;
    out.pose = poses[0];
    out.inliers = inliers;
    // Adaptive termination for a 2-point sample.
    const double w = static_cast<double>(std::count(inliers.begin(), inliers.end(), 1)) / n;
    const double miss = 1.0 - w * w;
    needed = miss <= 0.0 ? options.min_iterations
                         : std::max(options.min_iterations,
                                    static_cast<int>(std::ceil(std::log(1.0 - options.confidence) /
                                                               std::log(miss))));
  }
  if (!std::isfinite(best_cost)) return out;
  out.pose.t = refine(r, q, out.inliers, R, out.pose.t);
  std::vector<Eigen::Vector2d> in1, in2;
  for (int i = 0; i < n; ++i)
    if (out.inliers[i]) {
      in1.push_back(x1[i]);
      in2.push_back(x2[i]);
    }
  MatchView witnesses;
  witnesses.x1 = in1.data();
  witnesses.x2 = in2.data();
  witnesses.num_points = static_cast<int>(in1.size());
  if (!orient_translation(R, &out.pose.t, witnesses)) {
    // Noise near the epipole can make a few inliers disagree; take the majority's sign.
    int votes = 0;
    for (size_t i = 0; i < in1.size(); ++i) {
      const Eigen::Vector3d rr = R * homogeneous(in1[i]), qq = homogeneous(in2[i]);
      const int v = cheirality_vote(rr.dot(rr), qq.dot(qq), qq.dot(rr), qq.dot(out.pose.t),
                                    rr.dot(out.pose.t), 1.0);
      if (v == 1 || v == -1) votes += v;
    }
    if (votes < 0) out.pose.t = -out.pose.t;
  }
  score(camera1, camera2, points, out.pose, options.point_threshold_px, &out.inliers);
  out.num_inliers = static_cast<int>(std::count(out.inliers.begin(), out.inliers.end(), 1));
  out.ok = out.num_inliers >= std::max(options.min_inliers, 2);
  return out;
}

}  // namespace hybrid_vo
