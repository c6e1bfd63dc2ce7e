# shellcheck shell=sh disable=SC2154  # sourced by vm-test.sh, which sets gpiochip, pull, rate
# Stage "cmd" of the in-VM test (sourced by vm-test.sh): every command of the CAN protocol
# (docs/can-interface.md, "Commands and responses") sent by `gfins-can cmd` over vcan0 to the
# running gfins-fw (node 1), each response checked through gfins-can's exit status and what it
# prints; then malformed command frames sent with Debian's cansend, each answered with the
# Result the protocol gives for it (2 length not 8, 3 CRC mismatch, 5 unused bits set... as the
# frame is built), read back with candump.
# needs: build:firmware/app/gfins-fw
# needs: build:host_sim/can_tool/gfins-can
# needs: repo:scripts/vboard/fw-common.sh:/vboard/fw-common.sh
# needs: repo:scripts/vboard/gfins-fw-vboard.toml:/opt/gfins/etc/vboard.toml
# needs: cache:fw/scenarios/vboard-rest.toml:/opt/share/gfins/scenarios/vboard-rest.toml
. /vboard/fw-common.sh
drdy-toggle "$pull" "$rate" >/tmp/cmd-toggle.log &
toggle_pid=$!
# Settings set by commands (node id, dividers) are kept here across restarts of gfins-fw: the
# simulated board keeps them only in a file named with --settings-file.
settings=/tmp/gfins-can-settings.toml
rm -f $settings
fw_start /tmp/cmd-fw.log --settings-file $settings
check cmd-fw-start "gfins-fw runs on vcan0 with data-ready edges" [ $? -eq 0 ]
# Past the 1 s alignment (navigation.alignment_s): commands like realign need the navigating mode.
sleep 2

# cmd_ok NAME ARGS...: gfins-can cmd must exit 0 (the board answered Ok with the same token).
cmd_ok() {
  name=$1
  shift
  gfins-can cmd --iface vcan0 --node 1 --timeout-ms 2000 "$@" >/tmp/cmd-$name.out 2>&1
  rc=$?
  check "cmd-$name" "gfins-can cmd $* exit $rc ($(tr '\n' ' ' </tmp/cmd-$name.out | head -c 160))" [ $rc -eq 0 ]
}
# Every command frame the host sends from here to the malformed ones, for the replay below.
candump -L vcan0,601:7FF >/tmp/cmd-sent.log 2>/dev/null &
sent_pid=$!
sleep 0.3
cmd_ok realign realign --heading-deg 30
cmd_ok reset reset
cmd_ok compensator-exact compensator exact
cmd_ok compensator-paper compensator paper
cmd_ok divider divider GfinsEuler 20
cmd_ok cal-id cal-id
# The calibration id the board reports must be the one it publishes in its epochs: one second
# of frames (50 GfinsStatus at 500 Hz, divider 10) decoded, every CalId there equal to the
# reported id (decimal in the CSV, compared as text: busybox awk's printf %x stops at 2^31, the
# shell's arithmetic converts the hex id in 64 bits).
cal=$(tr 'A-F' 'a-f' </tmp/cmd-cal-id.out | sed -n 's/.*\(0x\)\{0,1\}\([0-9a-f]\{8\}\).*/\2/p' | head -n 1)
cal_dec=$([ -n "$cal" ] && echo $((0x$cal)))
timeout 1 candump -L vcan0 >/tmp/cmd-epochs.log 2>/dev/null
gfins-can decode /tmp/cmd-epochs.log --view csv -o /tmp/cmd-epochs.csv --quiet 2>/dev/null
ci=$(csv_col /tmp/cmd-epochs.csv CalId)
published=$(awk -F, -v c="${ci:-0}" 'NR > 1 && c && $c != "" { print $c }' /tmp/cmd-epochs.csv | sort -u)
n_pub=$(echo "$published" | grep -c .)
check cmd-cal-id-published "reported 0x${cal:-nothing} = ${cal_dec:-?}; the epochs of 1 s carry CalId $(echo $published | tr ' ' ',') ($n_pub distinct)" \
  [ -n "$cal" -a "$n_pub" -eq 1 -a "$published" = "$cal_dec" ]
cmd_ok capture capture --pose 0 --samples 50
# No calibration file is configured (the factory calibration is in use): a reload must be
# refused with Result 7 failed, which gfins-can reports as exit 4 (the board rejected it).
gfins-can cmd --iface vcan0 --node 1 --timeout-ms 2000 reload >/tmp/cmd-reload.out 2>&1
rc=$?
check cmd-reload "gfins-can cmd reload exit $rc, expected 4 with no calibration file ($(tr '\n' ' ' </tmp/cmd-reload.out | head -c 160))" \
  [ $rc -eq 4 ]
# A node that does not exist: no answer, exit 5.
gfins-can cmd --iface vcan0 --node 9 --timeout-ms 300 reset >/tmp/cmd-none.out 2>&1
rc=$?
check cmd-no-such-node "gfins-can cmd --node 9 exit $rc, expected 5 (no response)" [ $rc -eq 5 ]

kill $sent_pid 2>/dev/null
wait $sent_pid 2>/dev/null

# Replay (docs/can-interface.md, "Sequence numbers"): Debian's canplayer sends the captured command
# frames again, 20 ms apart; every configuration-changing one (opcode 1-4, 7-9) carries a number
# the board has taken and must be answered Result 11 (Replayed, 0x0B) without being carried out.
n_cfg=$(grep -cE ' vcan0 601#0[1234789][0-9A-F]{14}$' /tmp/cmd-sent.log)
candump -L vcan0,681:7FF >/tmp/cmd-replay-rsp.log 2>/dev/null &
rsp_pid=$!
sleep 0.3
canplayer -t -g 20 -I /tmp/cmd-sent.log
sleep 1
kill $rsp_pid 2>/dev/null
wait $rsp_pid 2>/dev/null
n_rep=$(grep -cE ' vcan0 681#0[1234789][0-9A-F]{2}000B' /tmp/cmd-replay-rsp.log)
check cmd-replayed "canplayer replayed $(grep -c . /tmp/cmd-sent.log) command frames, $n_cfg of them configuration-changing: $n_rep answered Replayed (11)" \
  [ "$n_cfg" -gt 0 -a "$n_rep" -eq "$n_cfg" ]

# raw_cmd NAME FRAME EXPECTED_RESULT: cansend a frame on 601, the response on 681 must be a status
# part (byte 2 = 0) with byte 3 = EXPECTED_RESULT.
raw_cmd() {
  candump -L -n 1 vcan0,681:7FF >/tmp/cmd-raw-$1.log &
  pid=$!
  sleep 0.3
  cansend vcan0 "601#$2"
  i=0
  while [ $i -lt 30 ] && kill -0 $pid 2>/dev/null; do sleep 0.1; i=$((i + 1)); done
  kill $pid 2>/dev/null
  wait $pid 2>/dev/null
  data=$(sed -n 's/.* vcan0 681#\([0-9A-F]*\).*/\1/p' /tmp/cmd-raw-$1.log)
  part=$(echo "$data" | cut -c5-6)
  result=$(echo "$data" | cut -c7-8)
  check "cmd-malformed-$1" "cansend 601#$2 answered 681#${data:-nothing}: part ${part:-?}, result ${result:-?}, expected 00/$3" \
    [ "$part" = 00 -a "$result" = "$3" ]
}
raw_cmd short-frame 0142 02         # 2 bytes: length not 8
raw_cmd bad-crc 0242000000000000 03  # ResetNavigation with a wrong CRC byte

# Stored settings (docs/can-interface.md, "Stored settings"): the divider set above is in the
# settings file; a node id and a data group base set by command are taken at the next start of
# gfins-fw, and RestoreDefaults gives the configuration's back at the start after that.
check cmd-settings-divider "settings file after the divider command: $(grep -c '^euler = 20$' $settings 2>/dev/null) line 'euler = 20'" \
  grep -q '^euler = 20$' $settings
cmd_ok node-id node-id 2
check cmd-settings-node "settings file node_id: $(sed -n 's/^node_id = //p' $settings 2>/dev/null)" \
  grep -q '^node_id = 2$' $settings
cmd_ok id-base id-base data 0x300
check cmd-settings-id-base "settings file data_id_base: $(sed -n 's/^data_id_base = //p' $settings 2>/dev/null)" \
  grep -q '^data_id_base = 0x300$' $settings
# epochs_of ID LOG: GfinsEpoch frames of one node id (0x100 + node) in 1 s of candump.
epochs_of() {
  timeout 1 candump -L vcan0 >"$2" 2>/dev/null
  grep -c " vcan0 $1#" "$2"
}
fw_stop
fw_start /tmp/cmd-fw-restart.log --settings-file $settings
check cmd-settings-restart "gfins-fw started again on the stored settings" [ $? -eq 0 ]
n2=$(epochs_of 302 /tmp/cmd-restart.log)
n1=$(grep -c ' vcan0 10[12]#' /tmp/cmd-restart.log)
check cmd-settings-node-after-restart "after the restart, 1 s: $n2 epochs of node 2 on 0x302 (data group at 0x300), $n1 on 0x101/0x102" \
  [ "$n2" -gt 0 -a "$n1" -eq 0 ]
gfins-can cmd --iface vcan0 --node 2 --timeout-ms 2000 restore-defaults >/tmp/cmd-restore.out 2>&1
rc=$?
left=$([ -e $settings ] && echo present || echo removed)
check cmd-settings-restore "restore-defaults exit $rc, settings file $left" [ $rc -eq 0 -a "$left" = removed ]
fw_stop
fw_start /tmp/cmd-fw-defaults.log --settings-file $settings
check cmd-settings-defaults-start "gfins-fw started again on the configuration" [ $? -eq 0 ]
n1=$(epochs_of 101 /tmp/cmd-defaults.log)
check cmd-settings-defaults "after RestoreDefaults and a restart, 1 s: $n1 epochs of node 1" [ "$n1" -gt 0 ]

fw_stop
kill -TERM $toggle_pid 2>/dev/null
wait $toggle_pid 2>/dev/null
check cmd-fw-exit "gfins-fw ended on SIGTERM with status $fw_rc after the commands" [ $fw_rc -eq 0 ]
grep -iE 'command' /tmp/cmd-fw.log | head -n 12 | sed 's/^/VBOARD-LOG cmd: /'
