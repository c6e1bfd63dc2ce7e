#!/usr/bin/env bash
# Runs the curated .clang-tidy set on the project's own translation units (not tests) using the
# compile database of a configured build folder (default build/host-release).
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build/host-release}
[ -f "$build/compile_commands.json" ] || { echo "check-tidy: no $build/compile_commands.json" >&2; exit 1; }
mapfile -t files < <(git ls-files 'nav_core/*.cpp' 'hal/*.cpp' 'drivers/*.cpp' 'firmware/*.cpp' 'host_sim/*.cpp' | grep -v '/baremetal/')
[ ${#files[@]} -gt 0 ] || { echo "check-tidy: nothing to check"; exit 0; }
printf '%s\n' "${files[@]}" | xargs -P "${GFINS_JOBS:-$(nproc)}" -n 1 clang-tidy -p "$build" --quiet --extra-arg=-Wno-unknown-warning-option 2>&1 \
  | grep -v -E '^[0-9]+ warnings? generated|^Suppressed|^Use -header-filter' | tee /tmp/gfins-tidy.log
if grep -q -E 'error:|warning:' /tmp/gfins-tidy.log; then
  echo "check-tidy: findings above" >&2
  exit 1
fi
echo "clang-tidy: ${#files[@]} files clean"
