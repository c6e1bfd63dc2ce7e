#!/usr/bin/env bash
# Writes the seed corpora of tests/fuzz/corpus/ (docs/reliability.md) from the project's own
# files and programs: usage `tests/fuzz/make_seeds.sh BUILD_DIR` (a release tree with gfins-sim,
# gfins-calibrate, gfins-fw and gfins-can-gen built). Findings kept as regression inputs are not touched:
# only files named seed-* are rewritten.
set -euo pipefail
cd "$(dirname "$0")/../.."
build=${1:?usage: make_seeds.sh BUILD_DIR}
corpus=tests/fuzz/corpus
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
rm -f "$corpus"/*/seed-*

# Text formats: the files the project ships or writes.
cp firmware/app/gfins-fw.toml "$corpus/firmware_config/seed-default.toml"
cp scripts/vboard/gfins-fw-vboard.toml "$corpus/firmware_config/seed-vboard.toml"
for f in host_sim/scenarios/*.toml; do cp "$f" "$corpus/scenario/seed-$(basename "$f")"; done
# Channel failures ([[sensors.failures]], docs/simulation.md): one of each kind.
{
  cat host_sim/scenarios/rest.toml
  for k in 'bias"\nbias_mg = 2.0' 'ramp"\nrate_mg_per_s = 5.0' 'noise"\nfactor = 8.0' \
    'saturation"\nlimit_g = 0.5' 'stuck"' 'dead"'; do
    printf '\n[[sensors.failures]]\nkind = "%b\nsensor = 3\nstart_s = 1.0\n' "$k"
  done
} >"$corpus/scenario/seed-failures.toml"
# Board faults ([[board.faults]], docs/simulation.md): one of each kind.
{
  cat host_sim/scenarios/rest.toml
  t=1
  for k in 'crc_error"' 'missed_edges"\ncount = 3' 'extra_edge"' 'silent_line"\ncount = 6' \
    'adc_reset"' 'saturated"\nsensor = 4\nduration_s = 0.05' 'stuck"\nsensor = 2\nduration_s = 0.2' \
    'can_refuse"\nduration_s = 0.5' 'bus_off"\nduration_s = 0.5' 'read_error"\ncount = 3' \
    'adc_dead"\nduration_s = 0.5'; do
    printf '\n[[board.faults]]\nkind = "%b\nat_s = %d.%d\n' "$k" $((t / 2)) $((t % 2 * 5))
    t=$((t + 1))
  done
} >"$corpus/scenario/seed-board-faults.toml"
"$build/host_sim/tools/gfins-calibrate" --means tests/golden/paper_tables_4_5.csv --latitude 24.8 \
  --adc-lsb 1.192e-6 --device-id board-001 --rho 0.1 -o "$tmp/cal.toml" >/dev/null
cp "$tmp/cal.toml" "$corpus/calibration_file/seed-paper.toml"

# Prefixed formats: the first byte picks the reader or the CRC sealing (see each target).
prefixed() {  # prefixed BYTE_OCTAL FILE OUT
  { printf "\\$1"; cat "$2"; } >"$3"
}
prefixed 000 tests/golden/paper_tables_4_5.csv "$corpus/calibration_tables/seed-means.csv"
printf 'attitude,fx_g,fy_g,fz_g\n1,0,0,1\n2,0,0,-1\n3,1,0,0\n' >"$tmp/poses.csv"
prefixed 001 "$tmp/poses.csv" "$corpus/calibration_tables/seed-poses.csv"
printf 't,v1,v2,v3,v4,v5,v6\n0,0.1,0.2,0.3,0.4,0.5,0.6\n0.001,0.1,0.2,0.3,0.4,0.5,0.6\n' \
  >"$tmp/volts.csv"
prefixed 002 "$tmp/volts.csv" "$corpus/calibration_tables/seed-volts.csv"

sed 's/^duration_s = .*/duration_s = 0.02/' host_sim/scenarios/rest.toml >"$tmp/short.toml"
"$build/host_sim/app/gfins-sim" run "$tmp/short.toml" --record "$tmp/rest.gfr" --no-plot \
  -o "$tmp/rest" >/dev/null
prefixed 001 "$tmp/rest.gfr" "$corpus/recording/seed-rest.gfr"
# Version 2 with frame records: the firmware recording an aided drive (its receiver's frames).
printf '[aiding]\nenabled = true\ntrack_heading_sigma_deg = 0.5\n' >"$tmp/vehicle.toml"
"$build/firmware/app/gfins-fw" --config "$tmp/vehicle.toml" --sim drive-gnss \
  --scenario-dir host_sim/scenarios --calibration "" --can-log "$tmp/drive.log" \
  --record "$tmp/drive.gfr" --duration 0.1 --watchdog none --log-level off
prefixed 001 "$tmp/drive.gfr" "$corpus/recording/seed-drive-frames.gfr"
for f in clean restart bad_crc sample_back time_jump out_of_range malformed_lines; do
  prefixed 001 "tests/golden/can/$f.log" "$corpus/can_log/seed-$f.log"
done
prefixed 000 tests/golden/can/crlf.log "$corpus/can_log/seed-crlf-unsealed.log"

# Binary formats, written field by field (each target's comment gives the layout).
python3 - "$corpus" <<'PY'
import struct, sys
corpus = sys.argv[1]
def put(name, data):
    open(f"{corpus}/{name}", "wb").write(data)
# can_frames: selector, shape (0: 8 bytes, CRC sealed by the harness), 8 data bytes, 1 unused.
# Selector i % 6: command, GNSS PositionNE, PositionD, Velocity, FixInfo, HeadingInput.
commands = b"".join(bytes([0, 0, op, 7, 0, 0, 0, 0, 0, 0, 0]) for op in range(1, 9))
put("can_frames/seed-commands", commands)
fix = b"".join(bytes([sel, 0, 0x10, 0, 0x20, 0, 0x30, 0, 0x11, 0, 0]) for sel in (1, 2, 3, 4))
put("can_frames/seed-gnss-fix", fix)
put("can_frames/seed-heading", bytes([5, 0, 0x40, 0x1F, 0x10, 0, 0x01, 0, 0x10, 0, 0]))
# hil_stream: byte 0 = 1 (the harness seals the CRC-32s), then frames 'G' 'H' type length ...
def frame(kind, body):
    n = 4 + len(body) + 4
    return b"GH" + bytes([kind, n]) + body + b"\0\0\0\0"
sample = struct.pack("<IIq6iI", 0, 100, 1_000_000, 1, -2, 3, -4, 5, -6, 0)
last = struct.pack("<IIq6iI", 1, 101, 2_000_000, 0, 0, 0, 0, 0, 0, 0)
ack = struct.pack("<IB3x", 0, 0)
can = struct.pack("<IB3x8s", 0x101, 8, bytes(range(8)))
can_in = struct.pack("<IB3x8s", 0x0C1, 8, bytes(range(8)))
put("hil_stream/seed-stream", b"\1" + frame(5, can_in) + frame(1, sample) + frame(2, last) +
    frame(3, ack) + frame(4, can))
# ads131m06: per transfer a mode byte (0: the chip's answer) and per data-ready wait a byte
# (0x01: the next edge; 0x19: two edges missed first); alternating, then fuzzed frames with
# sealed CRCs.
put("ads131m06/seed-clean", bytes([0x01, 0x00] * 32))
put("ads131m06/seed-fuzzed", bytes([0x01, 0x02] + list(range(24)) + [0x19, 0x06] +
                                   [0xFF] * 24 + [0x01, 0x00] * 8))
PY
echo "seeds written to $corpus"
