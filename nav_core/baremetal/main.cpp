// Bare-metal size and soft-double probe of the float32 navigation core (Cortex-M4F).
//
// One nav::NavPipeline<float> lives in static storage (.bss); main() configures it once with the
// paper's Table 6 calibration and the exact compensator (the solver of the calibrated geometry:
// one geometry, the configuration issue 13 sizes), then runs the per-sample step on counts read
// from a volatile buffer that stands for the ADC's DMA target, and writes the navigation state to a
// volatile sink, so the compiler can neither fold the inputs nor drop the outputs.
//
// The per-sample work is the out-of-line function gfins_nav_step(): scripts/embedded_size.sh
// walks the call graph from it in the disassembly and reports any soft-float double routine
// (__aeabi_d*, __*df*) it can reach, and the whole image must contain none either: the set-up
// (configure(), the solver's SVD) runs in single precision too.
#include <array>
#include <cstddef>
#include <cstdint>

#include "gfins/nav_core/paper_table6.hpp"
#include "gfins/nav_core/pipeline.hpp"

namespace {

namespace nav = gfins::nav;

// The converter's frame as DMA leaves it: one 24-bit code per channel, sign-extended.
volatile std::int32_t g_adc_counts[nav::kNumSensors];
volatile std::int64_t g_adc_t_ns;
volatile std::uint32_t g_adc_seq;

// What the publisher would read: attitude, velocity, position.
volatile float g_out[10];

nav::NavPipeline<float> g_pipeline;

// The calibration as the board would hold it: already in float. Table 6 is kept in double
// (nav_core/paper_table6.hpp); these constexpr copies are rounded by the compiler, so the image
// converts nothing at run time (a runtime double→float conversion is __aeabi_d2f).
template <std::size_t N>
constexpr std::array<float, N> to_float(const std::array<double, N>& d, double factor = 1.0) {
  std::array<float, N> f{};
  for (std::size_t i = 0; i < N; ++i) f[i] = static_cast<float>(d[i] * factor);
  return f;
}
namespace t6 = nav::paper_table6;
constexpr double kDegToRad = 3.14159265358979323846 / 180.0;
constexpr std::array<float, 6> kScaleVPerG = to_float(t6::kScaleVPerG);
constexpr std::array<float, 6> kBiasG = to_float(t6::kBiasG);
constexpr std::array<float, 6> kBetaRad = to_float(t6::kBetaDeg, kDegToRad);
constexpr std::array<float, 6> kAlphaRad = to_float(t6::kAlphaDeg, kDegToRad);

// Paper Table 6 (SF in V/g, bias in g, orientation errors in radians), sensors 1..6 in Table 1
// order, and an ADC full scale of ±16 g per channel (PGA gain matched to each load resistor).
nav::PipelineConfig<float> make_config() {
  nav::PipelineConfig<float> c;
  c.nominal = nav::table1_geometry(0.1f);
  constexpr float kFullScaleG = 16.0f;
  constexpr float kCodes = 8388608.0f;  // 2^23
  for (std::size_t j = 0; j < 6; ++j) {
    c.front_end.scale_v_per_g[j] = kScaleVPerG[j];
    c.front_end.bias_g[j] = kBiasG[j];
    c.front_end.volts_per_count[j] = kScaleVPerG[j] * kFullScaleG / kCodes;
  }
  c.misalignment.orientation.beta = kBetaRad;
  c.misalignment.orientation.alpha = kAlphaRad;
  for (std::size_t j = 0; j < 6; ++j) {
    c.misalignment.drho_b[j] = nav::Vec3<float>(0.001f, -0.0005f, 0.0008f);  // m, assumed
  }
  c.compensator = nav::CompensatorKind::kExact;
  c.sample_rate_hz = 1000.0f;
  return c;
}

gfins::RawSample read_adc() {
  gfins::RawSample s;
  for (std::size_t j = 0; j < s.counts.size(); ++j) s.counts[j] = g_adc_counts[j];
  s.t_ns = g_adc_t_ns;
  s.seq = g_adc_seq;
  return s;
}

}  // namespace

// The per-sample step of the firmware's sample loop: read a frame, run the pipeline, publish.
extern "C" [[gnu::noinline]] void gfins_nav_step() {
  g_pipeline.process(read_adc());
  const nav::NavState<float>& s = g_pipeline.state();
  g_out[0] = s.q_nb.w();
  g_out[1] = s.q_nb.x();
  g_out[2] = s.q_nb.y();
  g_out[3] = s.q_nb.z();
  for (int i = 0; i < 3; ++i) {
    g_out[4 + i] = s.v_n(i);
    g_out[7 + i] = s.r_n(i);
  }
}

#ifdef GFINS_PROBE_STEPS
// qemu_startup.cpp: the QEMU build (gfins_nav_qemu) runs a bounded number of steps and exits.
extern "C" [[noreturn]] void gfins_probe_exit(int code);
#endif

int main() {
  if (!g_pipeline.configure(make_config()).is_ok()) return 1;
  g_pipeline.start_at(nav::NavState<float>{}, read_adc());
#ifdef GFINS_PROBE_STEPS
  for (int i = 0; i < GFINS_PROBE_STEPS; ++i) {
#else
  for (;;) {
#endif
    g_adc_seq = g_adc_seq + 1;
    g_adc_t_ns = g_adc_t_ns + 1000000;
    gfins_nav_step();
  }
#ifdef GFINS_PROBE_STEPS
  gfins_probe_exit(0);
#endif
}
