// Bare-metal size and soft-double probe of the float32 navigation core (Cortex-M4F).
//
// One nav::NavPipeline<float> lives in static storage (.bss); main() configures it once with the
// paper's Table 6 calibration and the exact compensator (the solver of the calibrated geometry:
// one geometry, the configuration whose flash and RAM are budgeted), then runs the per-sample step
// on counts read from a volatile buffer that stands for the ADC's DMA target, and writes the
// navigation state to a volatile sink, so the compiler can neither fold the inputs nor drop the
// outputs. In the QEMU build (GFINS_PROBE_STEPS) main() fills that buffer before each step with the
// next of the benchmarks' 1 kHz samples of the manoeuvre (probe_samples.hpp): the traced steps see
// real, varying codes and navigate the trajectory they came from.
//
// The per-sample work is the out-of-line function gfins_nav_step(): scripts/embedded_size.sh
// walks the call graph from it in the disassembly and reports any soft-float double routine
// (__aeabi_d*, __*df*) it can reach, and the whole image must contain none either: the set-up
// (configure(), the solver's SVD) runs in single precision too.
#include <array>
#include <cstddef>
#include <cstdint>
#include <iterator>

#include "gfins/nav_core/pipeline.hpp"
#ifdef GFINS_PROBE_STEPS
#include "filter_rig.hpp"
#endif
#include "probe_config.hpp"
#include "probe_samples.hpp"

namespace {

namespace nav = gfins::nav;

// The converter's frame as DMA leaves it: one 24-bit code per channel, sign-extended.
volatile std::int32_t g_adc_counts[nav::kNumSensors];
volatile std::int64_t g_adc_t_ns;
volatile std::uint32_t g_adc_seq;

// What the publisher would read: attitude, velocity, position.
volatile float g_out[10];

nav::NavPipeline<float> g_pipeline;

// The pipeline owns the aided filter and the standstill detector (nav_core/filter/aiding.hpp):
// its aiding is off in the probe's configuration, so the per-sample results stay those of the
// x86 reference (probe_samples.hpp), while every filter routine is linked and measured.
// What the CAN side would receive: GNSS fixes and a heading, written by "DMA" like the ADC frame.
volatile float g_gnss[7];  // position N E D, velocity N E D, heading
volatile float g_acc_out[7];

// Configuration and initial state: probe_config.hpp (shared with the host program that writes
// probe_samples.hpp and the expected result of the QEMU run), the workload's converter LSB,
// location errors and true initial state (probe_samples.hpp).
nav::PipelineConfig<float> make_config() {
  return gfins::probe::make_probe_config(gfins::probe::kVoltsPerCount, gfins::probe::kDrhoM);
}

nav::NavState<float> initial_state() {
  namespace p = gfins::probe;
  return p::make_probe_state(p::kQ0, p::kW0, p::kWdot0, p::kV0, p::kR0);
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

static nav::Vec3<float> read_gnss(int first) {
  nav::Vec3<float> v;
  for (int i = 0; i < 3; ++i) v(i) = g_gnss[first + i];
  return v;
}

// The filter's work at the decimated rate: propagation, the standstill decision and every kind of
// update, then the accuracy outputs. Out of line so the size script can walk its call graph too.
extern "C" [[gnu::noinline]] void gfins_filter_step() {
  nav::GnssFix<float> fix;
  fix.t_valid_ns = g_pipeline.state().t_ns;
  fix.value_n = read_gnss(0);
  (void)g_pipeline.offer_gnss_position(fix);
  fix.value_n = read_gnss(3);
  (void)g_pipeline.offer_gnss_velocity(fix);
  nav::HeadingFix<float> heading;
  heading.t_valid_ns = fix.t_valid_ns;
  heading.yaw_rad = g_gnss[6];
  heading.sigma_rad = 0.05F;
  (void)g_pipeline.offer_heading(heading);
  const nav::NavAccuracy<float> a = g_pipeline.accuracy();
  for (int i = 0; i < 3; ++i) {
    g_acc_out[i] = a.euler_sigma_rad(i);
    g_acc_out[3 + i] = a.pos_sigma_m(i);
  }
  g_acc_out[6] = static_cast<float>(a.valid | (a.mode << 4));
}

#ifdef GFINS_PROBE_STEPS
// qemu_startup.cpp: the QEMU build (gfins_nav_qemu) runs a bounded number of steps and exits.
extern "C" [[noreturn]] void gfins_probe_exit(int code);
extern "C" void gfins_probe_report(const volatile float* values, int n);
extern "C" void gfins_probe_print(const char* text);

// The filter's operations one at a time (filter_rig.hpp: the rig the host's callgrind and Google
// Benchmark figures use), each call in gfins_filter_op so that m4f_step_cycles.sh finds them in
// the trace: kFilterOpCalls calls of each operation, in the order of kFilterOps, which the run
// announces on a line "FILTER-OPS calls name name ..." before the first.
constexpr int kFilterOpCalls = 5;
gfins::bench::FilterRig<float>* g_rig = nullptr;
volatile int g_filter_accepted;

extern "C" [[gnu::noinline]] void gfins_filter_op(gfins::bench::FilterOp op) {
  g_filter_accepted = g_filter_accepted + (g_rig->run(op) ? 1 : 0);
}

// Out of line and named: the trace's segments of gfins_filter_op end when the PC is back here.
extern "C" [[gnu::noinline]] void gfins_run_filter_ops() {
  static gfins::bench::FilterRig<float> rig;
  g_rig = &rig;
  if (!rig.ok()) gfins_probe_exit(4);
  char line[160] = "FILTER-OPS 5";
  static_assert(kFilterOpCalls == 5, "the announced count");
  std::size_t pos = 12;
  for (const gfins::bench::FilterOp op : gfins::bench::kFilterOps) {
    line[pos++] = ' ';
    for (const char* c = gfins::bench::to_string(op); *c != 0 && pos + 2 < sizeof line; ++c) {
      line[pos++] = *c;
    }
  }
  line[pos++] = '\n';
  line[pos] = 0;
  gfins_probe_print(line);
  for (const gfins::bench::FilterOp op : gfins::bench::kFilterOps) {
    for (int k = 0; k < kFilterOpCalls; ++k) gfins_filter_op(op);
  }
  // Every update accepted, as on the host (the rig is at rest: zero innovations).
  if (g_filter_accepted != kFilterOpCalls * static_cast<int>(std::size(gfins::bench::kFilterOps))) {
    gfins_probe_exit(5);
  }
}
static_assert(GFINS_PROBE_STEPS < gfins::probe::kSamples, "one recorded sample per step");
static_assert(GFINS_PROBE_STEPS == gfins::probe::kExpectedSteps,
              "the expected result in probe_samples.hpp is for this many steps");

// What the DMA would have written for sample k: the workload's codes (probe_samples.hpp).
static void dma_sample(int k) {
  const auto& c = gfins::probe::kCounts[static_cast<std::size_t>(k)];
  for (std::size_t j = 0; j < c.size(); ++j) g_adc_counts[j] = c[j];
}
#endif

int main() {
  if (!g_pipeline.configure(make_config()).is_ok()) return 1;
#ifdef GFINS_PROBE_STEPS
  dma_sample(0);
#endif
  g_pipeline.start_at(initial_state(), read_adc());
#ifdef GFINS_PROBE_STEPS
  for (int i = 1; i <= GFINS_PROBE_STEPS; ++i) {
    dma_sample(i);
#else
  for (;;) {
#endif
    g_adc_seq = g_adc_seq + 1;
    g_adc_t_ns = g_adc_t_ns + 1000000;
    gfins_nav_step();
#ifndef GFINS_PROBE_STEPS
    // Not in the QEMU build: m4f_step_cycles.sh traces the per-sample step alone.
    if (g_adc_seq % 10 == 0) gfins_filter_step();
#endif
  }
#ifdef GFINS_PROBE_STEPS
  // The state after the last step (attitude, velocity, position), for m4f_step_cycles.sh to
  // compare with the x86 float pipeline on the same samples (probe_samples.hpp kExpectedOut).
  gfins_probe_report(g_out, 10);
  gfins_run_filter_ops();
  gfins_probe_exit(0);
#endif
}
