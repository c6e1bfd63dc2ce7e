#!/bin/sh
# vboard-check.service (service-manager stage): assertions under a real systemd, printed as
# VBOARD-CHECK lines on the serial console and into /var/log/vboard-result (read by the host
# through the shared root). Then the unit powers the VM off.
out=/var/log/vboard-result
: >$out
failed=0
checks=0
say() { echo "$*"; echo "$*" >>$out; }
up() { cut -d' ' -f1 /proc/uptime; }
# Each check ends with the guest uptime it was decided at: where the stage's time goes.
pass() { checks=$((checks + 1)); say "VBOARD-CHECK PASS $* [t=$(up)s]"; }
fail() { checks=$((checks + 1)); failed=$((failed + 1)); say "VBOARD-CHECK FAIL $* [t=$(up)s]"; }
prop() { systemctl show -p "$2" --value "$1"; }
wait_for() { # wait_for SECONDS COMMAND...: poll every 0.5 s until the command succeeds
  # (each poll runs systemctl, which costs an emulated guest a good fraction of a second)
  n=$(($1 * 2))
  shift
  while [ $n -gt 0 ]; do
    "$@" && return 0
    sleep 0.5
    n=$((n - 1))
  done
  return 1
}
. /vboard/service.env
. /vboard/rate.env
say "VBOARD-BOOTED uptime=$(cut -d' ' -f1 /proc/uptime) (systemd $(systemctl --version | head -n 1 | cut -d' ' -f2))"

# --- Debian's systemd-notify as the service: the service manager's side ----------------------
restarted() { [ "$(prop vboard-notify-probe NRestarts)" -ge 1 ]; }
if wait_for 20 restarted; then
  pass "probe-watchdog-restart: the probe stopped kicking; systemd restarted it (NRestarts=$(prop vboard-notify-probe NRestarts))"
else
  fail "probe-watchdog-restart: no restart within 20 s (NRestarts=$(prop vboard-notify-probe NRestarts), state $(prop vboard-notify-probe ActiveState))"
fi
if journalctl -u vboard-notify-probe --no-pager | grep -q 'Watchdog timeout'; then
  pass "probe-watchdog-journal: the journal names the watchdog timeout"
else
  fail "probe-watchdog-journal: no 'Watchdog timeout' in the probe's journal"
fi

# The probe restarts every few seconds for ever (each restart a fork, six notifications and
# journal entries): stop it, so the firmware's checks below do not share the guest with it.
systemctl stop vboard-notify-probe

# --- gfins-fw from its .deb ------------------------------------------------------------------
if [ "$WANT_FW" = 1 ]; then
  if [ ! -x /usr/bin/gfins-fw ]; then
    fail "fw-installed: /usr/bin/gfins-fw missing (the .deb was not installed)"
  else
    pass "fw-installed: $(dpkg-query -W -f='${Package} ${Version} ${Architecture}' gfins-fw)"
    id gfins >/dev/null 2>&1 && pass "fw-user: $(id gfins)" || fail "fw-user: no user gfins"
    active() { [ "$(prop gfins-fw ActiveState)" = active ]; }
    # active, or failed for good (StartLimitBurst reached): no point waiting longer.
    settled() { active || [ "$(prop gfins-fw ActiveState)" = failed ]; }
    wait_for 60 settled
    if active; then
      pass "fw-active: Type=notify service reached active (READY=1); status '$(prop gfins-fw StatusText)'"
      # can0 appears 2 s after vboard-setup (vboard-late-can.service): the unit must have waited for its
      # device unit and started once, not failed on the missing interface and been restarted.
      systemctl show -p ExecMainStartTimestampMonotonic -p NRestarts gfins-fw >/tmp/start
      start_us=$(sed -n 's/^ExecMainStartTimestampMonotonic=//p' /tmp/start)
      nr0=$(sed -n 's/^NRestarts=//p' /tmp/start)
      can_up=$(cat /run/vboard-can0 2>/dev/null)
      late=$(awk -v s="${start_us:-0}" -v c="${can_up:-1e9}" 'BEGIN { print (s / 1e6 > c) ? 1 : 0 }')
      [ "$late" = 1 ] && [ "$nr0" = 0 ] &&
        pass "fw-waits-for-can0: started at ${start_us}us, after can0 appeared (uptime ${can_up}s), NRestarts 0" ||
        fail "fw-waits-for-can0: started at ${start_us:-?}us, can0 appeared at uptime ${can_up:-never}s, NRestarts ${nr0:-?} (expected a start after can0 and no restart)"
    else
      fail "fw-active: state $(prop gfins-fw ActiveState)/$(prop gfins-fw SubState) after 60 s"
      journalctl -u gfins-fw --no-pager | grep -E 'critical|error|Failed' | tail -n 8 | sed 's/^/VBOARD-LOG fw: /' | tee -a $out
    fi
    if ! active; then
      # Nothing below can happen without a running service: say so instead of waiting.
      for c in fw-waits-for-can0 fw-runs-as-gfins fw-realtime fw-frames fw-status-text fw-watchdog-pings fw-hang-restart fw-watchdog-journal fw-frames-after-restart; do
        fail "$c: not reached, gfins-fw.service is $(prop gfins-fw ActiveState) (NRestarts $(prop gfins-fw NRestarts))"
      done
    else
    pid=$(prop gfins-fw MainPID)
    # The real and effective uid from the kernel (the minimal root has no procps).
    uids=$(sed -n 's/^Uid:[[:space:]]*\([0-9]*\)[[:space:]]*\([0-9]*\).*/\1 \2/p' "/proc/$pid/status")
    want_uid=$(id -u gfins)
    [ "$uids" = "$want_uid $want_uid" ] && pass "fw-runs-as-gfins: MainPID $pid runs as uid $want_uid (gfins)" ||
      fail "fw-runs-as-gfins: MainPID $pid runs as uid(s) '${uids:-?}', gfins is $want_uid"
    # Real-time scheduling permitted by the unit (LimitRTPRIO, LimitMEMLOCK) and taken by the
    # firmware as a non-root user: the sample loop (the main thread, TID = PID) under SCHED_FIFO
    # at [realtime] priority 80, no other thread of the process under a real-time policy (they
    # would compete with the loop), its memory locked by mlockall. proc(5): in
    # /proc/PID/task/TID/stat, after "(comm) ", rt_priority is field 40 and policy field 41
    # (SCHED_OTHER 0, SCHED_FIFO 1, SCHED_RR 2), i.e. the 38th and 39th of what follows the comm;
    # VmLck in /proc/PID/status is the locked memory.
    sched=""
    others_rt=""
    for st in /proc/$pid/task/*/stat; do
      tid=${st%/stat}
      tid=${tid##*/}
      f=$(sed 's/^.*) //' "$st" | cut -d' ' -f38,39)
      sched="$sched $tid:$(echo "$f" | tr " " /)"
      if [ "$tid" = "$pid" ]; then main=$f; else case ${f#* } in 1 | 2) others_rt="$others_rt $tid" ;; esac; fi
    done
    lck=$(sed -n 's/^VmLck:[[:space:]]*\([0-9]*\) kB/\1/p' "/proc/$pid/status")
    if [ "${main:-}" = "80 1" ] && [ -z "$others_rt" ] && [ "${lck:-0}" -gt 0 ]; then
      pass "fw-realtime: loop thread $pid under SCHED_FIFO priority 80, the other threads not real-time (tid:priority/policy$sched), VmLck ${lck} kB"
    else
      fail "fw-realtime: expected thread $pid at SCHED_FIFO 80 alone and VmLck > 0; tid:priority/policy$sched, VmLck ${lck:-?} kB"
      journalctl -u gfins-fw --no-pager | grep -i 'realtime\|SCHED_FIFO\|mlockall' | tail -n 4 | sed 's/^/VBOARD-LOG fw: /' | tee -a $out
    fi
    frames=$(timeout 5 candump -n 20 can0 | wc -l)
    [ "$frames" -eq 20 ] && pass "fw-frames: 20 frames on can0 from the service" ||
      fail "fw-frames: $frames of 20 frames on can0 within 5 s"
    # The loop's WATCHDOG=1 pings: over more than WatchdogSec the service stays the same process.
    # One systemctl call per look (each costs the emulated guest about a second or more);
    # sets st (ActiveState), mp (MainPID), nr (NRestarts), wd (WatchdogUSec).
    look() {
      systemctl show -p ActiveState -p MainPID -p NRestarts -p WatchdogUSec gfins-fw >/tmp/look
      st=$(sed -n 's/^ActiveState=//p' /tmp/look) mp=$(sed -n 's/^MainPID=//p' /tmp/look)
      nr=$(sed -n 's/^NRestarts=//p' /tmp/look) wd=$(sed -n 's/^WatchdogUSec=//p' /tmp/look)
    }
    look
    n0=$nr
    sleep 3
    look
    if [ "$st $mp $nr" = "active $pid $n0" ]; then
      pass "fw-watchdog-pings: same PID $pid and NRestarts $n0 after 3 s > WatchdogSec ($wd)"
    else
      fail "fw-watchdog-pings: after 3 s (WatchdogSec $wd): state $st, PID $pid -> $mp, NRestarts $n0 -> $nr"
    fi

    # The firmware's STATUS= line (its reporter thread, once a second when it changes): past the
    # 1 s alignment, "navigating at <rate> Hz, calibration <id>; faults: none|<name> <count>, ...",
    # or DEGRADED when an input fault makes the output untrustworthy (an emulated guest under
    # host load misses data-ready edges) - and then it names at least one fault.
    status_ok() {
      text=$(prop gfins-fw StatusText)
      fault='[A-Za-z -]+ ([0-9]+|0x[0-9a-f]{2})'
      echo "$text" | grep -Eq "^(navigating|DEGRADED \(navigating on a faulty input\)) at $RATE Hz, (calibration [0-9a-f]{8}|UNCALIBRATED \(nominal parameters\)); faults: (none|$fault(, $fault)*)\$" ||
        return 1
      case $text in DEGRADED*"faults: none") return 1 ;; esac
    }
    if wait_for 3 status_ok; then
      pass "fw-status-text: systemctl show -p StatusText: '$text'"
    else
      fail "fw-status-text: StatusText '$text', expected '(navigating|DEGRADED ...) at $RATE Hz, calibration ...; faults: ...'"
    fi

    # Soak (run.sh --soak S, on request: not in CI). S seconds of the installed firmware under
    # systemd on a misbehaving bus: a second node floods can0 (cangen: random 11-bit identifiers,
    # lengths and data, a frame every millisecond, its commands' identifiers included) and every
    # 60 s can0 goes down for 2 s and comes back. Passes when the watchdog never fired (the same
    # PID, NRestarts unchanged, no 'Watchdog timeout' in the journal), the firmware's frames are
    # on can0 after the last flap, and its resident memory grew by at most 1 MiB (it allocates
    # nothing after start-up and locks its memory: a leak of one small block per flooded frame
    # would be about 10 MiB over 10 minutes).
    if [ "${SOAK_S:-0}" -gt 0 ]; then
      rss() { sed -n 's/^VmRSS:[[:space:]]*\([0-9]*\) kB/\1/p' "/proc/$1/status"; }
      secs() { cut -d. -f1 /proc/uptime; }
      look
      soak_nr=$nr
      rss0=$(rss "$pid")
      wd0=$(journalctl -u gfins-fw --no-pager | grep -c 'Watchdog timeout')
      say "VBOARD-INFO soak: ${SOAK_S} s from uptime $(up) s, PID $pid, VmRSS ${rss0} kB, status '$(prop gfins-fw StatusText)'"
      t_end=$(($(secs) + SOAK_S))
      flaps=0
      floods=0  # flaps whose flood was still sending when stopped: the second node really ran
      while [ "$(secs)" -lt "$t_end" ]; do
        cangen can0 -g 1 -I r -L r -D r -i >/dev/null 2>&1 &
        flood=$!
        left=$((t_end - $(secs)))
        sleep $((left < 58 ? (left > 0 ? left : 1) : 58))
        kill "$flood" 2>/dev/null && floods=$((floods + 1))
        wait "$flood" 2>/dev/null
        ip link set can0 down
        sleep 2
        ip link set can0 up
        flaps=$((flaps + 1))
        say "VBOARD-INFO soak: flap $flaps at uptime $(up) s, VmRSS $(rss "$pid") kB, status '$(prop gfins-fw StatusText)'"
      done
      look
      rss1=$(rss "$pid")
      wd1=$(journalctl -u gfins-fw --no-pager | grep -c 'Watchdog timeout')
      if [ "$st $mp $nr" = "active $pid $soak_nr" ] && [ "$wd1" = "$wd0" ] && [ "$floods" = "$flaps" ]; then
        pass "fw-soak-watchdog: ${SOAK_S} s, $flaps flaps of can0 under a flood (cangen sending until each flap: $floods): same PID $pid, NRestarts $nr, no watchdog timeout"
      else
        fail "fw-soak-watchdog: after ${SOAK_S} s: state $st, PID $pid -> $mp, NRestarts $soak_nr -> $nr, watchdog timeouts in the journal $wd0 -> $wd1, floods still sending at their flap $floods of $flaps"
      fi
      if [ -n "$rss0" ] && [ -n "$rss1" ] && [ $((rss1 - rss0)) -le 1024 ]; then
        pass "fw-soak-memory: VmRSS ${rss0} kB -> ${rss1} kB"
      else
        fail "fw-soak-memory: VmRSS ${rss0:-?} kB -> ${rss1:-?} kB (more than 1 MiB of growth)"
      fi
      frames=$(timeout 5 candump -n 20 can0 | wc -l)
      [ "$frames" -eq 20 ] && pass "fw-soak-frames: 20 frames on can0 after the last flap" ||
        fail "fw-soak-frames: $frames of 20 frames within 5 s after the last flap"
      journalctl -u gfins-fw --no-pager | grep -iE 'can0|bus|flood|malformed' | tail -n 6 | sed 's/^/VBOARD-LOG fw: /' | tee -a $out
    fi

    # A hung loop: stop the process; the watchdog must fire and systemd restart it.
    before=$nr
    kill -STOP "$pid"
    newpid() { look; [ "$st" = active ] && [ "$mp" != "$pid" ] && [ "$mp" != 0 ]; }
    if wait_for 30 newpid; then
      pass "fw-hang-restart: SIGSTOP'd loop killed on watchdog timeout, restarted as PID $mp (NRestarts $before -> $nr)"
    else
      fail "fw-hang-restart: no restart within 30 s (state $st, PID $mp, NRestarts $nr)"
    fi
    journalctl -u gfins-fw --no-pager | grep -q 'Watchdog timeout' &&
      pass "fw-watchdog-journal: the journal names the watchdog timeout" ||
      fail "fw-watchdog-journal: no 'Watchdog timeout' in gfins-fw's journal"
    frames=$(timeout 5 candump -n 20 can0 | wc -l)
    [ "$frames" -eq 20 ] && pass "fw-frames-after-restart: frames on can0 again" ||
      fail "fw-frames-after-restart: $frames of 20 frames within 5 s"
    fi
  fi
fi

if [ $failed -eq 0 ] && [ $checks -gt 0 ]; then result=PASS; else result=FAIL; fi
say "VBOARD-RESULT $result checks=$checks failed=$failed"
say "VBOARD-END status=$failed uptime=$(cut -d' ' -f1 /proc/uptime)"
