#pragma once
// Scalar polynomials in Bernstein form on a parameter interval, fixed capacity (no allocation).
// Used to isolate the roots of f(t) = (B(t)-P).B'(t) (Schneider, "Solving the Nearest-Point-on-
// Curve Problem", Graphics Gems 1990): by the variation-diminishing property a polynomial has at
// most as many roots in its interval as its coefficients have sign changes, and exactly one root
// when they have exactly one.
#include <array>
#include <cmath>

#include "calligraphy/model/element.hpp"

namespace calligraphy::detail {

/// Degree of f for the highest element degree: 2n - 1.
inline constexpr int kMaxBernsteinDegree = 2 * kMaxElementDegree - 1;

/// Binomial coefficients C(n, k) for n, k <= kMaxBernsteinDegree, computed at compile time (a
/// run-time loop of divisions would dominate the evaluation).
inline constexpr auto kBinomial = [] {
  std::array<std::array<double, kMaxBernsteinDegree + 1>, kMaxBernsteinDegree + 1> table{};
  for (std::size_t n = 0; n < table.size(); ++n) {
    table[n][0] = 1.0;
    for (std::size_t k = 1; k <= n; ++k) table[n][k] = table[n - 1][k - 1] + (k < n ? table[n - 1][k] : 0.0);
  }
  return table;
}();

/// C(n, k), 0 <= k <= n <= kMaxBernsteinDegree.
constexpr double binomial(int n, int k) {
  return kBinomial[static_cast<std::size_t>(n)][static_cast<std::size_t>(k)];
}

/// Plain aggregate without default member initializers, so that the root isolation's fixed stack
/// of them is not zero-filled on every query; write `BernsteinPolynomial f{}` for a zero polynomial.
struct BernsteinPolynomial {
  int degree;
  std::array<double, kMaxBernsteinDegree + 1> c;  ///< first degree+1 entries used
};

/// Number of sign changes in the coefficient sequence; coefficients of magnitude <= `noise` count
/// as zero and are skipped (rounding must not make or hide a sign change next to a root at an end).
inline int sign_variations(const BernsteinPolynomial& f, double noise) noexcept {
  int variations = 0;
  int previous_sign = 0;
  for (int i = 0; i <= f.degree; ++i) {
    const double value = f.c[static_cast<std::size_t>(i)];
    const int sign = (value > noise) - (value < -noise);
    if (sign == 0) continue;
    if (previous_sign != 0 && sign != previous_sign) ++variations;
    previous_sign = sign;
  }
  return variations;
}

/// True when every coefficient has magnitude <= `noise`: f is zero over the interval within rounding.
inline bool negligible(const BernsteinPolynomial& f, double noise) noexcept {
  for (int i = 0; i <= f.degree; ++i) {
    if (std::abs(f.c[static_cast<std::size_t>(i)]) > noise) return false;
  }
  return true;
}

/// De Casteljau split at the middle of the interval: `left` and `right` represent f on the two halves.
inline void split_at_middle(const BernsteinPolynomial& f, BernsteinPolynomial& left,
                            BernsteinPolynomial& right) noexcept {
  std::array<double, kMaxBernsteinDegree + 1> r = f.c;
  const int n = f.degree;
  left.degree = n;
  right.degree = n;
  left.c[0] = r[0];
  right.c[static_cast<std::size_t>(n)] = r[static_cast<std::size_t>(n)];
  for (int level = 1; level <= n; ++level) {
    for (int i = 0; i <= n - level; ++i) {
      const auto index = static_cast<std::size_t>(i);
      r[index] = 0.5 * (r[index] + r[index + 1]);
    }
    left.c[static_cast<std::size_t>(level)] = r[0];
    right.c[static_cast<std::size_t>(n - level)] = r[static_cast<std::size_t>(n - level)];
  }
}

struct ValueAndSlope {
  double value = 0.0;
  double slope = 0.0;  ///< derivative with respect to the interval's own parameter u in [0, 1]
};

/// f(u) and f'(u) at u in [0, 1] of the polynomial's interval. Horner's rule in s = u / (1 - u)
/// (in (1 - u) / u past the middle, so that s <= 1): O(degree) operations instead of the O(degree^2)
/// of de Casteljau, with a comparable rounding error.
inline ValueAndSlope evaluate(const BernsteinPolynomial& f, double u) noexcept {
  const int n = f.degree;
  if (n == 0) return {f.c[0], 0.0};
  const bool reversed = u > 0.5;
  const double s = reversed ? (1.0 - u) / u : u / (1.0 - u);
  const double w = reversed ? u : 1.0 - u;
  auto coefficient = [&](int i) { return f.c[static_cast<std::size_t>(reversed ? n - i : i)]; };
  double value = coefficient(n);
  double slope = coefficient(n) - coefficient(n - 1);
  for (int i = n - 1; i >= 0; --i) {
    value = value * s + binomial(n, i) * coefficient(i);
    if (i < n - 1) slope = slope * s + binomial(n - 1, i) * (coefficient(i + 1) - coefficient(i));
  }
  double w_power = 1.0;  // w^(n-1)
  for (int i = 1; i < n; ++i) w_power *= w;
  value *= w_power * w;
  slope *= n * w_power;
  return {value, reversed ? -slope : slope};
}

}  // namespace calligraphy::detail
