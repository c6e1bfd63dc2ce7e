#!/usr/bin/env bash
# Runs the curated .clang-tidy set on the project's own translation units (not tests) using the
# compile database of a configured build folder (default build/host-release). Exits 1 when
# clang-tidy reports anything or fails to run.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build/host-release}
[ -f "$build/compile_commands.json" ] || { echo "check-tidy: no $build/compile_commands.json" >&2; exit 1; }
# Only the files this build compiles: a file of another configuration (no_plugin_boards.cpp, built
# when GFINS_SIM_BOARD is OFF) has no entry, and clang-tidy would guess its flags from a neighbour.
# A file compiled twice (by two targets) has two entries, and clang-tidy would check it once per
# entry: the first entry of each file goes into a database of its own.
# clang-tidy 22 (Debian 12's clang-tidy-22): from version 22 on clang-tidy no longer matches its
# checks against the declarations of system headers (Eigen, toml++, spdlog, CLI11, libstdc++),
# whose findings it then discarded; version 14 spent most of its time there, 3-4 times the time
# of 22 on the same files and checks (docs/ci.md, "clang-tidy 22"). GFINS_CLANG_TIDY names another.
tidy=${GFINS_CLANG_TIDY:-clang-tidy-22}
command -v "$tidy" >/dev/null 2>&1 || {
  echo "check-tidy: $tidy not found (scripts/install-deps.sh installs clang-tidy-22)" >&2
  exit 1
}
db_dir=$(mktemp -d)
log=$(mktemp)
trap 'rm -rf "$db_dir" "$log"' EXIT
mapfile -t files < <(git ls-files 'nav_core/*.cpp' 'hal/*.cpp' 'drivers/*.cpp' 'firmware/*.cpp' 'host_sim/*.cpp' |
  grep -v -e '/baremetal/' -e '_double\.cpp$' |
  python3 -c 'import json, os, sys
entries = json.load(open(sys.argv[1]))
first = {}
for e in entries:
    first.setdefault(os.path.realpath(os.path.join(e["directory"], e["file"])), e)
json.dump(list(first.values()), open(os.path.join(sys.argv[2], "compile_commands.json"), "w"))
# The core first: its explicit-instantiation files take the longest (up to two minutes), and
# started last they would leave one core idle at the end.
files = [f for f in (line.strip() for line in sys.stdin) if os.path.realpath(f) in first]
for f in sorted(files, key=lambda f: not f.startswith("nav_core/")):
    print(f)' "$build/compile_commands.json" "$db_dir")
[ ${#files[@]} -gt 0 ] || { echo "check-tidy: nothing to check"; exit 0; }
# The templates are checked once, for float, the board's scalar: the double instantiation is the
# same source with T = double, and checking it doubled the cost of the most expensive files. The
# core's double instantiations are files of their own (*_double.cpp, left out above); the
# calibration solvers' are behind GFINS_NAV_FLOAT_ONLY, as in the bare-metal build.
# A finding makes clang-tidy (and so xargs) exit non-zero: record it instead of letting set -e
# end the script before the findings are printed.
tidy_status=0
printf '%s\n' "${files[@]}" |
  xargs -P "${GFINS_JOBS:-$(nproc)}" -n 1 "$tidy" -p "$db_dir" --quiet \
    --extra-arg=-Wno-unknown-warning-option --extra-arg=-DGFINS_NAV_FLOAT_ONLY \
    >"$log" 2>&1 || tidy_status=$?
{ grep -v -E '^[0-9]+ warnings? generated|^Suppressed|^Use -header-filter' "$log" || true; }
if [ "$tidy_status" -ne 0 ] || grep -q -E 'error:|warning:' "$log"; then
  echo "check-tidy: findings above (clang-tidy exit status $tidy_status)" >&2
  exit 1
fi
echo "clang-tidy: ${#files[@]} files clean"
