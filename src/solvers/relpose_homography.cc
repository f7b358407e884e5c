#include "hybrid_vo/solvers/relpose_homography.h"

#include <cmath>

#include <Eigen/Geometry>

#include "hybrid_vo/geometry/cheirality.h"
#include "hybrid_vo/geometry/homography.h"
#include "hybrid_vo/solvers/null_vector.h"

namespace hybrid_vo {

bool homography_from_points_and_lines(const Eigen::Vector2d* x1, const Eigen::Vector2d* x2,
                                      int num_points, const LineSegment* s1, const LineSegment* s2,
                                      int num_lines, Eigen::Matrix3d* H) {
  if (num_points < 0 || num_lines < 0 || num_points + num_lines != 4) return false;
  // Constraints as rows of A, h = row-major H.
  Eigen::Matrix<double, 8, 9> A = Eigen::Matrix<double, 8, 9>::Zero();
  int col = 0;
  for (int i = 0; i < num_points; ++i) {
    // x2 x (H x1) = 0; its first two components are independent since x2 = (u, v, 1).
    const Eigen::Vector3d p = homogeneous(x1[i]);
    const double u = x2[i].x(), v = x2[i].y();
    A.block<1, 3>(col, 3) = -p.transpose();
    A.block<1, 3>(col, 6) = v * p.transpose();
    A.block<1, 3>(col + 1, 0) = p.transpose();
    A.block<1, 3>(col + 1, 6) = -u * p.transpose();
    col += 2;
  }
  for (int i = 0; i < num_lines; ++i) {
    // l1 x (H^T l2) = 0; drop the component that does not involve l1's largest coordinate.
    Eigen::Vector3d l1 = s1[i].line(), l2 = s2[i].line();
    const double n1 = l1.norm(), n2 = l2.norm();
    if (!(n1 > 0.0 && n2 > 0.0)) return false;
    l1 /= n1;
    l2 /= n2;
    int skip;
    l1.cwiseAbs().maxCoeff(&skip);
    for (int eq = 0; eq < 3; ++eq) {
      if (eq == skip) continue;
      // (l1 x m)_eq = l1[a] m[b] - l1[b] m[a] with m_c = sum_r l2[r] H(r, c).
      const int a = (eq + 1) % 3, b = (eq + 2) % 3;
      for (int r = 0; r < 3; ++r) {
        A(col, 3 * r + b) += l1(a) * l2(r);
        A(col, 3 * r + a) -= l1(b) * l2(r);
      }
      ++col;
    }
  }
  Eigen::Matrix<double, 9, 1> h;
  if (!null_vector<8>(A, &h)) return false;  // also rejects non-finite input
  *H << h(0), h(1), h(2), h(3), h(4), h(5), h(6), h(7), h(8);
  return true;
}

int relpose_homography(const Eigen::Vector2d* x1, const Eigen::Vector2d* x2, int num_points,
                       const LineSegment* s1, const LineSegment* s2, int num_lines,
                       RelativePoses* poses) {
  poses->clear();
  Eigen::Matrix3d H;
  if (!homography_from_points_and_lines(x1, x2, num_points, s1, s2, num_lines, &H)) return 0;
  if (!orient_homography(&H, x1, x2, num_points)) return 0;
  PlanarMotion motions[4];
  const int n = decompose_homography(H, motions);
  MatchView matches;
  matches.x1 = x1;
  matches.x2 = x2;
  matches.num_points = num_points;
  matches.s1 = s1;
  matches.s2 = s2;
  matches.num_segments = num_lines;
  // Motions come in (t, n) / (-t, -n) pairs; cheirality picks the sign within each pair.
  for (int i = 0; i < n; i += 2) {
    const double norm = motions[i].t.norm();
    Eigen::Vector3d t = norm > 0.0 ? Eigen::Vector3d(motions[i].t / norm) : motions[i].t;
    if (!orient_translation(motions[i].R, &t, matches)) continue;
    poses->emplace_back(motions[i].R, t);
  }
  return static_cast<int>(poses->size());
}

int relpose_homography_4pt(const std::array<Eigen::Vector2d, 4>& x1,
                           const std::array<Eigen::Vector2d, 4>& x2, RelativePoses* poses) {
  return relpose_homography(x1.data(), x2.data(), 4, nullptr, nullptr, 0, poses);
}

int relpose_homography_3pt_1line(const std::array<Eigen::Vector2d, 3>& x1,
                                 const std::array<Eigen::Vector2d, 3>& x2, const LineSegment& s1,
                                 const LineSegment& s2, RelativePoses* poses) {
  return relpose_homography(x1.data(), x2.data(), 3, &s1, &s2, 1, poses);
}

int relpose_homography_2pt_2line(const std::array<Eigen::Vector2d, 2>& x1,
                                 const std::array<Eigen::Vector2d, 2>& x2,
                                 const std::array<LineSegment, 2>& s1,
                                 const std::array<LineSegment, 2>& s2, RelativePoses* poses) {
  return relpose_homography(x1.data(), x2.data(), 2, s1.data(), s2.data(), 2, poses);
}

int relpose_homography_1pt_3line(const Eigen::Vector2d& x1, const Eigen::Vector2d& x2,
                                 const std::array<LineSegment, 3>& s1,
                                 const std::array<LineSegment, 3>& s2, RelativePoses* poses) {
  return relpose_homography(&x1, &x2, 1, s1.data(), s2.data(), 3, poses);
}

int relpose_homography_4line(const std::array<LineSegment, 4>& s1,
                             const std::array<LineSegment, 4>& s2, RelativePoses* poses) {
  return relpose_homography(nullptr, nullptr, 0, s1.data(), s2.data(), 4, poses);
}

}  // namespace hybrid_vo
