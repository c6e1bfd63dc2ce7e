# Shared by the scripts/vboard/*.sh scripts (sourced, not run). Paths, logging, failure.
#
# Everything the virtual board downloads or builds lives under one folder the scripts own,
# GFINS_VBOARD_CACHE (default: <repo>/.cache/vboard, ignored by git):
#   debs/<kver>/      the .deb files apt-get download fetched (kept: a second run downloads none)
#   root/<kver>/      those packages unpacked with dpkg -x (kernel, modules, headers, source)
#   gpio-sim/<kver>/  the out-of-tree gpio-sim module and its build folder
#   initramfs/        the staged root file system and initrd.gz of the last assembly
#   runs/             console logs of the VM runs
# shellcheck shell=bash

vboard_repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
vboard_cache=${GFINS_VBOARD_CACHE:-$vboard_repo/.cache/vboard}

vb_log() { printf 'vboard: %s\n' "$*" >&2; }
vb_die() {
  printf 'vboard: FAILED: %s\n' "$*" >&2
  exit 1
}

# The five packages of kernel ABI $1 at Debian version $2, one per line (the headers, kbuild and
# source must be the image's own build).
vb_kernel_packages() {
  local kver=$1 debver=$2 series
  series=$(echo "$debver" | sed -n 's/^\([0-9]*\.[0-9]*\)\..*/\1/p')   # e.g. 6.1
  [ -n "$series" ] || return 1
  printf '%s\n' "linux-image-$kver=$debver" "linux-headers-$kver=$debver" \
    "linux-headers-${kver%-amd64}-common=$debver" "linux-kbuild-$series=$debver" \
    "linux-source-$series=$debver"
}

# True when the cache holds all five packages of kernel ABI $1 (a partial download does not count).
vb_kernel_cached() {
  local debs=("$vboard_cache/debs/$1"/*.deb)
  [ -e "${debs[0]}" ] && [ "${#debs[@]}" -ge 5 ]
}

# True when the kernel ABI $1's five packages are all listed by apt at its image's version.
vb_kernel_listed() {
  local v list spec
  v=$(apt-cache policy "linux-image-$1" 2>/dev/null | sed -n 's/^ *Candidate: //p' | head -n 1)
  [ -n "$v" ] && [ "$v" != "(none)" ] || return 1
  list=$(vb_kernel_packages "$1" "$v") || return 1
  while read -r spec; do
    apt-cache madison "${spec%%=*}" 2>/dev/null | awk -F'|' '{gsub(/ /, "", $2); print $2}' |
      grep -qxF "${spec#*=}" || return 1
  done <<<"$list"
}

# The kernel ABI name (e.g. 6.1.0-56-amd64) the mirror's linux-image-amd64 currently depends on.
# Never hard-coded: the mirror decides. GFINS_VBOARD_KVER overrides it (e.g. to pin a cached one).
# A mirror in mid-sync can list the image of one upload and the kbuild or source of the next
# (seen: linux-image 6.1.192-2 with linux-kbuild 6.1.192-3 only): unless that kernel is already
# cached, the newest ABI whose five packages are all listed at one version is taken instead.
vb_kernel_abi() {
  if [ -n "${GFINS_VBOARD_KVER:-}" ]; then
    echo "$GFINS_VBOARD_KVER"
    return
  fi
  local dep abi
  dep=$(apt-cache depends linux-image-amd64 2>/dev/null |
    sed -n 's/^ *Depends: linux-image-\([0-9][^ ]*-amd64\)$/\1/p' | head -n 1)
  [ -n "$dep" ] || vb_die "apt-cache depends linux-image-amd64 names no linux-image-<version>-amd64 (run apt-get update; is the Debian mirror configured?)"
  if vb_kernel_cached "$dep" || vb_kernel_listed "$dep"; then
    echo "$dep"
    return
  fi
  while read -r abi; do
    if vb_kernel_cached "$abi" || vb_kernel_listed "$abi"; then
      vb_log "the mirror lists no complete set for kernel $dep: using $abi, the newest it lists completely"
      echo "$abi"
      return
    fi
  done < <(apt-cache search --names-only '^linux-image-[0-9.]+-[0-9]+-amd64$' |
    sed -n 's/^linux-image-\([^ ]*\) .*/\1/p' | sort -rV)
  vb_die "the mirror lists no kernel whose image, headers, kbuild and source share a version (try apt-get update later)"
}

# The Debian version (e.g. 6.1.192-2) of the package $1 that apt would install.
vb_candidate() {
  local v
  v=$(apt-cache policy "$1" 2>/dev/null | sed -n 's/^ *Candidate: //p' | head -n 1)
  [ -n "$v" ] && [ "$v" != "(none)" ] || vb_die "package $1 has no installation candidate on the mirror"
  echo "$v"
}

# Host programs the virtual board needs; fail naming the package that provides a missing one.
vb_require() {
  local prog pkg
  for spec in "$@"; do
    prog=${spec%%:*}
    pkg=${spec#*:}
    command -v "$prog" >/dev/null 2>&1 || [ -x "$prog" ] ||
      vb_die "$prog not found: install Debian package '$pkg' (scripts/vboard/install-deps.sh does)"
  done
}
