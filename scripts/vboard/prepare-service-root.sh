#!/usr/bin/env bash
# The root file system of the service-manager stage: a fresh copy of the clean debootstrap
# root (make-sysroot.sh) with the virtual board's kernel modules, its units and scripts, and -
# when given - the gfins-fw .deb installed with dpkg inside it (a clean install: postinst
# creates the user, enables the unit). Needs the initramfs staged by make-initramfs.sh (the
# modules and drdy-toggle come from there).
#
#   prepare-service-root.sh [--deb FILE] [--fw-config FILE] [--rate HZ] [--soak S] -o DIR
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
source "$here/common.sh"

deb=""
fw_config=""
rate=500
soak=0
out=""
while [ $# -gt 0 ]; do
  case $1 in
    --deb) deb=$2; shift 2 ;;
    --fw-config) fw_config=$2; shift 2 ;;
    --rate) rate=$2; shift 2 ;;
    --soak) soak=$2; shift 2 ;;
    -o) out=$2; shift 2 ;;
    *) vb_die "prepare-service-root.sh: unknown argument '$1'" ;;
  esac
done
[ -n "$out" ] || vb_die "prepare-service-root.sh: -o DIR missing"
kver=$(vb_kernel_abi)
pristine=$("$here/make-sysroot.sh")
staged=$vboard_cache/initramfs/root
[ -e "$staged/lib/modules/load-order" ] || vb_die "no staged initramfs: run make-initramfs.sh first"

# The package's run-time dependencies come from the mirror as `apt install ./gfins-fw.deb`
# would fetch them: installed once into the cached root (apt-get satisfy with the package's own
# Depends field), so the copy below stays a clean root plus exactly what the package asks for.
if [ -n "$deb" ]; then
  [ -e "$deb" ] || vb_die "package $deb missing"
  deps=$(dpkg-deb -f "$deb" Depends)
  stamp=$pristine/.deps-$(echo "$deps" | md5sum | cut -c1-16)
  if [ -n "$deps" ] && [ ! -e "$stamp" ]; then
    [ "${GFINS_VBOARD_OFFLINE:-0}" != 1 ] ||
      vb_die "GFINS_VBOARD_OFFLINE=1 but the dependencies of $(basename "$deb") are not in the cached root"
    vb_log "installing the dependencies of $(basename "$deb") in the cached root: $deps"
    # shellcheck source=../lib/apt.sh
    apt_tag=vboard apt_get_cmd=(chroot "$pristine" apt-get)
    source "$here/../lib/apt.sh"
    { apt_update && \
      DEBIAN_FRONTEND=noninteractive chroot "$pristine" apt-get satisfy -y -qq --no-install-recommends "$deps" && \
      chroot "$pristine" apt-get clean; } >"$vboard_cache/service-apt.log" 2>&1 ||
      { tail -n 20 "$vboard_cache/service-apt.log" >&2; vb_die "cannot install the dependencies of $(basename "$deb") ($deps) from the mirror"; }
    touch "$stamp"
  fi
fi
rm -rf "$out"
cp -a "$pristine" "$out"
mkdir -p "$out/lib/modules/$kver/extra" "$out/vboard"
while read -r m; do cp "$staged/lib/modules/$m" "$out/lib/modules/$kver/extra/"; done \
  <"$staged/lib/modules/load-order"
for f in modules.builtin modules.builtin.modinfo modules.order; do
  cp "$vboard_cache/root/$kver/lib/modules/$kver/$f" "$out/lib/modules/$kver/" 2>/dev/null || true
done
depmod -b "$out" "$kver" || vb_die "depmod in the service root failed"
cp "$staged/vboard/drdy-toggle" "$out/vboard/"
cp "$here/service/"*.sh "$out/vboard/"
chmod +x "$out/vboard/"*.sh
echo "RATE=$rate" >"$out/vboard/rate.env"
{ echo "WANT_FW=$([ -n "$deb" ] && echo 1 || echo 0)"; echo "SOAK_S=$soak"; } >"$out/vboard/service.env"
for u in "$here/service/"*.service; do
  cp "$u" "$out/etc/systemd/system/"
done
for u in vboard-setup vboard-drdy vboard-check vboard-notify-probe; do
  ln -sf "/etc/systemd/system/$u.service" "$out/etc/systemd/system/multi-user.target.wants/$u.service"
done

if [ -n "$deb" ]; then
  [ -e "$deb" ] || vb_die "package $deb missing"
  cp "$deb" "$out/tmp/"
  chroot "$out" dpkg -i "/tmp/$(basename "$deb")" >"$vboard_cache/service-dpkg.log" 2>&1 ||
    { cat "$vboard_cache/service-dpkg.log" >&2; vb_die "dpkg -i $(basename "$deb") in the clean root failed"; }
  rm -f "$out/tmp/$(basename "$deb")"
  [ -L "$out/etc/systemd/system/multi-user.target.wants/gfins-fw.service" ] ||
    vb_die "the gfins-fw postinst did not enable gfins-fw.service"
  # The VM has no SPI controller: the firmware runs from a configuration for the virtual board
  # (the ADC chip model inside the process, paced by the gpio-sim line's falling edges, output
  # on a vcan named can0, the interface the package's unit waits for) through a unit drop-in.
  # Default: gfins-fw-vboard.toml at this rate with the systemd watchdog, on can0, the chip
  # found by its gpio-sim label, with the package's real-time settings (SCHED_FIFO 80,
  # mlockall). The scenario is not in the firmware package (scenarios ship with gfins-tools): it
  # goes to /etc/gfins/vboard-scenarios, named with --scenario-dir.
  if [ -z "$fw_config" ]; then
    fw_config=$vboard_cache/service-fw.toml
    sed -e "s/^sample_rate_hz = .*/sample_rate_hz = $rate.0/" -e 's/^gpio_chip = .*/gpio_chip = "gfins-vboard"/' \
      -e '/^\[watchdog\]/,/^kind/ s/^kind = .*/kind = "systemd"/' \
      -e '/^\[can\]/,/^interface/ s/^interface = .*/interface = "can0"/' \
      -e '/^\[realtime\]/,/^lock_memory/ s/^priority = .*/priority = 80/' \
      -e '/^\[realtime\]/,/^lock_memory/ s/^lock_memory = .*/lock_memory = true/' \
      "$here/gfins-fw-vboard.toml" >"$fw_config"
    grep -q '^kind = "systemd"' "$fw_config" || vb_die "could not set [watchdog] kind = systemd in $fw_config"
    grep -q '^interface = "can0"' "$fw_config" || vb_die "could not set [can] interface = can0 in $fw_config"
    # The package's real-time defaults (firmware/app/gfins-fw.toml): under the unit's LimitRTPRIO
    # and LimitMEMLOCK the gfins user may take them (check fw-realtime).
    grep -q '^priority = 80' "$fw_config" && grep -q '^lock_memory = true' "$fw_config" ||
      vb_die "could not set [realtime] priority = 80, lock_memory = true in $fw_config"
  fi
  cp "$fw_config" "$out/etc/gfins/vboard.toml"
  mkdir -p "$out/etc/gfins/vboard-scenarios"
  sed "s/^rate_hz = .*/rate_hz = $rate.0/" "$here/vboard-rest.toml" >"$out/etc/gfins/vboard-scenarios/vboard-rest.toml"
  mkdir -p "$out/etc/systemd/system/gfins-fw.service.d"
  printf '[Service]\nExecStart=\nExecStart=/usr/bin/gfins-fw --config /etc/gfins/vboard.toml --scenario-dir /etc/gfins/vboard-scenarios\n' \
    >"$out/etc/systemd/system/gfins-fw.service.d/vboard.conf"
fi
vb_log "service root ready: $out"
