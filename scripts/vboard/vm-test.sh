#!/bin/sh
# The in-VM test of the virtual board (busybox sh inside QEMU; see docs/deploy.md, "The virtual
# board"). Every assertion prints one line
#   VBOARD-CHECK PASS|FAIL <name>: <what was measured>
# and measurements print "VBOARD-MEASURE <name> <value>"; the last line is
#   VBOARD-RESULT PASS|FAIL checks=N failed=F
# Stages come from the kernel command line: vboard.stages=infra,backend,fw,cmd,faults,canlog,gnss,ids (default all).
# A stage whose program is missing FAILS naming it: nothing is skipped silently.
failed=0
checks=0
pass() { checks=$((checks + 1)); echo "VBOARD-CHECK PASS $*"; }
fail() { checks=$((checks + 1)); failed=$((failed + 1)); echo "VBOARD-CHECK FAIL $*"; }
check() { # check NAME DETAIL COMMAND...: PASS when the command succeeds
  name=$1 detail=$2
  shift 2
  if "$@"; then pass "$name: $detail"; else fail "$name: $detail"; fi
}
measure() { echo "VBOARD-MEASURE $1 $2"; }
param() { sed -n "s/.*$1=\([^ ]*\).*/\1/p" /proc/cmdline; }

stages=$(param vboard.stages)
[ -n "$stages" ] || stages=infra,backend,fw,cmd,faults,canlog,gnss,ids
# A stage name this test does not know fails (run.sh checks the names too; this catches a
# kernel command line written by hand).
for s in $(echo "$stages" | tr ',' ' '); do
  case $s in
    infra | backend | fw | cmd | faults | canlog | gnss | ids) ;;
    *) fail "stage-$s: no such in-VM stage (known: infra, backend, fw, cmd, faults, canlog, gnss, ids)" ;;
  esac
done
rate=$(param vboard.rate)
[ -n "$rate" ] || rate=500
want() { case ",$stages," in *",$1,"*) return 0 ;; esac; return 1; }

# --- the kernel side: vcan0 and a gpio-sim chip with the data-ready line -----------------------
setup_vcan() {
  ip link add dev vcan0 type vcan && ip link set up vcan0
}
setup_gpio_sim() {
  d=/sys/kernel/config/gpio-sim/vboard
  mkdir -p $d/bank0/line0 &&
    echo 1 >$d/bank0/num_lines &&
    echo gfins-vboard >$d/bank0/label &&
    echo adc-drdy >$d/bank0/line0/name &&
    echo 1 >$d/live || return 1
  dev=$(cat $d/dev_name)
  chip=$(cat $d/bank0/chip_name)
  pull=/sys/devices/platform/$dev/$chip/sim_gpio0/pull
  gpiochip=$chip
  [ -w "$pull" ]
}

check vcan0-up "ip link add dev vcan0 type vcan; ip link set up vcan0" setup_vcan
check gpio-sim-live "configfs chip with line 0 named adc-drdy is live" setup_gpio_sim
echo "VBOARD-INFO gpio-sim chip=$gpiochip pull=$pull"

# --- stage infra: the infrastructure checked with Debian's own tools ---------------------------
if want infra; then
  infra_t0=$(cut -d' ' -f1 /proc/uptime)
  n=200
  candump -L -n $n vcan0 >/tmp/infra-candump.log &
  dump_pid=$!
  sleep 1
  cangen vcan0 -g 1 -n $n -I 123 -L 8 -D i -p 10
  sleep 1
  kill $dump_pid 2>/dev/null
  wait $dump_pid 2>/dev/null
  got=$(grep -c ' vcan0 123#' /tmp/infra-candump.log)
  # cangen -D i: the first data byte counts up from 0, one per frame (mod 256).
  bad=$(awk '{ split($3, a, "#"); b = substr(a[2], 1, 2); v = 0;
               for (i = 1; i <= 2; ++i) v = v * 16 + index("0123456789ABCDEF", toupper(substr(b, i, 1))) - 1;
               if (v != (NR - 1) % 256) ++bad } END { print bad + 0 }' /tmp/infra-candump.log)
  check can-loopback "candump saw $got of $n cangen frames, $bad out of sequence" \
    [ "$got" -eq $n -a "$bad" -eq 0 ]

  check gpiodetect "gpiodetect lists $gpiochip" sh -c "gpiodetect | grep -q '^$gpiochip '"
  check gpioinfo-name "gpioinfo names line 0 adc-drdy" sh -c "gpioinfo $gpiochip | grep -q '\"adc-drdy\"'"

  # Data-ready edges (falling: the ADS131M06's DRDY is active low) at the nominal rate: gpiomon
# must see every one, spaced one period apart.
  n=$((rate * 4))
  gpiomon --falling-edge --num-events=$n --format='%s %n' $gpiochip 0 >/tmp/infra-gpiomon.log &
  mon_pid=$!
  sleep 1
  drdy-toggle "$pull" "$rate" $n >/tmp/infra-toggle.log
  sleep 1
  kill $mon_pid 2>/dev/null
  wait $mon_pid 2>/dev/null
  cat /tmp/infra-toggle.log
  got=$(wc -l </tmp/infra-gpiomon.log)
  # Kernel timestamps: mean spacing over the run (s) and the largest gap, in periods.
  # gpiomon's %n is not zero-padded: seconds and nanoseconds are read as two fields.
  set -- $(awk -v p="$rate" '{ t = $1 + $2 * 1e-9 }
                           NR > 1 { d = t - prev; s += d; if (d * p > m) { m = d * p; at = NR }
                                    if (d * p > 1.5) ++gaps }
                           { prev = t }
                           END { if (NR > 1) printf "%.1f %.2f %d %d", (NR - 1) / s, m, gaps, at }' \
    /tmp/infra-gpiomon.log)
  measure gpiomon-rate-hz "$1"
  measure gpiomon-max-gap-periods "$2"
  measure gpiomon-gaps-over-1.5-periods "$3"
  # The kernel's edge timestamps one period apart: no gap over 1.5 periods (a lost or late edge
  # makes one of 2 periods or more) and a mean rate within kRateTol of nominal. 1 %: under icount
  # guest time counts instructions and drdy-toggle sleeps to absolute deadlines, so the mean is
  # exact (measured 500.0 Hz); a toggler at a wrong rate or one skipping every 100th edge is off
  # by 1 % or more.
  gaps=${3:-x}
  irregular=$(sed -n 's/.*irregular=\([0-9]*\).*/\1/p' /tmp/infra-toggle.log)
  rate_ok=$(awk -v m="${1:-0}" -v r="$rate" 'BEGIN { d = m / r - 1; print (d < 0.01 && d > -0.01) ? 1 : 0 }')
  # A gap is allowed only where the toggler's own write landed late enough to make it (its
  # "irregular" bound, drdy-toggle.c): 0 when it kept time.
  check gpiomon-spacing "kernel timestamps: mean $1 Hz (nominal $rate, within 1 %), largest gap $2 periods (at event ${4:-none}), $gaps gap(s) over 1.5 periods (toggler writes late enough to make one: ${irregular:-?})" \
    [ "$gaps" != x -a "$gaps" -le "${irregular:-0}" -a "$rate_ok" = 1 ]
  skipped=$(sed -n 's/.*skipped=\([0-9]*\).*/\1/p' /tmp/infra-toggle.log)
  check gpiomon-edges "gpiomon saw $got of $n falling (data-ready) edges at $rate Hz (toggler skipped ${skipped:-?})" \
    [ "$got" -eq $n -a "${skipped:-1}" -eq 0 ]

  # The toggler alone at several rates: how often it is late (> 1/4 period) or stalls a period.
  # About 12 s of guest time: only with run.sh --measure (vboard.measure=1), not in CI.
  [ "$(param vboard.measure)" = 1 ] && for r in 250 500 1000 2000 4000; do
    measure toggle-alone-$r "$(drdy-toggle "$pull" $r $((r * 2)) | sed 's/drdy-toggle: //')"
  done

  # What the VM reaches at most (as fast as the sysfs writes go, gpiomon reading).
  if [ "$(param vboard.measure)" = 1 ]; then
    gpiomon --falling-edge --silent $gpiochip 0 &
    mon_pid=$!
    sleep 1
    drdy-toggle "$pull" 0 4000 >/tmp/infra-max.log
    kill $mon_pid 2>/dev/null
    wait $mon_pid 2>/dev/null
    measure toggle-max-rate-hz "$(sed -n 's/.*rate_hz=\([0-9.]*\).*/\1/p' /tmp/infra-max.log)"
  fi
  measure stage-infra-guest-seconds "$(awk -v a="$infra_t0" -v b="$(cut -d' ' -f1 /proc/uptime)" 'BEGIN { printf "%.1f", b - a }')"
fi

uptime_s() { cut -d' ' -f1 /proc/uptime; }
for s in backend fw cmd faults canlog gnss ids; do
  want $s || continue
  if [ -e /vboard/stage-$s.sh ]; then
    t0=$(uptime_s)
    . /vboard/stage-$s.sh
    # Guest seconds per stage (icount: instructions / 1e9), for the CI cost figures.
    measure stage-$s-guest-seconds "$(awk -v a="$t0" -v b="$(uptime_s)" 'BEGIN { printf "%.1f", b - a }')"
  else
    fail "stage-$s: its program is not in the image (see scripts/vboard/run.sh)"
  fi
done

dmesg | grep -iE 'clocksource|tsc' | sed 's/^/VBOARD-INFO dmesg /'
if [ $failed -eq 0 ] && [ $checks -gt 0 ]; then result=PASS; else result=FAIL; fi
echo "VBOARD-RESULT $result checks=$checks failed=$failed"
[ $result = PASS ]
