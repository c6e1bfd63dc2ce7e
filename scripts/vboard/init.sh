#!/bin/sh
# /init of the virtual board's initramfs (busybox sh, PID 1): mounts the kernel file systems,
# loads the CAN, configfs and gpio-sim modules, runs the in-VM test (/vboard/vm-test.sh) and
# powers off. Everything the host needs is printed on the console (ttyS0) as
# "VBOARD-..." lines; scripts/vboard/run.sh reads them.
export PATH=/bin:/sbin:/usr/bin:/usr/sbin:/opt/gfins/bin:/vboard
mount -t proc proc /proc
mount -t sysfs sysfs /sys
mount -t devtmpfs devtmpfs /dev
mount -t tmpfs tmpfs /tmp
mount -t tmpfs tmpfs /run
mkdir -p /var/lib/gfins /dev/shm
echo "VBOARD-BOOTED uptime=$(cut -d' ' -f1 /proc/uptime)"
while read -r m; do
  insmod "/lib/modules/$m" || echo "VBOARD-CHECK FAIL insmod $m: module did not load"
done </lib/modules/load-order
# Service-manager stage: the root file system is a Debian root shared by the host over 9p;
# systemd becomes PID 1 there (scripts/vboard/service/).
if grep -q 'vboard.root=9p' /proc/cmdline; then
  mkdir -p /newroot
  if mount -t 9p -o trans=virtio,version=9p2000.L,msize=262144,cache=loose vroot /newroot; then
    umount /sys /proc
    mount --move /dev /newroot/dev 2>/dev/null || umount /dev
    exec switch_root /newroot /lib/systemd/systemd
  fi
  echo "VBOARD-CHECK FAIL 9p-root: cannot mount the shared root (tag vroot)"
  poweroff -f
fi
mount -t configfs none /sys/kernel/config ||
  echo "VBOARD-CHECK FAIL mount configfs"
sh /vboard/vm-test.sh
echo "VBOARD-END status=$? uptime=$(cut -d' ' -f1 /proc/uptime)"
sync
poweroff -f
