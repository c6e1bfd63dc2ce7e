#!/usr/bin/env bash
# Assembles the virtual board's initramfs (cpio newc, gzip) from what is on the host:
#   busybox (busybox-static) as the shell and core utilities, /init = scripts/vboard/init.sh,
#   the kernel modules for CAN (can, can-raw, can-dev, vcan), configfs and the gpio-sim module,
#   Debian's iproute2 `ip` (busybox's cannot create a vcan link), can-utils candump/cangen/
#   cansend/canplayer, the libgpiod tools, the drdy-toggle helper (built static here), the in-VM test
#   (vm-test.sh), and every program named with --bin (project binaries) or --file, each dynamic
#   program with the shared libraries `ldd` lists, copied to the same paths.
#
#   make-initramfs.sh [--bin HOST_PATH]... [--file HOST_PATH:VM_PATH]... -o OUT.cpio.gz
#
# Project binaries go to /opt/gfins/bin/. Fails naming any program or module that is missing.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
source "$here/common.sh"

out=""
bins=()
files=()
while [ $# -gt 0 ]; do
  case $1 in
    --bin) bins+=("$2"); shift 2 ;;
    --file) files+=("$2"); shift 2 ;;
    -o) out=$2; shift 2 ;;
    *) vb_die "make-initramfs.sh: unknown argument '$1'" ;;
  esac
done
[ -n "$out" ] || vb_die "make-initramfs.sh: -o OUT missing"

vb_require file:file /bin/busybox:busybox-static cpio:cpio gzip:gzip ldd:libc-bin gcc:gcc \
  /usr/sbin/ip:iproute2 candump:can-utils cangen:can-utils cansend:can-utils canplayer:can-utils \
  gpiodetect:gpiod gpioinfo:gpiod gpiomon:gpiod gpioset:gpiod gpioget:gpiod
# `file` was required just above: a failure here is about busybox, not a missing tool.
busybox_type=$(file -L /bin/busybox) || vb_die "file -L /bin/busybox failed"
grep -q 'statically linked' <<<"$busybox_type" ||
  vb_die "/bin/busybox is not the static one ($busybox_type): install Debian package 'busybox-static'"
[ -e /usr/lib/x86_64-linux-gnu/libc.a ] || vb_die "no static libc for drdy-toggle: install 'libc6-dev'"

kver=$(vb_kernel_abi)
moddir=$vboard_cache/root/$kver/lib/modules/$kver/kernel
gpio_sim_ko=$vboard_cache/gpio-sim/$kver/gpio-sim-oot.ko
[ -d "$moddir" ] || vb_die "kernel modules of $kver not unpacked: run scripts/vboard/fetch-kernel.sh"
[ -e "$gpio_sim_ko" ] || vb_die "gpio-sim-oot.ko not built: run scripts/vboard/build-gpio-sim.sh"

stage=$vboard_cache/initramfs/root
rm -rf "$stage"
mkdir -p "$stage"/{bin,sbin,usr/bin,usr/sbin,lib/modules,dev,proc,sys,tmp,run,etc,vboard,opt/gfins/bin,opt/gfins/etc,var/lib/gfins}

cp /bin/busybox "$stage/bin/busybox"
for applet in $(/bin/busybox --list); do
  [ "$applet" = busybox ] || ln -sf /bin/busybox "$stage/bin/$applet"
done

# Kernel modules, with their dependencies from the image's modules.dep, in load order (a
# module after everything it depends on): CAN and vcan, configfs for gpio-sim, and virtio-pci
# + 9p for the service-manager stage's root file system. /lib/modules/load-order lists them.
wanted=(configfs can can-raw can-dev vcan virtio_pci 9pnet_virtio 9p)
moddep=$vboard_cache/root/$kver/lib/modules/$kver/modules.dep
[ -e "$moddep" ] || vb_die "no modules.dep in linux-image-$kver"
declare -A placed=()
order=()
place() { # place MODULE_PATH (relative to lib/modules/<kver>): its dependencies first
  local path=$1 dep
  [ -n "${placed[$path]:-}" ] && return
  placed[$path]=1
  for dep in $(sed -n "s|^$path: *||p" "$moddep"); do place "$dep"; done
  order+=("$path")
}
for m in "${wanted[@]}"; do
  path=$(awk -F: -v m="$m" '{ n = $1; sub(/.*\//, "", n); sub(/\.ko.*$/, "", n); gsub(/-/, "_", n)
                             mm = m; gsub(/-/, "_", mm); if (n == mm) { print $1; exit } }' "$moddep")
  [ -n "$path" ] || vb_die "kernel module $m is not in linux-image-$kver (modules.dep)"
  place "$path"
done
: >"$stage/lib/modules/load-order"
for path in "${order[@]}"; do
  [ -e "$moddir/../$path" ] || vb_die "kernel module $path missing from linux-image-$kver"
  cp "$moddir/../$path" "$stage/lib/modules/"
  basename "$path" >>"$stage/lib/modules/load-order"
done
cp "$gpio_sim_ko" "$stage/lib/modules/"
echo gpio-sim-oot.ko >>"$stage/lib/modules/load-order"

# A dynamic program and the libraries ldd lists, at the same paths as on the host.
copy_with_libs() {
  local src=$1 dst=$2
  mkdir -p "$(dirname "$stage$dst")"
  cp -L "$src" "$stage$dst"
  if ldd "$src" >/dev/null 2>&1; then
    ldd "$src" | awk '/=> \//{print $3} /^[ \t]*\//{print $1}' | while read -r lib; do
      [ -e "$stage$lib" ] && continue
      mkdir -p "$(dirname "$stage$lib")"
      cp -L "$lib" "$stage$lib"
    done
    if ldd "$src" | grep -q 'not found'; then
      vb_die "$src: ldd reports a missing library: $(ldd "$src" | grep 'not found' | head -n 1)"
    fi
  fi
}
copy_with_libs /usr/sbin/ip /usr/sbin/ip
for p in candump cangen cansend canplayer gpiodetect gpioinfo gpiomon gpioset gpioget; do
  copy_with_libs "$(command -v "$p")" "/usr/bin/$p"
done

gcc -static -O2 -Wall -Wextra -Werror -o "$stage/vboard/drdy-toggle" "$here/drdy-toggle.c" ||
  vb_die "building drdy-toggle (static) failed"
cp "$here/init.sh" "$stage/init"
cp "$here/vm-test.sh" "$stage/vboard/vm-test.sh"
chmod +x "$stage/init" "$stage/vboard/vm-test.sh"

for b in "${bins[@]}"; do
  [ -x "$b" ] || vb_die "project program $b not built"
  copy_with_libs "$b" "/opt/gfins/bin/$(basename "$b")"
done
for f in "${files[@]}"; do
  src=${f%%:*}
  dst=${f#*:}
  [ -e "$src" ] || vb_die "file $src missing"
  mkdir -p "$(dirname "$stage$dst")"
  cp -L "$src" "$stage$dst"
done

mkdir -p "$(dirname "$out")"
(cd "$stage" && find . -print0 | LC_ALL=C sort -z | cpio --null -o -H newc --quiet) | gzip -1 >"$out.tmp"
mv "$out.tmp" "$out"
vb_log "initramfs $(du -h "$out" | cut -f1) -> $out"
