// A second-order forward-mode Taylor "jet": a scalar carried with its first and second
// derivatives with respect to one variable (here always time t).
//
// Why: the simulator's truth must be analytic, not finite-differenced. Each trajectory is written
// once as a function of time over Jet<double>; evaluating it at the jet (t, 1, 0) gives the value,
// the first and the second time derivative of every quantity, each exact up to floating-point
// rounding (no truncation error, no step to choose). Velocity and acceleration are then the d1 and
// d2 parts of the position, and the body rate and its derivative follow from q, q̇, q̈ (see
// trajectory.hpp).
//
// Rules implemented (x = a function of t, primes are d/dt):
//   (a ± b)'' = a'' ± b''
//   (a b)'    = a' b + a b'              (a b)'' = a'' b + 2 a' b' + a b''
//   q = a / b: q' = (a' − q b') / b      q''   = (a'' − 2 q' b' − q b'') / b
//   f(x):      f(x)' = f'(x) x'          f(x)'' = f''(x) x'² + f'(x) x''   (chain rule)
// with f = sin, cos, sqrt, exp. Division by a jet whose value is zero and sqrt of a jet whose value
// is zero give inf/nan in the derivatives, like the plain functions would (sqrt'(0) is infinite).
#pragma once

#include <cmath>

namespace gfins::sim {

/// value, d/dt and d²/dt² of one scalar function of time.
template <typename T>
struct Jet {
  T val = T(0);
  T d1 = T(0);  // first derivative
  T d2 = T(0);  // second derivative

  constexpr Jet() = default;
  /// A constant (both derivatives zero). Implicit so that `2.0 * t` and `t + 1.0` read naturally.
  constexpr Jet(T value) : val(value) {}  // NOLINT(google-explicit-constructor)
  constexpr Jet(T value, T first, T second) : val(value), d1(first), d2(second) {}

  /// The independent variable itself at `value`: (value, 1, 0).
  static constexpr Jet variable(T value) { return Jet(value, T(1), T(0)); }

  constexpr Jet operator-() const { return Jet(-val, -d1, -d2); }
  constexpr Jet& operator+=(const Jet& b) {
    val += b.val;
    d1 += b.d1;
    d2 += b.d2;
    return *this;
  }
  constexpr Jet& operator-=(const Jet& b) {
    val -= b.val;
    d1 -= b.d1;
    d2 -= b.d2;
    return *this;
  }
  constexpr Jet& operator*=(const Jet& b) { return *this = *this * b; }
  constexpr Jet& operator/=(const Jet& b) { return *this = *this / b; }

  friend constexpr Jet operator+(Jet a, const Jet& b) { return a += b; }
  friend constexpr Jet operator-(Jet a, const Jet& b) { return a -= b; }
  friend constexpr Jet operator*(const Jet& a, const Jet& b) {
    return Jet(a.val * b.val, a.d1 * b.val + a.val * b.d1,
               a.d2 * b.val + T(2) * a.d1 * b.d1 + a.val * b.d2);
  }
  friend constexpr Jet operator/(const Jet& a, const Jet& b) {
    const T q = a.val / b.val;
    const T q1 = (a.d1 - q * b.d1) / b.val;
    const T q2 = (a.d2 - T(2) * q1 * b.d1 - q * b.d2) / b.val;
    return Jet(q, q1, q2);
  }
  // Scalar-on-the-left and scalar-on-the-right forms without building a full jet product.
  friend constexpr Jet operator*(T s, const Jet& b) { return Jet(s * b.val, s * b.d1, s * b.d2); }
  friend constexpr Jet operator*(const Jet& a, T s) { return s * a; }
  friend constexpr Jet operator/(const Jet& a, T s) { return Jet(a.val / s, a.d1 / s, a.d2 / s); }
};

/// f(x) from f(x0), f'(x0), f''(x0) by the chain rule (see the file comment).
template <typename T>
constexpr Jet<T> chain(const Jet<T>& x, T f0, T f1, T f2) {
  return Jet<T>(f0, f1 * x.d1, f2 * x.d1 * x.d1 + f1 * x.d2);
}

template <typename T>
Jet<T> sin(const Jet<T>& x) {
  const T s = std::sin(x.val);
  return chain(x, s, std::cos(x.val), -s);
}

template <typename T>
Jet<T> cos(const Jet<T>& x) {
  const T c = std::cos(x.val);
  return chain(x, c, -std::sin(x.val), -c);
}

/// sin and cos of the same argument, sharing the two library calls.
template <typename T>
void sin_cos(const Jet<T>& x, Jet<T>& s_out, Jet<T>& c_out) {
  const T s = std::sin(x.val);
  const T c = std::cos(x.val);
  s_out = chain(x, s, c, -s);
  c_out = chain(x, c, -s, -c);
}

/// sqrt'(x) = 1/(2√x), sqrt''(x) = −1/(4 x√x). Domain x ≥ 0; derivatives are infinite at 0.
template <typename T>
Jet<T> sqrt(const Jet<T>& x) {
  const T r = std::sqrt(x.val);
  const T f1 = T(0.5) / r;
  return chain(x, r, f1, -f1 / (T(2) * x.val));
}

/// atan'(x) = 1/(1+x²), atan''(x) = −2x/(1+x²)².
template <typename T>
Jet<T> atan(const Jet<T>& x) {
  const T d = T(1) + x.val * x.val;
  return chain(x, std::atan(x.val), T(1) / d, T(-2) * x.val / (d * d));
}

template <typename T>
Jet<T> exp(const Jet<T>& x) {
  const T e = std::exp(x.val);
  return chain(x, e, e, e);
}

}  // namespace gfins::sim
