#!/usr/bin/env bash
# Cross-build prerequisites for the Linux board presets (aarch64-linux, armhf-linux): adds the
# Debian architectures arm64 and armhf, installs the cross compilers, the target architectures'
# -dev packages the firmware and its tests link with (multiarch, next to the host's), and
# qemu-user-static to run the cross-built unit tests. Idempotent; run as root on Debian 12.
# Fails naming the package apt cannot install.
#   install-cross-deps.sh [ARCH...]   ARCH: arm64, armhf (default: both). One architecture is
#   half the download and half the foreign package lists of `apt-get update`: scripts/test.sh,
#   which builds the armhf package only, asks for armhf.
set -euo pipefail
apt_tag=install-cross-deps
source "$(dirname "$0")/lib/apt.sh"

archs=("$@")
[ ${#archs[@]} -gt 0 ] || archs=(arm64 armhf)
target_dev=(libgpiod-dev libsystemd-dev libgtest-dev libgmock-dev libtomlplusplus-dev
            libspdlog-dev libfmt-dev)
packages=(qemu-user-static binfmt-support)
qemu_handlers=()
for a in "${archs[@]}"; do
  case "$a" in
    arm64) packages+=(g++-aarch64-linux-gnu) qemu_handlers+=(qemu-aarch64) ;;
    armhf) packages+=(g++-arm-linux-gnueabihf) qemu_handlers+=(qemu-arm) ;;
    *)
      echo "install-cross-deps: unknown architecture '$a' (arm64 or armhf)" >&2
      exit 2
      ;;
  esac
  for p in "${target_dev[@]}"; do packages+=("$p:$a"); done
done

# Tests that start a cross-built program through a shell or posix_spawn (the CLI tests) need the
# kernel to hand foreign executables to qemu-user: mount binfmt_misc if needed and enable the
# handlers qemu-user-static registers (the arm64/armhf loaders and libraries are the multiarch
# packages installed here, so no -L sysroot is needed).
enable_binfmt() {
  [ -e /proc/sys/fs/binfmt_misc/status ] ||
    mount -t binfmt_misc binfmt_misc /proc/sys/fs/binfmt_misc ||
    { echo "install-cross-deps: cannot mount binfmt_misc: cross-built programs started by tests will fail" >&2; return 1; }
  for h in "${qemu_handlers[@]}"; do
    [ -e "/proc/sys/fs/binfmt_misc/$h" ] || update-binfmts --enable "$h" ||
      { echo "install-cross-deps: update-binfmts --enable $h failed" >&2; return 1; }
  done
}

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-cross-deps: all ${#packages[@]} packages present"
  [ "$(id -u)" -ne 0 ] || enable_binfmt
  exit 0
fi
if [ "$(id -u)" -ne 0 ]; then
  echo "install-cross-deps: must run as root to install: ${missing[*]}" >&2
  exit 1
fi
export DEBIAN_FRONTEND=noninteractive
added=0
for a in "${archs[@]}"; do
  if ! dpkg --print-foreign-architectures | grep -qx "$a"; then
    dpkg --add-architecture "$a"
    added=1
  fi
done
policy=$(apt-cache policy "${archs[@]/#/libgpiod-dev:}")
if [ $added -eq 1 ] || [ "$(grep -c 'Candidate: [0-9]' <<<"$policy")" -ne ${#archs[@]} ]; then
  apt_update
fi
echo "install-cross-deps: installing ${#missing[@]} package(s): ${missing[*]}"
# A Multi-Arch: same library must have one version on every architecture; when the mirror's
# indexes disagree (a security update published for amd64 first), apt gives up with "Depends:
# <lib>:<arch> ... but it is not going to be installed". Align such a library on the version
# the foreign architectures have, then install.
align_multiarch() {
  local sim lib v specs
  sim=$("${apt_get_cmd[@]}" install -s --no-install-recommends "${missing[@]}" 2>&1 || true)
  for lib in $(sed -n 's/.*Depends: \([a-z0-9.+-]*\):\(arm64\|armhf\) .*not going to be installed.*/\1/p' <<<"$sim" | sort -u); do
    v=$(apt-cache policy "$lib:${archs[0]}" | sed -n 's/^ *Candidate: //p')
    specs=("$lib:amd64=$v")
    for a in "${archs[@]}"; do specs+=("$lib:$a=$v"); done
    echo "install-cross-deps: aligning $lib on $v for amd64 and ${archs[*]}"
    "${apt_get_cmd[@]}" install -y -qq --no-install-recommends --allow-downgrades "${specs[@]}" >/dev/null ||
      { echo "install-cross-deps: cannot align $lib on version $v across architectures" >&2; exit 1; }
  done
}
align_multiarch
apt_install "${missing[@]}"
echo "install-cross-deps: done"
enable_binfmt
