#!/usr/bin/env bash
# First command of the README: install Debian packages, build the release preset and run the
# main job (the host simulation of the default scenario through the float32 navigation core).
set -euo pipefail
cd "$(dirname "$0")/.."

./scripts/install-deps.sh
cmake --preset host-release
cmake --build --preset host-release
./build/host-release/host_sim/app/gfins-sim "$@"
