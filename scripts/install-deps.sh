#!/usr/bin/env bash
# Installs every Debian package the project needs to build, test, benchmark and plot.
# Idempotent and non-interactive; run as root on Debian 12. Skips apt entirely when all
# packages are present already.
#   install-deps.sh [host|later]   default: both sets.
#   host:  what the host trees need to build and test (compilers, libraries, Python).
#   later: the static analysers, the bare-metal Arm toolchain, QEMU for the Cortex-M4F, lintian:
#          scripts/test.sh installs these in the background while the host trees compile.
set -euo pipefail
apt_tag=install-deps
source "$(dirname "$0")/lib/apt.sh"

host_packages=(
  build-essential cmake ninja-build git pkg-config
  libeigen3-dev libgtest-dev libgmock-dev libbenchmark-dev
  libgpiod-dev gpiod can-utils libsystemd-dev
  libtomlplusplus-dev libcli11-dev libspdlog-dev
  python3 python3-matplotlib python3-numpy python3-can nodejs
  clang lld clang-format valgrind  # clang, lld: the sanitizer preset (host-debug)
  libclang-rt-14-dev  # the sanitizer runtimes and libFuzzer (host-debug, host-tsan, tests/fuzz)
  help2man  # the manual pages, made from each program's --help at build time
)
later_packages=(
  clang-tidy-22  # scripts/check-tidy.sh (version 22: docs/ci.md, "clang-tidy 22")
  cppcheck  # scripts/check-cppcheck.sh
  gcc-arm-none-eabi libnewlib-arm-none-eabi libstdc++-arm-none-eabi-newlib
  qemu-system-arm  # scripts/m4f_step_cycles.sh: the Cortex-M4F step traced on mps2-an386
  lintian dpkg-dev  # scripts/package.sh: lintian on the .debs; dpkg-shlibdeps for CPack's Depends
)
[ $# -le 1 ] || { echo "install-deps: one package set at most (host or later), got: $*" >&2; exit 2; }
set_name=${1:-all}
case "$set_name" in
  host) packages=("${host_packages[@]}") ;;
  later) packages=("${later_packages[@]}") ;;
  all) packages=("${host_packages[@]}" "${later_packages[@]}") ;;
  *)
    echo "install-deps: unknown package set '$set_name' (host, later, or none for both)" >&2
    exit 2
    ;;
esac

# npm installs the CAN test's third-party DBC reader (tests/can/independent): Debian's package,
# unless the installed Node.js already bundles npm.
[ "$set_name" = later ] || command -v npm >/dev/null 2>&1 || packages+=(npm)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi

echo "install-deps: installing ${#missing[@]} package(s): ${missing[*]}"
if [ "$(id -u)" -ne 0 ]; then
  echo "install-deps: must run as root to install packages (try: sudo $0)" >&2
  exit 1
fi
apt_update
apt_install "${missing[@]}"
echo "install-deps: done"
