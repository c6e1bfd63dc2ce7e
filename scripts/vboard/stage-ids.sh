# shellcheck shell=sh disable=SC2154  # sourced by vm-test.sh, which sets gpiochip, pull, rate
# Stage "ids" of the in-VM test: a board with its identifier groups moved (docs/can-interface.md,
# "Identifiers": data 0x300, inputs 0x2A0, command 0x6C0, response 0x6D0, OxTS's 0x600-0x60F
# reserved) on a vcan0 that a second node shares. That node (cangen, 100 frames/s per identifier)
# sends OxTS-RT-like frames on every identifier of 0x600-0x60F and CANopen-like ones (TIME 0x100,
# TPDO1 0x181-0x18F, an SDO response 0x581, node 1's heartbeat 0x701 with its one byte). The
# board must answer none of them (no response storm, its refusal counter unchanged), send nothing
# outside its own groups, keep its epochs continuous, and answer gfins-can cmd --config at its
# moved identifiers while a command at the stock identifier goes unanswered.
# needs: build:firmware/app/gfins-fw
# needs: build:host_sim/can_tool/gfins-can
# needs: repo:scripts/vboard/fw-common.sh:/vboard/fw-common.sh
# needs: repo:scripts/vboard/gfins-fw-vboard.toml:/opt/gfins/etc/vboard.toml
# needs: cache:fw/scenarios/vboard-rest.toml:/opt/share/gfins/scenarios/vboard-rest.toml
. /vboard/fw-common.sh
ids_cfg=/tmp/vboard-ids.toml
sed '/^\[can\]/a data_id_base = 0x300\ninput_id_base = 0x2A0\ncommand_id_base = 0x6C0\nresponse_id_base = 0x6D0\nreserved_ids = [[0x600, 0x60F], [0x701, 0x701]]' \
  "$fw_cfg" >$ids_cfg
stock_cfg=$fw_cfg
fw_cfg=$ids_cfg
drdy-toggle "$pull" "$rate" >/tmp/ids-toggle.log &
toggle_pid=$!
fw_start /tmp/ids-fw.log
started=$?
check ids-fw-start "gfins-fw runs with the identifier groups moved ($(grep -c _id_base $ids_cfg) bases set)" [ $started -eq 0 ]
sleep 2

# The second node: 100 frames/s on each of its identifiers for 4 s, random data; the heartbeat
# with its one byte (0x05: operational).
traffic_ids="600 601 602 603 604 605 606 607 608 609 60A 60B 60C 60D 60E 60F 100 181 182 183 184 185 186 187 188 189 18A 18B 18C 18D 18E 18F 581"
traffic_pids=""
for id in $traffic_ids; do
  timeout 4 cangen vcan0 -g 10 -I "$id" -L 8 -D r >/dev/null 2>&1 &
  traffic_pids="$traffic_pids $!"
done
timeout 4 cangen vcan0 -g 10 -I 701 -L 1 -D 05 >/dev/null 2>&1 &
traffic_pids="$traffic_pids $!"
traffic_ids="$traffic_ids 701"
sleep 0.5
# 2 s of the bus (BusyBox's timeout takes whole seconds), and within them one command at the
# moved identifiers: answered by its status frame and the calibration id frame at 0x6D1.
timeout 2 candump -L vcan0 >/tmp/ids-during.log 2>/dev/null &
dump_pid=$!
sleep 0.5
gfins-can cmd --iface vcan0 --config $ids_cfg --timeout-ms 1000 cal-id >/tmp/ids-cmd.out 2>&1
cmd_rc=$?
wait $dump_pid
for p in $traffic_pids; do wait "$p" 2>/dev/null; done
# The same command at the stock identifiers (0x601, where the OxTS frames were): no answer.
gfins-can cmd --iface vcan0 --node 1 --timeout-ms 1000 cal-id >/tmp/ids-stock.out 2>&1
stock_rc=$?
# The board's command counters after all that: GfinsCommandCounters goes out every 1000 samples
# (2 s at 500 Hz), so 3 s of frames hold one.
timeout 3 candump -L vcan0 >/tmp/ids-after.log 2>/dev/null

# What the board sent during the traffic: every frame whose identifier is not the second node's
# (gfins-can's command at 0x6C1 aside). All must lie in the moved data group (0x301-0x40F) or be
# the response 0x6D1; the responses must be the two to our one command.
traffic_re=$(echo "$traffic_ids 6C1" | sed 's/ /|/g')
foreign=$(awk '{ split($3, a, "#"); print a[1] }' /tmp/ids-during.log | grep -cEx "$traffic_re")
own_bad=$(awk '{ split($3, a, "#"); print a[1] }' /tmp/ids-during.log | grep -vEx "$traffic_re" |
  grep -cvEx '3[0-9A-F][0-9A-F]|40[0-9A-F]|6D1')
responses=$(awk '{ split($3, a, "#"); print a[1] }' /tmp/ids-during.log | grep -cEx '6D[0-9A-F]|68[0-9A-F]')
check ids-no-storm "during 2 s of $foreign frames from a second node on 0x600-0x60F, 0x100, 0x181-0x18F, 0x581, 0x701 and one command of ours: $responses response frame(s) from the board (2: our command's status and calibration id), $own_bad board frame(s) outside its groups" \
  [ "$foreign" -gt 1000 -a "$own_bad" -eq 0 -a "$responses" -eq 2 ]
check ids-cmd "gfins-can cmd --config (command 0x6C1, response 0x6D1) during the traffic: exit $cmd_rc ($(head -n 1 /tmp/ids-cmd.out))" \
  [ $cmd_rc -eq 0 ]
check ids-stock-silent "gfins-can cmd at the stock identifier 0x601: exit $stock_rc (5 = no answer) ($(head -n 1 /tmp/ids-stock.out))" \
  [ $stock_rc -eq 5 ]
gfins-can decode /tmp/ids-during.log --config $ids_cfg --view csv -o /tmp/ids-during.csv --quiet 2>/tmp/ids-decode.out
epochs=$(($(wc -l </tmp/ids-during.csv) - 1))
# The second node's frames are "unknown id" to the decoder; an epoch lost would be "epoch drop".
jumps=$(sed -n 's/^ *epoch drop *\([0-9]*\).*/\1/p' /tmp/ids-decode.out | head -n 1)
# 2 s of epochs at divider 10 of the data-ready rate, less the capture's start-up: 3/4 of them.
check ids-epochs "the board's epochs decoded with --config during the traffic: $epochs in 2 s at $rate Hz, ${jumps:-0} epoch drops" \
  [ "$epochs" -ge $((rate * 2 / 10 * 3 / 4)) -a "${jumps:-0}" -eq 0 ]
gfins-can decode /tmp/ids-after.log --config $ids_cfg --view csv -o /tmp/ids-after.csv --quiet 2>/dev/null
c=$(csv_col /tmp/ids-after.csv CommandsRefused)
refused=$([ -n "$c" ] && awk -F, -v c="$c" 'NR > 1 && $c != "" { v = $c } END { print v }' /tmp/ids-after.csv)
c=$(csv_col /tmp/ids-after.csv CommandsDone)
done_n=$([ -n "$c" ] && awk -F, -v c="$c" 'NR > 1 && $c != "" { v = $c } END { print v }' /tmp/ids-after.csv)
check ids-counters "GfinsCommandCounters after the traffic: ${done_n:-not sent} done, ${refused:-not sent} refused (the OxTS and CANopen frames are not commands to it)" \
  [ "${refused:-x}" = 0 -a "${done_n:-0}" -ge 1 ]

fw_stop
fw_cfg=$stock_cfg
kill -TERM $toggle_pid 2>/dev/null
wait $toggle_pid 2>/dev/null
check ids-fw-exit "gfins-fw ended on SIGTERM with status $fw_rc" [ "$fw_rc" -eq 0 ]
