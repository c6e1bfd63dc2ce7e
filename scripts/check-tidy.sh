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
mapfile -t files < <(git ls-files 'nav_core/*.cpp' 'hal/*.cpp' 'drivers/*.cpp' 'firmware/*.cpp' 'host_sim/*.cpp' |
  grep -v '/baremetal/' |
  python3 -c 'import json, os, sys
db = {os.path.realpath(os.path.join(e["directory"], e["file"]))
      for e in json.load(open(sys.argv[1]))}
for line in sys.stdin:
    f = line.strip()
    if os.path.realpath(f) in db:
        print(f)' "$build/compile_commands.json")
[ ${#files[@]} -gt 0 ] || { echo "check-tidy: nothing to check"; exit 0; }
log=$(mktemp)
trap 'rm -f "$log"' EXIT
# A finding makes clang-tidy (and so xargs) exit non-zero: record it instead of letting set -e
# end the script before the findings are printed.
tidy_status=0
printf '%s\n' "${files[@]}" |
  xargs -P "${GFINS_JOBS:-$(nproc)}" -n 1 clang-tidy -p "$build" --quiet \
    --extra-arg=-Wno-unknown-warning-option >"$log" 2>&1 || tidy_status=$?
{ grep -v -E '^[0-9]+ warnings? generated|^Suppressed|^Use -header-filter' "$log" || true; }
if [ "$tidy_status" -ne 0 ] || grep -q -E 'error:|warning:' "$log"; then
  echo "check-tidy: findings above (clang-tidy exit status $tidy_status)" >&2
  exit 1
fi
echo "clang-tidy: ${#files[@]} files clean"
