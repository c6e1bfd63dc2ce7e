#!/usr/bin/env bash
# The virtual board: boots Debian's own kernel in QEMU (TCG, no KVM) with vcan0, a gpio-sim
# data-ready line and the project's programs, runs the in-VM test (vm-test.sh) and turns the
# console into a pass/fail and an exit status (0 = every check passed).
#
#   scripts/vboard/run.sh [--stages infra,backend,fw,cmd,faults,canlog,gnss,ids,service] [--deb FILE] [--fw-config FILE] [--rate HZ] [--timeout S]
#                         [--build-dir DIR] [--smp N] [--icount SHIFT|off] [--service-icount SHIFT|off]
#                         [--measure]   (infra also measures the toggler alone at 250-4000 Hz and at full speed)
#                         [--soak S]    (service, with --deb: S seconds of the firmware under systemd with can0
#                                        taken down and up every minute and a second node flooding it; not in CI)
#
# Every step is idempotent and cached under .cache/vboard (see common.sh): the first run
# installs the host packages, downloads the kernel, headers and source (about 220 MB) and builds
# gpio-sim; later runs download nothing. Fails naming whatever cannot be installed or built.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
source "$here/common.sh"

stages=infra,backend,fw,cmd,faults,canlog,gnss,ids,service
rate=500
timeout_s=600
build_dir=$vboard_repo/build/host-release
smp=1
icount=0          # data-ready timing stages: guest time counts instructions (docs/deploy.md)
service_icount=off  # systemd boot: icount's sleep=off would warp time over every 9p wait
service_deb=""
service_config=""
measure=0
soak_s=0
known_stages=infra,backend,fw,cmd,faults,canlog,gnss,ids,service
# value OPTION ARGS...: the option's value, or a usage error naming the option when none follows
# (set -u would otherwise stop at "$2: unbound variable").
value() {
  [ $# -ge 2 ] && [ -n "$2" ] && [ "${2#--}" = "$2" ] || vb_die "run.sh: $1 needs a value (try --help)"
  echo "$2"
}
while [ $# -gt 0 ]; do
  case $1 in
    --stages | --rate | --timeout | --build-dir | --smp | --icount | --service-icount | --deb | --fw-config | --soak)
      v=$(value "$@") || exit 1
      case $1 in
        --stages) stages=$v ;;
        --rate) rate=$v ;;
        --timeout) timeout_s=$v ;;
        --build-dir) build_dir=$v ;;
        --smp) smp=$v ;;
        --icount) icount=$v ;;
        --service-icount) service_icount=$v ;;
        --deb) service_deb=$v ;;
        --fw-config) service_config=$v ;;
        --soak) soak_s=$v ;;
      esac
      shift 2 ;;
    --measure) measure=1; shift ;;
    -h | --help) sed -n '2,13p' "$0"; exit 0 ;;
    *) vb_die "run.sh: unknown argument '$1' (try --help)" ;;
  esac
done
# Every value checked before anything is installed or booted: a misspelt stage would otherwise
# run nothing and pass, a rate the firmware refuses would fail late in the host reference run.
for s in ${stages//,/ }; do
  case ",$known_stages," in *",$s,"*) ;; *) vb_die "run.sh: --stages: unknown stage '$s' (known: $known_stages)" ;; esac
done
[ -n "${stages//,/}" ] || vb_die "run.sh: --stages names no stage (known: $known_stages)"
is_uint() { [[ $1 =~ ^[0-9]+$ ]] && [ "$1" -gt 0 ]; }
is_uint "$rate" || vb_die "run.sh: --rate '$rate' is not a positive whole number of Hz"
case ",$stages," in
  *,fw,* | *,cmd,* | *,faults,* | *,service,*)
    # The firmware's data rates (ADS131M06 at 8.192 MHz: gfins::app::kSampleRatesHz).
    case $rate in 500 | 1000 | 2000 | 4000) ;;
      *) vb_die "run.sh: --rate $rate: the firmware stages need 500, 1000, 2000 or 4000 Hz (the ADC's data rates)" ;;
    esac ;;
esac
is_uint "$timeout_s" || vb_die "run.sh: --timeout '$timeout_s' is not a positive whole number of seconds"
is_uint "$smp" || vb_die "run.sh: --smp '$smp' is not a positive whole number of CPUs"
for ic in "$icount" "$service_icount"; do
  [ "$ic" = off ] || [[ $ic =~ ^[0-9]+$ ]] || vb_die "run.sh: icount shift '$ic' is neither a whole number nor 'off'"
done
if [ -n "$service_deb" ]; then [ -f "$service_deb" ] || vb_die "run.sh: --deb $service_deb: no such file"; fi
[[ $soak_s =~ ^[0-9]+$ ]] || vb_die "run.sh: --soak '$soak_s' is not a whole number of seconds"
if [ "$soak_s" -gt 0 ]; then
  [ -n "$service_deb" ] && case ",$stages," in *,service,*) true ;; *) false ;; esac ||
    vb_die "run.sh: --soak needs the service stage and --deb (it soaks the installed firmware)"
  # The service boot's own checks take about 3 minutes of wall time under TCG.
  timeout_s=$((timeout_s + soak_s))
fi
if [ -n "$service_config" ]; then [ -f "$service_config" ] || vb_die "run.sh: --fw-config $service_config: no such file"; fi
t_start=$(date +%s)
elapsed() { echo $(($(date +%s) - t_start)); }

"$here/install-deps.sh"
kver=$("$here/fetch-kernel.sh")
"$here/build-gpio-sim.sh" >/dev/null
vb_log "kernel $kver ready (+$(elapsed)s)"

# Programs and files per stage; a missing one fails here, naming it.
want() { case ",$stages," in *",$1,"*) return 0 ;; esac; return 1; }
# What stage $1's script lists in its "# needs: build:<path> | repo:<path>:<vm> |
# cache:<path>:<vm>" lines (paths in the build folder, the repository, the vboard cache).
stage_needs() { sed -n 's/^# needs: //p' "$here/stage-$1.sh"; }
args=()
# The programs the stages need ("# needs: build:<path>", target = the file name) are brought up
# to date in the build folder first, so a partial build (test.sh builds only what it runs)
# cannot leave one missing or stale.
targets=()
for s in backend fw cmd faults canlog gnss ids; do
  want "$s" || continue
  [ -e "$here/stage-$s.sh" ] || continue
  while read -r need; do
    case $need in build:*) targets+=("$(basename "${need#build:}")") ;; esac
  done < <(stage_needs "$s")
done
if want canlog || want fw; then targets+=(gfins-fw gfins-can); fi
if [ ${#targets[@]} -gt 0 ]; then
  [ -f "$build_dir/CMakeCache.txt" ] ||
    vb_die "no configured build folder at $build_dir (cmake --preset host-release, or --build-dir)"
  mapfile -t targets < <(printf '%s\n' "${targets[@]}" | sort -u)
  mkdir -p "$vboard_cache"
  vb_log "building ${targets[*]} in $build_dir"
  cmake --build "$build_dir" --target "${targets[@]}" >"$vboard_cache/build.out" 2>&1 || {
    tail -n 30 "$vboard_cache/build.out" >&2
    vb_die "building ${targets[*]} in $build_dir failed (log: $vboard_cache/build.out)"
  }
fi
# Stage canlog replays a candump log written by the firmware's file sink on the host.
if want canlog; then
  fw=$build_dir/firmware/app/gfins-fw
  [ -x "$fw" ] || vb_die "stage canlog: $fw not built (it writes the log canplayer replays)"
  mkdir -p "$vboard_cache/canlog"
  rm -f "$vboard_cache/canlog/fw-rest.log"
  "$fw" --sim rest --calibration "" --duration 2 --can-log "$vboard_cache/canlog/fw-rest.log" \
    >"$vboard_cache/canlog/fw-rest.out" 2>&1 ||
    vb_die "stage canlog: gfins-fw --sim rest --can-log failed (see $vboard_cache/canlog/fw-rest.out)"
  [ -s "$vboard_cache/canlog/fw-rest.log" ] || vb_die "stage canlog: gfins-fw wrote no log"
fi
# Stages fw, cmd, faults run gfins-fw from gfins-fw-vboard.toml on the scenario vboard-rest.toml
# at the VM's data-ready rate. Stage fw compares the VM's output epoch by epoch with a host-only
# run: the same configuration and scenario through the same binary in fast pacing, its frames
# written to a candump log by the file sink and decoded to CSV by gfins-can.
if want fw || want cmd || want faults || want gnss || want ids; then
  fwc=$vboard_cache/fw
  mkdir -p "$fwc/scenarios"
  sed "s/^rate_hz = .*/rate_hz = $rate.0/" "$here/vboard-rest.toml" >"$fwc/scenarios/vboard-rest.toml"
  # Only the scenario's rate (the first rate_hz), not the receiver's.
  sed "0,/^rate_hz = .*/s//rate_hz = $rate.0/" "$here/vboard-gnss.toml" >"$fwc/scenarios/vboard-gnss.toml"
fi
if want fw; then
  fw=$build_dir/firmware/app/gfins-fw
  can_tool=$build_dir/host_sim/can_tool/gfins-can
  [ -x "$fw" ] || vb_die "stage fw: $fw not built (it writes the host-only reference)"
  [ -x "$can_tool" ] || vb_die "stage fw: $can_tool not built (it decodes the host-only reference)"
  sed "s/^sample_rate_hz = .*/sample_rate_hz = $rate.0/" "$here/gfins-fw-vboard.toml" >"$fwc/ref.toml"
  rm -f "$fwc/ref.log" "$fwc/ref.csv"
  # 12 s: the VM stage's 10 s of edges and a margin.
  "$fw" --config "$fwc/ref.toml" --scenario-dir "$fwc/scenarios" --pacing fast --duration 12 \
    --can-log "$fwc/ref.log" >"$fwc/ref.out" 2>&1 ||
    vb_die "stage fw: the host-only reference run failed (see $fwc/ref.out)"
  "$can_tool" decode "$fwc/ref.log" --view csv -o "$fwc/ref.csv" --quiet 2>"$fwc/ref-decode.out" ||
    vb_die "stage fw: gfins-can decode of the host-only reference failed (see $fwc/ref-decode.out)"
  # The reference's CPU (libm's ifunc variants follow it); the VM prints the guest's.
  vb_log "stage fw: host CPU $(grep -m1 '^flags' /proc/cpuinfo | tr -s ' \t' ' ')"
fi
for s in backend fw cmd faults canlog gnss ids; do
  want "$s" || continue
  stage_script=$here/stage-$s.sh
  [ -e "$stage_script" ] || vb_die "stage '$s' has no scripts/vboard/stage-$s.sh yet"
  args+=(--file "$stage_script:/vboard/stage-$s.sh")
  while read -r need; do
    case $need in
      build:*) args+=(--bin "$build_dir/${need#build:}") ;;
      repo:*) spec=${need#repo:}; args+=(--file "$vboard_repo/${spec%%:*}:${spec#*:}") ;;
      cache:*) spec=${need#cache:}; args+=(--file "$vboard_cache/${spec%%:*}:${spec#*:}") ;;
      *) vb_die "$stage_script: unknown need '$need'" ;;
    esac
  done < <(stage_needs "$s")
done
initrd=$vboard_cache/initramfs/initrd.gz
"$here/make-initramfs.sh" "${args[@]}" -o "$initrd"
vb_log "initramfs ready (+$(elapsed)s)"

vb_require qemu-system-x86_64:qemu-system-x86 timeout:coreutils
mkdir -p "$vboard_cache/runs"
kernel=$vboard_cache/root/$kver/boot/vmlinuz-$kver
overall=0

# boot NAME EXTRA_APPEND [QEMU ARGS...]: one VM run; sets $log and $qemu_rc.
boot() {
  local name=$1 append=$2
  shift 2
  log=$vboard_cache/runs/$name-$(date +%Y%m%dT%H%M%S).log
  local timing=()
  if [ "$icount" != off ]; then timing=(-icount "shift=$icount,sleep=off"); fi
  vb_log "booting $kver under QEMU TCG (-smp $smp, icount $icount): $name; console: $log"
  t_boot=$(date +%s.%N)
  set +e
  # -accel tcg: KVM boots did not come up on the machines this was written on; TCG always does.
  # panic=-1 and -no-reboot: a kernel panic ends QEMU instead of hanging the test.
  timeout "$timeout_s" qemu-system-x86_64 -accel tcg -cpu max -smp "$smp" -m 768 "${timing[@]}" \
    -nographic -no-reboot -monitor none -serial stdio -display none \
    -kernel "$kernel" -initrd "$initrd" "$@" \
    -append "console=ttyS0 panic=-1 quiet loglevel=3 $append" \
    </dev/null >"$log" 2>&1
  qemu_rc=$?
  set -e
  t_end=$(date +%s.%N)
  # Plain text: no carriage returns, no terminal escapes from the firmware's boot messages, and
  # each VBOARD line starting its own line.
  sed -e 's/\r//g' -e 's/\x1b\[[0-9;?]*[a-zA-Z]//g' -e 's/\x1bc//g' -e 's/^.*\(VBOARD-[A-Z]*\)/\1/' \
    "$log" >"$log.txt" && mv "$log.txt" "$log"
  vm_s=$(awk -v a="$t_boot" -v b="$t_end" 'BEGIN { printf "%.1f", b - a }')
}

# verdict RESULT_FILE: prints the checks and returns 0 when all passed.
verdict() {
  local file=$1 booted nfail
  grep -E '^VBOARD-(CHECK|MEASURE|INFO|RESULT|BOOTED|END|LOG)' "$file" || true
  booted=$(sed -n 's/^VBOARD-BOOTED uptime=\([0-9.]*\).*/\1/p' "$file" | head -n 1)
  vb_log "QEMU ran ${vm_s}s (test start at ${booted:-?}s guest uptime), total +$(elapsed)s"
  if [ "$qemu_rc" -eq 124 ]; then
    vb_log "FAILED: the VM did not power off within ${timeout_s}s (console: $log)"; return 1
  fi
  if [ -z "$booted" ] || ! grep -q '^VBOARD-END' "$file"; then
    tail -n 40 "$log" >&2
    vb_log "FAILED: the in-VM test did not run to its end (console: $log)"; return 1
  fi
  nfail=$(grep -c '^VBOARD-CHECK FAIL' "$file" || true)
  if grep -q '^VBOARD-RESULT PASS' "$file" && [ "$nfail" -eq 0 ]; then
    vb_log "PASS ($(grep -c '^VBOARD-CHECK PASS' "$file") checks)"; return 0
  fi
  vb_log "FAILED: $nfail check(s) failed (console: $log)"; return 1
}

vm_stages=$(echo ",$stages," | sed 's/,service,/,/g; s/^,//; s/,$//')
if [ -n "$vm_stages" ]; then
  boot vm "vboard.stages=$vm_stages vboard.rate=$rate vboard.measure=$measure"
  verdict "$log" || overall=1
fi

if want service; then
  sroot=$vboard_cache/service-root
  sargs=(--rate "$rate" -o "$sroot")
  if [ -n "$service_deb" ]; then sargs+=(--deb "$service_deb"); fi
  if [ -n "$service_config" ]; then sargs+=(--fw-config "$service_config"); fi
  sargs+=(--soak "$soak_s")
  "$here/prepare-service-root.sh" "${sargs[@]}"
  icount=$service_icount
  boot service "vboard.root=9p" \
    -virtfs "local,path=$sroot,mount_tag=vroot,security_model=passthrough,id=vroot"
  # The result file in the shared root is complete even when the console interleaves.
  if [ -e "$sroot/var/log/vboard-result" ]; then
    verdict "$sroot/var/log/vboard-result" || overall=1
  else
    verdict "$log" || overall=1
  fi
fi
exit $overall
