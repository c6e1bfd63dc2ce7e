// Gravity in the navigation frame of docs/architecture.md: local-level North-East-Down axes fixed
// at the alignment point and treated as inertial (Earth rate neglected, as in the paper), so
// gravity points along +z (down). Two models: a constant magnitude, or WGS-84 normal gravity at the
// alignment latitude with its free-air variation along the height.
#pragma once

#include <cmath>

#include "gfins/nav_core/math.hpp"

namespace gfins::nav {

enum class GravityKind : unsigned char { kConstant, kNormal };

template <typename T>
class GravityModel {
 public:
  /// Constant gravity of magnitude g_mps2 along +z (down).
  static GravityModel constant(T g_mps2) {
    GravityModel m;
    m.kind_ = GravityKind::kConstant;
    m.g0_ = g_mps2;
    m.dg_dh_ = T(0);
    return m;
  }

  /// WGS-84 normal gravity (Somigliana) at geodetic latitude lat_rad and ellipsoidal height h0_m
  /// of the alignment point; the height of a navigation position is h0 − r_n.z (NED). The
  /// free-air gradient is evaluated at h0 (second-order term dropped: < 1e-6 m/s² for
  /// |h − h0| < 10 km).
  static GravityModel normal(double lat_rad, double h0_m) {
    constexpr double kGammaE = 9.7803253359;    // normal gravity at the equator, m/s²
    constexpr double kK = 0.00193185265241;     // Somigliana constant
    constexpr double kE2 = 0.00669437999013;    // first eccentricity squared
    constexpr double kA = 6378137.0;            // semi-major axis, m
    constexpr double kF = 1.0 / 298.257223563;  // flattening
    constexpr double kM = 0.00344978600308;     // ω²a²b/GM
    const double s2 = std::sin(lat_rad) * std::sin(lat_rad);
    const double gamma = kGammaE * (1.0 + kK * s2) / std::sqrt(1.0 - kE2 * s2);
    const double c1 = 2.0 / kA * (1.0 + kF + kM - 2.0 * kF * s2);
    const double g_h0 = gamma * (1.0 - c1 * h0_m + 3.0 * h0_m * h0_m / (kA * kA));
    const double dg_dh = gamma * (-c1 + 6.0 * h0_m / (kA * kA));
    GravityModel m;
    m.kind_ = GravityKind::kNormal;
    m.g0_ = static_cast<T>(g_h0);
    m.dg_dh_ = static_cast<T>(dg_dh);
    return m;
  }

  /// g_n (m/s², NED) at navigation position r_n (m, NED from the alignment point).
  Vec3<T> g_n(const Vec3<T>& r_n) const { return Vec3<T>(T(0), T(0), g_down(r_n.z())); }
  /// The down component of g_n (the others are zero) at the NED down coordinate r_down_m (m).
  T g_down(T r_down_m) const { return g0_ - dg_dh_ * r_down_m; }

  GravityKind kind() const { return kind_; }
  T magnitude_at_origin() const { return g0_; }

 private:
  GravityKind kind_ = GravityKind::kConstant;
  T g0_ = static_cast<T>(kStandardGravity);
  T dg_dh_ = T(0);  // d|g|/dh, m/s² per m of height (negative)
};

}  // namespace gfins::nav
