# apt helpers shared by scripts/install-deps.sh, scripts/install-cross-deps.sh and
# scripts/vboard/install-deps.sh (sourced, not run).
#
# A Debian mirror in mid-sync serves an index whose size or hash does not match its Release file
# for a few minutes ("File has unexpected size ... Mirror sync in progress?"); apt-get update then
# exits non-zero although every other index was refreshed and the packages still install from the
# lists apt has. So:
#   apt_update      retries `apt-get update` with a pause, then goes on with the lists apt has
#                   (a warning, exit status 0): an update error alone never fails a script;
#   apt_install     installs a list of packages; when apt refuses, it tries them one by one and
#                   fails naming the first package that cannot be installed, with apt's last
#                   lines for it.
# Both print what they do on stderr with the caller's tag. Settings (environment):
#   GFINS_APT_GET            the apt-get program (tests put a fake one here; default apt-get)
#   GFINS_APT_UPDATE_TRIES   attempts of apt-get update (default 3)
#   GFINS_APT_RETRY_PAUSE_S  seconds between them (default 20: a sync usually settles in minutes,
#                            and three tries with 20 s and 40 s pauses cost one minute at most)
# A caller that runs apt-get elsewhere (in a chroot) sets the array apt_get_cmd before calling.
# shellcheck shell=bash

if [ -z "${apt_get_cmd+x}" ]; then
  apt_get_cmd=("${GFINS_APT_GET:-apt-get}")
fi

apt_note() { printf '%s: %s\n' "${apt_tag:-apt}" "$*" >&2; }

# apt_update: refresh the package lists; never fails on an index error (see above).
apt_update() {
  local tries=${GFINS_APT_UPDATE_TRIES:-3} pause=${GFINS_APT_RETRY_PAUSE_S:-20} i out
  for ((i = 1; i <= tries; i++)); do
    if out=$(DEBIAN_FRONTEND=noninteractive "${apt_get_cmd[@]}" update -qq 2>&1); then
      [ -z "$out" ] || printf '%s\n' "$out" >&2
      return 0
    fi
    printf '%s\n' "$out" | tail -n 5 >&2
    if ((i < tries)); then
      apt_note "apt-get update failed (attempt $i of $tries; a mirror in mid-sync?), retrying in $((pause * i)) s"
      sleep $((pause * i))
    fi
  done
  apt_note "apt-get update still reports errors after $tries attempts: going on with the package lists apt has; an install that needs a missing index fails below, naming the package"
  return 0
}

# dpkg without an fsync per unpacked file (dpkg(1), --force-unsafe-io): only a power loss in the
# middle of the install would need them (the packages are then installed again), and on a disk
# whose syncs are slow they are much of a fresh machine's install. On the development machine's
# virtio disk the install is CPU-bound and the option changes nothing (docs/ci.md, "Smaller cuts").
apt_dpkg_options=(-o "Dpkg::Options::=--force-unsafe-io")

# apt_install PACKAGE...: install without recommends; on failure name the package that fails.
apt_install() {
  local log p
  log=$(mktemp)
  if DEBIAN_FRONTEND=noninteractive "${apt_get_cmd[@]}" install -y -qq --no-install-recommends \
    "${apt_dpkg_options[@]}" "$@" >"$log" 2>&1; then
    rm -f "$log"
    return 0
  fi
  for p in "$@"; do
    if ! DEBIAN_FRONTEND=noninteractive "${apt_get_cmd[@]}" install -y -qq \
      --no-install-recommends "${apt_dpkg_options[@]}" "$p" >"$log" 2>&1; then
      tail -n 5 "$log" >&2
      rm -f "$log"
      apt_note "cannot install package $p (apt-get install $p failed; see apt's lines above)"
      return 1
    fi
  done
  # The list failed but every package installed on its own (a transient fetch error): done.
  rm -f "$log"
  apt_note "installed one by one after apt-get refused the list: $*"
  return 0
}
