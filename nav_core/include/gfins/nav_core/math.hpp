// Fixed-size linear algebra vocabulary of the navigation core and the few rotation helpers the
// integrator needs. Everything is templated on the scalar: float on the target, double for the
// host reference (docs/architecture.md). No function here allocates.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <type_traits>

namespace gfins::nav {

template <typename T>
using Vec3 = Eigen::Matrix<T, 3, 1>;
template <typename T>
using Mat3 = Eigen::Matrix<T, 3, 3>;
template <typename T>
using Vec6 = Eigen::Matrix<T, 6, 1>;
template <typename T>
using Mat6 = Eigen::Matrix<T, 6, 6>;
template <typename T>
using Quat = Eigen::Quaternion<T>;

/// `rows` rounded up to whole SIMD packets of T: 4 for three floats with SSE (packets of 4), 4 for
/// three doubles (packets of 2), `rows` itself without SIMD (Cortex-M4F). The per-sample products
/// keep their matrices with zero rows up to this count, so that Eigen evaluates every column as
/// whole packets instead of one packet plus scalar leftovers (docs/performance.md).
template <typename T>
constexpr int padded_rows(int rows) {
  constexpr int kPacket = Eigen::internal::packet_traits<T>::size;
  return (rows + kPacket - 1) / kPacket * kPacket;
}

/// A 64-bit integer (a time in nanoseconds, a difference of two) as T, rounded to nearest as
/// static_cast<T> rounds. For float, with 32-bit conversions only: the Cortex-M4F's FPU converts
/// 32-bit integers (VCVT), while static_cast<float>(int64) calls libgcc's soft-float __aeabi_l2f,
/// which drags 668 bytes of soft-float add and subtract into the flash image. Magnitudes from
/// 2^31 on are shifted right into 31 bits with every bit shifted out ORed into the lowest one (a
/// sticky bit): 31 significant bits are more than float's 24 + 2 that round-to-nearest needs to
/// round the shorter number exactly as the full one, and the power-of-two scale back is exact.
template <typename T>
constexpr T from_int64(std::int64_t v) {
  if constexpr (!std::is_same_v<T, float>) {
    return static_cast<T>(v);
  } else {
    if (v >= -2147483647 && v <= 2147483647)
      return static_cast<float>(static_cast<std::int32_t>(v));
    const bool negative = v < 0;
    // |v| as unsigned: well defined for INT64_MIN too (two's complement negation modulo 2^64).
    std::uint64_t m =
        negative ? ~static_cast<std::uint64_t>(v) + 1u : static_cast<std::uint64_t>(v);
    float scale = 1.0f;
    while (m > 0x7FFFFFFFu) {
      m = (m >> 1) | (m & 1u);  // the sticky bit keeps "something was shifted out"
      scale *= 2.0f;
    }
    const float f = static_cast<float>(static_cast<std::int32_t>(m)) * scale;
    return negative ? -f : f;
  }
}

/// An array of N zero vectors. Eigen leaves fixed-size matrices uninitialised even when
/// value-initialised (`std::array<Vec3, N> a{}` holds garbage), so members are defaulted with this.
template <typename T, std::size_t N>
std::array<Vec3<T>, N> zero_vectors() {
  std::array<Vec3<T>, N> a;
  a.fill(Vec3<T>::Zero());
  return a;
}

/// Standard gravity, the "g" of the accelerometer scale factors in V/g (paper Table 6).
inline constexpr double kStandardGravity = 9.80665;

/// [v×]: the matrix with skew(v) * w == v.cross(w).
template <typename T>
Mat3<T> skew(const Vec3<T>& v) {
  Mat3<T> m;
  m << T(0), -v.z(), v.y(), v.z(), T(0), -v.x(), -v.y(), v.x(), T(0);
  return m;
}

/// sin x and cos x. float: reduced to [−π, π] by the nearest multiple of 2π, folded to
/// [0, π/2] by the symmetries, and Taylor polynomials there to x¹³ and x¹⁴ (truncation below
/// 7e-10, under float's rounding; within 3e-7 of the exact values for |x| ≤ 100, tested against
/// double's std::sin and std::cos). The core's angles are rotation angles and Euler angles, a few
/// π at most. newlib's sinf and cosf carry a range reduction for any float (its Payne-Hanek
/// table and kernel, 3.1 KB of the Cortex-M4F image's flash), needed only far outside them; from
/// 2^12 turns (25,736 rad) on, and for a non-finite x, both are NaN (not available, never a wrong
/// number).
/// double: std::sin and std::cos.
template <typename T>
void sin_cos(T x, T& s, T& c) {
  if constexpr (std::is_same_v<T, float>) {
    constexpr float kTwoPi = 6.28318530717958647692F;
    constexpr float kPi = 3.14159265358979323846F;
    constexpr float kHalfPi = 1.57079632679489661923F;
    // Two-constant reduction: 2π = kTwoPiHi + kTwoPiLo, kTwoPiHi = 201/32 with 8 significant
    // bits, so k·kTwoPiHi is exact for |k| < 2^16; kTwoPiLo's rounding times k stays below 3e-7
    // for |k| ≤ 2^12 (|x| < 25,736 rad), where the guard below stops.
    constexpr float kTwoPiHi = 6.28125F;
    constexpr float kTwoPiLo = 1.9353071795864769e-3F;
    if (!(std::fabs(x) < 25736.0F)) {  // 2^12 turns, or not finite: never a core angle
      s = std::numeric_limits<float>::quiet_NaN();
      c = s;
      return;
    }
    const float q = x * (1.0F / kTwoPi);
    const auto k = static_cast<float>(static_cast<std::int32_t>(q + (q < 0.0F ? -0.5F : 0.5F)));
    float y = (x - k * kTwoPiHi) - k * kTwoPiLo;  // [−π, π] (a rounding beyond at the ends)
    const float sign_s = y < 0.0F ? -1.0F : 1.0F;
    y = std::fabs(y);
    float sign_c = 1.0F;
    if (y > kHalfPi) {  // sin(π − y) = sin y, cos(π − y) = −cos y
      y = kPi - y;
      sign_c = -1.0F;
    }
    const float z = y * y;
    const float sp =
        y * (1.0F + z * (-1.0F / 6.0F +
                         z * (1.0F / 120.0F +
                              z * (-1.0F / 5040.0F +
                                   z * (1.0F / 362880.0F +
                                        z * (-1.0F / 39916800.0F + z * (1.0F / 6227020800.0F)))))));
    const float cp =
        1.0F +
        z * (-0.5F + z * (1.0F / 24.0F +
                          z * (-1.0F / 720.0F +
                               z * (1.0F / 40320.0F + z * (-1.0F / 3628800.0F +
                                                           z * (1.0F / 479001600.0F +
                                                                z * (-1.0F / 87178291200.0F)))))));
    s = sign_s * sp;
    c = sign_c * cp;
  } else {
    s = std::sin(x);
    c = std::cos(x);
  }
}

/// cos(|phi|/2) and sin(|phi|/2)/|phi| from a2 = |phi|² (rad²), the two factors of
/// exp(phi/2) = (c, s·phi). Below |phi| = 0.1 rad a Taylor series is used; its truncation error
/// (|phi|^6/46080 in the scalar part) is below the float and double rounding of the terms kept,
/// and it avoids sin/cos on the per-sample path (a 1 kHz step rotates by far less than 0.1 rad
/// for any rate below 100 rad/s).
template <typename T>
void half_angle_factors(T a2, T& c, T& s) {
  if (a2 < T(0.01)) {
    // Horner form, constant reciprocals: cos y = 1 − y²/2 + y⁴/24 − y⁶/720 and
    // sin(y)/(2y) = 1/2 − y²/12 + y⁴/240 − y⁶/10080 with y = |phi|/2 (no division per sample).
    const T x = a2 * T(0.25);  // y² = (|phi|/2)²
    c = T(1) + x * (T(-0.5) + x * (T(1) / T(24) - x * (T(1) / T(720))));
    s = T(0.5) + x * (T(-1) / T(12) + x * (T(1) / T(240) - x * (T(1) / T(10080))));
  } else {
    const T a = std::sqrt(a2);
    sin_cos(a / T(2), s, c);
    s /= a;
  }
}

/// Quaternion of the rotation vector `phi` (rad): exp(phi/2) (half_angle_factors).
template <typename T>
Quat<T> quat_from_rotation_vector(const Vec3<T>& phi) {
  T c;
  T s;
  half_angle_factors(phi.squaredNorm(), c, s);
  return Quat<T>(c, s * phi.x(), s * phi.y(), s * phi.z());
}

/// a × b of 3-vectors, plain (P = 3) or padded to four lanes (P = 4, lane 3 ignored on input and
/// zero on output for finite inputs): Eigen's SIMD cross3, the same products and differences
/// per lane as cross().
template <typename T, int P>
Eigen::Matrix<T, P, 1> cross_padded(const Eigen::Matrix<T, P, 1>& a,
                                    const Eigen::Matrix<T, P, 1>& b) {
  static_assert(P == 3 || P == 4, "a 3-vector, padded or not");
  if constexpr (P == 4) {
    return a.cross3(b);
  } else {
    return a.cross(b);
  }
}

/// quat_from_rotation_vector for a padded 3-vector (lane 3, if any, zero): same arithmetic.
template <typename T, int P>
Quat<T> quat_from_rotation_vector_padded(const Eigen::Matrix<T, P, 1>& phi) {
  T c;
  T s;
  half_angle_factors(phi.template head<3>().squaredNorm(), c, s);
  if constexpr (P == 4) {
    Eigen::Matrix<T, 4, 1> xyzw = s * phi;  // Eigen's coefficient order: x, y, z, w
    xyzw(3) = c;
    return Quat<T>(xyzw);
  } else {
    return Quat<T>(c, s * phi(0), s * phi(1), s * phi(2));
  }
}

/// q v q* for a padded 3-vector v (lane 3 zero): Eigen's QuaternionBase::_transformVector,
/// v + 2w (q_v × v) + q_v × (2 q_v × v), written on packets.
template <typename T, int P>
Eigen::Matrix<T, P, 1> rotate_padded(const Quat<T>& q, const Eigen::Matrix<T, P, 1>& v) {
  Eigen::Matrix<T, P, 1> qv;
  if constexpr (P == 4) {
    qv = q.coeffs();  // x, y, z and w in lane 3, which cross3 ignores
  } else {
    qv = q.vec();
  }
  Eigen::Matrix<T, P, 1> uv = cross_padded(qv, v);
  uv += uv;
  return v + q.w() * uv + cross_padded(qv, uv);
}

/// Rotation vector of a unit quaternion (inverse of quat_from_rotation_vector), with the
/// rotation angle folded into [0, pi].
template <typename T>
Vec3<T> rotation_vector_from_quat(const Quat<T>& q_in) {
  Quat<T> q = q_in;
  if (q.w() < T(0)) q.coeffs() = -q.coeffs();
  const T sn = q.vec().norm();
  if (sn < T(1e-6)) return T(2) * q.vec() / q.w();  // angle/sin(angle/2) -> 2/w
  const T angle = T(2) * std::atan2(sn, q.w());
  return (angle / sn) * q.vec();
}

/// Roll, pitch, yaw (rad, aerospace Z-Y-X sequence) of the body-to-navigation rotation q_nb.
template <typename T>
Vec3<T> euler_from_quat(const Quat<T>& q_nb) {
  const Mat3<T> c = q_nb.toRotationMatrix();
  const T sp = std::clamp(-c(2, 0), T(-1), T(1));
  return Vec3<T>(std::atan2(c(2, 1), c(2, 2)), std::asin(sp), std::atan2(c(1, 0), c(0, 0)));
}

/// q_nb of roll, pitch, yaw (rad, Z-Y-X sequence).
template <typename T>
Quat<T> quat_from_euler(T roll, T pitch, T yaw) {
  // q_z(ψ) ⊗ q_y(θ) ⊗ q_x(φ) written out, half angles through sin_cos.
  T sr;
  T cr;
  T sp;
  T cp;
  T sy;
  T cy;
  sin_cos(roll / T(2), sr, cr);
  sin_cos(pitch / T(2), sp, cp);
  sin_cos(yaw / T(2), sy, cy);
  return Quat<T>(cr * cp * cy + sr * sp * sy, sr * cp * cy - cr * sp * sy,
                 cr * sp * cy + sr * cp * sy, cr * cp * sy - sr * sp * cy);
}

}  // namespace gfins::nav
