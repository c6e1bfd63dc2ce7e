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
# filter's start are the same for any N and cancel (tests/bench/filter_ops.hpp).
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
if ! (( n2 > n1 && n1 > 0 )); then
  echo "callgrind_filter.sh: need 0 < N1 < N2" >&2
  exit 2
fi
gfins_scratch_dir

printf '%-7s %-14s %12s %12s %10s\n' scalar operation "Ir(N1=${n1})" "Ir(N2=${n2})" "Ir/call"
for scalar in float double; do
  for op in propagate zupt zaru gnss-position gnss-velocity heading; do
    declare -A ir=()
    for tag in N1 N2; do
      n="${n1}"; [[ "${tag}" == N2 ]] && n="${n2}"
      f="${gfins_scratch}/callgrind.${scalar}.${op}.${tag}.out"
      if ! valgrind --tool=callgrind --callgrind-out-file="${f}" "${exe}" "${scalar}" "${op}" "${n}" \
        >/dev/null 2>"${f}.log"; then
        echo "callgrind_filter.sh: ${exe} ${scalar} ${op} ${n} failed:" >&2
        cat "${f}.log" >&2
        exit 1
      fi
      ir[${tag}]="$(gfins_total_ir "${f}")"
    done
    per_call="$(awk -v a="${ir[N1]}" -v b="${ir[N2]}" -v n1="${n1}" -v n2="${n2}" \
                 'BEGIN { printf "%.0f", (b - a) / (n2 - n1) }')"
    printf '%-7s %-14s %12s %12s %10s\n' "${scalar}" "${op}" "${ir[N1]}" "${ir[N2]}" "${per_call}"
    unset ir
  done
done
