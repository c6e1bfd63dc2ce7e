#!/usr/bin/env bash
# A clean Debian root file system with systemd, made with debootstrap, for the virtual board's
# service-manager stage: the gfins-fw .deb is installed into a copy of it and the VM boots it
# with systemd as PID 1. The suite is the host's (Debian 12: bookworm); the mirror is the one
# apt uses. Cached: the root is made once ($vboard_cache/sysroot/<suite>, with the .debs in
# $vboard_cache/debootstrap-debs) and a second run downloads nothing. Prints the root's path.
set -euo pipefail
source "$(dirname "$0")/common.sh"
vb_require debootstrap:debootstrap

suite=$(sed -n 's/^VERSION_CODENAME=//p' /etc/os-release)
[ -n "$suite" ] || vb_die "cannot read VERSION_CODENAME from /etc/os-release"
mirror=$(sed -n 's/^URIs: *\(http[^ ]*debian\)$/\1/p' /etc/apt/sources.list.d/*.sources 2>/dev/null | head -n 1)
[ -n "$mirror" ] || mirror=$(sed -n 's/^deb \(http[^ ]*debian\) .*/\1/p' /etc/apt/sources.list 2>/dev/null | head -n 1)
[ -n "$mirror" ] || vb_die "no Debian mirror found in /etc/apt/sources.list*"

root=$vboard_cache/sysroot/$suite
if [ -e "$root/.complete" ]; then
  echo "$root"
  exit 0
fi
[ "${GFINS_VBOARD_OFFLINE:-0}" != 1 ] ||
  vb_die "GFINS_VBOARD_OFFLINE=1 but the debootstrap root $root is not in the cache"
debs=$vboard_cache/debootstrap-debs
mkdir -p "$debs"
rm -rf "$root"
# What the service stage runs inside: systemd (PID 1, journal), kmod (modprobe), iproute2 (vcan),
# can-utils (candump), gpiod (tools), and the runtime libraries gfins-fw links with (so that
# installing the .deb needs no network), adduser for its postinst.
include=systemd,systemd-sysv,udev,kmod,iproute2,can-utils,gpiod,libgpiod2,libsystemd0,adduser,init-system-helpers,libstdc++6
vb_log "debootstrap $suite (minbase + $include) from $mirror"
debootstrap --variant=minbase --include="$include" --cache-dir="$debs" "$suite" "$root" "$mirror" \
  >"$vboard_cache/debootstrap.log" 2>&1 ||
  { tail -n 20 "$vboard_cache/debootstrap.log" >&2; vb_die "debootstrap $suite failed (log: $vboard_cache/debootstrap.log)"; }
# No getty on the serial console, no network waits: the VM boots, runs its test, powers off.
chroot "$root" systemctl mask serial-getty@ttyS0.service getty@tty1.service \
  systemd-networkd-wait-online.service systemd-timesyncd.service apt-daily.timer \
  apt-daily-upgrade.timer >/dev/null 2>&1 || true
echo vboard >"$root/etc/hostname"
touch "$root/.complete"
echo "$root"
