#include "hybrid_vo/solvers/polynomial.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>

namespace hybrid_vo {
namespace {

constexpr int kMax = kMaxPolynomialDegree;

// Sturm chain p0 = p, p1 = p', p_k = -rem(p_{k-2}, p_{k-1}); each member scaled to a leading
// coefficient of +-1, which keeps magnitudes sane and leaves signs (all Sturm needs) unchanged.
class SturmChain {
 public:
  SturmChain(const double* monic, int degree) {
    deg_[0] = degree;
    std::copy(monic, monic + degree + 1, seq_[0]);
    deg_[1] = degree - 1;
    for (int i = 1; i <= degree; ++i) seq_[1][i - 1] = i * monic[i] / degree;
    length_ = 2;
    while (deg_[length_ - 1] > 0 && length_ <= kMax) {
      const int k = length_;
      double rem[kMax + 1];
      const int rem_deg = remainder(seq_[k - 2], deg_[k - 2], seq_[k - 1], deg_[k - 1], rem);
      if (rem_deg < 0) break;  // p and p' share a factor: the chain ends at their gcd.
      const double lead = std::abs(rem[rem_deg]);
      for (int i = 0; i <= rem_deg; ++i) seq_[k][i] = -rem[i] / lead;
      deg_[k] = rem_deg;
      ++length_;
    }
  }

  // Sign changes of the chain at x; *value receives p(x).
  int sign_changes(double x, double* value) const {
    int changes = 0;
    double previous = 0.0;
    for (int k = 0; k < length_; ++k) {
      const double* c = seq_[k];
      double v = c[deg_[k]];
      for (int i = deg_[k] - 1; i >= 0; --i) v = v * x + c[i];
      if (k == 0) *value = v;
      if (v == 0.0) continue;
      if (previous != 0.0 && (v > 0.0) != (previous > 0.0)) ++changes;
      previous = v;
    }
    return changes;
  }

 private:
  // Remainder of a / b; returns its degree, or -1 when it vanishes relative to a.
  static int remainder(const double* a, int deg_a, const double* b, int deg_b, double* r) {
    double work[kMax + 1];
    std::copy(a, a + deg_a + 1, work);
    double scale = 0.0;
    for (int i = 0; i <= deg_a; ++i) scale = std::max(scale, std::abs(a[i]));
    for (int i = deg_a; i >= deg_b; --i) {
      const double q = work[i] / b[deg_b];
      for (int j = 0; j <= deg_b; ++j) work[i - deg_b + j] -= q * b[j];
    }
    int deg_r = deg_b - 1;
    const double tiny = 1e-13 * scale;
    while (deg_r >= 0 && std::abs(work[deg_r]) <= tiny) --deg_r;
    std::copy(work, work + deg_r + 1, r);
    return deg_r;
  }

  double seq_[kMax + 1][kMax + 1];
  int deg_[kMax + 1];
  int length_;
};

// The generic Sturm chain of a monic p of degree n, where every remainder has degree one less
// than its divisor, as the three-term recurrence p_{k-1} = (a_k + b_k x) p_k - c_k p_{k+1}
// (c_k > 0) from p_n (a constant) and p_{n-1} (linear). Evaluating the whole chain at x then
// costs O(n) instead of one Horner pass per member, O(n^2); bisection evaluates it many times.
// Degree drops (a common factor of p and p', or a remainder that vanishes to rounding) are
// left to SturmChain. kFixed > 0 is the degree known at compile time (the 5-point solver's 10),
// which lets the compiler unroll the evaluation; 0 takes it at run time.
template <int kFixed>
class ThreeTermSturmChain {
 public:
  // False when the chain is not generic; the object is then unusable.
  bool build(const double* monic, int degree) {
    n_ = kFixed > 0 ? kFixed : degree;
    double prev[kMax + 1], cur[kMax + 1], next[kMax + 1];
    std::copy(monic, monic + degree + 1, prev);
    for (int i = 1; i <= degree; ++i) cur[i - 1] = i * monic[i] / degree;
    // prev has degree m + 1 and cur degree m, with leading coefficients +-1.
    for (int m = degree - 1; m >= 1; --m) {
      const double b = prev[m + 1] / cur[m];
      const double a = (prev[m] - b * cur[m - 1]) / cur[m];
      next[0] = prev[0] - a * cur[0];
      for (int j = 1; j < m; ++j) next[j] = prev[j] - b * cur[j - 1] - a * cur[j];
      // next is the remainder, of degree m - 1 unless its top coefficient vanishes against the
      // dividend (SturmChain's test).
      double scale = 0.0;
      for (int j = 0; j <= m + 1; ++j) scale = std::max(scale, std::abs(prev[j]));
      const double lead = std::abs(next[m - 1]);
      if (!(lead > 1e-13 * scale)) return false;
      const int k = degree - m;  // divisor p_k, remainder gives p_{k+1}
      a_[k] = a;
      b_[k] = b;
      c_[k] = lead;
      const double inv = -1.0 / lead;
      for (int j = 0; j < m; ++j) prev[j] = cur[j];
      prev[m] = cur[m];
      for (int j = 0; j < m; ++j) cur[j] = next[j] * inv;
    }
    // cur is now p_n, a nonzero constant (+-1); prev is p_{n-1}, linear.
    last_ = cur[0];
    linear0_ = prev[0];
    linear1_ = prev[1];
    return true;
  }

  // Sign changes of the chain at x; *value receives p_0(x) = p(x).
  int sign_changes(double x, double* value) const {
    const int n = kFixed > 0 ? kFixed : n_;
    double f_next = last_;                      // p_n
    double f = linear0_ + linear1_ * x;         // p_{n-1}
    int changes = 0;
    double previous = f_next;                   // nonzero
    auto count = [&](double v) {
      if (v == 0.0) return;
      changes += (v > 0.0) != (previous > 0.0);
      previous = v;
    };
    count(f);
    for (int k = n - 1; k >= 1; --k) {
      const double g = (a_[k] + b_[k] * x) * f - c_[k] * f_next;  // p_{k-1}
      f_next = f;
      f = g;
      count(f);
    }
    *value = f;
    return changes;
  }

 private:
  double a_[kMax + 1], b_[kMax + 1], c_[kMax + 1];
  double last_ = 1.0, linear0_ = 0.0, linear1_ = 1.0;
  int n_ = 0;
};

// The single root of p in (lo, hi) where p changes sign: Newton steps, bisection when a step
// leaves the bracket or fails to halve the step before last (from afar, Newton creeps towards a
// root of a degree-n polynomial by a factor of about 1 - 1/n per step). Converged after a step
// below 1e-8 |x|: Newton's error after a step of size h is of order h^2 / (distance to the next
// root), and the 5-point solver refines each root once more on its original equations. Near
// convergence, also stops when |p(x)| is within the rounding error of its own evaluation, where
// further steps only move x by noise (they made up half the steps on the 5-point solver's
// polynomials before this test). kFixed as for ThreeTermSturmChain.
template <int kFixed>
double polish_bracketed_root(const double* c, const double* abs_c, int degree_at_run_time,
                             double lo, double hi, double f_lo) {
  const int degree = kFixed > 0 ? kFixed : degree_at_run_time;
  // The rounding error of Horner's rule is below 2 degree eps sum |c_i| |x|^i (Higham 2002,
  // Sec. 5.1) and typically near 2 eps times that sum.
  constexpr double kNoise = 4e-16;
  double x = 0.5 * (lo + hi);
  double step_before_last = hi - lo, last_step = step_before_last;
  for (int iter = 0; iter < 100; ++iter) {
    double f = c[degree], df = 0.0;
    for (int i = degree - 1; i >= 0; --i) {
      df = df * x + f;
      f = f * x + c[i];
    }
    if ((f > 0.0) == (f_lo > 0.0)) {
      lo = x;
      f_lo = f;
    } else {
      hi = x;
    }
    double next = df != 0.0 ? x - f / df : lo - 1.0;
    const bool newton =
        next > lo && next < hi && std::abs(2.0 * f) <= std::abs(step_before_last * df);
    if (!newton) next = 0.5 * (lo + hi);
    step_before_last = last_step;
    last_step = next - x;
    const double ax = std::abs(x);
    if (newton && std::abs(last_step) <= 1e-8 * ax) return next;
    if (std::abs(last_step) <= 1e-4 * ax || f == 0.0) {
      double magnitude = abs_c[degree];
      for (int i = degree - 1; i >= 0; --i) magnitude = magnitude * ax + abs_c[i];
      if (std::abs(f) <= kNoise * magnitude) return x;
    }
    x = next;
    if (hi - lo <= 4e-16 * std::max(std::abs(lo), std::abs(hi))) break;
  }
  return x;
}

// 2^ceil(log2(v) / k) for v > 0 and k >= 2, an upper bound on v^(1/k) within a factor of 2,
// from the bits of v: pow, frexp and ldexp calls cost more than the rest of the bound.
double root_power_bound(double v, int k) {
  uint64_t bits;
  std::memcpy(&bits, &v, sizeof bits);
  // v < 2^exponent (frexp's exponent); subnormals are below 2^-1022.
  const int exponent = std::max(1, static_cast<int>((bits >> 52) & 0x7ff)) - 1022;
  const int e = exponent >= 0 ? (exponent + k - 1) / k : -((-exponent) / k);  // in [-511, 513]
  bits = static_cast<uint64_t>(e + 1023) << 52;
  double r;
  std::memcpy(&r, &bits, sizeof r);
  return r;
}

// Fujiwara's bound on the magnitude of the roots of a monic polynomial, each k-th root rounded
// up to a power of two: at most one more bisection than the exact bound, without pow calls.
double root_bound(const double* monic, int degree) {
  double bound = std::abs(monic[degree - 1]);
  for (int k = 2; k < degree; ++k) {
    const double v = std::abs(monic[degree - k]);
    if (v > 0.0) bound = std::max(bound, root_power_bound(v, k));
  }
  const double v = 0.5 * std::abs(monic[0]);
  if (v > 0.0) bound = std::max(bound, root_power_bound(v, degree));
  return 2.0 * bound * (1.0 + 1e-12) + 1e-300;
}

// Largest real root of the monic cubic x^3 + e2 x^2 + e1 x + e0.
double largest_cubic_root(double e2, double e1, double e0) {
  constexpr double kThird = 1.0 / 3.0;
  const double P = e1 - e2 * e2 * kThird;
  const double Q = 2.0 * e2 * e2 * e2 * (kThird * kThird * kThird) - e2 * e1 * kThird + e0;
  const double D = 0.25 * Q * Q + P * P * P * (kThird * kThird * kThird);
  double t;
  if (D > 0.0) {
    const double u = std::cbrt(-0.5 * Q - std::copysign(std::sqrt(D), Q));
    t = u != 0.0 ? u - P * kThird / u : 0.0;
  } else {
    const double rho = std::sqrt(std::max(0.0, -P * kThird));
    const double cos_arg = rho > 0.0 ? std::clamp(-0.5 * Q / (rho * rho * rho), -1.0, 1.0) : 0.0;
    t = 2.0 * rho * std::cos(std::acos(cos_arg) * kThird);
  }
  double x = t - e2 * kThird;
  for (int i = 0; i < 2; ++i) {
    const double f = ((x + e2) * x + e1) * x + e0;
    const double df = (3.0 * x + 2.0 * e2) * x + e1;
    if (df == 0.0) break;
    x -= f / df;
  }
  return x;
}

// Real roots of y^2 + B y + C; a slightly negative discriminant (rounding) counts as zero.
int quadratic_roots(double B, double C, double* roots) {
  double disc = B * B - 4.0 * C;
  if (disc < 0.0) {
    if (disc < -1e-12 * (B * B + 4.0 * std::abs(C))) return 0;
    disc = 0.0;
  }
  const double q = -0.5 * (B + std::copysign(std::sqrt(disc), B));
  if (q == 0.0) {
    roots[0] = 0.0;  // B = C = 0
    return 1;
  }
  roots[0] = q;
  roots[1] = C / q;
  return 2;
}

// Isolates the distinct real roots of the monic polynomial in [-bound, bound] by bisection on
// the Sturm counts of `chain`, then polishes each; ascending. The chain's evaluation also gives
// p at each end of an interval, which decides whether p changes sign there.
template <int kFixed, typename Chain>
int isolate_and_polish_roots(const Chain& chain, const double* monic, int degree, double bound,
                             double* roots) {
  struct Interval {
    double lo, hi;
    int changes_lo, changes_hi;
    double f_lo, f_hi;
  };
  double abs_monic[kMax + 1];
  for (int i = 0; i <= degree; ++i) abs_monic[i] = std::abs(monic[i]);
  Interval stack[4 * kMax + 8];
  int top = 0;
  {
    double f_lo, f_hi;
    const int changes_lo = chain.sign_changes(-bound, &f_lo);
    const int changes_hi = chain.sign_changes(bound, &f_hi);
    stack[top++] = {-bound, bound, changes_lo, changes_hi, f_lo, f_hi};
  }
  int found = 0;
  int budget = 2000;  // bisections; only clusters of near-multiple roots come close.
  while (top > 0 && found < degree && budget-- > 0) {
    const Interval iv = stack[--top];
    const int count = iv.changes_lo - iv.changes_hi;
    if (count <= 0) continue;
    const double width = iv.hi - iv.lo;
    const double mid = 0.5 * (iv.lo + iv.hi);
    if (width <= 1e-14 * std::max(1.0, std::abs(mid))) {
      roots[found++] = mid;  // a multiple root, or roots closer than we can separate
      continue;
    }
    if (count == 1) {
      if (iv.f_lo == 0.0) {
        roots[found++] = iv.lo;
        continue;
      }
      if ((iv.f_lo > 0.0) != (iv.f_hi > 0.0)) {
        roots[found++] =
            polish_bracketed_root<kFixed>(monic, abs_monic, degree, iv.lo, iv.hi, iv.f_lo);
        continue;
      }
      // No sign change: an even-multiplicity root; keep bisecting on the Sturm counts.
    }
    double f_mid;
    const int changes_mid = chain.sign_changes(mid, &f_mid);
    // Upper half first so that the lower half is popped first and roots come out ascending.
    if (changes_mid - iv.changes_hi > 0 && top < 4 * kMax + 8)
      stack[top++] = {mid, iv.hi, changes_mid, iv.changes_hi, f_mid, iv.f_hi};
    if (iv.changes_lo - changes_mid > 0 && top < 4 * kMax + 8)
      stack[top++] = {iv.lo, mid, iv.changes_lo, changes_mid, iv.f_lo, f_mid};
  }
  std::sort(roots, roots + found);
  return found;
}

}  // namespace

int real_roots_quartic(const double* c, double* roots) {
  // A non-finite coefficient makes the sum non-finite (or it overflows near 1e308).
  if (!std::isfinite(c[0] + c[1] + c[2] + c[3] + c[4])) return 0;
  const double scale = std::max(std::max(std::max(std::abs(c[0]), std::abs(c[1])),
                                         std::max(std::abs(c[2]), std::abs(c[3]))),
                                std::abs(c[4]));
  // A leading coefficient below 1e-3 of the largest means a root beyond ~1e3 times the others:
  // dividing by it, Ferrari's resolvent loses the small roots' digits and turns close pairs
  // complex (most 3-0-1 failures on random instances, where tan(phi / 2) ~ 1e4 is common).
  // The Sturm path keeps them: with a threshold of 1e-8, 3-0-1 failed on 53 of 1M instances,
  // with 1e-3 on 3 (with 1e-2 on 1, for 7 % more instructions).
  if (!(std::abs(c[4]) > 1e-3 * scale)) return real_roots(c, 4, roots);
  const double inv = 1.0 / c[4];
  const double a = c[3] * inv, b = c[2] * inv, cc = c[1] * inv, d = c[0] * inv;
  // x = y - a/4 gives y^4 + p y^2 + q y + r.
  const double a2 = a * a;
  const double p = b - 3.0 * a2 / 8.0;
  const double q = cc - 0.5 * a * b + a2 * a / 8.0;
  const double r = d - 0.25 * a * cc + a2 * b / 16.0 - 3.0 * a2 * a2 / 256.0;
  // (y^2 + p/2 + m)^2 = 2m y^2 - q y + m^2 + m p + p^2/4 - r, a square when m solves the resolvent.
  const double m = largest_cubic_root(p, 0.25 * p * p - r, -q * q / 8.0);
  double ys[4];
  int n = 0;
  if (m > 1e-14 * (std::abs(p) + std::sqrt(std::abs(r)) + 1e-300)) {
    const double s = std::sqrt(2.0 * m);
    const double k = 0.5 * q / s;
    n += quadratic_roots(-s, 0.5 * p + m + k, ys + n);
    n += quadratic_roots(s, 0.5 * p + m - k, ys + n);
  } else {
    // q = 0: biquadratic in y^2.
    double zs[2];
    const int nz = quadratic_roots(p, r, zs);
    for (int i = 0; i < nz; ++i) {
      if (zs[i] < 0.0) continue;
      ys[n++] = std::sqrt(zs[i]);
      ys[n++] = -std::sqrt(zs[i]);
    }
  }
  // Newton steps on each root until a step falls below 1e-12 (1 + |x|), when the error left is
  // of the order of its square: most roots need one or two, and a near-double root, where Newton
  // converges only linearly, up to 16. Three fixed steps for every root, as before, cost more
  // and left twice the 3-0-1 failures.
  for (int i = 0; i < n; ++i) {
    double x = ys[i] - 0.25 * a;
    for (int iter = 0; iter < 16; ++iter) {
      const double f = (((x + a) * x + b) * x + cc) * x + d;
      const double df = ((4.0 * x + 3.0 * a) * x + 2.0 * b) * x + cc;
      if (df == 0.0) break;
      const double step = f / df;
      x -= step;
      if (std::abs(step) <= 1e-12 * (1.0 + std::abs(x))) break;
    }
    roots[i] = x;
  }
  for (int i = 1; i < n; ++i)  // insertion sort of at most four
    for (int j = i; j > 0 && roots[j] < roots[j - 1]; --j) std::swap(roots[j], roots[j - 1]);
  return n;
}

double evaluate_polynomial(const double* c, int degree, double x) {
  double v = c[degree];
  for (int i = degree - 1; i >= 0; --i) v = v * x + c[i];
  return v;
}

int real_roots(const double* c, int degree, double* roots) {
  if (degree > kMax) return 0;
  for (int i = 0; i <= degree; ++i)
    if (!std::isfinite(c[i])) return 0;
  while (degree > 0 && c[degree] == 0.0) --degree;
  if (degree <= 0) return 0;
  double monic[kMax + 1];
  for (int i = 0; i <= degree; ++i) monic[i] = c[i] / c[degree];
  if (degree == 1) {
    roots[0] = -monic[0];
    return 1;
  }

  const double bound = root_bound(monic, degree);
  if (degree == kMax) {  // the 5-point solver's degree, unrolled
    ThreeTermSturmChain<kMax> generic;
    if (generic.build(monic, degree))
      return isolate_and_polish_roots<kMax>(generic, monic, degree, bound, roots);
  } else {
    ThreeTermSturmChain<0> generic;
    if (generic.build(monic, degree))
      return isolate_and_polish_roots<0>(generic, monic, degree, bound, roots);
  }
  return isolate_and_polish_roots<0>(SturmChain(monic, degree), monic, degree, bound, roots);
}

}  // namespace hybrid_vo
