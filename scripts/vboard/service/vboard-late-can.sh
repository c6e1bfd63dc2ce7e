#!/bin/sh
# vboard-late-can.service (service-manager stage): the board's CAN interface appears late, as a
# USB or SPI CAN controller's driver may bring it after the service manager started the
# firmware's unit. gfins-fw.service is ordered after the interface's device unit
# (sys-subsystem-net-devices-can0.device): it must wait for it, not fail and use up its start
# limit. The guest uptime just before the interface exists goes to /run/vboard-can0.
set -e
sleep "${1:-2}"
cut -d' ' -f1 /proc/uptime >/run/vboard-can0
ip link add dev can0 type vcan
ip link set up can0
