#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "hybrid_vo/solvers/polynomial.h"

namespace hybrid_vo {
namespace {

// Coefficients (ascending) of scale * prod (x - r_i) * (x^2 + 1)^pairs.
std::vector<double> from_roots(const std::vector<double>& roots, int complex_pairs, double scale) {
  std::vector<double> c = {scale};
  auto multiply = [&c](const std::vector<double>& f) {
    std::vector<double> r(c.size() + f.size() - 1, 0.0);
    for (size_t i = 0; i < c.size(); ++i)
      for (size_t j = 0; j < f.size(); ++j) r[i + j] += c[i] * f[j];
    c = r;
  };
  for (double root : roots) multiply({-root, 1.0});
  for (int k = 0; k < complex_pairs; ++k) multiply({1.0, 0.0, 1.0});
  return c;
}

TEST(RealRoots, RecoversRandomSimpleRoots) {
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> root(-5.0, 5.0);
  for (int degree = 1; degree <= kMaxPolynomialDegree; ++degree) {
    for (int trial = 0; trial < 200; ++trial) {
      const int pairs = (trial % 3 == 0) ? degree / 2 / 2 : 0;
      std::vector<double> expected(degree - 2 * pairs);
      for (double& r : expected) r = root(rng);
      std::sort(expected.begin(), expected.end());
      // Clustered roots are ill-conditioned in the coefficients themselves; keep them apart.
      bool separated = true;
      for (size_t i = 1; i < expected.size(); ++i)
        separated = separated && expected[i] - expected[i - 1] > 0.05;
      if (!separated) continue;
      const std::vector<double> c = from_roots(expected, pairs, -3.7);
      double roots[kMaxPolynomialDegree];
      const int n = real_roots(c.data(), degree, roots);
      ASSERT_EQ(n, static_cast<int>(expected.size())) << "degree " << degree;
      for (int i = 0; i < n; ++i) {
        EXPECT_NEAR(roots[i], expected[i], 1e-6) << "degree " << degree;
        // Backward error: the residual relative to the size of the terms.
        double terms = 0.0;
        for (int k = 0; k <= degree; ++k) terms += std::abs(c[k] * std::pow(roots[i], k));
        EXPECT_LT(std::abs(evaluate_polynomial(c.data(), degree, roots[i])), 1e-13 * terms);
      }
    }
  }
}

TEST(RealRoots, ResultsAreAscendingAndAccurate) {
  const std::vector<double> c = from_roots({-1e-3, 2.0, 1e3}, 1, 1.0);
  double roots[kMaxPolynomialDegree];
  ASSERT_EQ(real_roots(c.data(), 5, roots), 3);
  EXPECT_NEAR(roots[0], -1e-3, 1e-15);
  EXPECT_NEAR(roots[1], 2.0, 1e-12);
  EXPECT_NEAR(roots[2], 1e3, 1e-9);
}

TEST(RealRoots, NoRealRoots) {
  const std::vector<double> c = from_roots({}, 2, 2.0);
  double roots[kMaxPolynomialDegree];
  EXPECT_EQ(real_roots(c.data(), 4, roots), 0);
}

TEST(RealRoots, DoubleRootReportedOnce) {
  const std::vector<double> c = from_roots({1.5, 1.5, -2.0}, 0, 1.0);
  double roots[kMaxPolynomialDegree];
  const int n = real_roots(c.data(), 3, roots);
  ASSERT_EQ(n, 2);
  EXPECT_NEAR(roots[0], -2.0, 1e-10);
  EXPECT_NEAR(roots[1], 1.5, 1e-6);
}

// x^4 + x = x (x + 1) (x^2 - x + 1): dividing p by p' = 4 x^3 + 1 leaves 3x/4, a remainder two
// degrees lower, so the fast three-term chain gives way to the general one.
TEST(RealRoots, SturmChainWithADegreeDrop) {
  const double c[5] = {0.0, 1.0, 0.0, 0.0, 1.0};
  double roots[4];
  ASSERT_EQ(real_roots(c, 4, roots), 2);
  EXPECT_NEAR(roots[0], -1.0, 1e-14);
  EXPECT_NEAR(roots[1], 0.0, 1e-14);
}

TEST(RealRoots, LeadingZerosLowerTheDegree) {
  const double c[5] = {-2.0, 1.0, 0.0, 0.0, 0.0};  // x - 2
  double roots[4];
  ASSERT_EQ(real_roots(c, 4, roots), 1);
  EXPECT_DOUBLE_EQ(roots[0], 2.0);
}

TEST(RealRoots, DegenerateInputs) {
  double roots[kMaxPolynomialDegree];
  const double zero[3] = {0.0, 0.0, 0.0};
  EXPECT_EQ(real_roots(zero, 2, roots), 0);
  const double constant[1] = {4.0};
  EXPECT_EQ(real_roots(constant, 0, roots), 0);
  const double with_nan[3] = {1.0, NAN, 1.0};
  EXPECT_EQ(real_roots(with_nan, 2, roots), 0);
  const double with_inf[3] = {1.0, INFINITY, 1.0};
  EXPECT_EQ(real_roots(with_inf, 2, roots), 0);
  const double too_high[12] = {1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1};
  EXPECT_EQ(real_roots(too_high, 11, roots), 0);
}

TEST(RealRootsQuartic, AgreesWithRootsAndSturm) {
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> root(-5.0, 5.0);
  for (int trial = 0; trial < 2000; ++trial) {
    const int pairs = trial % 3;  // 4, 2 or 0 real roots
    std::vector<double> expected(4 - 2 * pairs);
    for (double& r : expected) r = root(rng);
    std::sort(expected.begin(), expected.end());
    bool separated = true;
    for (size_t i = 1; i < expected.size(); ++i)
      separated = separated && expected[i] - expected[i - 1] > 1e-3;
    if (!separated) continue;
    const std::vector<double> c = from_roots(expected, pairs, 0.7);
    double roots[4], sturm[4];
    const int n = real_roots_quartic(c.data(), roots);
    ASSERT_EQ(n, static_cast<int>(expected.size()));
    ASSERT_EQ(real_roots(c.data(), 4, sturm), n);
    for (int i = 0; i < n; ++i) {
      EXPECT_NEAR(roots[i], expected[i], 1e-9);
      EXPECT_NEAR(roots[i], sturm[i], 1e-9);
    }
  }
  const double biquadratic[5] = {4.0, 0.0, -5.0, 0.0, 1.0};  // roots +-1, +-2
  double roots[4];
  ASSERT_EQ(real_roots_quartic(biquadratic, roots), 4);
  EXPECT_NEAR(roots[0], -2.0, 1e-14);
  EXPECT_NEAR(roots[3], 2.0, 1e-14);
  const double cubic_in_disguise[5] = {-6.0, 11.0, -6.0, 1.0, 0.0};  // roots 1, 2, 3
  ASSERT_EQ(real_roots_quartic(cubic_in_disguise, roots), 3);
  EXPECT_NEAR(roots[1], 2.0, 1e-12);
  const double with_nan[5] = {1.0, NAN, 0.0, 0.0, 1.0};
  EXPECT_EQ(real_roots_quartic(with_nan, roots), 0);
}

TEST(EvaluatePolynomial, Horner) {
  const double c[3] = {1.0, -2.0, 3.0};
  EXPECT_DOUBLE_EQ(evaluate_polynomial(c, 2, 2.0), 9.0);
}

}  // namespace
}  // namespace hybrid_vo
