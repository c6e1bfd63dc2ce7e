# shellcheck shell=sh disable=SC2154  # sourced by vm-test.sh, which sets gpiochip, pull, rate
# Stage "faults" of the in-VM test (sourced by vm-test.sh, after stage fw): faults made through
# the kernel while gfins-fw runs from gfins-fw-vboard.toml; after each the firmware must still
# run and frames must flow again on vcan0.
#   vcan0 down for 1 s, then up      (SocketCAN: ENETDOWN on send, the backend counts and recovers)
#   data-ready edges stopped 1 s      (SIGSTOP/SIGCONT of the toggler: timeouts, missed edges)
#   the bus flooded 2 s with cangen   (cangen -g 0: frames as fast as the kernel takes them)
# needs: build:firmware/app/gfins-fw
# needs: repo:scripts/vboard/gfins-fw-vboard.toml:/opt/gfins/etc/vboard.toml
cfg=/opt/gfins/etc/vboard.toml
alive() { kill -0 $fw_pid 2>/dev/null && echo yes || echo no; }
frames_within() { # frames_within SECONDS: how many frames of node 1 candump sees in that time
  timeout "$1" candump -L vcan0 2>/dev/null | grep -vc ' vcan0 7FF#'
}
drdy-toggle "$pull" "$rate" >/tmp/faults-toggle.log &
toggle_pid=$!
gfins-fw --config $cfg --scenario-dir /opt/share/gfins/scenarios >/tmp/faults-fw.log 2>&1 &
fw_pid=$!
sleep 3
n=$(frames_within 1)
check faults-baseline "$n frames in 1 s before any fault" [ "$n" -gt 0 ]

ip link set down vcan0
sleep 1
ip link set up vcan0
sleep 1
n=$(frames_within 1)
check faults-vcan-down-up "firmware alive: $(alive); $n frames in 1 s after vcan0 came back" \
  [ "$n" -gt 0 -a "$(alive)" = yes ]

kill -STOP $toggle_pid
sleep 1
kill -CONT $toggle_pid
sleep 1
n=$(frames_within 1)
check faults-drdy-stop "firmware alive: $(alive); $n frames in 1 s after the edges resumed" \
  [ "$n" -gt 0 -a "$(alive)" = yes ]

# 0x7FF: the lowest priority identifier, so the firmware's frames still win arbitration on a
# real bus; on vcan it is the socket queues that fill.
timeout 2 cangen vcan0 -g 0 -I 7FF -L 8 -i >/dev/null 2>&1
sleep 1
n=$(frames_within 1)
check faults-flood "firmware alive: $(alive); $n frames in 1 s after a 2 s cangen flood" \
  [ "$n" -gt 0 -a "$(alive)" = yes ]

kill -TERM $fw_pid 2>/dev/null
wait $fw_pid
kill -TERM $toggle_pid 2>/dev/null
wait $toggle_pid 2>/dev/null
# The firmware's log names each fault (docs/faults.md); show what it said.
grep -iE 'bus|data-ready|drop|timeout|recover' /tmp/faults-fw.log | head -n 20 | sed 's/^/VBOARD-LOG faults: /'
