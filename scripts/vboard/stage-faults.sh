# shellcheck shell=sh disable=SC2154  # sourced by vm-test.sh, which sets gpiochip, pull, rate
# Stage "faults" of the in-VM test (sourced by vm-test.sh): faults made through the kernel while
# gfins-fw runs from gfins-fw-vboard.toml; after each, what the firmware reported (health counters
# and status bits decoded by gfins-can, docs/can-interface.md) and that it recovered (epochs flow
# again with a continuous sample counter):
#   vcan0 down for 1 s, then up   SocketCAN refuses sends (ENETDOWN): CanTxDropped grows, bit 11
#   data-ready edges stopped 1 s   SIGSTOP/SIGCONT of the toggler: bit 15 "data-ready lost",
#                                  MissedEdges grows by the edges the ADC would have given
#   the bus flooded 2 s            cangen -g 0 on 0x601: the receive queue overflows, bit 18
#                                  "CAN frames lost on receive" and a log line with the count;
#                                  the firmware keeps publishing
# needs: build:firmware/app/gfins-fw
# needs: build:host_sim/can_tool/gfins-can
# needs: repo:scripts/vboard/fw-common.sh:/vboard/fw-common.sh
# needs: repo:scripts/vboard/gfins-fw-vboard.toml:/opt/gfins/etc/vboard.toml
# needs: cache:fw/scenarios/vboard-rest.toml:/opt/share/gfins/scenarios/vboard-rest.toml
. /vboard/fw-common.sh
# window NAME SECONDS: records vcan0 for SECONDS (the firmware's frames only) and decodes it to
# /tmp/faults-NAME.csv; sets w_epochs, w_jumps (consecutive epochs whose sample counters are
# not one divider apart), w_flags (OR of StatusFlags), w_missed / w_dropped (last MissedEdges /
# CanTxDropped carried).
window() {
  w=/tmp/faults-$1
  timeout "$2" candump -L vcan0 2>/dev/null | grep -v ' vcan0 7FF#' >$w.log
  gfins-can decode $w.log --view csv -o $w.csv --quiet 2>/dev/null
  w_epochs=$(($(wc -l <$w.csv) - 1))
  sc=$(csv_col $w.csv SampleCount)
  st=$(csv_col $w.csv StatusFlags)
  # (busybox awk has no ^: the bits are taken by halving)
  w_jumps=$(awk -F, -v c="$sc" 'NR > 2 && $c - prev != 10 { ++j } NR > 1 { prev = $c } END { print j + 0 }' $w.csv)
  w_flags=$(awk -F, -v s="$st" 'NR > 1 { v = $s; p = 1; for (b = 0; b < 20; ++b) { if (v % 2 && !f[b]) { f[b] = 1; o += p }; v = int(v / 2); p *= 2 } }
                                END { print o + 0 }' $w.csv)
  w_missed=$(health_last $w.csv MissedEdges)
  w_dropped=$(health_last $w.csv CanTxDropped)
}
# bitname FLAGS N: "set" or "clear". Each check tests it inside its one `check` command (a
# `check ... && bit ...` would decide outside check and throw the result away).
bitname() { [ $(($1 / (1 << $2) % 2)) -eq 1 ] && echo set || echo clear; }
# toggler_irregular: the toggler's running bound on edges a timestamp-based receiver may count as
# missed although it wrote them (its writes landing over half a period late on a loaded VM;
# drdy-toggle.c says how it is bounded), read from the line SIGUSR1 makes it print.
toggler_irregular() {
  kill -USR1 $toggle_pid
  sleep 0.2
  sed -n 's/.*irregular=\([0-9]*\).*/\1/p' /tmp/faults-toggle.log | tail -n 1
}

drdy-toggle "$pull" "$rate" >/tmp/faults-toggle.log &
toggle_pid=$!
fw_start /tmp/faults-fw.log
check faults-fw-start "gfins-fw runs on vcan0 with data-ready edges" [ $? -eq 0 ]
sleep 1
window baseline 2
# Missed edges: none beyond what the toggler's own lateness can explain (0 when it kept time; the
# firmware inventing a gap, or counting each edge twice, is caught either way).
irregular=$(toggler_irregular)
check faults-baseline "$w_epochs epochs in 2 s, $w_jumps counter jumps, flags $w_flags, missed $w_missed (toggler writes that may look missed: ${irregular:-?}), dropped $w_dropped" \
  [ "$w_epochs" -gt 0 -a "$w_jumps" -eq 0 -a "$w_missed" -le "${irregular:-0}" -a "$w_dropped" -eq 0 ]

ip link set down vcan0
sleep 1
ip link set up vcan0
window vcan 2
check faults-vcan-reported "after vcan0 down 1 s and up: CanTxDropped $w_dropped, status bit 11 (CAN frames dropped) $(bitname $w_flags 11)" \
  [ "$w_dropped" -gt 0 -a "$(bitname $w_flags 11)" = set ]
check faults-vcan-recovered "alive $(fw_alive); $w_epochs epochs in 2 s after, $w_jumps counter jumps" \
  [ "$(fw_alive)" = yes -a "$w_epochs" -gt 0 -a "$w_jumps" -eq 0 ]

missed_before=$w_missed
kill -STOP $toggle_pid
sleep 1
kill -CONT $toggle_pid
window drdy 2
# About rate x 1 s of edges lost; at least half of them (the stop lasts "sleep 1" of guest time).
check faults-drdy-reported "after 1 s without edges: MissedEdges $missed_before -> $w_missed (>= $((rate / 2)) more), status bit 15 (data-ready lost) $(bitname $w_flags 15)" \
  [ "$w_missed" -ge $((missed_before + rate / 2)) -a "$(bitname $w_flags 15)" = set ]
window drdy-after 2
check faults-drdy-recovered "alive $(fw_alive); $w_epochs epochs in 2 s after, $w_jumps counter jumps" \
  [ "$(fw_alive)" = yes -a "$w_epochs" -gt 0 -a "$w_jumps" -eq 0 ]
# Before the flood nothing has been lost on receive: bit 18 clear, no such line in the log.
rx_bit_before=$(bitname $w_flags 18)
rx_lines_before=$(grep -c 'received CAN frame(s) lost' /tmp/faults-fw.log)

# At the board's own command identifier (node 1: 0x601): the kernel's receive filter passes the
# board only its command and input identifiers (docs/can-interface.md, "Identifiers"), so a flood
# elsewhere never reaches its queue (stage ids); a babbling host at its command identifier does.
# Eight zero bytes: the CRC-8/SAE-J1850 of identifier 0x601 and seven zeros is 0xC6, not the 0x00
# in byte 7, so no frame of the flood can pass for a command; each one the loop reads is answered
# BadCrc and counted.
dropped_before=$w_dropped
timeout 2 cangen vcan0 -g 0 -I 601 -L 8 -D 0000000000000000 >/dev/null 2>&1 &
flood_pid=$!
window flood 2
wait $flood_pid 2>/dev/null
# The loop reads at most kMaxCommandsPerCycle (2) frames per sample, 1000 frames/s at 500 Hz,
# far fewer than cangen -g 0 sends: the socket's receive queue overflows, the kernel counts the
# drops (SO_RXQ_OVFL) and the firmware reports them as status bit 18 "CAN frames lost on
# receive" (docs/can-interface.md) and a log line with the running total (the CAN health frame
# carries no receive counter). CanRxDropped below is that total from the log's last such line.
sleep 0.2  # the logger thread writes every 10 ms: the last line reaches the file meanwhile
rx_lost=$(sed -n 's/.*received CAN frame(s) lost before the loop read them (lost: \([0-9]*\)[;)].*/\1/p' /tmp/faults-fw.log | tail -n 1)
check faults-flood-reported "during a 2 s cangen flood: $w_epochs epochs, status bit 18 (CAN frames lost on receive) $rx_bit_before -> $(bitname $w_flags 18), log reports ${rx_lost:-no} lost frame(s) (lines before the flood: $rx_lines_before)" \
  [ "$rx_bit_before" = clear -a "$rx_lines_before" -eq 0 -a "$(bitname $w_flags 18)" = set -a "${rx_lost:-0}" -gt 0 ]
window flood-after 2
check faults-flood-recovered "alive $(fw_alive); $w_epochs epochs in 2 s after a 2 s cangen flood, $w_jumps counter jumps" \
  [ "$(fw_alive)" = yes -a "$w_epochs" -gt 0 -a "$w_jumps" -eq 0 ]

fw_stop
kill -TERM $toggle_pid 2>/dev/null
wait $toggle_pid 2>/dev/null
check faults-fw-exit "gfins-fw ended on SIGTERM with status $fw_rc after the faults" [ $fw_rc -eq 0 ]
grep -iE 'bus|data-ready|drop|timeout|recover|missed|health' /tmp/faults-fw.log | head -n 16 | sed 's/^/VBOARD-LOG faults: /'
