// The bare-metal probe's configuration (main.cpp), shared with the host program that writes its
// samples and the expected result (tests/bench/m4f_probe_samples.cpp), so that the x86 float
// pipeline the QEMU run is compared with is configured by the same code.
//
// The calibration as a board would hold it: already in float. Table 6 is kept in double
// (nav_core/paper_table6.hpp); the constexpr copies below are rounded by the compiler, so the
// Cortex-M4F image converts nothing at run time (a run-time double→float conversion would be
// __aeabi_d2f, which scripts/embedded_size.sh refuses).
#pragma once

#include <array>
#include <cstddef>

#include "gfins/nav_core/paper_table6.hpp"
#include "gfins/nav_core/pipeline.hpp"

namespace gfins::probe {

template <std::size_t N>
constexpr std::array<float, N> to_float(const std::array<double, N>& d, double factor = 1.0) {
  std::array<float, N> f{};
  for (std::size_t i = 0; i < N; ++i) f[i] = static_cast<float>(d[i] * factor);
  return f;
}
inline constexpr double kDegToRad = 3.14159265358979323846 / 180.0;
inline constexpr std::array<float, 6> kScaleVPerG = to_float(nav::paper_table6::kScaleVPerG);
inline constexpr std::array<float, 6> kBiasG = to_float(nav::paper_table6::kBiasG);
inline constexpr std::array<float, 6> kBetaRad = to_float(nav::paper_table6::kBetaDeg, kDegToRad);
inline constexpr std::array<float, 6> kAlphaRad = to_float(nav::paper_table6::kAlphaDeg, kDegToRad);

using Vec3f = std::array<float, 3>;

/// Paper Table 6 (SF in V/g, bias in g, orientation errors in radians), sensors 1..6 in Table 1
/// order, a cube of half-size 0.1 m, 1 kHz, the exact compensator (the solver of the calibrated
/// geometry: one geometry, the configuration whose flash and RAM are budgeted), with the
/// converter's LSB (V per count) and each sensor's location error Δρ_j (m, body) given.
inline nav::PipelineConfig<float> make_probe_config(float volts_per_count,
                                                    const std::array<Vec3f, 6>& drho_m) {
  nav::PipelineConfig<float> c;
  c.nominal = nav::table1_geometry(0.1f);
  for (std::size_t j = 0; j < 6; ++j) {
    c.front_end.scale_v_per_g[j] = kScaleVPerG[j];
    c.front_end.bias_g[j] = kBiasG[j];
    c.front_end.volts_per_count[j] = volts_per_count;
  }
  c.misalignment.orientation.beta = kBetaRad;
  c.misalignment.orientation.alpha = kAlphaRad;
  for (std::size_t j = 0; j < 6; ++j) {
    c.misalignment.drho_b[j] = nav::Vec3<float>(drho_m[j][0], drho_m[j][1], drho_m[j][2]);
  }
  c.compensator = nav::CompensatorKind::kExact;
  c.sample_rate_hz = 1000.0f;
  return c;
}

/// A navigation state from its parts: q_nb (w, x, y, z), ω_b (rad/s), ω̇_b (rad/s²), v_n (m/s),
/// r_n (m); sequence number and time 0.
inline nav::NavState<float> make_probe_state(const std::array<float, 4>& q, const Vec3f& w,
                                             const Vec3f& wdot, const Vec3f& v, const Vec3f& r) {
  const auto vec = [](const Vec3f& a) { return nav::Vec3<float>(a[0], a[1], a[2]); };
  nav::NavState<float> s;
  s.q_nb = nav::Quat<float>(q[0], q[1], q[2], q[3]);
  s.w_b = vec(w);
  s.wdot_b = vec(wdot);
  s.v_n = vec(v);
  s.r_n = vec(r);
  return s;
}

/// What the probe publishes after a step (main.cpp g_out): q_nb w, x, y, z, then v_n, then r_n.
inline std::array<float, 10> probe_outputs(const nav::NavState<float>& s) {
  return {s.q_nb.w(), s.q_nb.x(), s.q_nb.y(), s.q_nb.z(), s.v_n(0),
          s.v_n(1),   s.v_n(2),   s.r_n(0),   s.r_n(1),   s.r_n(2)};
}

}  // namespace gfins::probe
