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
mount -t configfs none /sys/kernel/config ||
  echo "VBOARD-CHECK FAIL mount configfs"
sh /vboard/vm-test.sh
echo "VBOARD-END status=$? uptime=$(cut -d' ' -f1 /proc/uptime)"
sync
poweroff -f
