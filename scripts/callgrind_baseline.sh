#!/usr/bin/env bash
# Instructions per sample of the core's step and of the straightforward baseline, side by side in
# one process (tests/bench/baseline_bench.cpp), counted by callgrind, and their ratio.
#
# Usage: scripts/callgrind_baseline.sh [build-dir] [samples]
#   build-dir  Release build with GFINS_BUILD_BENCHMARKS=ON (default build/host-release); build
#              target gfins_baseline_bench first
#   samples    samples per measured section (default 20000)
# The program dumps callgrind's counters after each section (CALLGRIND_DUMP_STATS_AT), so each
# dump holds exactly one section's instructions: set-up and printing are in none of them.
set -euo pipefail

# shellcheck source=scripts/measure_common.sh source-path=SCRIPTDIR
source "$(dirname "${BASH_SOURCE[0]}")/measure_common.sh"
gfins_build_dir "$@" build/host-release
samples="${2:-20000}"
exe="${gfins_build}/tests/bench/gfins_baseline_bench"
gfins_need_file "${exe}" "build target gfins_baseline_bench"
gfins_need_command valgrind "apt-get install valgrind"
gfins_scratch_dir
out_dir="${gfins_scratch}"
valgrind --tool=callgrind --callgrind-out-file="${out_dir}/cg.out" "${exe}" "${samples}" \
  >/dev/null 2>"${out_dir}/log" || { cat "${out_dir}/log" >&2; exit 1; }
python3 - "${out_dir}" "${samples}" <<'PY'
import glob, re, sys
out_dir, n = sys.argv[1], int(sys.argv[2])
ir = {}
for f in glob.glob(out_dir + "/cg.out*"):
    desc, total = None, None
    for line in open(f, errors="replace"):
        m = re.match(r"desc: Trigger: Client Request: (.*)", line)
        if m:
            desc = m.group(1).strip()
        m = re.match(r"(summary|totals): (\d+)", line)
        if m and total is None:
            total = int(m.group(2))
    if desc and total is not None:
        ir[desc] = total / n
print("%-7s %-6s %12s %12s %8s" % ("scalar", "comp", "core Ir", "baseline Ir", "ratio"))
for scalar in ("float", "double"):
    for comp in ("none", "paper", "exact"):
        c, b = ir["core %s %s" % (scalar, comp)], ir["baseline %s %s" % (scalar, comp)]
        print("%-7s %-6s %12.1f %12.1f %8.2f" % (scalar, comp, c, b, b / c))
print("(instructions per sample, %d samples per section)" % n)
PY
