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

# The five packages of kernel ABI $1 at Debian version $2 (the headers, kbuild and source must be
# the image's own build).
kernel_packages() {
  local kver=$1 debver=$2 series
  series=$(echo "$debver" | sed -n 's/^\([0-9]*\.[0-9]*\)\..*/\1/p')   # e.g. 6.1
  [ -n "$series" ] || return 1
  printf '%s\n' "linux-image-$kver=$debver" "linux-headers-$kver=$debver" \
    "linux-headers-${kver%-amd64}-common=$debver" "linux-kbuild-$series=$debver" \
    "linux-source-$series=$debver"
}

# True when apt's lists hold every package of the set at its exact version.
all_listed() {
  local spec
  for spec in "$@"; do
    apt-cache madison "${spec%%=*}" 2>/dev/null | awk -F'|' '{gsub(/ /, "", $2); print $2}' |
      grep -qxF "${spec#*=}" || return 1
  done
}

kver=$(vb_kernel_abi)                     # e.g. 6.1.0-56-amd64
debver=$(vb_candidate "linux-image-$kver")   # e.g. 6.1.192-2
list=$(kernel_packages "$kver" "$debver") ||
  vb_die "cannot read the kernel series from version '$debver' of linux-image-$kver"
mapfile -t wanted <<<"$list"
# A mirror in mid-sync can list the image of one upload and the kbuild or source of the next
# (seen: linux-image 6.1.192-2 with linux-kbuild 6.1.192-3 only). Unless the kernel is pinned or
# already cached, take then the newest ABI whose five packages are all listed at one version.
if [ -z "${GFINS_VBOARD_KVER:-}" ] && ! compgen -G "$vboard_cache/debs/$kver/*.deb" >/dev/null &&
  ! all_listed "${wanted[@]}"; then
  vb_log "the mirror lists no complete set for kernel $kver ($debver): looking for an older one"
  found=
  while read -r abi; do
    v=$(apt-cache policy "linux-image-$abi" 2>/dev/null | sed -n 's/^ *Candidate: //p' | head -n 1)
    [ -n "$v" ] && [ "$v" != "(none)" ] || continue
    list=$(kernel_packages "$abi" "$v") || continue
    mapfile -t set <<<"$list"
    if all_listed "${set[@]}"; then
      kver=$abi debver=$v found=1
      wanted=("${set[@]}")
      break
    fi
  done < <(apt-cache search --names-only '^linux-image-[0-9.]+-[0-9]+-amd64$' |
    sed -n 's/^linux-image-\([^ ]*\) .*/\1/p' | sort -rV)
  [ -n "$found" ] ||
    vb_die "the mirror lists no kernel whose image, headers, kbuild and source share a version (try apt-get update later)"
  vb_log "using kernel $kver ($debver), the newest the mirror lists completely"
fi
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
