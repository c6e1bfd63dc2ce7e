#!/usr/bin/env bash
# Downloads Debian's current amd64 kernel image, its headers (with the kbuild tools) and the
# matching linux-source tarball with `apt-get download`, and unpacks them with `dpkg -x` into
# $vboard_cache/root/<kver>. The version comes from the mirror (apt-cache depends
# linux-image-amd64). Idempotent: a .deb already in the cache is never fetched again, an
# unpacked tree is never unpacked again. Prints the kernel ABI name on stdout.
# GFINS_VBOARD_OFFLINE=1: fail instead of downloading (proves a warm cache downloads nothing).
set -euo pipefail
source "$(dirname "$0")/common.sh"
vb_require apt-get:apt dpkg:dpkg

kver=$(vb_kernel_abi)                       # e.g. 6.1.0-56-amd64
debver=$(vb_candidate "linux-image-$kver")   # e.g. 6.1.192-2
list=$(vb_kernel_packages "$kver" "$debver") ||
  vb_die "cannot read the kernel series from version '$debver' of linux-image-$kver"
mapfile -t wanted <<<"$list"
image=linux-image-$kver
series=$(echo "$debver" | sed -n 's/^\([0-9]*\.[0-9]*\)\..*/\1/p')   # e.g. 6.1

debs=$vboard_cache/debs/$kver
root=$vboard_cache/root/$kver
mkdir -p "$debs" "$root"

downloaded=0
for spec in "${wanted[@]}"; do
  name=${spec%%=*}
  if compgen -G "$debs/${name}_${debver/:/%3a}_*.deb" >/dev/null; then
    continue
  fi
  [ "${GFINS_VBOARD_OFFLINE:-0}" != 1 ] ||
    vb_die "GFINS_VBOARD_OFFLINE=1 but $spec is not in the cache $debs"
  vb_log "downloading $spec"
  downloaded=$((downloaded + 1))
  # The cache belongs to root, not to apt's sandbox user: download as root, quietly.
  (cd "$debs" && apt-get download -q -o APT::Sandbox::User=root "$spec" >&2) ||
    vb_die "apt-get download $spec failed (is it still on the mirror? try apt-get update)"
done

vb_log "kernel $kver ($debver): $downloaded package(s) downloaded, $((${#wanted[@]} - downloaded)) from the cache"
for deb in "$debs"/*.deb; do
  stamp=$root/.unpacked-$(basename "$deb")
  [ -e "$stamp" ] && continue
  vb_log "unpacking $(basename "$deb")"
  dpkg -x "$deb" "$root" || vb_die "dpkg -x $deb failed"
  touch "$stamp"
done

# The package's postinst would run depmod; do it on the unpacked tree (modules.dep gives the
# initramfs its module load order).
if [ ! -e "$root/lib/modules/$kver/modules.dep" ]; then
  vb_require depmod:kmod
  depmod -b "$root" "$kver" || vb_die "depmod on the unpacked $image failed"
fi
[ -e "$root/boot/vmlinuz-$kver" ] || vb_die "$image holds no /boot/vmlinuz-$kver"
[ -d "$root/lib/modules/$kver/kernel" ] || vb_die "$image holds no /lib/modules/$kver"
tarball=$(compgen -G "$root/usr/src/linux-source-$series.tar.*" | head -n 1 || true)
[ -n "$tarball" ] || vb_die "linux-source-$series holds no /usr/src/linux-source-$series.tar.*"
echo "$kver"
