#include "hybrid_vo/solvers/relpose_homography.h"

#include <cmath>

#include <Eigen/Geometry>

#include "hybrid_vo/geometry/cheirality.h"
#include "hybrid_vo/geometry/homography.h"

namespace hybrid_vo {

namespace {

// Relative size below which three of the entities count as collinear (concurrent), or a point as
// lying on a line: the determinant (dot product) of the unit vectors, about the angle between them.
constexpr double kDegenerate = 1e-10;

// |det(u, v, w)| > kDegenerate |u| |v| |w| on squares (no roots); false for NaN too.
bool independent(double det, double uu, double vv, double ww) {
  return det * det > kDegenerate * kDegenerate * uu * vv * ww;
}

// G = B diag(d) A^-1 takes a_i to b_i (i < 3) for every d; the fourth correspondence fixes d.
// adj(A), whose rows are cross products, stands in for A^-1 (equal up to scale).
Eigen::Matrix3d frame_map(const Eigen::Matrix3d& adj_a, const Eigen::Vector3d* b,
                          const Eigen::Vector3d& d) {
  Eigen::Matrix3d B;
  B << b[0] * d(0), b[1] * d(1), b[2] * d(2);
  return B * adj_a;
}

Eigen::Matrix3d adjugate_of_columns(const Eigen::Vector3d* a) {
  Eigen::Matrix3d adj;
  adj.row(0) = a[1].cross(a[2]);
  adj.row(1) = a[2].cross(a[0]);
  adj.row(2) = a[0].cross(a[1]);
  return adj;
}

// Scales G to unit Frobenius norm; false when it is zero or not finite.
bool normalise(Eigen::Matrix3d* G) {
  const double norm = G->norm();
  if (!(norm > 0.0) || !std::isfinite(norm)) return false;
  *G *= 1.0 / norm;
  return true;
}

// The two results without the final normalisation (see the header).
bool map_of_4(const Eigen::Vector3d* a, const Eigen::Vector3d* b, Eigen::Matrix3d* G) {
  // lambda = A^-1 a3 scales the frame so that e1 + e2 + e3 goes to a3; then d_i = mu_i / lambda_i
  // ~ mu_i lambda_j lambda_k. The four determinants vanish when one triple is collinear.
  const Eigen::Matrix3d adj_a = adjugate_of_columns(a), adj_b = adjugate_of_columns(b);
  const Eigen::Vector3d lambda = adj_a * a[3], mu = adj_b * b[3];
  const double det_a = adj_a.row(0).dot(a[0]), det_b = adj_b.row(0).dot(b[0]);
  double na[4], nb[4];
  for (int i = 0; i < 4; ++i) na[i] = a[i].squaredNorm(), nb[i] = b[i].squaredNorm();
  if (!independent(det_a, na[0], na[1], na[2]) || !independent(det_b, nb[0], nb[1], nb[2]) ||
      !independent(lambda(0), na[1], na[2], na[3]) || !independent(mu(0), nb[1], nb[2], nb[3]) ||
      !independent(lambda(1), na[2], na[0], na[3]) || !independent(mu(1), nb[2], nb[0], nb[3]) ||
      !independent(lambda(2), na[0], na[1], na[3]) || !independent(mu(2), nb[0], nb[1], nb[3]))
    return false;
  *G = frame_map(adj_a, b, Eigen::Vector3d(mu(0) * lambda(1) * lambda(2),
                                           mu(1) * lambda(2) * lambda(0),
                                           mu(2) * lambda(0) * lambda(1)));
  return true;
}

bool map_of_3_and_dual(const Eigen::Vector3d* a, const Eigen::Vector3d* b, const Eigen::Vector3d& f,
                       const Eigen::Vector3d& g, Eigen::Matrix3d* G) {
  // G^T g = A^-T diag(d) B^T g ~ f gives d_i (b_i . g) ~ a_i . f, so d_i ~ u_i w_j w_k.
  const Eigen::Matrix3d adj_a = adjugate_of_columns(a);
  const double det_a = adj_a.row(0).dot(a[0]), det_b = b[0].dot(b[1].cross(b[2]));
  const Eigen::Vector3d u(a[0].dot(f), a[1].dot(f), a[2].dot(f));
  const Eigen::Vector3d w(b[0].dot(g), b[1].dot(g), b[2].dot(g));
  double na[3], nb[3];
  for (int i = 0; i < 3; ++i) na[i] = a[i].squaredNorm(), nb[i] = b[i].squaredNorm();
  const double nf = f.squaredNorm(), ng = g.squaredNorm();
  if (!independent(det_a, na[0], na[1], na[2]) || !independent(det_b, nb[0], nb[1], nb[2]))
    return false;
  for (int i = 0; i < 3; ++i)
    if (!independent(u(i), na[i], nf, 1.0) || !independent(w(i), nb[i], ng, 1.0)) return false;
  *G = frame_map(adj_a, b, Eigen::Vector3d(u(0) * w(1) * w(2), u(1) * w(2) * w(0),
                                           u(2) * w(0) * w(1)));
  return true;
}

}  // namespace

bool homography_from_4_correspondences(const Eigen::Vector3d* a, const Eigen::Vector3d* b,
                                       Eigen::Matrix3d* G) {
  return map_of_4(a, b, G) && normalise(G);
}

bool homography_from_3_correspondences_and_dual(const Eigen::Vector3d* a, const Eigen::Vector3d* b,
                                                const Eigen::Vector3d& f, const Eigen::Vector3d& g,
                                                Eigen::Matrix3d* G) {
  return map_of_3_and_dual(a, b, f, g, G) && normalise(G);
}

bool homography_4pt(const Eigen::Vector2d* x1, const Eigen::Vector2d* x2, Eigen::Matrix3d* H) {
  // map_of_4 for points (x, y, 1), written out: every cross product of two such points is
  // (y_a - y_b, x_b - x_a, x_a y_b - y_a x_b), two products instead of six. Centred as in
  // homography_from_points_and_lines.
  const double c1x = 0.25 * (x1[0].x() + x1[1].x() + x1[2].x() + x1[3].x());
  const double c1y = 0.25 * (x1[0].y() + x1[1].y() + x1[2].y() + x1[3].y());
  const double c2x = 0.25 * (x2[0].x() + x2[1].x() + x2[2].x() + x2[3].x());
  const double c2y = 0.25 * (x2[0].y() + x2[1].y() + x2[2].y() + x2[3].y());
  double ax[4], ay[4], bx[4], by[4], na[4], nb[4];
  for (int i = 0; i < 4; ++i) {
    ax[i] = x1[i].x() - c1x;
    ay[i] = x1[i].y() - c1y;
    bx[i] = x2[i].x() - c2x;
    by[i] = x2[i].y() - c2y;
    na[i] = ax[i] * ax[i] + ay[i] * ay[i] + 1.0;
    nb[i] = bx[i] * bx[i] + by[i] * by[i] + 1.0;
  }
  // Rows of adj[a0 a1 a2] (a1 x a2, a2 x a0, a0 x a1) and of adj[b0 b1 b2].
  double A[3][3], B[3][3];
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3, k = (i + 2) % 3;
    A[i][0] = ay[j] - ay[k];
    A[i][1] = ax[k] - ax[j];
    A[i][2] = ax[j] * ay[k] - ay[j] * ax[k];
    B[i][0] = by[j] - by[k];
    B[i][1] = bx[k] - bx[j];
    B[i][2] = bx[j] * by[k] - by[j] * bx[k];
  }
  const double det_a = A[0][0] * ax[0] + A[0][1] * ay[0] + A[0][2];
  const double det_b = B[0][0] * bx[0] + B[0][1] * by[0] + B[0][2];
  double lambda[3], mu[3];
  for (int i = 0; i < 3; ++i) {
    lambda[i] = A[i][0] * ax[3] + A[i][1] * ay[3] + A[i][2];
    mu[i] = B[i][0] * bx[3] + B[i][1] * by[3] + B[i][2];
  }
  if (!independent(det_a, na[0], na[1], na[2]) || !independent(det_b, nb[0], nb[1], nb[2]) ||
      !independent(lambda[0], na[1], na[2], na[3]) || !independent(mu[0], nb[1], nb[2], nb[3]) ||
      !independent(lambda[1], na[2], na[0], na[3]) || !independent(mu[1], nb[2], nb[0], nb[3]) ||
      !independent(lambda[2], na[0], na[1], na[3]) || !independent(mu[2], nb[0], nb[1], nb[3]))
    return false;
  // G = B diag(d) adj(A) = sum_i d_i b_i adj(A).row(i), with b_i = (bx_i, by_i, 1).
  const double d[3] = {mu[0] * lambda[1] * lambda[2], mu[1] * lambda[2] * lambda[0],
                       mu[2] * lambda[0] * lambda[1]};
  double G[3][3] = {};
  for (int i = 0; i < 3; ++i)
    for (int c = 0; c < 3; ++c) {
      const double w = d[i] * A[i][c];
      G[0][c] += bx[i] * w;
      G[1][c] += by[i] * w;
      G[2][c] += w;
    }
  // Undo the centring, H = T(c2)^-1 G T(c1), and scale to unit Frobenius norm.
  for (int r = 0; r < 3; ++r) G[r][2] -= G[r][0] * c1x + G[r][1] * c1y;
  for (int c = 0; c < 3; ++c) {
    G[0][c] += c2x * G[2][c];
    G[1][c] += c2y * G[2][c];
  }
  double norm2 = 0.0;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) norm2 += G[r][c] * G[r][c];
  if (!(norm2 > 0.0) || !std::isfinite(norm2)) return false;
  const double inv = 1.0 / std::sqrt(norm2);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) (*H)(r, c) = G[r][c] * inv;
  return true;
}

bool homography_from_points_and_lines(const Eigen::Vector2d* x1, const Eigen::Vector2d* x2,
                                      int num_points, const LineSegment* s1, const LineSegment* s2,
                                      int num_lines, Eigen::Matrix3d* H) {
  if (num_points < 0 || num_lines < 0 || num_points + num_lines != 4) return false;
  // Two points and two lines never fix H (doc/solvers.md, "2-2-0 is degenerate").
  if (num_points == 2) return false;
  if (num_points == 4) return homography_4pt(x1, x2, H);
  // Centred coordinates (as HZ2004 Sec. 4.4.4 normalises the DLT): the cross products then do
  // not cancel digits against the homogeneous 1.
  Eigen::Vector2d c1 = Eigen::Vector2d::Zero(), c2 = Eigen::Vector2d::Zero();
  for (int i = 0; i < num_points; ++i) c1 += x1[i], c2 += x2[i];
  for (int i = 0; i < num_lines; ++i) c1 += s1[i].p1 + s1[i].p2, c2 += s2[i].p1 + s2[i].p2;
  const double inv_count = 1.0 / (num_points + 2 * num_lines);
  c1 *= inv_count;
  c2 *= inv_count;
  // Points map as x2 ~ H x1, lines as l1 ~ H^T l2.
  Eigen::Vector3d p1[4], p2[4], l1[4], l2[4];
  for (int i = 0; i < num_points; ++i) p1[i] = homogeneous(x1[i] - c1), p2[i] = homogeneous(x2[i] - c2);
  for (int i = 0; i < num_lines; ++i) {
    l1[i] = homogeneous(s1[i].p1 - c1).cross(homogeneous(s1[i].p2 - c1));
    l2[i] = homogeneous(s2[i].p1 - c2).cross(homogeneous(s2[i].p2 - c2));
  }
  Eigen::Matrix3d Hc;
  bool ok;
  switch (num_points) {
    case 4: ok = map_of_4(p1, p2, &Hc); break;
    case 3: ok = map_of_3_and_dual(p1, p2, l1[0], l2[0], &Hc); break;  // H^T l2 ~ l1
    case 1: ok = map_of_3_and_dual(l2, l1, p2[0], p1[0], &Hc); break;  // H^T: l2 -> l1, H x1 ~ x2
    default: ok = map_of_4(l2, l1, &Hc); break;                         // H^T: l2 -> l1
  }
  if (!ok) return false;
  if (num_points < 3) Hc.transposeInPlace();
  // Undo the centring: H = T(c2)^-1 Hc T(c1) with T(c) x = x - c.
  Hc.col(2) -= Hc.col(0) * c1.x() + Hc.col(1) * c1.y();
  Hc.row(0) += c2.x() * Hc.row(2);
  Hc.row(1) += c2.y() * Hc.row(2);
  if (!normalise(&Hc)) return false;
  *H = Hc;
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
