// Callgrind driver: runs N per-sample pipeline steps so that scripts/callgrind_per_sample.sh can
// take the instruction count per sample as (Ir(N2) − Ir(N1)) / (N2 − N1); the set-up (the samples,
// made by the sample source before the loop; configuration, process start) is the same for any N
// and cancels.
//
//   gfins_pipeline_ir <float|double> <none|paper|exact> <samples>
// Prints a checksum of the final state so the work cannot be optimised away.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>

#include "bench_scenario.hpp"

namespace gfins::bench {
namespace {

template <typename T>
double run(nav::CompensatorKind kind, long samples) {
  const Workload w = make_workload();
  Replay<T> replay(kind, w);
  for (long n = 0; n < samples; ++n) replay.step();
  const auto& s = replay.pipeline().state();
  return static_cast<double>(s.q_nb.w() + s.v_n.sum() + s.r_n.sum() + s.w_b.sum());
}

}  // namespace
}  // namespace gfins::bench

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fprintf(stderr, "usage: %s <float|double> <none|paper|exact> <samples>\n", argv[0]);
    return 2;
  }
  try {
    const std::string scalar = argv[1];
    const auto kind = gfins::bench::parse_kind(argv[2]);
    const long samples = std::strtol(argv[3], nullptr, 10);
    double checksum = 0.0;
    if (scalar == "float") {
      checksum = gfins::bench::run<float>(kind, samples);
    } else if (scalar == "double") {
      checksum = gfins::bench::run<double>(kind, samples);
    } else {
      std::fprintf(stderr, "scalar must be float or double\n");
      return 2;
    }
    std::printf("%s %s %ld samples, checksum %.9g\n", argv[1], argv[2], samples, checksum);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "gfins_pipeline_ir: %s\n", e.what());
    return 1;
  }
  return 0;
}
