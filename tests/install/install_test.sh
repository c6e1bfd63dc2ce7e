#!/usr/bin/env bash
# The installed programs, away from the trees they were built from (docs/install.md):
#
#   tests/install/install_test.sh [BUILD_DIR]     default build/host-release, built with
#                                                 `--target gfins_package_programs`
#
# 1. `cmake --install BUILD --prefix T` (and the firmware package's files alone into T2);
# 2. no installed program contains the path of the source or build tree (a compiled-in data path
#    would be one);
# 3. the programs under test run in a private mount namespace (`unshare --mount`) in which an
#    empty tmpfs is mounted over the source tree and the build tree: a program that reaches back
#    into them fails, and nothing else on the machine (other builds, ctest -j) sees a change;
#    this needs root (as CI is) and fails with exit status 2 and a message saying so when not;
# 4. every program and subcommand runs from T: --version, --help, gfins-sim list / run (PNG when
#    matplotlib is there) / aided / paper63 / montecarlo / covariance, a built-in name next to a
#    folder of the same name, an unknown name's suggestion, gfins-calibrate on the shipped example,
#    gfins-can decode + plot of the shipped log, gfins-can-gen, gfins-fw --sim writing a candump
#    log that gfins-can decodes cleanly, and gfins-fw from its own package alone.
#
# Cost: about 15 s (measured 12 s here; the install ~1 s, paper63 and the runs with PNGs
# dominate). Exit status: 0 all passed, 1 a check failed, 2 bad usage.
set -euo pipefail
# The defaults are under test, not a developer's overrides.
unset GFINS_SCENARIO_DIR GFINS_SCRIPTS_DIR GFINS_EXAMPLES_DIR

failures=0
fail() {
  echo "FAIL: $*" >&2
  failures=$((failures + 1))
}

# Steps 1-3, with the trees visible.
outer() {
  src=$(cd "$(dirname "$0")/../.." && pwd)
  local build_arg=${1:-$src/build/host-release}
  if [ ! -f "$build_arg/CMakeCache.txt" ]; then
    echo "install_test: $build_arg is not a configured build folder" >&2
    exit 2
  fi
  build=$(cd "$build_arg" && pwd)
  if [ "$(id -u)" != 0 ] || ! command -v unshare >/dev/null; then
    echo "install_test: needs root and unshare (util-linux): the programs under test run in a" \
      "private mount namespace with the source and build trees hidden" >&2
    exit 2
  fi
  if ! unshare --mount --propagation private true 2>/dev/null; then
    echo "install_test: unshare --mount is not permitted here (it needs CAP_SYS_ADMIN, e.g. a" \
      "container started without it): the trees cannot be hidden from the programs under test" >&2
    exit 2
  fi
  work=$(mktemp -d "${TMPDIR:-/tmp}/gfins-install-test.XXXXXX")
  trap 'rm -rf "$work"' EXIT
  prefix=$work/prefix
  fw_prefix=$work/fw-only

  # --- 1. install ------------------------------------------------------------------------------
  echo "install_test: installing $build into $prefix"
  cmake --install "$build" --prefix "$prefix" >"$work/install.log"
  cmake --install "$build" --prefix "$fw_prefix" --component board >>"$work/install.log"

  # --- 2. no source or build path inside an installed program ---------------------------------
  local p tree
  for p in $(program_names); do
    if [ ! -x "$prefix/bin/$p" ]; then
      fail "$p is not installed in $prefix/bin"
      continue
    fi
    for tree in "$src" "$build"; do
      if grep -q -a -F "$tree" "$prefix/bin/$p"; then fail "$p contains the path $tree"; fi
    done
    # Its manual page, made from its --help (help2man): the NAME line and the help's exit codes.
    local man=$prefix/share/man/man1/$p.1.gz
    if [ ! -s "$man" ]; then
      fail "$p has no manual page $man"
    elif ! zcat "$man" | grep -q "^$p \\\\- " || ! zcat "$man" | grep -q "Exit codes"; then
      fail "$p: $man is not its --help (no NAME line for $p, or no exit codes)"
    fi
  done

  # The oracle for --version: git's own description of the checkout (build and test run on the
  # same commit in scripts/test.sh; "-dirty" is left out, an edit after the build changes it).
  local expected_rev=unknown rev
  if command -v git >/dev/null && rev=$(git -C "$src" describe --always --dirty 2>/dev/null); then
    expected_rev=${rev%-dirty}
  fi
  # The oracle for `list`: the scenario files of the source tree.
  local expected_list
  expected_list=$(for f in "$src"/host_sim/scenarios/*.toml; do basename "$f" .toml; done | sort)

  # --- 3. the rest in a private mount namespace, the trees hidden ----------------------------
  # This script runs again there (`--inner`); the mounts it makes are seen by nobody else, and
  # vanish with it. bash keeps reading the script through the descriptor it opened before.
  local rc=0
  GFINS_IT_SRC=$src GFINS_IT_BUILD=$build GFINS_IT_WORK=$work GFINS_IT_PREFIX=$prefix \
    GFINS_IT_FW_PREFIX=$fw_prefix GFINS_IT_REV=$expected_rev GFINS_IT_LIST=$expected_list \
    unshare --mount --propagation private bash "$0" --inner || rc=$?
  if [ "$failures" != 0 ] || [ "$rc" != 0 ]; then
    echo "install_test: failed ($failures check(s) before the run, run exit status $rc)" >&2
    exit 1
  fi
  echo "install_test: every installed program ran from $prefix with the trees hidden"
}

# The programs every install has, and gfins-replay when the build has it.
program_names() {
  echo gfins-sim gfins-fw gfins-can gfins-can-gen gfins-calibrate
  if [ -x "$prefix/bin/gfins-replay" ]; then echo gfins-replay; fi
}

# Step 4, inside the mount namespace.
inner() {
  src=$GFINS_IT_SRC build=$GFINS_IT_BUILD work=$GFINS_IT_WORK prefix=$GFINS_IT_PREFIX
  fw_prefix=$GFINS_IT_FW_PREFIX expected_rev=$GFINS_IT_REV expected_list=$GFINS_IT_LIST
  local tree
  for tree in "$src" "$build"; do
    if [ -d "$tree" ] && ! mount -t tmpfs -o ro,size=4k gfins-hidden "$tree"; then
      echo "install_test: cannot mount a tmpfs over $tree" >&2
      exit 2
    fi
  done
  if [ -e "$src/README.md" ] || [ -e "$build/CMakeCache.txt" ]; then
    echo "install_test: the trees are still visible after the mounts" >&2
    exit 2
  fi
  echo "install_test: $src and $build hidden from the programs under test"
  # A failed check is counted, not fatal: every check runs.
  set +e
  checks
  if [ "$failures" != 0 ]; then
    echo "install_test: $failures check(s) failed" >&2
    exit 1
  fi
}

# expect RC CMD...: runs CMD with output in $log; a different exit status is a failure.
expect() {
  local want=$1
  shift
  local rc=0
  "$@" >"$log" 2>&1 || rc=$?
  if [ "$rc" != "$want" ]; then
    fail "$* exited $rc, expected $want:"
    sed 's/^/    /' "$log" | tail -n 20 >&2
    return 1
  fi
}
# log_has TEXT WHAT: the last command's output contains TEXT.
log_has() { grep -q -F -- "$1" "$log" || fail "$2: output lacks '$1'"; }

# Every program and subcommand, from the prefix.
checks() {
  run_dir=$work/run
  mkdir -p "$run_dir"
  cd "$run_dir"
  bin=$prefix/bin
  log=$work/last.log

  # PNGs when Debian's python3 (or $GFINS_PYTHON) has matplotlib, as the programs choose it.
  python=${GFINS_PYTHON:-/usr/bin/python3}
  plot=(--no-plot)
  if "$python" -c 'import matplotlib' 2>/dev/null; then plot=(); else
    echo "install_test: no matplotlib for $python: CSV only"
  fi

  for p in $(program_names); do
    if expect 0 "$bin/$p" --version; then
      grep -q -E "^$p [0-9]+\.[0-9]+\.[0-9]+ \(git [^)]+\)$" "$log" ||
        fail "$p --version printed '$(cat "$log")', not '$p X.Y.Z (git REV)'"
      got_rev=$(sed -n 's/.*(git \(.*\))$/\1/p' "$log")
      [ "${got_rev%-dirty}" = "$expected_rev" ] ||
        fail "$p --version: revision '$got_rev', git describe says '$expected_rev' (a stale build? cmake --build $build --target gfins_package_programs)"
    fi
    expect 0 "$bin/$p" --help && log_has "Exit codes" "$p --help"
  done

  # gfins-sim: the list is the shipped scenario files.
  if expect 0 "$bin/gfins-sim" list; then
    got=$(awk '{print $1}' "$log" | sort)
    [ "$got" = "$expected_list" ] || fail "gfins-sim list: '$got' differs from the shipped files"
  fi
  if expect 0 "$bin/gfins-sim" run rest -o run-rest "${plot[@]}"; then
    [ -s run-rest/compensated.csv ] || fail "run rest: no compensated.csv"
    if [ ${#plot[@]} = 0 ]; then
      [ -s run-rest/nav_errors.png ] || fail "run rest: no nav_errors.png"
    fi
  fi
  # A folder named like a built-in scenario does not shadow it.
  expect 0 "$bin/gfins-sim" run drive -o drive --no-plot
  expect 0 "$bin/gfins-sim" montecarlo drive -n 2 -o mc-drive --no-plot
  expect 2 "$bin/gfins-sim" run drvie && log_has "closest: drive" "unknown scenario name"
  expect 0 "$bin/gfins-sim" run "$prefix/share/gfins/scenarios/spin.toml" -o spin --no-plot
  if expect 0 "$bin/gfins-sim" paper63 -o p63 "${plot[@]}" && [ ${#plot[@]} = 0 ]; then
    ls p63/fig10_*.png >/dev/null 2>&1 || fail "paper63: no fig10 PNG"
  fi
  expect 0 "$bin/gfins-sim" montecarlo rest -n 3 -o mc-rest --no-plot
  expect 0 "$bin/gfins-sim" covariance rest -o cov --no-plot
  if expect 0 "$bin/gfins-sim" aided walk -o aided-walk "${plot[@]}"; then
    log_has "within the filter's 3 sigma" "aided walk"
    [ -s aided-walk/aided.csv ] || fail "aided walk: no aided.csv"
    if [ ${#plot[@]} = 0 ]; then
      [ -s aided-walk/accuracy.png ] || fail "aided walk: no accuracy.png"
    fi
  fi
  expect 0 "$bin/gfins-sim" --duration 1

  # Record, replay (navigate, PNG, dump, means), from the prefix with the trees hidden:
  # gfins-replay finds its plot script relative to itself, like gfins-sim.
  if [ -x "$bin/gfins-replay" ]; then
    if expect 0 "$bin/gfins-sim" run rest -o rec-rest --no-plot --record rest.gfr; then
      [ -s rest.gfr ] || fail "run --record: no rest.gfr"
    fi
    if expect 0 "$bin/gfins-replay" rest.gfr -o replay-rest "${plot[@]}"; then
      [ -s replay-rest/navigation.csv ] || fail "gfins-replay: no navigation.csv"
      if [ ${#plot[@]} = 0 ]; then
        [ -s replay-rest/replay.png ] || fail "gfins-replay: no replay.png"
      fi
    fi
    expect 0 "$bin/gfins-replay" dump rest.gfr && log_has "seq,t_ns,count_1" "gfins-replay dump"
    expect 0 "$bin/gfins-replay" means rest.gfr --mounting 0 --up 0 0 1 --rate-rad-s 6 --header &&
      log_has "mounting,axis_x" "gfins-replay means"
    expect 0 "$bin/gfins-replay" dump --help && log_has "Exit codes" "gfins-replay dump --help"
    if grep -q -F "plotting" "$log"; then fail "gfins-replay dump --help lists plot exit codes"; fi
  fi

  # gfins-calibrate on the shipped example (the paper's Tables 4/5).
  ex=$prefix/share/gfins/examples
  expect 0 "$bin/gfins-calibrate" --means "$ex/paper_tables_4_5.csv" --latitude 24.8 \
    --adc-lsb 1.192e-6 --device-id board-001 --rho 0.1 -o cal.toml
  [ -s cal.toml ] || fail "gfins-calibrate wrote no cal.toml"

  # gfins-can on the shipped log, and its plot.
  expect 0 "$bin/gfins-can" decode --view none "$ex/clean.log"
  if [ ${#plot[@]} = 0 ]; then
    expect 0 "$bin/gfins-can" plot "$ex/clean.log" -o can.png && { [ -s can.png ] || fail "no can.png"; }
  fi
  expect 0 "$bin/gfins-can-gen" dbc && log_has "BO_ " "gfins-can-gen dbc"
  expect 0 "$bin/gfins-can-gen" log 1

  # gfins-fw on the simulated board, its candump log decoded with no problem.
  expect 0 "$bin/gfins-fw" --sim rest --calibration "" --duration 2 --can-log fw.log
  expect 0 "$bin/gfins-can" decode --view none fw.log
  # The firmware package alone carries its scenarios; without them the error says where to look
  # (exit 2: the configuration names a scenario that cannot be loaded, found before the run).
  expect 0 "$fw_prefix/bin/gfins-fw" --sim rest --calibration "" --duration 1 --can-log fw2.log
  GFINS_SCENARIO_DIR=$work/none expect 2 "$fw_prefix/bin/gfins-fw" --sim rest --calibration "" \
    --duration 1 --can-log fw3.log && log_has "GFINS_SCENARIO_DIR" "gfins-fw without scenarios"

}

if [ "${1:-}" = --inner ]; then
  inner
else
  outer "$@"
fi
