#!/usr/bin/env bash
# Builds the kernel's GPIO simulator (drivers/gpio/gpio-sim.c, what libgpiod's own tests use)
# as an out-of-tree module for Debian's kernel, which does not ship it (no CONFIG_GPIO_SIM).
# Sources come from Debian's linux-source tarball of the same version; the headers and kbuild
# tools from the packages fetch-kernel.sh unpacked. Idempotent: an existing module is kept.
#
# One change to the kernel's code: irq_sim.c (linked into the module because the kernel was
# built without CONFIG_IRQ_SIM) calls irq_to_desc(), which this kernel does not export to
# modules; generic_handle_irq(irq) looks the descriptor up itself and calls the same flow
# handler (handle_simple_irq, set by irq_sim's domain map), so it is substituted.
# Prints the module's path on stdout.
set -euo pipefail
source "$(dirname "$0")/common.sh"
vb_require make:make gcc-12:gcc-12 xz:xz-utils tar:tar

kver=$(vb_kernel_abi)
root=$vboard_cache/root/$kver
out=$vboard_cache/gpio-sim/$kver
ko=$out/gpio-sim-oot.ko
if [ -e "$ko" ]; then
  echo "$ko"
  exit 0
fi
[ -d "$root/usr/src/linux-headers-$kver" ] || vb_die "headers for $kver not unpacked: run scripts/vboard/fetch-kernel.sh"

# The -amd64 headers' Makefile includes the -common one by its absolute installed path; point it
# at the unpacked copy instead (the cache is ours to edit; nothing is installed on the host).
headers=$root/usr/src/linux-headers-$kver
common=$(sed -n 's|^include /usr/src/\(linux-headers-[^/]*-common\)/Makefile$|\1|p' "$headers/Makefile")
if [ -n "$common" ]; then
  sed -i "s|^include /usr/src/$common/Makefile$|include $root/usr/src/$common/Makefile|" "$headers/Makefile"
fi

src=$out/src
rm -rf "$src"
mkdir -p "$src"
tarball=$(compgen -G "$root/usr/src/linux-source-*.tar.*" | head -n 1 || true)
[ -n "$tarball" ] || vb_die "no linux-source tarball under $root/usr/src: run scripts/vboard/fetch-kernel.sh"
top=$(basename "$tarball" | sed 's/\.tar\..*$//')
vb_log "extracting gpio-sim sources from $(basename "$tarball")"
# One pass, and --occurrence ends it at the last of the three (kernel/ comes after drivers/): the
# 138 MB tarball is otherwise decompressed to its end once per call (two calls: 17 CPU s; this:
# 7 CPU s).
tar -xf "$tarball" -C "$src" --strip-components=3 --occurrence \
  "$top/drivers/gpio/gpio-sim.c" "$top/drivers/gpio/gpiolib.h" "$top/kernel/irq/irq_sim.c" ||
  vb_die "drivers/gpio/gpio-sim.c, drivers/gpio/gpiolib.h or kernel/irq/irq_sim.c missing from $(basename "$tarball")"

grep -q 'handle_simple_irq(irq_to_desc(irqnum));' "$src/irq_sim.c" ||
  vb_die "irq_sim.c no longer calls handle_simple_irq(irq_to_desc(irqnum)): the irq_to_desc substitution needs revisiting for $kver"
sed -i 's/handle_simple_irq(irq_to_desc(irqnum));/generic_handle_irq(irqnum);/' "$src/irq_sim.c"

cat >"$src/Kbuild" <<'KBUILD'
obj-m += gpio-sim-oot.o
gpio-sim-oot-objs := gpio-sim.o irq_sim.o
KBUILD

vb_log "building gpio-sim-oot.ko against $kver"
make -C "$headers" M="$src" modules >"$out/build.log" 2>&1 ||
  { tail -n 30 "$out/build.log" >&2; vb_die "gpio-sim module build failed (log: $out/build.log)"; }
cp "$src/gpio-sim-oot.ko" "$ko"
echo "$ko"
