#!/usr/bin/env bash
# Debian packages the virtual board needs on the host (QEMU, busybox, the tools copied into the
# VM, the kernel-module build). Idempotent: apt runs only when something is missing; when apt
# cannot install a package the script fails naming it.
set -euo pipefail
source "$(dirname "$0")/common.sh"
apt_tag=vboard
source "$(dirname "$0")/../lib/apt.sh"

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
apt_update
apt_install "${missing[@]}" || vb_die "host packages could not be installed (the package is named above)"
