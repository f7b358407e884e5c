#include "hybrid_vo/solvers/relpose_5pt.h"

#include <algorithm>
#include <cmath>

#include <Eigen/LU>

#include "hybrid_vo/geometry/essential.h"
#include "hybrid_vo/geometry/homogeneous.h"
#include "hybrid_vo/solvers/polynomial.h"

namespace hybrid_vo {
namespace {

// E = x X + y Y + z Z + W. Polynomials in (x, y, z) up to degree 3 use these monomial orders:
//   degree 1: x y z 1
//   degree 2: xx xy xz yy yz zz x y z 1
//   degree 3: xxx yyy xxy xyy xxz xx yyz yy xyz xy | xzz xz x yzz yz y zzz zz z 1
// The first ten cubic monomials are eliminated (Nistér's Sec. 3.2 ordering).
using Linear = Eigen::Matrix<double, 4, 1>;
using Quadratic = Eigen::Matrix<double, 10, 1>;
using Cubic = Eigen::Matrix<double, 20, 1>;

constexpr int kLinearTimesLinear[4][4] = {{0, 1, 2, 6}, {1, 3, 4, 7}, {2, 4, 5, 8}, {6, 7, 8, 9}};
constexpr int kQuadraticTimesLinear[10][4] = {
    {0, 2, 4, 5},     {2, 3, 8, 9},    {4, 8, 10, 11},  {3, 1, 6, 7},    {8, 6, 13, 14},
    {10, 13, 16, 17}, {5, 9, 11, 12},  {9, 7, 14, 15},  {11, 14, 17, 18}, {12, 15, 18, 19}};

Quadratic multiply(const Linear& a, const Linear& b) {
  Quadratic r = Quadratic::Zero();
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) r(kLinearTimesLinear[i][j]) += a(i) * b(j);
  return r;
}

void multiply_add(const Quadratic& a, const Linear& b, Cubic* r) {
  for (int i = 0; i < 10; ++i)
    for (int j = 0; j < 4; ++j) (*r)(kQuadraticTimesLinear[i][j]) += a(i) * b(j);
}

// Product of polynomials in z with ascending coefficients.
template <int A, int B>
Eigen::Matrix<double, A + B - 1, 1> poly_multiply(const Eigen::Matrix<double, A, 1>& a,
                                                  const Eigen::Matrix<double, B, 1>& b) {
  Eigen::Matrix<double, A + B - 1, 1> r = Eigen::Matrix<double, A + B - 1, 1>::Zero();
  for (int i = 0; i < A; ++i)
    for (int j = 0; j < B; ++j) r(i + j) += a(i) * b(j);
  return r;
}

template <int N>
double poly_eval(const Eigen::Matrix<double, N, 1>& c, double z) {
  double v = c(N - 1);
  for (int i = N - 2; i >= 0; --i) v = v * z + c(i);
  return v;
}

// Row (top) - z * row (bottom) of the eliminated system is linear in x and y: its x, y and
// constant parts as polynomials in z.
struct ZRow {
  Eigen::Vector4d x, y;
  Eigen::Matrix<double, 5, 1> one;
};

ZRow z_row(const Eigen::Matrix<double, 10, 10>& B, int top, int bottom) {
  const auto t = B.row(top), b = B.row(bottom);
  ZRow r;
  r.x << t(2), t(1) - b(2), t(0) - b(1), -b(0);
  r.y << t(5), t(4) - b(5), t(3) - b(4), -b(3);
  r.one << t(9), t(8) - b(9), t(7) - b(8), t(6) - b(7), -b(6);
  return r;
}

// Gauss-Jordan elimination with partial pivoting of the left 10x10 block of C; B receives the
// right block of the reduced system [I | B]. Hand-written because Eigen's blocked LU and triangular
// solves cost more than the arithmetic at this size. Each step subtracts multiples of the pivot
// column from whole columns, which are contiguous (fixed-size vector operations rather than a
// scalar loop along strided rows), and rows are not swapped: each pivot row is remembered and
// gathered into B at the end.
bool eliminate_leading_monomials(Eigen::Matrix<double, 10, 20> M, Eigen::Matrix<double, 10, 10>* B) {
  using Column = Eigen::Matrix<double, 10, 1>;
  int pivot_row[10];
  bool used[10] = {};
  for (int k = 0; k < 10; ++k) {
    int pivot = -1;
    double largest = -1.0;
    for (int i = 0; i < 10; ++i) {
      const double v = std::abs(M(i, k));
      if (!used[i] && v > largest) largest = v, pivot = i;
    }
    if (!(largest > 0.0) || !std::isfinite(largest)) return false;
    used[pivot] = true;
    pivot_row[k] = pivot;
    // Multipliers of the pivot row for every other row; zero for the pivot row itself, which is
    // scaled instead.
    const double inv = 1.0 / M(pivot, k);
    Column factors = M.col(k);
    factors(pivot) = 0.0;
    for (int j = k + 1; j < 20; ++j) {
      const double pivot_row_entry = M(pivot, j) * inv;
      M.col(j) -= pivot_row_entry * factors;
      M(pivot, j) = pivot_row_entry;
    }
  }
  for (int k = 0; k < 10; ++k) B->row(k) = M.row(pivot_row[k]).rightCols<10>();
  return all_finite(*B);
}

// Orthonormal basis of the 4-dimensional null space of the five constraints (the columns of
// At): the last four columns of Q in the Householder QR of At (Golub and Van Loan, Sec. 5.2),
// written out for the fixed size; Eigen's QR and the application of its Q cost four times as
// many instructions here. False when the constraints are dependent (|R_ii| below 1e-10 of the
// largest).
bool null_space_basis(Eigen::Matrix<double, 9, 5> A, Eigen::Matrix<double, 9, 4>* basis) {
  // Reflector k is I - beta_k v_k v_k^T with v_k zero above row k.
  Eigen::Matrix<double, 9, 5> V = Eigen::Matrix<double, 9, 5>::Zero();
  double beta[5];
  double largest = 0.0, smallest = INFINITY;
  for (int k = 0; k < 5; ++k) {
    double tail = 0.0;  // squared norm below the diagonal
    for (int i = k + 1; i < 9; ++i) tail += A(i, k) * A(i, k);
    const double head = A(k, k);
    const double norm = std::sqrt(head * head + tail);
    // alpha = -sign(head) |x| avoids cancellation in v_k = x - alpha e_k.
    const double alpha = head >= 0.0 ? -norm : norm;
    largest = std::max(largest, norm);
    smallest = std::min(smallest, norm);  // |R_kk|
    for (int i = k + 1; i < 9; ++i) V(i, k) = A(i, k);
    V(k, k) = head - alpha;
    const double vv = V(k, k) * V(k, k) + tail;
    beta[k] = vv > 0.0 ? 2.0 / vv : 0.0;
    for (int j = k + 1; j < 5; ++j) {
      const double s = beta[k] * V.col(k).dot(A.col(j));
      A.col(j) -= s * V.col(k);
    }
  }
  if (!(smallest > 1e-10 * largest)) return false;  // repeated or otherwise dependent constraints
  // Q [0; I] = H_0 H_1 ... H_4 [0; I], applying H_4 first.
  basis->setZero();
  basis->bottomRows<4>().setIdentity();
  for (int k = 4; k >= 0; --k)
    for (int j = 0; j < 4; ++j) {
      const double s = beta[k] * V.col(k).dot(basis->col(j));
      basis->col(j) -= s * V.col(k);
    }
  return true;
}

// The ten cubic constraints on E = x X + y Y + z Z + W (the basis columns), in the monomial
// order above: (2 E E^T - tr(E E^T) I) E = 0, nine rows, and det(E) = 0 (Nistér's Sec. 3.1).
void cubic_constraints(const Eigen::Matrix<double, 9, 4>& basis,
                       Eigen::Matrix<double, 10, 20>* C) {
  Linear e[3][3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) e[i][j] = basis.row(3 * i + j).transpose();
  Quadratic EEt[3][3];
  for (int i = 0; i < 3; ++i)
    for (int j = i; j < 3; ++j) {
      EEt[i][j] = multiply(e[i][0], e[j][0]) + multiply(e[i][1], e[j][1]) +
                  multiply(e[i][2], e[j][2]);
      EEt[j][i] = EEt[i][j];
    }
  const Quadratic trace = EEt[0][0] + EEt[1][1] + EEt[2][2];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      Cubic row = Cubic::Zero();
      for (int k = 0; k < 3; ++k) {
        Quadratic m = 2.0 * EEt[i][k];
        if (i == k) m -= trace;
        multiply_add(m, e[k][j], &row);
      }
      C->row(3 * i + j) = row.transpose();
    }
  Cubic det = Cubic::Zero();
  multiply_add(multiply(e[1][1], e[2][2]) - multiply(e[1][2], e[2][1]), e[0][0], &det);
  multiply_add(multiply(e[1][2], e[2][0]) - multiply(e[1][0], e[2][2]), e[0][1], &det);
  multiply_add(multiply(e[1][0], e[2][1]) - multiply(e[1][1], e[2][0]), e[0][2], &det);
  C->row(9) = det.transpose();
}

// One Gauss-Newton step of (x, y, z) on the ten cubic constraints C m(x, y, z) = 0. The degree-10
// polynomial loses digits when two of its roots are close; the original system does not.
void refine_xyz(const Eigen::Matrix<double, 10, 20>& C, double* x, double* y, double* z) {
  const double a = *x, b = *y, c = *z;
  const double aa = a * a, bb = b * b, cc = c * c, ab = a * b, ac = a * c, bc = b * c;
  using Column = Eigen::Matrix<double, 10, 1>;
  auto col = [&C](int k) { return C.col(k); };
  // Residual C m and its x, y, z derivatives, one column of C at a time and only where the
  // monomial's derivative is nonzero (kCubic order): a dense 10x20 by 20x4 product costs
  // twice as much.
  const double m[20] = {aa * a, bb * b, aa * b, a * bb, aa * c, aa, bb * c, bb, ab * c, ab,
                        a * cc, ac,     a,      b * cc, bc,     b,  cc * c, cc, c,      1.0};
  Column r = Column::Zero();
  for (int k = 0; k < 20; ++k) r += m[k] * col(k);
  Eigen::Matrix<double, 10, 3> J;
  J.col(0) = 3 * aa * col(0) + 2 * ab * col(2) + bb * col(3) + 2 * ac * col(4) + 2 * a * col(5) +
             bc * col(8) + b * col(9) + cc * col(10) + c * col(11) + col(12);
  J.col(1) = 3 * bb * col(1) + aa * col(2) + 2 * ab * col(3) + 2 * bc * col(6) + 2 * b * col(7) +
             ac * col(8) + a * col(9) + cc * col(13) + c * col(14) + col(15);
  J.col(2) = aa * col(4) + bb * col(6) + ab * col(8) + 2 * ac * col(10) + a * col(11) +
             2 * bc * col(13) + b * col(14) + 3 * cc * col(16) + 2 * c * col(17) + col(18);
  const Eigen::Matrix3d JtJ = J.transpose().lazyProduct(J);
  const Eigen::Vector3d step = -(JtJ.inverse() * (J.transpose().lazyProduct(r)));
  if (!all_finite(step)) return;
  *x += step(0);
  *y += step(1);
  *z += step(2);
}

}  // namespace

int essential_5pt(const Eigen::Vector2d* x1, const Eigen::Vector2d* x2, Eigen::Matrix3d* essentials) {
  Eigen::Matrix<double, 9, 5> At;  // epipolar constraints as columns
  for (int i = 0; i < 5; ++i) {
    const Eigen::Vector3d p = homogeneous(x1[i]), q = homogeneous(x2[i]);
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k) At(3 * j + k, i) = q(j) * p(k);
  }
  if (!all_finite(At)) return 0;
  Eigen::Matrix<double, 9, 4> basis;
  if (!null_space_basis(At, &basis)) return 0;

  Eigen::Matrix<double, 10, 20> C;
  cubic_constraints(basis, &C);

  // Gauss-Jordan on the first ten monomials: monomial_i + B.row(i) . rest = 0.
  Eigen::Matrix<double, 10, 10> B;
  if (!eliminate_leading_monomials(C, &B)) return 0;

  const ZRow k = z_row(B, 4, 5), l = z_row(B, 6, 7), m = z_row(B, 8, 9);
  // (x, y, 1) is orthogonal to all three rows, so det = 0 and (x, y, 1) ~ k x l.
  const Eigen::Matrix<double, 8, 1> p1 = poly_multiply(k.y, l.one) - poly_multiply(k.one, l.y);
  const Eigen::Matrix<double, 8, 1> p2 = poly_multiply(k.one, l.x) - poly_multiply(k.x, l.one);
  const Eigen::Matrix<double, 7, 1> p3 = poly_multiply(k.x, l.y) - poly_multiply(k.y, l.x);
  Eigen::Matrix<double, 11, 1> det_z = poly_multiply(m.x, p1) + poly_multiply(m.y, p2);
  det_z += poly_multiply(m.one, p3);

  double roots[10];
  const int num_roots = real_roots(det_z.data(), 10, roots);
  int count = 0;
  for (int r = 0; r < num_roots; ++r) {
    const double z = roots[r];
    // Null vector of the 3x3 system at z from its best-conditioned pair of rows.
    Eigen::Matrix3d Bz;
    Bz << poly_eval(k.x, z), poly_eval(k.y, z), poly_eval(k.one, z), poly_eval(l.x, z),
        poly_eval(l.y, z), poly_eval(l.one, z), poly_eval(m.x, z), poly_eval(m.y, z),
        poly_eval(m.one, z);
    Eigen::Vector3d xy1 = Bz.row(0).cross(Bz.row(1));
    const Eigen::Vector3d c02 = Bz.row(0).cross(Bz.row(2)), c12 = Bz.row(1).cross(Bz.row(2));
    if (std::abs(c02(2)) > std::abs(xy1(2))) xy1 = c02;
    if (std::abs(c12(2)) > std::abs(xy1(2))) xy1 = c12;
    if (!(std::abs(xy1(2)) > 0.0)) continue;
    double x = xy1(0) / xy1(2), y = xy1(1) / xy1(2), z_refined = z;
    refine_xyz(C, &x, &y, &z_refined);
    const Eigen::Matrix<double, 9, 1> e_vec = x * basis.col(0) + y * basis.col(1) +
                                              z_refined * basis.col(2) + basis.col(3);
    if (!all_finite(e_vec)) continue;
    Eigen::Matrix3d& E = essentials[count++];
    E << e_vec(0), e_vec(1), e_vec(2), e_vec(3), e_vec(4), e_vec(5), e_vec(6), e_vec(7), e_vec(8);
  }
  return count;
}

int relpose_5pt(const Eigen::Vector2d* x1, const Eigen::Vector2d* x2, const MatchView& witnesses,
                RelativePoses* poses) {
  poses->clear();
  Eigen::Matrix3d essentials[10];
  const int n = essential_5pt(x1, x2, essentials);
  for (int i = 0; i < n; ++i) poses_from_essential(essentials[i], witnesses, poses);
  return static_cast<int>(poses->size());
}

int relpose_5pt(const std::array<Eigen::Vector2d, 5>& x1, const std::array<Eigen::Vector2d, 5>& x2,
                RelativePoses* poses) {
  MatchView witnesses;
  witnesses.x1 = x1.data();
  witnesses.x2 = x2.data();
  witnesses.num_points = 5;
  return relpose_5pt(x1.data(), x2.data(), witnesses, poses);
}

}  // namespace hybrid_vo
