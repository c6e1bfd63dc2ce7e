#!/bin/sh
# vboard-setup.service (service-manager stage, inside the VM's Debian root): the kernel side
# the firmware needs, before gfins-fw.service starts: the CAN modules, a gpio-sim chip whose
# line 0 is named adc-drdy, and the data-ready toggler. The CAN interface itself (a vcan named
# can0, as the package's unit expects) comes late, from vboard-late-can.service.
set -e
modprobe vcan
modprobe gpio-sim-oot
mountpoint -q /sys/kernel/config || mount -t configfs none /sys/kernel/config
d=/sys/kernel/config/gpio-sim/vboard
if [ ! -e $d/live ] || [ "$(cat $d/live)" != 1 ]; then
  mkdir -p $d/bank0/line0
  echo 1 >$d/bank0/num_lines
  echo gfins-vboard >$d/bank0/label
  echo adc-drdy >$d/bank0/line0/name
  echo 1 >$d/live
fi
dev=$(cat $d/dev_name)
chip=$(cat $d/bank0/chip_name)
# The udev rule of the package gives gpiochips to group gpio; wait for it to have run.
udevadm settle || true
printf 'GPIOCHIP=%s\nPULL=/sys/devices/platform/%s/%s/sim_gpio0/pull\n' "$chip" "$dev" "$chip" >/run/vboard.env
