// Misalignment compensation between the front end and Chen's mechanization (paper §5).
//
//  kNone   outputs pass through; the solver uses the nominal geometry (Table 1).
//  kPaper  the paper's two-step compensator on the outputs, then the nominal solver:
//          location (eqs. (27)/(28)): s* = s** − C [Δf_j·θ_j], Δf_j = ω×(ω×Δρ_j) + ω̇×Δρ_j
//            (eq. (22) with its misprint ω×ω̇×Δρ read as ω×(ω×Δρ)), ω and ω̇ from the previous
//            step, as the paper's compensator has no better estimate;
//          orientation (eqs. (29)/(30)): s = C⁻¹ s*, per set.
//          Exact at rest; under rotation eqs. (23)-(26) leave a first-order residual, because C
//          mixes the other sensors' rigid-body terms, which sit at other positions
//          (docs/paper-errata.md).
//  kExact  outputs pass through; the solver is built from the calibrated geometry θ*_j, ρ*_j
//          (misaligned_geometry), so the 6×6 inversion itself removes the misalignment and stays
//          exact under rotation.
#pragma once

#include <cstdint>

#include "gfins/nav_core/geometry.hpp"
#include "gfins/nav_core/misalignment.hpp"
#include "gfins/status/status.hpp"

namespace gfins::nav {

enum class CompensatorKind : std::uint8_t { kNone = 0, kPaper = 1, kExact = 2 };

constexpr const char* to_string(CompensatorKind k) {
  switch (k) {
    case CompensatorKind::kNone:
      return "none";
    case CompensatorKind::kPaper:
      return "paper";
    case CompensatorKind::kExact:
      return "exact";
  }
  return "unknown";
}

template <typename T>
class Compensator {
 public:
  /// Largest orientation error accepted (rad). Eqs. (14)/(15) are first-order in the angles; at
  /// 0.2 rad their second-order terms reach 2 % and the model no longer describes the array.
  static constexpr double kMaxAngleRad = 0.2;

  using Outputs = Vec6<T>;

  Compensator() = default;

  /// Fails with kInvalidArgument when an angle is outside the small-angle model or a value is not
  /// finite, and with kSingular when a set matrix C of eq. (14)/(15) cannot be inverted.
  static Result<Compensator> create(CompensatorKind kind, const ArrayGeometry<T, 6>& nominal,
                                    const Misalignment<T>& m) {
    for (std::size_t i = 0; i < 6; ++i) {
      const T b = m.orientation.beta[i];
      const T a = m.orientation.alpha[i];
      if (!std::isfinite(a) || !std::isfinite(b) || std::abs(a) > T(kMaxAngleRad) ||
          std::abs(b) > T(kMaxAngleRad)) {
        return Status(ErrorCode::kInvalidArgument,
                      "compensator: an orientation error is not finite or exceeds 0.2 rad "
                      "(11.5 deg), outside the small-angle model of eqs. (14)/(15)");
      }
      if (!std::isfinite(m.drho_b[i].squaredNorm())) {
        return Status(ErrorCode::kInvalidArgument, "compensator: a location error is not finite");
      }
    }
    Compensator c;
    c.kind_ = kind;
    c.theta_b_ = nominal.theta_b;
    c.drho_b_ = m.drho_b;
    c.c_beta_ = set_matrix(m.orientation.beta);
    c.c_alpha_ = set_matrix(m.orientation.alpha);
    const T det_b = c.c_beta_.determinant();
    const T det_a = c.c_alpha_.determinant();
    if (!(std::abs(det_b) > T(0.5)) || !(std::abs(det_a) > T(0.5))) {
      return Status(ErrorCode::kSingular,
                    "compensator: an orientation-error set matrix (eq. 14/15) is near singular; "
                    "the angles are outside the small-angle model");
    }
    c.c_beta_inv_ = c.c_beta_.inverse();
    c.c_alpha_inv_ = c.c_alpha_.inverse();
    c.build_fused_form();
    return c;
  }

  CompensatorKind kind() const { return kind_; }

  /// The geometry the solver must be built from for this compensator.
  static ArrayGeometry<T, 6> solver_geometry(CompensatorKind kind,
                                             const ArrayGeometry<T, 6>& nominal,
                                             const Misalignment<T>& m) {
    return kind == CompensatorKind::kExact ? misaligned_geometry(nominal, m) : nominal;
  }

  /// s (compensated) from s** (front-end output); w_b and wdot_b are the latest estimates.
  /// Since C⁻¹(s** − C Δfθ) = C⁻¹ s** − Δfθ and Δf_j·θ_j is linear in [m(ω); ω̇], eqs. (27)-(30)
  /// collapse to s = P s** − D [m(ω); ω̇] with P (the two C⁻¹ blocks on their sensors) and D
  /// built once in create(); apply_reference() keeps the step-by-step form the tests compare to.
  void apply(const Outputs& s_raw, const Vec3<T>& w_b, const Vec3<T>& wdot_b, Outputs& s) const {
    if (kind_ != CompensatorKind::kPaper) {
      s = s_raw;
      return;
    }
    Eigen::Matrix<T, 9, 1> x;
    x << centripetal_monomials(w_b), wdot_b;
    s = p_ * s_raw - d_ * x;
  }

  /// Folds the fused form into the solver's M for the per-sample path: with u = M s the
  /// integrator's input, u = M P s** − M D [m(ω); ω̇] = F [s**; m(ω); ω̇], F = [M P | −M D]
  /// (padded to ArraySolver::kRows rows), one product instead of three. Call after create() with
  /// the solver the integrator uses (the nominal one for kPaper).
  void fold_into(const ArraySolver<T, 6>& solver) {
    const auto& m = solver.padded_m();
    fold_.template leftCols<6>() = m * p_;
    fold_.template rightCols<9>() = -(m * d_);
  }

  /// u = M s for the integrator (Strapdown::step_linear) from the front-end output s**, with
  /// this compensator applied: kPaper uses the folded F of fold_into(); the others, which pass
  /// the outputs through, return the solver's M s**.
  typename ArraySolver<T, 6>::PaddedVec padded_linear_part(const ArraySolver<T, 6>& solver,
                                                           const Outputs& s_raw, const Vec3<T>& w_b,
                                                           const Vec3<T>& wdot_b) const {
    if (kind_ != CompensatorKind::kPaper) return solver.padded_linear_part(s_raw);
    Eigen::Matrix<T, 15, 1> x;
    x << s_raw, centripetal_monomials(w_b), wdot_b;
    return fold_.lazyProduct(x);
  }

  /// The paper's sequence as printed (misprints fixed): location compensation (27)/(28), then
  /// orientation compensation (29)/(30), set by set.
  void apply_reference(const Outputs& s_raw, const Vec3<T>& w_b, const Vec3<T>& wdot_b,
                       Outputs& s) const {
    if (kind_ != CompensatorKind::kPaper) {
      s = s_raw;
      return;
    }
    apply_set(kSetBeta, c_beta_, c_beta_inv_, s_raw, w_b, wdot_b, s);
    apply_set(kSetAlpha, c_alpha_, c_alpha_inv_, s_raw, w_b, wdot_b, s);
  }

 private:
  void apply_set(const std::array<int, 3>& set, const Mat3<T>& c, const Mat3<T>& c_inv,
                 const Outputs& s_raw, const Vec3<T>& w, const Vec3<T>& wdot, Outputs& s) const {
    Vec3<T> df_theta;  // Δf_j·θ_j, eq. (22)
    Vec3<T> s2;        // s** of the set
    for (int i = 0; i < 3; ++i) {
      const auto j = static_cast<std::size_t>(set[static_cast<std::size_t>(i)]);
      const Vec3<T>& d = drho_b_[j];
      df_theta(i) = theta_b_[j].dot(w.cross(w.cross(d)) + wdot.cross(d));
      s2(i) = s_raw(static_cast<Eigen::Index>(j));
    }
    const Vec3<T> s_star = s2 - c * df_theta;  // eqs. (27)/(28)
    const Vec3<T> s_ideal = c_inv * s_star;    // eqs. (29)/(30)
    for (int i = 0; i < 3; ++i) s(set[static_cast<std::size_t>(i)]) = s_ideal(i);
  }

  // P: C⁻¹ of each set scattered onto its sensors. D row j: Δf_j·θ_j = q_jᵀ m(ω) + (Δρ_j×θ_j)·ω̇,
  // with q_j the centripetal quadratic form of geometry.hpp evaluated at Δρ_j instead of ρ_j.
  void build_fused_form() {
    p_.setZero();
    const auto scatter = [this](const std::array<int, 3>& set, const Mat3<T>& c_inv) {
      for (std::size_t i = 0; i < 3; ++i) {
        for (std::size_t k = 0; k < 3; ++k) {
          p_(set[i], set[k]) = c_inv(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(k));
        }
      }
    };
    scatter(kSetBeta, c_beta_inv_);
    scatter(kSetAlpha, c_alpha_inv_);
    for (std::size_t j = 0; j < 6; ++j) {
      const Vec3<T>& th = theta_b_[j];
      const Vec3<T>& d = drho_b_[j];
      const T td = th.dot(d);
      const Vec3<T> dxt = d.cross(th);
      d_.row(static_cast<Eigen::Index>(j)) << th.x() * d.x() - td, th.y() * d.y() - td,
          th.z() * d.z() - td, th.y() * d.z() + th.z() * d.y(), th.x() * d.z() + th.z() * d.x(),
          th.x() * d.y() + th.y() * d.x(), dxt.x(), dxt.y(), dxt.z();
    }
  }

  CompensatorKind kind_ = CompensatorKind::kNone;
  std::array<Vec3<T>, 6> theta_b_ = zero_vectors<T, 6>();
  std::array<Vec3<T>, 6> drho_b_ = zero_vectors<T, 6>();
  Mat3<T> c_beta_ = Mat3<T>::Identity();
  Mat3<T> c_alpha_ = Mat3<T>::Identity();
  Mat3<T> c_beta_inv_ = Mat3<T>::Identity();
  Mat3<T> c_alpha_inv_ = Mat3<T>::Identity();
  Mat6<T> p_ = Mat6<T>::Identity();
  Eigen::Matrix<T, 6, 9> d_ = Eigen::Matrix<T, 6, 9>::Zero();
  Eigen::Matrix<T, ArraySolver<T, 6>::kRows, 15> fold_ =
      Eigen::Matrix<T, ArraySolver<T, 6>::kRows, 15>::Zero();
};

}  // namespace gfins::nav
