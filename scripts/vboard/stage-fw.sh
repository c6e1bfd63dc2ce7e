# shellcheck shell=sh disable=SC2154  # sourced by vm-test.sh, which sets gpiochip, pull, rate
# Stage "fw" of the in-VM test (sourced by vm-test.sh): gfins-fw from its configuration file
# (gfins-fw-vboard.toml: ADC chip model on SPI, data-ready from the gpio-sim line through
# libgpiod, output on vcan0 through SocketCAN), read by candump and gfins-can on vcan0.
# needs: build:firmware/app/gfins-fw
# needs: build:host_sim/can_tool/gfins-can
# needs: repo:scripts/vboard/gfins-fw-vboard.toml:/opt/gfins/etc/vboard.toml
# needs: repo:host_sim/scenarios/rest.toml:/opt/share/gfins/scenarios/rest.toml
fw_seconds=10
cfg=/opt/gfins/etc/vboard.toml
sed -i "s/^sample_rate_hz = .*/sample_rate_hz = $rate.0/; s/^gpio_chip = .*/gpio_chip = \"$gpiochip\"/" $cfg
gfins-fw --config $cfg --scenario-dir /opt/share/gfins/scenarios --check-config >/tmp/fw-check.log 2>&1
check fw-config "gfins-fw --check-config accepts $cfg ($(head -c 200 /tmp/fw-check.log | tr '\n' ' '))" \
  [ $? -eq 0 ]

candump -L vcan0 >/tmp/fw-candump.log &
dump_pid=$!
gfins-fw --config $cfg --scenario-dir /opt/share/gfins/scenarios >/tmp/fw-run.log 2>&1 &
fw_pid=$!
sleep 1
drdy-toggle "$pull" "$rate" $((rate * fw_seconds)) >/tmp/fw-toggle.log
sleep 1
kill -TERM $fw_pid 2>/dev/null
wait $fw_pid
fw_rc=$?
kill $dump_pid 2>/dev/null
wait $dump_pid 2>/dev/null
sed 's/^/VBOARD-LOG fw: /' /tmp/fw-run.log | tail -n 20
cat /tmp/fw-toggle.log
check fw-exit "gfins-fw ended on SIGTERM with status $fw_rc" [ $fw_rc -eq 0 ]

gfins-can decode /tmp/fw-candump.log --view none --quiet 2>/tmp/fw-decode.log
dec_rc=$?
summary=$(grep '^summary:' /tmp/fw-decode.log)
echo "VBOARD-INFO fw decode: $summary"
check fw-decode-clean "gfins-can decode exit $dec_rc (0 = every frame valid: CRCs, counters continuous, no issue)" \
  [ $dec_rc -eq 0 ]
epochs=$(echo "$summary" | sed -n 's/.* \([0-9]*\) epochs.*/\1/p')
# One epoch per data-ready edge divided by the epoch divider (10 by default): the toggler's
# edges after the 1 s alignment, within +-1 s of edges for start-up and stop.
edges=$((rate * fw_seconds))
expect=$(((edges - rate) / 10))
tol=$((rate / 10))
check fw-epochs "${epochs:-0} epochs decoded, expected $expect +- $tol ($edges edges at $rate Hz, divider 10)" \
  [ "${epochs:-0}" -ge $((expect - tol)) -a "${epochs:-0}" -le $((expect + tol)) ]
