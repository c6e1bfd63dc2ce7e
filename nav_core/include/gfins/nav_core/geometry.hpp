// Accelerometer array geometry and the linear map from the six outputs to [ω̇; f].
//
// Sensor j sits at rho_b[j] (m, body frame, from the array centre o_b) and senses along the unit
// axis theta_b[j]. Its specific force is the one of the centre plus the rigid-body terms
// (paper eq. (22), with the misprint ω×ω̇×Δρ read as ω×(ω×Δρ); see docs/paper-errata.md):
//
//   s_j = θ_j·f + (ρ_j×θ_j)·ω̇ + θ_j·(ω×(ω×ρ_j))
//
// where f = C_n^b (r̈_n − g_n) is the specific force at the centre. Stacking N ≥ 6 sensors gives
// s = H [ω̇; f] + c(ω) with row j of H = [(ρ_j×θ_j)ᵀ  θ_jᵀ]. The centripetal term is a quadratic
// form in ω: c_j(ω) = (θ_j·ω)(ρ_j·ω) − (θ_j·ρ_j)|ω|², i.e. a fixed N×6 matrix times the monomials
// m(ω) = [ωx², ωy², ωz², ωyωz, ωxωz, ωxωy]. Hence, with M = (HᵀH)⁻¹Hᵀ precomputed at start-up,
//
//   [ω̇; f] = M s − K m(ω),   K = M Q.
//
// For Table 1 M = [S/(2ρ); T/2] and −K m(ω) = [0; ρ(ωyωz, ωxωz, ωxωy)], which is the paper's
// eq. (4) (with C_i^b on its left side, misprint fixed) once gravity is added back (eq. (5)).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "gfins/nav_core/math.hpp"
#include "gfins/status/status.hpp"

namespace gfins::nav {

/// Number of accelerometers of the paper's array; the solver accepts any N ≥ 6.
inline constexpr int kNumSensors = 6;

/// A set of an array's channels: bit j stands for sensor j (arrays of up to 32 sensors).
using ChannelMask = std::uint32_t;

/// Every channel of an N-sensor array.
template <int N>
constexpr ChannelMask all_channels() {
  static_assert(N >= 1 && N <= 32, "a ChannelMask holds 32 channels");
  return N == 32 ? ~ChannelMask{0} : ((ChannelMask{1} << static_cast<unsigned>(N)) - 1U);
}

/// Number of channels in a mask.
constexpr int channel_count(ChannelMask mask) {
  int n = 0;
  for (; mask != 0U; mask &= mask - 1U) ++n;
  return n;
}

/// Positions (m) and unit sensitive axes of an array of N accelerometers, body frame.
template <typename T, int N = kNumSensors>
struct ArrayGeometry {
  static_assert(N >= 6, "six outputs are the minimum that determine [ω̇; f]");
  std::array<Vec3<T>, N> rho_b = zero_vectors<T, static_cast<std::size_t>(N)>();
  std::array<Vec3<T>, N> theta_b = zero_vectors<T, static_cast<std::size_t>(N)>();

  template <typename U>
  ArrayGeometry<U, N> cast() const {
    ArrayGeometry<U, N> g;
    for (int j = 0; j < N; ++j) {
      g.rho_b[static_cast<std::size_t>(j)] = rho_b[static_cast<std::size_t>(j)].template cast<U>();
      g.theta_b[static_cast<std::size_t>(j)] =
          theta_b[static_cast<std::size_t>(j)].template cast<U>();
    }
    return g;
  }
};

/// The paper's Table 1 (Chen's cube configuration) with half-size rho_m (m).
template <typename T>
ArrayGeometry<T, 6> table1_geometry(T rho_m) {
  const T r = rho_m;
  const T k = T(1) / std::sqrt(T(2));
  ArrayGeometry<T, 6> g;
  g.rho_b = {Vec3<T>(0, 0, -r), Vec3<T>(0, -r, 0), Vec3<T>(-r, 0, 0),
             Vec3<T>(r, 0, 0),  Vec3<T>(0, r, 0),  Vec3<T>(0, 0, r)};
  g.theta_b = {Vec3<T>(k, k, 0),  Vec3<T>(k, 0, k),  Vec3<T>(0, k, k),
               Vec3<T>(0, -k, k), Vec3<T>(-k, 0, k), Vec3<T>(-k, k, 0)};
  return g;
}

/// Monomials m(ω) = [ωx², ωy², ωz², ωyωz, ωxωz, ωxωy] of the centripetal term.
/// m(ω) of a padded 3-vector (ArraySolver::PaddedVec3: 3 or 4 lanes, the 4th ignored).
template <typename T, int P>
Vec6<T> centripetal_monomials(const Eigen::Matrix<T, P, 1>& w) {
  static_assert(P == 3 || P == 4, "a 3-vector, padded or not");
  Vec6<T> m;
  m << w(0) * w(0), w(1) * w(1), w(2) * w(2), w(1) * w(2), w(0) * w(2), w(0) * w(1);
  return m;
}

/// Largest condition number of the (column-scaled) design H accepted by default. Table 1 has 1;
/// a geometry near 1e3 loses three digits, which float32 cannot afford.
inline constexpr double kDefaultMaxCondition = 100.0;

/// The precomputed inversion of the array equations: [ω̇; f] = M s − K m(ω).
template <typename T, int N = kNumSensors>
class ArraySolver {
 public:
  using Outputs = Eigen::Matrix<T, N, 1>;
  using MapMatrix = Eigen::Matrix<T, 6, N>;
  /// A 3-vector padded to one SIMD packet of T when a packet holds four (floats with SSE or
  /// NEON), plain otherwise (doubles on SSE, where a 4-vector is two packets and measured slower;
  /// no SIMD on the Cortex-M4F); the extra lane is zero. The integrator keeps its per-sample
  /// 3-vectors in this form so that each operation is one packet.
  static constexpr int kHalfRows = Eigen::internal::packet_traits<T>::size == 4 ? 4 : 3;
  using PaddedVec3 = Eigen::Matrix<T, kHalfRows, 1>;
  /// Rows of the stored M and K, and of u = M s: the three ω̇ rows at 0..2 and the three f rows
  /// at kHalfRows..kHalfRows+2, each group padded with zero rows to kHalfRows, so that
  /// u.head<kHalfRows>() is ω̇ and u.tail<kHalfRows>() is f, both as PaddedVec3.
  static constexpr int kRows = 2 * kHalfRows;
  /// Rows of the stored bottom (specific-force) rows of K: three, padded the same way.
  static constexpr int kForceRows = kHalfRows;
  using PaddedVec = Eigen::Matrix<T, kRows, 1>;
  using PaddedMap = Eigen::Matrix<T, kRows, N>;
  using PaddedK = Eigen::Matrix<T, kRows, 6>;
  using PaddedKForce = Eigen::Matrix<T, kForceRows, 6>;

  /// Builds M and K from a geometry, in T (single precision on the target: no double arithmetic
  /// anywhere in the float core; geometry_impl.hpp states the accuracy). Fails with kSingular
  /// when the design is singular or its condition number exceeds max_condition; fails with
  /// kInvalidArgument when an axis is not near unit length (|‖θ‖−1| > 0.1: the calibrated
  /// axes θ* of eq. (23) carry gains of a few percent, so they are not exactly unit) or the array
  /// has no size. The condition number is that of H with its ω̇ columns scaled by the mean lever
  /// arm, so it does not depend on the unit of length.
  static Result<ArraySolver> create(const ArrayGeometry<T, N>& geometry,
                                    T max_condition = T(kDefaultMaxCondition));
  /// create() over the sensors in `active` only (a redundant array that has excluded a failed
  /// channel, redundancy/parity_monitor.hpp): the others get zero columns in M, so their outputs
  /// do not enter [ω̇; f]. At least six must remain (kInvalidArgument) and their geometry must
  /// still determine [ω̇; f] (kSingular otherwise). A member template defined apart from create()
  /// (geometry_impl.hpp), so that the six-sensor instantiation the board links is create() alone:
  /// a shared body changed link-time inlining in the Cortex-M4F probe by 2.8 KB of flash.
  template <typename Mask = ChannelMask>
  static Result<ArraySolver> create_subset(const ArrayGeometry<T, N>& geometry, T max_condition,
                                           Mask active);

  /// Angular acceleration ω̇ (rad/s², body) and specific force f (m/s², body, at o_b) from the
  /// outputs s (m/s², along each axis) and the current angular rate ω (rad/s, body).
  void solve(const Outputs& s, const Vec3<T>& w, Vec3<T>& wdot_b, Vec3<T>& f_b) const {
    const PaddedVec u = m_.lazyProduct(s) - k_.lazyProduct(centripetal_monomials(w));
    wdot_b = u.template head<3>();
    f_b = u.template segment<3>(kHalfRows);
  }

  /// The linear part M s (ω-independent), [ω̇; f] order.
  Vec6<T> linear_part(const Outputs& s) const { return unpad(padded_linear_part(s)); }
  /// M s in the padded layout the integrator takes (Strapdown::step_linear).
  PaddedVec padded_linear_part(const Outputs& s) const { return m_.lazyProduct(s); }
  /// The centripetal correction K m(ω) that solve() subtracts, [ω̇; f] order.
  Vec6<T> centripetal_part(const Vec3<T>& w) const {
    return unpad(k_.lazyProduct(centripetal_monomials(w)));
  }

  /// M (6×N) and K (6×6), gathered from the padded storage.
  MapMatrix m() const { return unpad_rows(m_); }
  Mat6<T> k() const { return unpad_rows(k_); }
  /// The padded storage itself, for the per-sample products.
  const PaddedMap& padded_m() const { return m_; }
  const PaddedK& padded_k() const { return k_; }
  /// Rows 3..5 of K (the specific-force rows), padded.
  const PaddedKForce& padded_k_force() const { return k_force_; }
  /// Condition number of the column-scaled design (computed in T).
  double condition_number() const { return static_cast<double>(condition_); }
  const ArrayGeometry<T, N>& geometry() const { return geometry_; }
  /// The sensors the solution uses (all of them unless made by create_subset()): those whose
  /// column of M is not zero. Computed, not stored: a stored mask made every copy of the solver
  /// longer and cost 2.8 KB of Cortex-M4F flash in the probe (docs/performance.md).
  ChannelMask active() const {
    ChannelMask mask = 0;
    for (int j = 0; j < N; ++j) {
      if (!(m_.col(j).array() == T(0)).all()) mask |= ChannelMask{1} << static_cast<unsigned>(j);
    }
    return mask;
  }

  /// [ω̇; f] (6 values) from the padded layout.
  static Vec6<T> unpad(const PaddedVec& u) {
    Vec6<T> r;
    r << u.template head<3>(), u.template segment<3>(kHalfRows);
    return r;
  }

  /// Forward model: the outputs an ideal array with this geometry gives for (ω̇, f, ω).
  Outputs predict(const Vec3<T>& wdot_b, const Vec3<T>& f_b, const Vec3<T>& w) const;

 private:
  template <int C>
  static Eigen::Matrix<T, 6, C> unpad_rows(const Eigen::Matrix<T, kRows, C>& p) {
    Eigen::Matrix<T, 6, C> r;
    r << p.template topRows<3>(), p.template middleRows<3>(kHalfRows);
    return r;
  }

  PaddedMap m_ = PaddedMap::Zero();
  PaddedK k_ = PaddedK::Zero();
  PaddedKForce k_force_ = PaddedKForce::Zero();
  T condition_ = T(0);
  ArrayGeometry<T, N> geometry_{};
};

extern template class ArraySolver<float, 6>;
extern template class ArraySolver<double, 6>;

}  // namespace gfins::nav
