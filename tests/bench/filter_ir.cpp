// Callgrind driver: N calls of one aided-filter operation, so that scripts/callgrind_filter.sh
// can take the instructions per call as (Ir(N2) − Ir(N1)) / (N2 − N1); the set-up (process
// start, configuration, the filter's start) is the same for any N and cancels.
//
//   gfins_filter_ir <float|double> <propagate|zupt|zaru|gnss-position|gnss-velocity|heading> <N>
// Prints a checksum of the covariance so the work cannot be optimised away; exits 1 when the
// filter refuses an operation (the figure would not be the cost of a whole update).
#include <cstdio>
#include <cstdlib>
#include <string>

#include "filter_ops.hpp"

namespace {

template <typename T>
int run(gfins::bench::FilterOp op, long n) {
  gfins::bench::FilterRig<T> rig;
  if (!rig.ok()) {
    std::fprintf(stderr, "gfins_filter_ir: filter configuration rejected\n");
    return 1;
  }
  for (long i = 0; i < n; ++i) {
    if (!rig.run(op)) {
      std::fprintf(stderr, "gfins_filter_ir: %s refused at call %ld\n", to_string(op), i + 1);
      return 1;
    }
  }
  std::printf("%s %ld calls, checksum %.9g\n", to_string(op), n, rig.checksum());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  gfins::bench::FilterOp op{};
  char* end = nullptr;
  const long n = argc == 4 ? std::strtol(argv[3], &end, 10) : 0;
  if (argc != 4 || !gfins::bench::parse_op(argv[2], op) || end == argv[3] || *end != '\0' ||
      n < 0) {
    std::fprintf(stderr,
                 "usage: %s <float|double> "
                 "<propagate|zupt|zaru|gnss-position|gnss-velocity|heading> <N>\n",
                 argc > 0 ? argv[0] : "gfins_filter_ir");
    return 2;
  }
  const std::string scalar = argv[1];
  if (scalar == "float") return run<float>(op, n);
  if (scalar == "double") return run<double>(op, n);
  std::fprintf(stderr, "gfins_filter_ir: scalar must be float or double\n");
  return 2;
}
