#!/usr/bin/env bash
# Second command of the README, and what CI runs (.ci/run): install packages, check formatting,
# build every preset and run the whole test suite. Exits non-zero on the first failure.
set -euo pipefail
cd "$(dirname "$0")/.."
jobs=${GFINS_JOBS:-$(nproc)}
step() { printf '\n=== %s (%s)\n' "$*" "$(date +%T)"; }

step "install packages"
./scripts/install-deps.sh

step "clang-format check"
./scripts/check-format.sh

step "host-debug (ASan + UBSan): build"
cmake --preset host-debug >/dev/null
cmake --build --preset host-debug -j "$jobs"

step "host-release: build"
cmake --preset host-release >/dev/null
cmake --build --preset host-release -j "$jobs"

step "clang-tidy"
./scripts/check-tidy.sh build/host-release

if [ -f toolchains/arm-none-eabi-cortex-m4f.cmake ]; then
  step "cortex-m4f: bare-metal build of the navigation core"
  cmake --preset cortex-m4f >/dev/null
  cmake --build --preset cortex-m4f -j "$jobs"
fi

step "host-release: tests"
ctest --preset host-release -j "$jobs"

step "host-debug (ASan + UBSan): tests"
ctest --preset host-debug -j "$jobs"
