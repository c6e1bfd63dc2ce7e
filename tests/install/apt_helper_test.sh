#!/usr/bin/env bash
# The three package scripts against a Debian mirror in mid-sync, with fake apt tools first on PATH
# (apt-get, apt-cache, dpkg-query, dpkg, mount, update-binfmts: nothing is installed or changed
# on the machine). Each script must
#   - retry `apt-get update`, then go on with the lists apt has and exit 0 when the install works;
#   - fail when the install itself fails, naming the package apt cannot install.
# The fake apt-get fails every `update` the way a mirror in mid-sync does (an index of unexpected
# size, exit 100) and refuses to install the packages listed in FAKE_APT_BROKEN.
set -euo pipefail
repo=$(cd "$(dirname "$0")/../.." && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
bin=$work/bin
mkdir -p "$bin"

cat >"$bin/apt-get" <<'EOF'
#!/usr/bin/env bash
echo "apt-get $*" >>"$FAKE_APT_LOG"
case " $* " in
  *" update "*)
    echo "E: Failed to fetch http://deb.debian.org/debian-security/dists/bookworm-security/main/binary-armhf/Packages.xz  File has unexpected size (290544 != 290504). Mirror sync in progress? [IP: 151.101.2.132 80]" >&2
    exit 100 ;;
  *" install "*)
    [[ " $* " == *" -s "* ]] && exit 0  # the simulation of install-cross-deps.sh
    for a in "$@"; do
      for b in ${FAKE_APT_BROKEN:-}; do
        if [ "$a" = "$b" ]; then
          echo "E: Unable to locate package $b" >&2
          exit 100
        fi
      done
    done
    exit 0 ;;
esac
exit 0
EOF
cat >"$bin/dpkg-query" <<'EOF'
#!/usr/bin/env bash
# dpkg-query -W -f='${Status}' PKG: "installed" unless PKG (without :arch) is in FAKE_MISSING.
p=${!#}
for m in ${FAKE_MISSING:-}; do
  if [ "${p%%:*}" = "$m" ]; then exit 1; fi
done
printf 'install ok installed'
EOF
cat >"$bin/dpkg" <<'EOF'
#!/usr/bin/env bash
case "$1" in
  --print-foreign-architectures) printf 'arm64\narmhf\n' ;;
esac
exit 0
EOF
# No candidate: install-cross-deps.sh then runs apt-get update (the step that met the mid-sync).
printf '#!/bin/sh\necho "  Candidate: (none)"\n' >"$bin/apt-cache"
printf '#!/bin/sh\nexit 0\n' >"$bin/mount"
printf '#!/bin/sh\nexit 0\n' >"$bin/update-binfmts"
chmod +x "$bin"/*

failures=0
# run_case NAME SCRIPT MISSING BROKEN EXPECT_RC EXPECT_TEXT [ARG...]
run_case() {
  local name=$1 script=$2 missing=$3 broken=$4 want_rc=$5 want_text=$6 rc=0 updates safe_io
  shift 6
  : >"$work/apt.log"
  FAKE_APT_LOG=$work/apt.log FAKE_MISSING=$missing FAKE_APT_BROKEN=$broken \
    GFINS_APT_RETRY_PAUSE_S=0 PATH="$bin:$PATH" "$repo/$script" "$@" >"$work/out" 2>&1 || rc=$?
  updates=$(grep -c ' update' "$work/apt.log" || true)
  # Every real install (not install-cross-deps.sh's simulation, -s) skips dpkg's fsync per file.
  safe_io=$(grep ' install ' "$work/apt.log" | grep -v ' -s ' | grep -vcF -- '--force-unsafe-io' || true)
  if [ "$rc" -ne "$want_rc" ] || ! grep -qF -- "$want_text" "$work/out" || [ "$updates" -ne 3 ] ||
    [ "$safe_io" -ne 0 ]; then
    echo "FAIL $name: exit $rc (want $want_rc), $updates apt-get update calls (want 3)," \
      "$safe_io install(s) without --force-unsafe-io (want 0), output:"
    sed 's/^/    /' "$work/out"
    failures=$((failures + 1))
  else
    echo "ok   $name"
  fi
}

run_case "install-deps: update errors, install works" scripts/install-deps.sh \
  "cmake" "" 0 "going on with the package lists apt has"
run_case "install-deps: a package apt cannot install is named" scripts/install-deps.sh \
  "cmake valgrind" "valgrind" 1 "cannot install package valgrind"
run_case "vboard/install-deps: update errors, install works" scripts/vboard/install-deps.sh \
  "cpio" "" 0 "going on with the package lists apt has"
run_case "vboard/install-deps: a package apt cannot install is named" \
  scripts/vboard/install-deps.sh "cpio kmod" "kmod" 1 "cannot install package kmod"
run_case "install-cross-deps: update errors, install works" scripts/install-cross-deps.sh \
  "qemu-user-static" "" 0 "going on with the package lists apt has"
run_case "install-cross-deps: a package apt cannot install is named" \
  scripts/install-cross-deps.sh "qemu-user-static libgpiod-dev" "libgpiod-dev:armhf" 1 \
  "cannot install package libgpiod-dev:armhf"

# refused NAME SCRIPT TEXT ARG...: SCRIPT ARG... exits 2 saying TEXT, before any apt call.
refused() {
  local name=$1 script=$2 text=$3 rc=0
  shift 3
  : >"$work/apt.log"
  PATH="$bin:$PATH" FAKE_APT_LOG=$work/apt.log "$repo/$script" "$@" >"$work/out" 2>&1 || rc=$?
  if [ "$rc" -ne 2 ] || ! grep -qF -- "$text" "$work/out" || [ -s "$work/apt.log" ]; then
    echo "FAIL $name: exit $rc (want 2), apt calls: $(wc -l <"$work/apt.log"), output:"
    sed 's/^/    /' "$work/out"
    failures=$((failures + 1))
  else
    echo "ok   $name"
  fi
}
# installed NAME REGEX WANT: whether a real install (not a simulation) of the last case named a
# package matching REGEX is WANT (yes or no).
installed() {
  local got=no
  if grep ' install ' "$work/apt.log" | grep -v ' -s ' | grep -qE -- "$2"; then got=yes; fi
  if [ "$got" != "$3" ]; then
    echo "FAIL $1: a package matching '$2' installed: $got (want $3); apt calls:"
    sed 's/^/    /' "$work/apt.log"
    failures=$((failures + 1))
  fi
}

# The two sets of install-deps.sh (scripts/test.sh installs the second in the background): each
# installs its own packages and none of the other's.
run_case "install-deps host: update errors, install works" scripts/install-deps.sh \
  "cmake cppcheck" "" 0 "going on with the package lists apt has" host
installed "install-deps host: cmake" ' cmake( |$)' yes
installed "install-deps host: cppcheck (set later)" cppcheck no
run_case "install-deps later: update errors, install works" scripts/install-deps.sh \
  "cmake cppcheck" "" 0 "going on with the package lists apt has" later
installed "install-deps later: cppcheck" cppcheck yes
installed "install-deps later: cmake (set host)" ' cmake( |$)' no
refused "install-deps: an unknown package set is refused" scripts/install-deps.sh \
  "unknown package set 'everything'" everything
refused "install-deps: two package sets are refused" scripts/install-deps.sh \
  "one package set at most" host later

# One architecture (scripts/test.sh): only its compiler and its -dev packages are installed.
run_case "install-cross-deps armhf: update errors, install works" scripts/install-cross-deps.sh \
  "qemu-user-static g++-arm-linux-gnueabihf libgpiod-dev" "" 0 \
  "going on with the package lists apt has" armhf
installed "install-cross-deps armhf: libgpiod-dev:armhf" 'libgpiod-dev:armhf' yes
installed "install-cross-deps armhf: arm64 packages" 'aarch64|:arm64' no
refused "install-cross-deps: an unknown architecture is refused" scripts/install-cross-deps.sh \
  "unknown architecture 'mips'" mips

[ "$failures" -eq 0 ] || { echo "$failures case(s) failed"; exit 1; }
echo "all cases passed"
