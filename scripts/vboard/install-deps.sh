#!/usr/bin/env bash
# Debian packages the virtual board needs on the host (QEMU, busybox, the tools copied into the
# VM, the kernel-module build). Idempotent: apt runs only when something is missing; when apt
# cannot install a package the script fails naming it.
set -euo pipefail
source "$(dirname "$0")/common.sh"

packages=(
  qemu-system-x86 busybox-static cpio gzip kmod
  iproute2 can-utils gpiod libgpiod-dev
  build-essential gcc-12 make xz-utils
  file        # make-initramfs.sh: is /bin/busybox the static one
  debootstrap # make-sysroot.sh: the clean Debian root of the service stage
)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  vb_log "host packages: all ${#packages[@]} present"
  exit 0
fi
[ "$(id -u)" -eq 0 ] || vb_die "must run as root to install: ${missing[*]}"
vb_log "installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
apt-get update -qq || vb_die "apt-get update failed (Debian mirror unreachable?)"
if ! apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null; then
  # Name the package that cannot be installed.
  for p in "${missing[@]}"; do
    apt-get install -y -qq --no-install-recommends "$p" >/dev/null ||
      vb_die "apt-get install $p failed"
  done
fi
