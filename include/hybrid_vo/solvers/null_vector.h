#pragma once

#include <cmath>
#include <utility>

#include <Eigen/Core>

namespace hybrid_vo {

// Null vector (unit norm) of an N x (N + 1) matrix by Gaussian elimination with complete pivoting:
// several times cheaper than a QR for the tiny DLT systems of minimal solvers, and as accurate in
// practice. False when the rank is below N, judged by the last pivot relative to the first.
template <int N>
bool null_vector(Eigen::Matrix<double, N, N + 1> A, Eigen::Matrix<double, N + 1, 1>* v,
                 double rank_tolerance = 1e-10) {
  int column_of[N + 1];
  for (int j = 0; j <= N; ++j) column_of[j] = j;
  double first_pivot = 0.0;
  for (int k = 0; k < N; ++k) {
    int pr = k, pc = k;
    double best = -1.0;
    for (int i = k; i < N; ++i)
      for (int j = k; j <= N; ++j)
        if (std::abs(A(i, j)) > best) best = std::abs(A(i, j)), pr = i, pc = j;
    if (k == 0) first_pivot = best;
    if (!(best > rank_tolerance * first_pivot) || !std::isfinite(best)) return false;
    if (pr != k) A.row(pr).swap(A.row(k));
    if (pc != k) {
      A.col(pc).swap(A.col(k));
      std::swap(column_of[pc], column_of[k]);
    }
    for (int i = k + 1; i < N; ++i) {
      const double f = A(i, k) / A(k, k);
      for (int j = k + 1; j <= N; ++j) A(i, j) -= f * A(k, j);
      A(i, k) = 0.0;
    }
  }
  double y[N + 1];
  y[N] = 1.0;
  for (int k = N - 1; k >= 0; --k) {
    double s = 0.0;
    for (int j = k + 1; j <= N; ++j) s += A(k, j) * y[j];
    y[k] = -s / A(k, k);
  }
  for (int j = 0; j <= N; ++j) (*v)(column_of[j]) = y[j];
  v->normalize();
  return true;
}

}  // namespace hybrid_vo
