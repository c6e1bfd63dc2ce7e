#!/usr/bin/env bash
# Second command of the README, and what CI runs (.ci/run): install packages, check formatting,
# build every preset, run the whole test suite, with clang-tidy in the background from the
# start. Exits non-zero on the first failure. GFINS_JOBS sets the build parallelism (default: all
# cores).
set -euo pipefail
cd "$(dirname "$0")/.."
jobs=${GFINS_JOBS:-$(nproc)}
start=$(date +%s)
log_dir=$(mktemp -d)
# Per step: wall seconds and the CPU seconds (user + sys) of everything it started, which is
# what the step costs on an idle machine whatever the load was (docs/ci.md); printed as a table
# when the script ends, passing or failing.
# `times` runs in this shell (in a pipe or $(...) it would see a subshell's children only).
children_cpu() {
  times >"$log_dir/times"
  cpu_s=$(awk 'END { s = 0; for (i = 1; i <= 2; i++) { split($i, a, "m"); s += a[1] * 60 + a[2] } printf "%d", s }' "$log_dir/times")
}
step_rows=()
step_close() {
  [ -n "${step_name:-}" ] || return 0
  children_cpu
  step_rows+=("$(printf '%6d s %7d s   %s' $(($(date +%s) - step_t)) $((cpu_s - step_cpu)) "$step_name")")
}
step_table() {
  step_close
  step_name=""
  printf '\n   wall  CPU (u+s)   step\n'
  printf '%s\n' "${step_rows[@]}"
  printf '%6d s             total\n' $(($(date +%s) - start))
}
tidy_pid=""
cppcheck_pid=""
vboard_pid=""
trap 'rc=$?; for p in $tidy_pid $cppcheck_pid $vboard_pid; do kill -- "-$p" 2>/dev/null; done; step_table; rm -rf "$log_dir"; exit $rc' EXIT
step() {
  step_close
  children_cpu
  step_name="$*" step_t=$(date +%s) step_cpu=$cpu_s
  printf '\n=== %s (%s, +%ds)\n' "$*" "$(date +%T)" "$((step_t - start))"
}

# The free space of the file system the trees are on, in MiB, with a label.
free_space() {
  printf 'test.sh: %s: %s MiB free on the file system of %s\n' "$1" \
    "$(df -Pm . | awk 'NR == 2 { print $4 }')" "$PWD"
}
# Deletes the ELF executables a build tree linked (not its objects, libraries or scripts).
prune_programs() {
  local n=0 bytes=0 f size
  while IFS= read -r -d '' f; do
    [ "$(head -c 4 "$f" | od -An -c | tr -d ' ')" = '177ELF' ] || continue
    size=$(stat -c %s "$f")
    rm -f -- "$f"
    n=$((n + 1)) bytes=$((bytes + size))
  done < <(find "$1" -path "$1/CMakeFiles" -prune -o -type f -perm -u+x -print0)
  printf 'test.sh: removed %d programs of %s (%d MiB)\n' "$n" "$1" $((bytes / 1048576))
}

# A background check's result: its log, and the run fails when it did.
collect() {  # collect NAME PID LOG
  local rc=0
  wait "$2" || rc=$?
  cat "$3"
  [ "$rc" -eq 0 ] || { echo "test.sh: $1 failed (exit $rc)" >&2; exit 1; }
}

# The packages the host trees build and test with come first; the rest (clang-tidy, cppcheck,
# the bare-metal Arm toolchain, lintian, then the virtual board's and the armhf build's) install
# in the background while the host trees compile (docs/ci.md, "apt beside the compiles"). One apt
# at a time: the later sets in turn, after this one. clang-tidy and cppcheck start when theirs is
# in ($later_ok written with its exit status). The background install is collected before the
# packages step and never killed (a dpkg stopped half-way leaves the package database to repair).
step "install packages (what the host trees need; the rest in the background)"
free_space "at the start"
./scripts/install-deps.sh host
later_ok=$log_dir/later-tools.status
{
  rc=0
  ./scripts/install-deps.sh later || rc=$?
  echo "$rc" >"$later_ok"
  [ "$rc" -eq 0 ] && ./scripts/vboard/install-deps.sh && ./scripts/install-cross-deps.sh armhf
} >"$log_dir/apt-later.log" 2>&1 &
apt_pid=$!
# after_later_tools CMD...: CMD once install-deps.sh later has ended, or a failure naming it.
after_later_tools() {
  until [ -e "$later_ok" ]; do sleep 2; done
  [ "$(cat "$later_ok")" = 0 ] || { echo "test.sh: install-deps.sh later failed: $* not run" >&2; return 1; }
  "$@"
}

step "clang-format check"
./scripts/check-format.sh

# clang-tidy needs only the release tree's compile database, which configuring writes (the files
# it checks include no generated header), so it starts here, in the background at the lowest CPU
# priority (nice 19: it gets a core only when the steps below leave one idle: link and test
# phases, the serial install and documentation steps, apt downloads, the tests under qemu-user,
# lintian, the virtual machine's one TCG thread), in its own process group, stopped if the script
# ends early; its result is collected at the end. The virtual board's data-ready stages run on
# instruction-counted guest time, so this load does not move their timing (docs/deploy.md).
# Own process group through job control (set -m), not setsid: a new session is a new scheduler
# autogroup, in which nice 19 would count only against itself and tidy would take half the CPU.
cmake --preset host-release >/dev/null
set -m
{ after_later_tools nice -n 19 ./scripts/check-tidy.sh build/host-release; } >"$log_dir/tidy.log" 2>&1 &
tidy_pid=$!
# cppcheck the same way, beside it (docs/ci.md): the two share what the steps leave idle.
{ after_later_tools nice -n 19 ./scripts/check-cppcheck.sh build/host-release; } >"$log_dir/cppcheck.log" 2>&1 &
cppcheck_pid=$!
set +m

step "host-debug (ASan + UBSan): build"
cmake --preset host-debug >/dev/null
cmake --build --preset host-debug -j "$jobs"

step "host-debug (ASan + UBSan): unit tests"
ctest --preset host-debug -j "$jobs" | tee "$log_dir/ctest-debug.log"

# The libFuzzer targets (tests/fuzz, built with the sanitizer tree above) fuzz every parser of
# outside input from its seed corpus for GFINS_FUZZ_SECONDS each (10 s, seed 1: about 55 s on 2 cores);
# a crash, a sanitizer report or a broken invariant fails the step and leaves the input in
# build/host-debug/fuzz-findings/ (docs/reliability.md). Not the preset: it excludes the label.
step "host-debug: fuzzing (libFuzzer, every parser of outside input)"
ctest --test-dir build/host-debug -L fuzz -j "$jobs" --output-on-failure | tee "$log_dir/ctest-fuzz.log"

# The sanitizer tree's linked programs (about 120 test and fuzz executables of 30-50 MB each: ASan
# at -O0, every library linked in) are 5-6 GB, most of what the run writes; nothing after this
# step uses them, and a machine with 10 GB free ran out of space in the virtual board's kernel
# download with them kept (docs/ci.md, "Disk"). The objects and libraries stay, so
# `cmake --build --preset host-debug` relinks them in about a minute. On a failure above the
# script has ended already and the tree is left whole, with any fuzz finding.
step "host-debug: remove its linked programs (disk)"
free_space "before"
prune_programs build/host-debug
free_space "after"

# The threaded parts (the Monte-Carlo pool, the candump log writer, the reload worker, the
# status reporter, and gfins-fw as a process: logger thread, HIL link) under ThreadSanitizer:
# preset host-tsan builds only their tests (label threads, tests/CMakeLists.txt); a race or a
# lock-order inversion fails the test (TSAN_OPTIONS halt_on_error=1 in the test preset).
step "host-tsan (ThreadSanitizer): the threaded parts' tests"
cmake --preset host-tsan >/dev/null
cmake --build --preset host-tsan -j "$jobs"
ctest --preset host-tsan -j "$jobs" | tee "$log_dir/ctest-tsan.log"

# Every unit test ran above under the sanitizers; the release build adds what needs optimised
# code: the hour-long simulations, the heap checks with NDEBUG defined, the resource figures of
# gfins-sim montecarlo and covariance (label optimised, tests/CMakeLists.txt), the applications and
# the benchmarks (built and run briefly so they cannot rot). The full release suite is
# `ctest --preset host-release` after a full release build.
step "host-release: build (applications, benchmarks, long and heap tests)"
cmake --preset host-release >/dev/null
# Build preset host-release-ci: the packaged programs, every benchmark program (gfins_benchmarks,
# tests/bench/CMakeLists.txt) and every test labelled long, heap or optimised
# (gfins_release_checks): targets that collect their members, so a new benchmark or test cannot
# be left out of a list kept by hand.
cmake --build --preset host-release-ci -j "$jobs"
step "host-release: hour-long runs (label long), heap checks (label heap), resource figures (label optimised), benchmarks once (label bench)"
ctest --preset host-release -j "$jobs" -L 'long|heap|optimised|bench' | tee "$log_dir/ctest-release.log"

step "host-release: main job and benchmarks, smoke run"
./build/host-release/host_sim/app/gfins-sim --duration 1 >/dev/null
# Every benchmark program ran above, briefly: each has a test labelled bench
# (tests/bench/CMakeLists.txt). The filter's other operations as instruction-count runs:
for op in zupt zaru gnss-position gnss-velocity heading; do
  ./build/host-release/tests/bench/gfins_filter_ir float "$op" 50 >/dev/null
done
# The firmware on the simulated board, its candump log decoded by gfins-can: every CRC valid,
# every counter continuous (gfins-can exits non-zero on any problem).
fw_log="$log_dir/fw-rest.log"
./build/host-release/firmware/app/gfins-fw --sim rest --calibration "" --duration 2 \
  --can-log "$fw_log" >/dev/null
./build/host-release/host_sim/can_tool/gfins-can decode --view none "$fw_log"

# Every installed program and subcommand from a temporary prefix, the source and build trees
# hidden from them by a private mount namespace (docs/install.md); about 15 s.
step "host-release: installed programs away from the trees (tests/install/install_test.sh)"
./tests/install/install_test.sh build/host-release
# The README rows and docs blocks marked <!-- runnable -->, as written, after what bootstrap.sh
# leaves (out/gfins installed); about 30 s.
step "host-release: the documentation's runnable commands (tests/install/runnable_docs.py)"
./tests/install/runnable_docs.py --build build/host-release

# The virtual board's boots run QEMU's one TCG thread (its fresh-cache set-up before them uses
# both cores: docs/ci.md, "Where the budget stands"). It starts in the background here, once the
# amd64 package it installs is made, and the bare-metal and armhf builds run beside it at nice 10
# (CFS weight 110 against the VM's 1024: the VM keeps its core; the data-ready stages run on
# instruction-counted guest time, and the systemd stage ran beside clang-tidy's two nice-19 jobs
# the same way before). Its log is printed when it is collected, after the armhf step. Its
# packages and the armhf build's were installed in the background (above, collected here), so
# run.sh finds them present.
step "Debian packages (amd64, from the host-release tree) and lintian; the virtual board started"
collect "the virtual board's and the armhf build's packages (apt)" "$apt_pid" "$log_dir/apt-later.log"
apt_pid=""
./scripts/package.sh host-release
# scripts/package.sh keeps one version per package and architecture in out/deb: the one it made.
fw_debs=(out/deb/gfins-fw_*_amd64.deb)
[ ${#fw_debs[@]} -eq 1 ] && [ -e "${fw_debs[0]}" ] ||
  { echo "test.sh: expected one out/deb/gfins-fw_*_amd64.deb, found: ${fw_debs[*]}" >&2; exit 1; }
fw_deb=${fw_debs[0]}
free_space "before the virtual board"
# One VM boot runs infra (Debian's tools on vcan0 and the gpio-sim line), backend (the Linux
# backends' real-kernel checks), fw / cmd / faults (the unchanged gfins-fw paced by the gpio-sim
# line, on vcan0: output within one quantisation step of a host-only run, every CAN command,
# kernel-made faults) and canlog; a second boot runs service (systemd: the amd64 package above
# installed in a clean root, READY=1, watchdog pings, a SIGSTOP'd loop restarted). Costs in
# docs/ci.md. Its own process group (set -m), stopped if the script ends early.
set -m
./scripts/vboard/run.sh --stages "${GFINS_VBOARD_STAGES:-infra,backend,fw,cmd,faults,canlog,gnss,ids,service}" \
  --deb "$fw_deb" >"$log_dir/vboard.log" 2>&1 &
vboard_pid=$!
set +m
echo "test.sh: the virtual board runs in the background (its log follows when it ends)"

step "cortex-m4f: bare-metal build of the navigation core and the soft-double check (beside the virtual board)"
# --fresh: the toolchain's flags (-flto among them) reach an existing build folder only on a new
# cache; a stale one links without LTO and over the flash limit.
cmake --preset cortex-m4f --fresh >/dev/null
nice -n 10 cmake --build --preset cortex-m4f -j "$jobs"
# The limits (flash, RAM, no soft-float double) are a test of that tree: GFINS_M4F_*_LIMIT.
ctest --preset cortex-m4f | tail -n 40

# The board's program cross-built for 32-bit armhf (ARM code generation, 32-bit size_t and long,
# the hard-float ABI, every warning an error) and packaged (CPack, lintian). The tests of the code
# that runs on the board (label `board`) cross-built and run under qemu-arm-static (preset
# armhf-linux) or qemu-aarch64-static (preset aarch64-linux; the whole suite: aarch64-linux-all)
# are one command each, run before a release (docs/deploy.md): per commit they compiled the same
# sources a third time, about 430 s of the run, for targets whose code x86-64 and the bare-metal
# ARM build bracket (docs/ci.md, "The 40-minute budget"). The armhf tools and both arm64 packages
# are made on request (scripts/package.sh armhf-linux, scripts/package.sh aarch64-linux).
step "armhf cross build of gfins-fw, its Debian package and lintian (beside the virtual board)"
nice -n 10 ./scripts/package.sh armhf-linux:board

step "virtual board: Debian's kernel in QEMU (TCG), vcan0, gpio-sim, systemd (started before the bare-metal build)"
collect "the virtual board" "$vboard_pid" "$log_dir/vboard.log"
vboard_pid=""

step "clang-tidy (started after the format check, at the lowest priority)"
collect clang-tidy "$tidy_pid" "$log_dir/tidy.log"
tidy_pid=""

step "cppcheck (started with clang-tidy, at the lowest priority)"
collect cppcheck "$cppcheck_pid" "$log_dir/cppcheck.log"
cppcheck_pid=""

step "all checks passed"
total=$(sed -n 's/.*tests passed, 0 tests failed out of \([0-9]*\).*/\1/p' "$log_dir"/ctest-*.log |
  awk '{ n += $1 } END { print n + 0 }')
echo "tests: $total passed, 0 failed"
