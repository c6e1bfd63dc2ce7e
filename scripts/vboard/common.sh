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

# The kernel ABI name (e.g. 6.1.0-56-amd64) the mirror's linux-image-amd64 currently depends on.
# Never hard-coded: the mirror decides. GFINS_VBOARD_KVER overrides it (e.g. to pin a cached one).
vb_kernel_abi() {
  if [ -n "${GFINS_VBOARD_KVER:-}" ]; then
    echo "$GFINS_VBOARD_KVER"
    return
  fi
  local dep
  dep=$(apt-cache depends linux-image-amd64 2>/dev/null |
    sed -n 's/^ *Depends: linux-image-\([0-9][^ ]*-amd64\)$/\1/p' | head -n 1)
  [ -n "$dep" ] || vb_die "apt-cache depends linux-image-amd64 names no linux-image-<version>-amd64 (run apt-get update; is the Debian mirror configured?)"
  echo "$dep"
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
