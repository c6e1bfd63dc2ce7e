// Side by side in one process: nav_core's per-sample step (NavPipeline<T>::process) against the
// straightforward baseline of the same step (baseline_step.hpp), on the same counts, float32 and
// double, each compensator. Prints time per sample of both and their ratio.
//
//   gfins_baseline_bench [samples]        time: best of 5 runs of `samples` (default 200000)
//   scripts/callgrind_baseline.sh         instructions: runs this program under callgrind, which
//                                         it detects; each measured section is then dumped
//                                         separately (CALLGRIND_DUMP_STATS_AT) and the script
//                                         prints Ir per sample of both and their ratio.
// The inputs (host_sim's sample source) and the restart at each wrap of the 1 s buffer are those
// of bench_scenario.hpp.
#include <valgrind/callgrind.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>

#include "baseline_step.hpp"
#include "bench_scenario.hpp"

namespace gfins::bench {
namespace {

/// Replay of the buffer through the baseline, restarting exactly as Replay does.
template <typename T>
class BaselineReplay {
 public:
  BaselineReplay(nav::CompensatorKind kind, const Workload& w)
      : buf_(w.samples),
        init_(initial_state<T>(w)),
        base_(make_config<T>(kind), make_pipeline<T>(kind, w).solver()) {
    base_.start(init_, buf_[0]);
  }
  void step() {
    ++seq_;
    t_ns_ += 1000000;
    RawSample s = buf_[i_];
    s.t_ns = t_ns_;
    s.seq = seq_;
    if (i_ == 0) {
      nav::NavState<T> init = init_;
      init.seq = seq_;
      init.t_ns = t_ns_;
      base_.start(init, s);
    } else {
      base_.step(s);
    }
    i_ = (i_ + 1 == buf_.size()) ? 0 : i_ + 1;
  }
  const nav::NavState<T>& state() const { return base_.state(); }

 private:
  const std::vector<RawSample>& buf_;
  nav::NavState<T> init_;
  BaselineStep<T> base_;
  std::size_t i_ = 1;
  std::uint32_t seq_ = 0;
  std::int64_t t_ns_ = 0;
};

volatile double g_sink = 0.0;

template <typename T>
void consume(const nav::NavState<T>& s) {
  g_sink = g_sink + static_cast<double>(s.q_nb.w() + s.v_n.sum() + s.r_n.sum());
}

/// Best-of-5 ns per sample of `replay.step()`.
template <typename R>
double time_ns(R& replay, long samples) {
  double best = 1e300;
  for (int rep = 0; rep < 5; ++rep) {
    const auto t0 = std::chrono::steady_clock::now();
    for (long n = 0; n < samples; ++n) replay.step();
    const auto t1 = std::chrono::steady_clock::now();
    best = std::min(best, std::chrono::duration<double, std::nano>(t1 - t0).count() /
                              static_cast<double>(samples));
  }
  return best;
}

template <typename T>
void run(const char* scalar, nav::CompensatorKind kind, const Workload& buf, long samples,
         bool under_callgrind) {
  Replay<T> core(kind, buf);
  BaselineReplay<T> base(kind, buf);
  const std::string tag = std::string(scalar) + " " + nav::to_string(kind);
  if (under_callgrind) {
    // One dump per section: set-up above and printing below are not in either.
    const std::string setup = "setup " + tag;
    const std::string core_tag = "core " + tag;
    const std::string base_tag = "baseline " + tag;
    CALLGRIND_DUMP_STATS_AT(setup.c_str());
    for (long n = 0; n < samples; ++n) core.step();
    CALLGRIND_DUMP_STATS_AT(core_tag.c_str());
    for (long n = 0; n < samples; ++n) base.step();
    CALLGRIND_DUMP_STATS_AT(base_tag.c_str());
  } else {
    const double ns_core = time_ns(core, samples);
    const double ns_base = time_ns(base, samples);
    std::printf("%-7s %-6s %12.1f %12.1f %8.2f\n", scalar, nav::to_string(kind), ns_core, ns_base,
                ns_base / ns_core);
  }
  consume(core.pipeline().state());
  consume(base.state());
}

}  // namespace
}  // namespace gfins::bench

int main(int argc, char** argv) {
  namespace b = gfins::bench;
  namespace nav = gfins::nav;
  try {
    const bool cg = RUNNING_ON_VALGRIND != 0;
    const long samples = argc > 1 ? std::strtol(argv[1], nullptr, 10) : (cg ? 20000 : 200000);
    if (samples <= 0) {
      std::fprintf(stderr, "usage: %s [samples > 0]\n", argv[0]);
      return 2;
    }
    const b::Workload buf = b::make_workload();
    if (!cg) {
      std::printf("%ld samples per run, best of 5; ns per sample\n", samples);
      std::printf("%-7s %-6s %12s %12s %8s\n", "scalar", "comp", "core", "baseline", "ratio");
    }
    for (const auto kind : {nav::CompensatorKind::kNone, nav::CompensatorKind::kPaper,
                            nav::CompensatorKind::kExact}) {
      b::run<float>("float", kind, buf, samples, cg);
    }
    for (const auto kind : {nav::CompensatorKind::kNone, nav::CompensatorKind::kPaper,
                            nav::CompensatorKind::kExact}) {
      b::run<double>("double", kind, buf, samples, cg);
    }
    if (cg) std::printf("%ld samples per section\n", samples);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "gfins_baseline_bench: %s\n", e.what());
    return 1;
  }
  return 0;
}
