# shellcheck shell=sh disable=SC2154  # sourced by the stage scripts, after vm-test.sh set gpiochip, rate
# Shared by stages fw, cmd and faults (sourced inside the VM): gfins-fw from gfins-fw-vboard.toml
# on the scenario vboard-rest (both written for the VM's rate by run.sh), and CSV helpers.
fw_cfg=/opt/gfins/etc/vboard.toml
fw_scenarios=/opt/share/gfins/scenarios
# The configuration at the VM's rate, on the gpio-sim chip of this boot (idempotent).
sed -i "s/^sample_rate_hz = .*/sample_rate_hz = $rate.0/; s/^gpio_chip = .*/gpio_chip = \"$gpiochip\"/" $fw_cfg

# fw_start LOG [OPTION...]: starts gfins-fw in the background (fw_pid), with the options after the
# configuration's, and waits up to 20 s for its loop.
fw_start() {
  fw_log=$1
  shift
  gfins-fw --config $fw_cfg --scenario-dir $fw_scenarios "$@" >"$fw_log" 2>&1 &
  fw_pid=$!
  i=0
  while [ $i -lt 200 ] && ! grep -q 'sample loop running' "$fw_log"; do
    kill -0 $fw_pid 2>/dev/null || return 1
    sleep 0.1
    i=$((i + 1))
  done
  grep -q 'sample loop running' "$fw_log"
}
# fw_stop: SIGTERM, then its exit status in fw_rc.
fw_stop() {
  kill -TERM $fw_pid 2>/dev/null
  wait $fw_pid
  fw_rc=$?
}
fw_alive() { kill -0 $fw_pid 2>/dev/null && echo yes || echo no; }

# csv_col FILE NAME: the 1-based column of NAME in the CSV header of FILE.
csv_col() {
  head -n 1 "$1" | tr ',' '\n' | grep -nxF "$2" | cut -d: -f1
}
# health_faults CSV: the sum of every health fault counter the decoded epochs carry (missed
# edges, ADC CRC errors, ADC resets, stuck mask, saturated samples, CAN tx dropped, bus-off
# events, loop overruns) and how many rows carried them, as "SUM ROWS MAX_PER_FIELD".
health_faults() {
  awk -F, 'NR == 1 { for (i = 1; i <= NF; ++i) if ($i ~ /^(MissedEdges|AdcCrcErrors|AdcResets|StuckMask|SaturatedSamples|CanTxDropped|BusOffEvents|LoopOverruns)$/) c[++n] = i; next }
           { had = 0; for (k = 1; k <= n; ++k) if ($c[k] != "") { had = 1; s += $c[k]; if ($c[k] + 0 > m[k]) m[k] = $c[k] + 0 } rows += had }
           END { out = ""; for (k = 1; k <= n; ++k) out = out (k > 1 ? "/" : "") m[k] + 0; print s + 0, rows + 0, out }' "$1"
}
# health_last CSV NAME: the last non-empty value of health column NAME (0 when none).
health_last() {
  awk -F, -v name="$2" 'NR == 1 { for (i = 1; i <= NF; ++i) if ($i == name) c = i; next }
                        c && $c != "" { v = $c } END { print v + 0 }' "$1"
}
