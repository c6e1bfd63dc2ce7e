# shellcheck shell=sh disable=SC2154  # sourced by vm-test.sh, which sets gpiochip, pull, rate
# Stage "fw" of the in-VM test (sourced by vm-test.sh): the unchanged gfins-fw from
# gfins-fw-vboard.toml (the ADC chip model inside the process, paced by the REAL falling
# data-ready edges of the gpio-sim line through libgpiod, output on the REAL vcan0 through
# SocketCAN) for a fixed number of edges while candump records; then assertions on the decoded
# recording: the epoch count, continuous counters and valid CRCs (gfins-can decode exit 0 and the
# sample counter's spacing), the waits before the first and after the last edge published as
# no-sample epochs, values within one quantisation step of the host-only run of the
# same configuration (run.sh), epoch by epoch keyed by the sample counter, and zero faults in
# the health frames.
# needs: build:firmware/app/gfins-fw
# needs: build:host_sim/can_tool/gfins-can
# needs: repo:scripts/vboard/fw-common.sh:/vboard/fw-common.sh
# needs: repo:scripts/vboard/fw-compare.awk:/vboard/fw-compare.awk
# needs: repo:docs/can/gfins.dbc:/vboard/gfins.dbc
# needs: repo:scripts/vboard/gfins-fw-vboard.toml:/opt/gfins/etc/vboard.toml
# needs: cache:fw/scenarios/vboard-rest.toml:/opt/share/gfins/scenarios/vboard-rest.toml
# needs: cache:fw/ref.csv:/vboard/fw-ref.csv
. /vboard/fw-common.sh
fw_seconds=4
edges=$((rate * fw_seconds))
# The default epoch divider (docs/can-interface.md): one epoch per 10 samples, the first at
# sample 0, so samples 0 .. edges-1 give ceil(edges / 10) epochs.
divider=10
gfins-fw --config $fw_cfg --scenario-dir $fw_scenarios --check-config >/tmp/fw-check.log 2>&1
rc=$?
check fw-config "gfins-fw --check-config exit $rc ($(head -c 200 /tmp/fw-check.log | tr '\n' ' '))" [ $rc -eq 0 ]

candump -L vcan0 >/tmp/fw-candump.log &
dump_pid=$!
fw_start /tmp/fw-run.log
check fw-start "gfins-fw opened the gpio-sim line and vcan0 and its loop runs" [ $? -eq 0 ]
drdy-toggle "$pull" "$rate" $edges >/tmp/fw-toggle.log
sleep 1
fw_stop
kill $dump_pid 2>/dev/null
wait $dump_pid 2>/dev/null
sed 's/^/VBOARD-LOG fw: /' /tmp/fw-run.log | tail -n 8
cat /tmp/fw-toggle.log
# SIGTERM interrupts the data-ready wait (EINTR): a stop, not an ADC fault, so no read error.
read_errors=$(grep -c 'ADC read failed' /tmp/fw-run.log)
check fw-exit "gfins-fw ended on SIGTERM with status $fw_rc, $read_errors 'ADC read failed' line(s) in its log" \
  [ $fw_rc -eq 0 -a "$read_errors" -eq 0 ]
skipped=$(sed -n 's/.*skipped=\([0-9]*\).*/\1/p' /tmp/fw-toggle.log)

gfins-can decode /tmp/fw-candump.log --view csv -o /tmp/fw.csv --quiet 2>/tmp/fw-decode.log
dec_rc=$?
summary=$(grep '^summary:' /tmp/fw-decode.log)
echo "VBOARD-INFO fw decode: $summary"
# The problems themselves (FILE:LINE: kind: what), so a failure says what it was.
grep -v '^summary:' /tmp/fw-decode.log | head -n 10 | sed 's/^/VBOARD-LOG fw decode: /'
check fw-decode-clean "gfins-can decode exit $dec_rc (0: every frame's CRC valid, counters continuous, no issue)" \
  [ $dec_rc -eq 0 ]

# The firmware publishes from its start, before the toggler's first edge, and until SIGTERM, a
# second after the last edge: the periods without a conversion go out as no-sample epochs
# (docs/faults.md, "While the ADC delivers nothing": StatusFlags bits 2 InputInvalid, 5 "a value
# not available", 13 HealthDegraded and 15 DataReadyLost, navigation values not available). The
# ones before the first conversion count the loop's periods from its start; the first conversion
# is sample 0 (the counter restarts once, a note for gfins-can). Split the decoded epochs: those
# with a sample (bits 2 and 5 clear in this fault-free run) must be the 2000 edges' epochs, whole
# and in order; the no-sample ones may only lead or trail them, never fall between.
fl=$(csv_col /tmp/fw.csv StatusFlags)
sc=$(csv_col /tmp/fw.csv SampleCount)
set -- $(awk -F, -v f="$fl" -v c="$sc" -v d=$divider '
  # bit(v, 2^b): busybox awk has no "^" (no math support)
  function bit(v, p) { return int(v / p) % 2 }
  NR == 1 { print > "/tmp/fw-samples.csv"; next }
  {
    nosample = bit($f, 4) && bit($f, 32)
    if (!nosample) {
      print > "/tmp/fw-samples.csv"
      if (n && trail) inner += trail  # no-sample epochs between two with a sample
      trail = 0
      if ($c != n * d) ++bad
      ++n
      last = $c
      next
    }
    if (!bit($f, 8192) || !bit($f, 32768)) ++badbits
    if (!n) { if (lead && $c != prev + d) ++leadgap; ++lead; prev = $c; next }
    if (!trail && $c != last + d) ++trailgap
    if (trail && $c != prev + d) ++trailgap
    ++trail
    prev = $c
  }
  END { print n + 0, lead + 0, trail + 0, inner + 0, bad + 0, leadgap + 0, trailgap + 0, badbits + 0 }' /tmp/fw.csv)
epochs=$1 lead=$2 trail=$3 inner=$4 gaps=$5 leadgap=$6 trailgap=$7 badbits=$8
expect=$(((edges + divider - 1) / divider))
check fw-epochs "$epochs epochs with a sample decoded, expected $expect ($edges edges at $rate Hz, divider $divider, toggler skipped ${skipped:-?}); no-sample epochs: $lead before the first edge, $trail after the last, $inner between (expected 0)" \
  [ "$epochs" -eq $expect -a "${skipped:-1}" -eq 0 -a "$inner" -eq 0 ]

# Counters continuous, checked on the decoded sample counter itself: the epochs with a sample
# 0, 10, 20, ...; the no-sample epochs after the last edge continue it (2000, 2010, ...), those
# before the first edge are consecutive among themselves.
check fw-sample-counter "$gaps epochs with a sample whose counter is not 10 x their index (first 0); $trailgap breaks after the last edge, $leadgap before the first" \
  [ "$gaps" -eq 0 -a "$trailgap" -eq 0 -a "$leadgap" -eq 0 ]
# The waits are published, not silent: the toggler starts after the firmware and stops a second
# before SIGTERM, so both kinds exist, each with its fault bits.
check fw-nosample-epochs "$lead + $trail no-sample epochs (bits 2 and 5), $badbits of them without bits 13/15" \
  [ "$lead" -gt 0 -a "$trail" -gt 0 -a "$badbits" -eq 0 ]

# Equal to the host-only run epoch by epoch, keyed by the sample counter, every field within ONE
# quantisation step of its signal in docs/can/gfins.dbc (fw-compare.awk says why one step, and
# which fields must be equal: counters, flags, mode, ids). Both runs quantise the same float32
# navigation (it integrates with the nominal period times the sequence step, never the edge
# times); only libm's CPU-dependent code paths (the reference runs on the host's CPU, the VM on
# QEMU's `-cpu max`) may move a value on a rounding boundary by one step. Any real difference (a
# conversion taken from the wrong sample, a lost edge, a different calibration) is more, or a
# missing epoch. Not compared: the frame's log line, its capture time and the edge time
# (TimeUs), which are the VM's clock; and in StatusFlags (docs/can-interface.md) bit 15
# "data-ready lost" with bit 13 "health degraded", which the VM run sets, rightly, for the waits
# before the first edge (held 1 s); they are asserted to clear within the first 2 s of edges,
# and never to reappear.
echo "VBOARD-INFO fw guest CPU $(grep -m1 '^flags' /proc/cpuinfo | tr -s ' \t' ' ')"
set -- $(awk -F, -v rate="$rate" -f /vboard/fw-compare.awk /vboard/gfins.dbc /vboard/fw-ref.csv /tmp/fw-samples.csv)
check fw-compare-inputs "DBC, reference and VM CSV read (problem: ${10:-none})" [ "${10:-?}" = - ]
check fw-equals-host "$1 of $epochs epochs equal the host-only run within one quantisation step per field, $2 differ, $3 not in it ($6 fields compared, $4 exactly one step apart, largest difference $5 step(s); first out of tolerance: $7)" \
  [ "$1" -eq "$epochs" -a "$2" -eq 0 -a "$3" -eq 0 -a "$epochs" -gt 0 ]
measure fw-fields-one-step-apart "$4"
check fw-startup-flags "StatusFlags bits 13/15 (waits before the first edge) last set at sample $8, limit $9" \
  [ "$8" -lt "$9" ]

set -- $(health_faults /tmp/fw.csv)
check fw-health-zero "health fields in $2 epochs, fault counters sum $1 (max per field $3)" \
  [ "$1" -eq 0 -a "$2" -gt 0 ]
