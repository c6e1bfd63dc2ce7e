#!/usr/bin/env bash
# Instructions per navigation sample, counted by callgrind (valgrind), for every configuration:
# scalar float/double × compensator none/paper/exact.
#
# Usage: scripts/callgrind_per_sample.sh [build-dir] [N1] [N2]
#   build-dir  a Release build with GFINS_BUILD_BENCHMARKS=ON (default: build/host-release), e.g.
#              cmake --preset host-release && cmake --build --preset host-release \
#                    --target gfins_pipeline_ir
#   N1, N2     sample counts of the two runs (default 20000 and 120000)
#
# Ir per sample = (Ir(N2) − Ir(N1)) / (N2 − N1): everything that does not depend on N (process
# start, the input buffer, configuration) cancels. With GFINS_CALLGRIND_KEEP=dir the callgrind
# output files are kept in dir for callgrind_annotate, e.g.
#   callgrind_annotate --auto=yes dir/callgrind.float.paper.N2.out
set -euo pipefail

# shellcheck source=scripts/measure_common.sh source-path=SCRIPTDIR
source "$(dirname "${BASH_SOURCE[0]}")/measure_common.sh"
gfins_build_dir "$@" build/host-release
build="${gfins_build}"
n1="${2:-20000}"
n2="${3:-120000}"
exe="${build}/tests/bench/gfins_pipeline_ir"
gfins_need_file "${exe}" "build target gfins_pipeline_ir (Release, GFINS_BUILD_BENCHMARKS=ON) first"
gfins_need_command valgrind "apt-get install valgrind"
if ! (( n2 > n1 && n1 > 0 )); then
  echo "callgrind_per_sample.sh: need 0 < N1 < N2" >&2
  exit 2
fi
build_type="$(sed -n 's/^CMAKE_BUILD_TYPE:[A-Z]*=//p' "${build}/CMakeCache.txt" 2>/dev/null || true)"
if [[ "${build_type}" != "Release" ]]; then
  echo "warning: ${build} is a '${build_type}' build; the documented figures are Release" >&2
fi

if [[ -n "${GFINS_CALLGRIND_KEEP:-}" ]]; then
  out_dir="${GFINS_CALLGRIND_KEEP}"
  mkdir -p "${out_dir}"
else
  gfins_scratch_dir
  out_dir="${gfins_scratch}"
fi

printf '%-7s %-6s %14s %14s %12s\n' scalar comp "Ir(N1=${n1})" "Ir(N2=${n2})" "Ir/sample"
for scalar in float double; do
  for comp in none paper exact; do
    declare -A ir=()
    for tag in N1 N2; do
      n="${n1}"; [[ "${tag}" == N2 ]] && n="${n2}"
      f="${out_dir}/callgrind.${scalar}.${comp}.${tag}.out"
      valgrind --tool=callgrind --callgrind-out-file="${f}" "${exe}" "${scalar}" "${comp}" "${n}" \
        >/dev/null 2>"${f}.log"
      ir[${tag}]="$(gfins_total_ir "${f}")"
    done
    per_sample="$(awk -v a="${ir[N1]}" -v b="${ir[N2]}" -v n1="${n1}" -v n2="${n2}" \
                   'BEGIN { printf "%.1f", (b - a) / (n2 - n1) }')"
    printf '%-7s %-6s %14s %14s %12s\n' "${scalar}" "${comp}" "${ir[N1]}" "${ir[N2]}" "${per_sample}"
    unset ir
  done
done
