# shellcheck shell=sh disable=SC2154  # sourced by vm-test.sh, which sets gpiochip, pull, rate
# Stage "gnss" of the in-VM test: aiding through the real kernel's SocketCAN. gfins-fw runs the
# aiding filter (--aiding; aiding.inputs on) on the rest scenario, paced by the gpio-sim line;
# `gfins-can gnss vboard-gnss --iface vcan0` plays a receiver of the same board (1.5 m / 3 m,
# 0.05 m/s, 5 Hz, 60 ms latency) onto vcan0 in real time, as a GNSS gateway would. The board's
# own frames, decoded by gfins-can, must show every fix taken by the filter (docs/can-interface.md,
# "Aiding inputs" and "Accuracy and aiding").
# needs: build:firmware/app/gfins-fw
# needs: build:host_sim/can_tool/gfins-can
# needs: repo:scripts/vboard/fw-common.sh:/vboard/fw-common.sh
# needs: repo:scripts/vboard/gfins-fw-vboard.toml:/opt/gfins/etc/vboard.toml
# needs: cache:fw/scenarios/vboard-rest.toml:/opt/share/gfins/scenarios/vboard-rest.toml
# needs: cache:fw/scenarios/vboard-gnss.toml:/opt/share/gfins/scenarios/vboard-gnss.toml
. /vboard/fw-common.sh
drdy-toggle "$pull" "$rate" >/tmp/gnss-toggle.log &
toggle_pid=$!
fw_start /tmp/gnss-fw.log --aiding
check gnss-fw-start "gfins-fw runs with the aiding filter on vcan0" [ $? -eq 0 ]
# Past the 1 s static alignment: fixes before it are not the filter's yet.
sleep 2

gnss_seconds=10
gfins-can gnss vboard-gnss --scenario-dir "$fw_scenarios" --iface vcan0 --node 1 \
  --duration $gnss_seconds >/tmp/gnss-send.out 2>&1 &
gnss_pid=$!
# While the receiver sends: 2 s of the board's frames (epochs, velocity with FilterMode, the
# aiding counters with the time since the last accepted fix).
sleep 6
timeout 2 candump -L vcan0 >/tmp/gnss-during.log 2>/dev/null
wait $gnss_pid
gnss_rc=$?
sent=$(sed -n 's/.*: \([0-9]*\) fixes sent.*/\1/p' /tmp/gnss-send.out)
check gnss-sent "gfins-can gnss --iface vcan0: exit $gnss_rc, ${sent:-no} fixes sent ($(tr '\n' ' ' </tmp/gnss-send.out | head -c 120))" \
  [ $gnss_rc -eq 0 -a "${sent:-0}" -ge $((gnss_seconds * 5 - 1)) ]
# After the last fix: the counters' final values (AidingCounters go out every 0.4 s at 1 kHz, each
# kind every 2 s: 3 s of frames hold each kind at least once; BusyBox's timeout takes whole
# seconds, 2.5 would be 2).
sleep 0.5
timeout 3 candump -L vcan0 >/tmp/gnss-after.log 2>/dev/null

gfins-can decode /tmp/gnss-during.log --view csv -o /tmp/gnss-during.csv --quiet 2>/dev/null
gfins-can decode /tmp/gnss-after.log --view csv -o /tmp/gnss-after.csv --quiet 2>/dev/null
# column_values CSV NAME: the non-empty values of a column, one per line.
column_values() {
  c=$(csv_col "$1" "$2")
  [ -n "$c" ] && awk -F, -v c="$c" 'NR > 1 && $c != "" { print $c }' "$1"
}
# FilterMode bit 2: a GNSS update within the filter's aiding window, in every epoch that carries it.
modes=$(column_values /tmp/gnss-during.csv FilterMode | sort -u | tr '\n' ' ')
n_modes=$(column_values /tmp/gnss-during.csv FilterMode | grep -c .)
n_gnss=$(column_values /tmp/gnss-during.csv FilterMode | awk 'int($1 / 4) % 2 == 1' | grep -c .)
check gnss-filter-mode "while fixes arrive: $n_gnss of $n_modes epochs with FilterMode bit 2 (GNSS); values seen: ${modes:-none}" \
  [ "$n_modes" -gt 0 -a "$n_gnss" -eq "$n_modes" ]
# The time since the last accepted fix: at 5 Hz, at most a period plus the latency and the bus.
since=$(column_values /tmp/gnss-during.csv 'GnssPosSince[s]' | sort -g | tail -n 1)
check gnss-since "while fixes arrive: the longest GnssPosSince is ${since:-not sent} s (fixes every 0.2 s)" \
  awk -v s="${since:-99}" 'BEGIN { exit !(s <= 0.5) }'
pos_ok=$(column_values /tmp/gnss-after.csv GnssPosAccepted | sort -n | tail -n 1)
pos_bad=$(column_values /tmp/gnss-after.csv GnssPosRejected | sort -n | tail -n 1)
vel_ok=$(column_values /tmp/gnss-after.csv GnssVelAccepted | sort -n | tail -n 1)
vel_bad=$(column_values /tmp/gnss-after.csv GnssVelRejected | sort -n | tail -n 1)
# Every fix goes through the innovation test; at rest with the receiver's stated σ it rejects
# about 1 in 1000, so 2 of 50 allow for a rare tail without hiding a broken input path.
check gnss-accepted "of ${sent:-?} fixes: position ${pos_ok:-?} accepted / ${pos_bad:-?} rejected, velocity ${vel_ok:-?} / ${vel_bad:-?}" \
  [ -n "$sent" -a -n "$pos_ok" -a -n "$vel_ok" -a \
    "${pos_ok:-0}" -ge $((sent - 2)) -a "${vel_ok:-0}" -ge $((sent - 2)) -a \
    "${pos_ok:-0}" -le "$sent" -a "${vel_ok:-0}" -le "$sent" ]

fw_stop
kill -TERM $toggle_pid 2>/dev/null
wait $toggle_pid 2>/dev/null
check gnss-fw-exit "gfins-fw ended on SIGTERM with status $fw_rc after the fixes" [ "$fw_rc" -eq 0 ]
grep -iE 'aiding|gnss|filter' /tmp/gnss-fw.log | head -n 8 | sed 's/^/VBOARD-LOG gnss: /'
