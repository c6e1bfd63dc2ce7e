#!/usr/bin/env bash
# Second command of the README, and what CI runs (.ci/run): install packages, check formatting,
# build every preset, run the whole test suite, then clang-tidy. Exits non-zero on the first
# failure. GFINS_JOBS sets the build parallelism (default: all cores).
set -euo pipefail
cd "$(dirname "$0")/.."
jobs=${GFINS_JOBS:-$(nproc)}
start=$(date +%s)
step() { printf '\n=== %s (%s, +%ds)\n' "$*" "$(date +%T)" "$(($(date +%s) - start))"; }

step "install packages"
./scripts/install-deps.sh

step "clang-format check"
./scripts/check-format.sh

step "host-debug (ASan + UBSan): build"
cmake --preset host-debug >/dev/null
cmake --build --preset host-debug -j "$jobs"

step "host-debug (ASan + UBSan): unit tests"
ctest --preset host-debug -j "$jobs"

step "host-release: build (tests, tools, benchmarks)"
cmake --preset host-release >/dev/null
cmake --build --preset host-release -j "$jobs"

step "host-release: all tests, including the hour-long runs (label long)"
ctest --preset host-release -j "$jobs"

step "cortex-m4f: bare-metal build of the navigation core and the soft-double check"
cmake --preset cortex-m4f >/dev/null
cmake --build --preset cortex-m4f -j "$jobs"
./scripts/embedded_size.sh | tail -n 25

step "clang-tidy"
./scripts/check-tidy.sh build/host-release

step "all checks passed"
