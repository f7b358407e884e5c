#pragma once

namespace hybrid_vo {

constexpr int kMaxPolynomialDegree = 10;

// Distinct real roots of c[0] + c[1] x + ... + c[degree] x^degree, ascending. Roots are isolated
// with a Sturm sequence inside the Fujiwara bound and polished by safeguarded Newton steps, so
// no companion-matrix eigenproblem is needed. Leading zeros lower the degree. Returns the count
// (at most `degree`, which must not exceed kMaxPolynomialDegree); 0 for non-finite input.
int real_roots(const double* c, int degree, double* roots);

// Real roots of c[0] + c[1] x + ... + c[4] x^4 in closed form (Ferrari, through the largest root
// of the resolvent cubic), each polished by Newton steps; ascending. Several times faster than
// the Sturm path. A (near-)double root may be reported twice or, when rounding makes it complex,
// not at all; callers that must see double roots use real_roots. A nearly vanishing leading
// coefficient falls back to real_roots.
int real_roots_quartic(const double* c, double* roots);

// Value of the polynomial at x (Horner).
double evaluate_polynomial(const double* c, int degree, double x);

}  // namespace hybrid_vo
