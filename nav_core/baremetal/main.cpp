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

// Paper Table 6 (SF in V/g, bias in g, orientation errors in degrees), sensors 1..6 in Table 1
// order, and an ADC full scale of ±16 g per channel (PGA gain matched to each load resistor).
nav::PipelineConfig<float> make_config() {
  nav::PipelineConfig<float> c;
  c.nominal = nav::table1_geometry(0.1f);
  namespace t6 = nav::paper_table6;
  constexpr float kFullScaleG = 16.0f;
  constexpr float kCodes = 8388608.0f;  // 2^23
  for (std::size_t j = 0; j < 6; ++j) {
    const auto sf = static_cast<float>(t6::kScaleVPerG[j]);
    c.front_end.scale_v_per_g[j] = sf;
    c.front_end.bias_g[j] = static_cast<float>(t6::kBiasG[j]);
    c.front_end.volts_per_count[j] = sf * kFullScaleG / kCodes;
  }
  c.misalignment = t6::misalignment<float>();
  for (std::size_t j = 0; j < 6; ++j) {
    c.misalignment.drho_b[j] = nav::Vec3<float>(0.001f, -0.0005f, 0.0008f);  // m, assumed
  }
  c.compensator = nav::CompensatorKind::kPaper;
  c.sample_rate_hz = 1000.0;
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

int main() {
  if (!g_pipeline.configure(make_config()).is_ok()) return 1;
  g_pipeline.start_at(nav::NavState<float>{}, read_adc());
  for (;;) {
    g_adc_seq = g_adc_seq + 1;
    g_adc_t_ns = g_adc_t_ns + 1000000;
    gfins_nav_step();
  }
}
