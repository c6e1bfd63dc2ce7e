// A vehicle (or a walker) that stops and goes along a weaving road: the scenarios for standstill
// aiding (stops to detect) and for GNSS aiding with turns.
//
// Progress north s(t) (the road's x coordinate) repeats one cycle after an initial stop of t_init:
//   stop (t_stop) → speed 0 → V over t_acc → cruise at V for t_cruise → V → 0 over t_acc
// with the minimum-jerk speed profile v = V h(τ), h(τ) = 10τ³ − 15τ⁴ + 6τ⁵ (τ = time into the
// ramp / t_acc), whose integral is V t_acc H(τ), H(τ) = 2.5τ⁴ − 3τ⁵ + τ⁶. Speed and acceleration
// are continuous; the jerk steps at the ramp ends (the angular acceleration of the bank below
// steps with it, a finite step, which the array senses as such).
//
// The road weaves: p(s) = [s, A (1 − cos k s), 0] (NED), k = 2π / L. Heading along the tangent,
// ψ = atan(A k sin k s); the bank of a coordinated turn, tan φ = |ṗ| ψ̇ / g, with
// ψ̇ = dψ/ds · v(t), dψ/ds = A k² cos k s / (1 + (A k sin k s)²) and |ṗ| = v √(1 + (A k sin k s)²).
// Every quantity is written over jets of t, so rates and angular accelerations are exact.
#include <cmath>
#include <memory>
#include <string>

#include "gfins/host_sim/jet.hpp"
#include "gfins/host_sim/trajectory.hpp"
#include "gfins/nav_core/math.hpp"

namespace gfins::sim {
namespace {

class StopAndGoTrajectory final : public JetTrajectory {
 public:
  explicit StopAndGoTrajectory(const StopAndGoSpec& spec)
      : p_(spec),
        k_(2.0 * M_PI / spec.weave_length_m),
        cycle_s_(spec.stop_s + 2.0 * spec.accel_s + spec.cruise_s),
        cycle_m_(spec.speed_mps * (spec.accel_s + spec.cruise_s)) {}

  void pose(const JetD& t, JetVec3& r_n, JetQuat& q_nb) const override {
    JetD s;
    JetD v;
    distance_and_speed(t, s, v);
    JetD sn;
    JetD cs;
    sin_cos(k_ * s, sn, cs);
    const double ak = p_.weave_amplitude_m * k_;
    r_n = {s, p_.weave_amplitude_m * (1.0 - cs), JetD(0.0)};
    const JetD slope = ak * sn;  // dy/ds
    const JetD stretch = 1.0 + slope * slope;
    const JetD psi = atan(slope);
    const JetD psi_dot = (ak * k_) * cs / stretch * v;
    const JetD phi = atan(sqrt(stretch) * v * psi_dot / nav::kStandardGravity);
    q_nb = jet_rot_z(psi) * jet_rot_x(phi);
  }
  std::string name() const override { return "stop_and_go"; }

 private:
  /// s(t) and v(t) = ṡ(t) as jets of t (the file comment's profile).
  void distance_and_speed(const JetD& t, JetD& s, JetD& v) const {
    const double tc = t.val - p_.initial_stop_s;
    if (tc <= 0.0) {  // the initial stop
      s = JetD(0.0);
      v = JetD(0.0);
      return;
    }
    const double n = std::floor(tc / cycle_s_);
    const double base_m = n * cycle_m_;
    const JetD u = t - (p_.initial_stop_s + n * cycle_s_);  // time into this cycle
    const double vmax = p_.speed_mps;
    const double ta = p_.accel_s;
    const double up0 = p_.stop_s;
    const double cruise0 = up0 + ta;
    const double down0 = cruise0 + p_.cruise_s;
    if (u.val < up0) {
      s = JetD(base_m);
      v = JetD(0.0);
    } else if (u.val < cruise0) {
      const JetD tau = (u - up0) / ta;
      s = base_m + vmax * ta * big_h(tau);
      v = vmax * small_h(tau);
    } else if (u.val < down0) {
      s = base_m + vmax * ta / 2.0 + vmax * (u - cruise0);
      v = JetD(vmax);
    } else {
      const JetD tau = (u - down0) / ta;
      s = base_m + vmax * ta / 2.0 + vmax * p_.cruise_s + vmax * ta * (tau - big_h(tau));
      v = vmax * (1.0 - small_h(tau));
    }
  }
  static JetD small_h(const JetD& x) {  // 10τ³ − 15τ⁴ + 6τ⁵
    const JetD x3 = x * x * x;
    return x3 * (10.0 + x * (-15.0 + 6.0 * x));
  }
  static JetD big_h(const JetD& x) {  // 2.5τ⁴ − 3τ⁵ + τ⁶, ∫₀^τ h
    const JetD x4 = x * x * x * x;
    return x4 * (2.5 + x * (-3.0 + x));
  }

  StopAndGoSpec p_;
  double k_;
  double cycle_s_;
  double cycle_m_;
};

}  // namespace

std::unique_ptr<Trajectory> make_stop_and_go(const StopAndGoSpec& spec) {
  return std::make_unique<StopAndGoTrajectory>(spec);
}

}  // namespace gfins::sim
