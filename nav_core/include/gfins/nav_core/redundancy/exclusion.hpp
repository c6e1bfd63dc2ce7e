// Undoing what a failed channel did to the navigation state before its exclusion
// (docs/redundancy.md, "Navigation after exclusion").
//
// Until the exclusion the solver mapped the fault f_j(t) into [ω̇; f] as M e_j f_j (M of the solver
// in use then). Integrated, that is an error of
//   δω_b = M_ω̇ e_j ∫ f_j dt                δθ_b = M_ω̇ e_j ∫ f_j (t_now − t) dt
//   δv_n = C_nb M_f e_j ∫ f_j dt           δr_n = C_nb M_f e_j ∫ f_j (t_now − t) dt
// (first order; the body frame barely turns during the few tenths of a second before an
// exclusion), with the two integrals from ParityMonitor::transient(). The integrator's closed-loop
// correction (Strapdown::apply_correction, the aiding filter's own path) removes them. The
// velocity and position the tilt error made meanwhile (g δθ t) are not removed: for a 1 mg fault
// excluded after 0.3 s they are the larger part (the correction removes 36 % of the velocity
// error and 56 % of the position error, docs/redundancy.md), left to the aiding.
#pragma once

#include "gfins/nav_core/integrator.hpp"
#include "gfins/nav_core/redundancy/parity_monitor.hpp"

namespace gfins::nav {

/// Removes from `nav` the error the excluded channel's fault left (see above). `before` is the
/// solver the integrator used while the fault was present. Does nothing for a transient without
/// a channel.
template <typename T, int N>
void correct_for_excluded_fault(Strapdown<T, N>& nav, const ArraySolver<T, N>& before,
                                const FaultTransient<T>& transient) {
  if (transient.channel < 0 || transient.channel >= N) return;
  const typename ArraySolver<T, N>::MapMatrix m = before.m();
  const Vec3<T> wdot_per_mps2 = m.col(transient.channel).template head<3>();
  const Vec3<T> f_per_mps2 = m.col(transient.channel).template tail<3>();
  const Quat<T> q_nb = nav.state().q_nb;
  const Vec3<T> dw_b = wdot_per_mps2 * transient.integral_mps;
  // The estimate turned by δθ_b more than the truth: q̂ = q ⊗ exp(δθ_b) = exp(C δθ_b) ⊗ q, so the
  // correction applied on the left (exp(φ) ⊗ q̂) is φ = −C δθ_b.
  const Vec3<T> phi_n = -(q_nb * (wdot_per_mps2 * transient.moment_m));
  const Vec3<T> dv_n = q_nb * (f_per_mps2 * transient.integral_mps);
  const Vec3<T> dr_n = q_nb * (f_per_mps2 * transient.moment_m);
  nav.apply_correction(phi_n, dr_n, dv_n, dw_b);
}

}  // namespace gfins::nav
