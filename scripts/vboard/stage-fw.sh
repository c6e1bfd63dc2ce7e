# shellcheck shell=sh disable=SC2154  # sourced by vm-test.sh, which sets gpiochip, pull, rate
# Stage "fw" of the in-VM test (sourced by vm-test.sh): the unchanged gfins-fw from
# gfins-fw-vboard.toml (the ADC chip model inside the process, paced by the REAL falling
# data-ready edges of the gpio-sim line through libgpiod, output on the REAL vcan0 through
# SocketCAN) for a fixed number of edges while candump records; then assertions on the decoded
# recording: the epoch count, continuous counters and valid CRCs (gfins-can decode exit 0 and the
# sample counter's spacing), values equal to the host-only run of the same configuration
# (run.sh), epoch by epoch keyed by the sample counter, and zero faults in the health frames.
# needs: build:firmware/app/gfins-fw
# needs: build:host_sim/can_tool/gfins-can
# needs: repo:scripts/vboard/fw-common.sh:/vboard/fw-common.sh
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
check fw-exit "gfins-fw ended on SIGTERM with status $fw_rc" [ $fw_rc -eq 0 ]
skipped=$(sed -n 's/.*skipped=\([0-9]*\).*/\1/p' /tmp/fw-toggle.log)

gfins-can decode /tmp/fw-candump.log --view csv -o /tmp/fw.csv --quiet 2>/tmp/fw-decode.log
dec_rc=$?
summary=$(grep '^summary:' /tmp/fw-decode.log)
echo "VBOARD-INFO fw decode: $summary"
check fw-decode-clean "gfins-can decode exit $dec_rc (0: every frame's CRC valid, counters continuous, no issue)" \
  [ $dec_rc -eq 0 ]

epochs=$(($(wc -l </tmp/fw.csv) - 1))
expect=$(((edges + divider - 1) / divider))
check fw-epochs "$epochs epochs decoded, expected $expect ($edges edges at $rate Hz, divider $divider, toggler skipped ${skipped:-?})" \
  [ "$epochs" -eq $expect -a "${skipped:-1}" -eq 0 ]

# Counters continuous, checked on the decoded sample counter itself: 0, 10, 20, ...
sc=$(csv_col /tmp/fw.csv SampleCount)
gaps=$(awk -F, -v c="$sc" -v d=$divider 'NR > 1 { if ($c != (NR - 2) * d) ++bad } END { print bad + 0 }' /tmp/fw.csv)
check fw-sample-counter "$gaps epochs whose sample counter is not 10 x their index (first 0)" [ "$gaps" -eq 0 ]

# Equal to the host-only run epoch by epoch, keyed by the sample counter. Both runs quantise the
# same float32 values to the same wire fields, and the navigation integrates with the nominal
# period times the sequence step (never the edge times), so every decoded field must be equal
# to the digit: the quantisation step is the tolerance, and any real difference (a conversion
# taken from the wrong sample, a lost edge, a different calibration) is at least one step. Not
# compared: the frame's log line, its capture time and the edge time (TimeUs), which are the
# VM's clock; and in StatusFlags (docs/can-interface.md) bit 15 "data-ready lost" with bit 13
# "health degraded", which the VM run sets, rightly, for the waits before the first edge (held
# 1 s); they are asserted to clear within the first 2 s of edges, and never to reappear.
set -- $(awk -F, -v rate="$rate" '
  function masked(v) { return v - (int(v / 8192) % 2) * 8192 - (int(v / 32768) % 2) * 32768 }
  FNR == 1 { n = NF; for (i = 1; i <= NF; ++i) { name[i] = $i; if ($i == "SampleCount") key = i
             if ($i == "StatusFlags") st = i
             skip[i] = ($i == "line" || $i == "log_time_s" || $i == "TimeUs[us]") }; next }
  FNR == NR { ref[$key] = $0; next }
  { if (!($key in ref)) { ++missing; next }
    split(ref[$key], r, ",")
    bad = 0
    for (i = 1; i <= n; ++i) {
      if (skip[i]) continue
      if (i == st) { same = masked(r[i]) == masked($i); if (r[i] != $i) last_startup = $key }
      else same = r[i] == $i
      if (!same) { bad = 1; if (!first) first = name[i] "@" $key ":" r[i] "/" $i }
    }
    matched += !bad; mism += bad }
  END { print matched + 0, mism + 0, missing + 0, (first ? first : "-"), last_startup + 0, 2 * rate }' \
  /vboard/fw-ref.csv /tmp/fw.csv)
check fw-equals-host "$1 of $epochs epochs equal the host-only run field by field, $2 differ, $3 not in it (first difference: $4)" \
  [ "$1" -eq "$epochs" -a "$epochs" -gt 0 ]
check fw-startup-flags "StatusFlags bits 13/15 (waits before the first edge) last set at sample $5, limit $6" \
  [ "$5" -lt "$6" ]

set -- $(health_faults /tmp/fw.csv)
check fw-health-zero "health fields in $2 epochs, fault counters sum $1 (max per field $3)" \
  [ "$1" -eq 0 -a "$2" -gt 0 ]
