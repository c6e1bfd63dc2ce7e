#!/usr/bin/env bash
# First command of the README: install Debian packages, build the release preset, then the main
# job: a scenario in → gfins-fw, the firmware, on the simulated board (ADS131M06 chip model behind
# the real driver, the real sample loop and CAN publisher) → a candump log out → a short decoded
# summary.
#
#   scripts/bootstrap.sh [SCENARIO] [gfins-fw options...]    (default scenario: rest)
#
# The log goes to out/gfins-fw-<scenario>.log. The summary comes from gfins-can (the CAN decoder)
# when it is built; otherwise gfins-fw's own end-of-run summary is what you see.
set -euo pipefail
cd "$(dirname "$0")/.."

./scripts/install-deps.sh
cmake --preset host-release
cmake --build --preset host-release
# The programs by name for the README's rows: installed in out/gfins (bin/ and their data in
# share/gfins; docs/install.md). `export PATH="$PWD/out/gfins/bin:$PATH"` puts them on PATH.
cmake --install build/host-release --prefix "$PWD/out/gfins" >/dev/null

scenario="${1:-rest}"
if [[ $# -gt 0 ]]; then shift; fi
mkdir -p out
log="out/gfins-fw-$(basename "${scenario%.toml}").log"
bin=./build/host-release
# --calibration "": the simulated board's factory calibration (its scenario's true parameters).
"$bin/firmware/app/gfins-fw" --sim "$scenario" --calibration "" --can-log "$log" "$@"
echo "candump log: $log ($(wc -l < "$log") frames)"
if [[ -x "$bin/host_sim/can_tool/gfins-can" ]]; then
  "$bin/host_sim/can_tool/gfins-can" decode "$log" --view none
else
  echo "note: gfins-can is not in this build; the summary above is gfins-fw's own."
fi
# What the board's aiding does: the 10-minute stop-and-go drive with GNSS, aided and unaided from
# the same simulated sensors, errors against the truth side by side (docs/navigation-accuracy.md;
# a few seconds).
echo
"$bin/host_sim/app/gfins-sim" aided urban-stop-and-go -o out/aided-urban-stop-and-go --no-plot
echo "programs installed in out/gfins/bin: export PATH=\"\$PWD/out/gfins/bin:\$PATH\" (README, Running things)"
