# shellcheck shell=sh disable=SC2154  # sourced by vm-test.sh, which sets the check helpers
# Stage "canlog" of the in-VM test (sourced by vm-test.sh): the CAN log checks on a real kernel's SocketCAN.
#   1. A candump log written by the firmware's file sink (gfins-fw --sim rest --can-log, made on
#      the host by run.sh) is replayed by Debian's canplayer on vcan0; candump -L must capture
#      exactly the log's frames (same count, same ID#DATA, same order).
#   2. gfins-can decodes the same replay live from vcan0 (--iface vcan0 --duration): its summary
#      must report the log's epochs and frames and 0 problems (CRCs valid, counters continuous).
# needs: build:host_sim/can_tool/gfins-can
# needs: cache:canlog/fw-rest.log:/vboard/canlog-fw.log
log=/vboard/canlog-fw.log
live_seconds=20  # gfins-can's live window; guest time (icount, sleep=off: idle time is free)

if ! [ -s $log ]; then
  fail "canlog-input: $log is missing or empty (run.sh generates it with gfins-fw --can-log)"
elif ! command -v canplayer >/dev/null; then
  fail "canlog-input: canplayer is not in the image (scripts/vboard/make-initramfs.sh)"
elif ! command -v gfins-can >/dev/null; then
  fail "canlog-input: gfins-can is not in the image (scripts/vboard/run.sh, needs: lines)"
else
  # The log's frames in order (ID#DATA, the third field) and the one interface its lines name.
  awk '$1 ~ /^\(/ { print $3 }' $log >/tmp/canlog-want.txt
  want_n=$(wc -l </tmp/canlog-want.txt)
  ifaces=$(awk '$1 ~ /^\(/ { print $2 }' $log | sort -u | tr '\n' ' ' | sed 's/ $//')
  # shellcheck disable=SC2086  # split into words on purpose: one per interface
  set -- $ifaces
  check canlog-input "$log: $want_n frames, interface(s) named: ${ifaces:-none}" \
    [ "$want_n" -gt 0 -a $# -eq 1 ]
  log_if=$1

  # What the log holds, decoded offline by the same gfins-can (the expected live summary).
  gfins-can decode $log --view none --quiet >/tmp/canlog-offline.log 2>&1
  off_rc=$?
  off_summary=$(grep '^summary:' /tmp/canlog-offline.log)
  echo "VBOARD-INFO canlog offline decode: $off_summary"
  off_epochs=$(echo "$off_summary" | sed -n 's/.* \([0-9]*\) epochs.*/\1/p')
  off_frames=$(echo "$off_summary" | sed -n 's/.* \([0-9]*\) frames.*/\1/p')
  check canlog-offline-decode "gfins-can decode of the log: exit $off_rc, ${off_frames:-?} frames, ${off_epochs:-?} epochs" \
    [ $off_rc -eq 0 -a "${off_epochs:-0}" -gt 0 -a "${off_frames:-0}" -eq "$want_n" ]

  # Replay with both receivers on vcan0: candump -L into a file and gfins-can live.
  candump -L vcan0 >/tmp/canlog-candump.log &
  dump_pid=$!
  gfins-can decode --iface vcan0 --duration $live_seconds --view none --quiet >/tmp/canlog-live.log 2>&1 &
  live_pid=$!
  sleep 1
  t0=$(cut -d' ' -f1 /proc/uptime)
  canplayer -t -I $log "vcan0=$log_if" >/tmp/canlog-player.log 2>&1
  play_rc=$?
  t1=$(cut -d' ' -f1 /proc/uptime)
  measure canlog-replay-seconds "$(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.2f", b - a }')"
  sed 's/^/VBOARD-LOG canlog canplayer: /' /tmp/canlog-player.log | head -n 5
  check canlog-canplayer "canplayer -t -I $log vcan0=$log_if: exit $play_rc" [ $play_rc -eq 0 ]
  sleep 1
  kill $dump_pid 2>/dev/null
  wait $dump_pid 2>/dev/null

  awk '$2 == "vcan0" { print $3 }' /tmp/canlog-candump.log >/tmp/canlog-got.txt
  got_n=$(wc -l </tmp/canlog-got.txt)
  first_diff=$(awk 'NR == FNR { w[FNR] = $0; n = FNR; next }
                    { m = FNR; if (!(FNR in w) || w[FNR] != $0) { print FNR ": log " w[FNR] ", candump " $0; d = 1; exit } }
                    END { if (!d && m < n) print m + 1 ": log " w[m + 1] ", candump (nothing)" }' \
    /tmp/canlog-want.txt /tmp/canlog-got.txt)
  check canlog-candump "candump -L vcan0 captured $got_n of $want_n frames; first difference: ${first_diff:-none}" \
    [ "$got_n" -eq "$want_n" -a -z "$first_diff" ]

  # gfins-can stops by itself after --duration; it must end with its summary and exit 0.
  wait $live_pid
  live_rc=$?
  sed 's/^/VBOARD-LOG canlog gfins-can: /' /tmp/canlog-live.log | head -n 10
  live_summary=$(grep '^summary:' /tmp/canlog-live.log)
  echo "VBOARD-INFO canlog live decode: $live_summary"
  live_epochs=$(echo "$live_summary" | sed -n 's/.* \([0-9]*\) epochs.*/\1/p')
  live_frames=$(echo "$live_summary" | sed -n 's/.* \([0-9]*\) frames.*/\1/p')
  live_problems=$(echo "$live_summary" | sed -n 's/.* \([0-9]*\) problems.*/\1/p')
  check canlog-live-decode "gfins-can decode --iface vcan0 --duration $live_seconds: exit $live_rc, ${live_frames:-?} of $want_n frames, ${live_epochs:-?} of ${off_epochs:-?} epochs, ${live_problems:-?} problems" \
    [ $live_rc -eq 0 -a "${live_frames:--1}" -eq "$want_n" -a "${live_epochs:--1}" -eq "${off_epochs:-0}" \
      -a "${live_problems:--1}" -eq 0 ]
fi
