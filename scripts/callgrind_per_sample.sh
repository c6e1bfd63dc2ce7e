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
gfins_need_counts "${n1}" "${n2}"
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
    gfins_ir_per_unit "${out_dir}/callgrind.${scalar}.${comp}" "${n1}" "${n2}" \
      "${exe}" "${scalar}" "${comp}"
    printf '%-7s %-6s %14s %14s %12s\n' "${scalar}" "${comp}" "${gfins_ir1}" "${gfins_ir2}" \
      "${gfins_per_unit}"
  done
done
