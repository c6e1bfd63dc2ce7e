// Quantiles of the standard normal and χ² distributions without heap or tables, for the
// filter's innovation gates and the standstill detector's threshold (docs/math.md, "Aided
// navigation: the error-state filter").
//
//   normal_quantile: Acklam's rational approximation (relative error < 1.2e-9 in double; in
//     float the rounding of the terms, ~1e-6, dominates).
//   chi_square_quantile(p, k):
//     k = 1: exact, z²  with z = Φ⁻¹((1 + p)/2);
//     k = 2: exact, −2 ln(1 − p) (the χ²(2) law is exponential);
//     k ≥ 3: Wilson–Hilferty, k (1 − 2/(9k) + z_p √(2/(9k)))³. Its relative error falls with k:
//       about +1.8 % at k = 3, p = 0.999 (16.55 for 16.266: a slightly wider gate), below 0.1 %
//       for k ≥ 30 at p ≤ 0.999, and below 0.01 % for the detector's 6W − 3 ≥ 100
//       (tests/nav_core/chi_square_test.cpp checks tabulated values).
//   chi_square_upper_quantile(α, k): the x with P(χ²_k > x) = α, from the exact survival function
//     (chi_square_survival, below) by bisection for k ≤ 200: for the tiny tail probabilities of a
//     detector with a stated false-alarm rate per hour (α ~ 1e-7 per decision), where 1 − α is not
//     representable in float and Wilson–Hilferty is several percent off at small k; above 200,
//     Wilson–Hilferty written for the upper tail (no 1 − α).
#pragma once

#include <cmath>
#include <limits>

namespace gfins::nav {

/// Φ⁻¹(p), the standard normal quantile, for 0 < p < 1 (NaN outside).
template <typename T>
T normal_quantile(T p) {
  if (!(p > T(0) && p < T(1))) return std::numeric_limits<T>::quiet_NaN();
  // Acklam (2003): central region |p − 0.5| ≤ 0.475 rational in q = p − 0.5, tails in √(−2 ln p).
  constexpr T a[] = {T(-3.969683028665376e+01), T(2.209460984245205e+02),
                     T(-2.759285104469687e+02), T(1.383577518672690e+02),
                     T(-3.066479806614716e+01), T(2.506628277459239e+00)};
  constexpr T b[] = {T(-5.447609879822406e+01), T(1.615858368580409e+02), T(-1.556989798598866e+02),
                     T(6.680131188771972e+01), T(-1.328068155288572e+01)};
  constexpr T c[] = {T(-7.784894002430293e-03), T(-3.223964580411365e-01),
                     T(-2.400758277161838e+00), T(-2.549732539343734e+00),
                     T(4.374664141464968e+00),  T(2.938163982698783e+00)};
  constexpr T d[] = {T(7.784695709041462e-03), T(3.224671290700398e-01), T(2.445134137142996e+00),
                     T(3.754408661907416e+00)};
  constexpr T kLow = T(0.02425);
  if (p < kLow || p > T(1) - kLow) {
    const bool upper = p > T(0.5);
    const T q = std::sqrt(T(-2) * std::log(upper ? T(1) - p : p));
    const T x = (((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
                ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + T(1));
    return upper ? -x : x;
  }
  const T q = p - T(0.5);
  const T r = q * q;
  return (((((a[0] * r + a[1]) * r + a[2]) * r + a[3]) * r + a[4]) * r + a[5]) * q /
         (((((b[0] * r + b[1]) * r + b[2]) * r + b[3]) * r + b[4]) * r + T(1));
}

/// The p-quantile of χ² with k ≥ 1 degrees of freedom (0 < p < 1); NaN for bad arguments.
template <typename T>
T chi_square_quantile(T p, int k) {
  if (k < 1 || !(p > T(0) && p < T(1))) return std::numeric_limits<T>::quiet_NaN();
  if (k == 1) {
    const T z = normal_quantile((T(1) + p) / T(2));
    return z * z;
  }
  if (k == 2) return T(-2) * std::log(T(1) - p);
  const T kk = static_cast<T>(k);
  const T v = T(2) / (T(9) * kk);
  const T c = T(1) - v + normal_quantile(p) * std::sqrt(v);  // Wilson–Hilferty
  return kk * c * c * c;
}

/// P(χ²_k > x), exact, for 1 ≤ k ≤ 200 (NaN outside, 1 for x ≤ 0). Abramowitz & Stegun 26.4.4
/// and 26.4.5, in terms of y = x/2:
///   even k = 2m:     Q = Σ_{i<m} e^(−y) yⁱ/i!
///   odd k = 2m + 1:  Q = erfc(√y) + Σ_{i=1..m} e^(−y) y^(i−1/2) / (Γ(i + 1/2))
/// (every term positive: no cancellation, so the relative accuracy holds deep in the tail). Each
/// term is formed from its logarithm: e^(−y) underflows and y^i/i! overflows float long before
/// their product does (y ≈ 160 at k = 198 and α = 1e-7).
template <typename T>
T chi_square_survival(T x, int k) {
  if (k < 1 || k > 200 || std::isnan(x)) return std::numeric_limits<T>::quiet_NaN();
  if (!(x > T(0))) return T(1);
  const T y = x / T(2);
  const T log_y = std::log(y);
  T sum = T(0);
  if (k % 2 == 0) {
    T log_term = -y;  // i = 0
    for (int i = 0; i < k / 2; ++i) {
      sum += std::exp(log_term);
      log_term += log_y - std::log(static_cast<T>(i + 1));
    }
    return sum;
  }
  // i = 1: e^(−y) y^(1/2) / Γ(3/2), Γ(3/2) = √π / 2.
  T log_term = -y + log_y / T(2) - std::log(std::sqrt(T(3.14159265358979323846)) / T(2));
  for (int i = 1; i <= k / 2; ++i) {
    sum += std::exp(log_term);
    log_term += log_y - std::log(static_cast<T>(i) + T(0.5));
  }
  return std::erfc(std::sqrt(y)) + sum;
}

/// The x with P(χ²_k > x) = alpha (0 < alpha < 1, k ≥ 1; NaN otherwise). For k ≤ 200, bisection
/// on chi_square_survival to the resolution of T (a hundred survival evaluations: start-up use).
/// Above, Wilson–Hilferty in its upper-tail form, z = −Φ⁻¹(α), so that 1 − α never has to be
/// formed (it rounds to 1 in float for α < 3e-8); its x is slightly high there, the tail at x
/// up to 5 % below α (k = 201, α = 1.4e-7; tests/nav_core/chi_square_test.cpp): conservative.
template <typename T>
T chi_square_upper_quantile(T alpha, int k) {
  if (k < 1 || !(alpha > T(0) && alpha < T(1))) return std::numeric_limits<T>::quiet_NaN();
  if (k > 200) {
    const T kk = static_cast<T>(k);
    const T v = T(2) / (T(9) * kk);
    const T c = T(1) - v - normal_quantile(alpha) * std::sqrt(v);
    return kk * c * c * c;
  }
  T lo = T(0);
  T hi = static_cast<T>(k) + T(10);
  while (chi_square_survival(hi, k) > alpha) {
    lo = hi;
    hi *= T(2);
    if (!std::isfinite(hi)) return std::numeric_limits<T>::quiet_NaN();
  }
  for (int i = 0; i < 200; ++i) {
    const T mid = (lo + hi) / T(2);
    if (!(mid > lo && mid < hi)) break;  // converged to adjacent representable values
    (chi_square_survival(mid, k) > alpha ? lo : hi) = mid;
  }
  return (lo + hi) / T(2);
}

}  // namespace gfins::nav
