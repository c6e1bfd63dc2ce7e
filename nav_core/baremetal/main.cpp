// Bare-metal size and soft-double probe of the float32 navigation core (Cortex-M4F).
//
// One nav::NavPipeline<float> lives in static storage (.bss); main() configures it once with the
// paper's Table 6 calibration and the paper's compensator (the per-sample path with the most
// arithmetic), then runs the per-sample step on counts read from a volatile buffer that stands
// for the ADC's DMA target, and writes the navigation state to a volatile sink, so the compiler
// can neither fold the inputs nor drop the outputs.
//
// The per-sample work is the out-of-line function gfins_nav_step(): scripts/embedded_size.sh
// walks the call graph from it in the disassembly and reports any soft-float double routine
// (__aeabi_d*, __*df*) it can reach. configure() may use double (the solver is built in double,
// once); the step must not.
#include <array>
#include <cstdint>

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

constexpr float kDegToRad = 0.017453292519943295f;

// Paper Table 6 (SF in V/g, bias in g, orientation errors in degrees), sensors 1..6 in Table 1
// order, and an ADC full scale of ±16 g per channel (PGA gain matched to each load resistor).
nav::PipelineConfig<float> make_config() {
  nav::PipelineConfig<float> c;
  c.nominal = nav::table1_geometry(0.1f);
  constexpr std::array<float, 6> kSfVPerG = {0.509874f, 0.332572f, 0.500242f,
                                             2.493301f, 0.339215f, 2.476663f};
  constexpr std::array<float, 6> kBiasG = {-0.000731f, -0.000242f, 0.000867f,
                                           -0.007977f, -0.000891f, -0.004691f};
  constexpr float kFullScaleG = 16.0f;
  constexpr float kCodes = 8388608.0f;  // 2^23
  for (std::size_t j = 0; j < 6; ++j) {
    c.front_end.scale_v_per_g[j] = kSfVPerG[j];
    c.front_end.bias_g[j] = kBiasG[j];
    c.front_end.volts_per_count[j] = kSfVPerG[j] * kFullScaleG / kCodes;
  }
  // Order xy, xz, yx, yz, zx, zy (misalignment.hpp).
  constexpr std::array<float, 6> kBetaDeg = {1.117319f,  -0.175730f, -0.581196f,
                                             -0.738742f, 2.454457f,  2.482135f};
  constexpr std::array<float, 6> kAlphaDeg = {-2.654967f, 2.596778f, -0.838703f,
                                              -0.737387f, 0.119537f, -1.451107f};
  for (std::size_t i = 0; i < 6; ++i) {
    c.misalignment.orientation.beta[i] = kBetaDeg[i] * kDegToRad;
    c.misalignment.orientation.alpha[i] = kAlphaDeg[i] * kDegToRad;
  }
  for (std::size_t j = 0; j < 6; ++j) {
    c.misalignment.drho_b[j] = nav::Vec3<float>(0.001f, -0.0005f, 0.0008f);  // m, assumed
  }
  c.compensator = nav::CompensatorKind::kPaper;
  c.sample_rate_hz = 1000.0;
  return c;
}

nav::NavPipeline<float>::Counts read_adc() {
  nav::NavPipeline<float>::Counts counts;
  for (std::size_t j = 0; j < counts.size(); ++j) counts[j] = g_adc_counts[j];
  return counts;
}

}  // namespace

// The per-sample step of the firmware's sample loop: read a frame, run the pipeline, publish.
extern "C" [[gnu::noinline]] void gfins_nav_step() {
  const auto counts = read_adc();
  g_pipeline.process(counts, g_adc_t_ns, g_adc_seq);
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

int main() {
  if (!g_pipeline.configure(make_config()).is_ok()) return 1;
  g_pipeline.start_at(nav::NavState<float>{}, read_adc());
  for (;;) {
    g_adc_seq = g_adc_seq + 1;
    g_adc_t_ns = g_adc_t_ns + 1000000;
    gfins_nav_step();
  }
}
