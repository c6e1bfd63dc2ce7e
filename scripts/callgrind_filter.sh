#!/usr/bin/env bash
# Instructions per call of each aided-filter operation (propagation over 10 ms, ZUPT, ZARU, GNSS
# position, GNSS velocity, heading), float and double, counted by callgrind (valgrind).
#
# Usage: scripts/callgrind_filter.sh [build-dir] [N1] [N2]
#   build-dir  a Release build with GFINS_BUILD_BENCHMARKS=ON (default: build/host-release), e.g.
#              cmake --build --preset host-release --target gfins_filter_ir
#   N1, N2     call counts of the two runs (default 200 and 1200)
#
# Ir per call = (Ir(N2) − Ir(N1)) / (N2 − N1): the process start, the configuration and the
# filter's start are the same for any N and cancel (nav_core/baremetal/filter_rig.hpp).
set -euo pipefail

# shellcheck source=scripts/measure_common.sh source-path=SCRIPTDIR
source "$(dirname "${BASH_SOURCE[0]}")/measure_common.sh"
gfins_build_dir "$@" build/host-release
build="${gfins_build}"
n1="${2:-200}"
n2="${3:-1200}"
exe="${build}/tests/bench/gfins_filter_ir"
gfins_need_file "${exe}" "build target gfins_filter_ir (Release, GFINS_BUILD_BENCHMARKS=ON) first"
gfins_need_command valgrind "apt-get install valgrind"
gfins_need_counts "${n1}" "${n2}"
gfins_scratch_dir

printf '%-7s %-14s %12s %12s %10s\n' scalar operation "Ir(N1=${n1})" "Ir(N2=${n2})" "Ir/call"
for scalar in float double; do
  for op in propagate zupt zaru gnss-position gnss-velocity heading; do
    gfins_ir_per_unit "${gfins_scratch}/callgrind.${scalar}.${op}" "${n1}" "${n2}" \
      "${exe}" "${scalar}" "${op}"
    printf '%-7s %-14s %12s %12s %10.0f\n' "${scalar}" "${op}" "${gfins_ir1}" "${gfins_ir2}" \
      "${gfins_per_unit}"
  done
done
