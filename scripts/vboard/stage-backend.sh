# shellcheck shell=sh disable=SC2154  # sourced by vm-test.sh, which sets gpiochip, pull, rate
# Stage "backend" of the in-VM test (sourced by vm-test.sh): the Linux backends' own real-kernel
# test program (tests/drivers_linux/vm_check.cpp) against vcan0 and the gpio-sim line.
# needs: build:tests/drivers_linux/drivers_linux_vm_check
prog=/opt/gfins/bin/drivers_linux_vm_check
GFINS_VM=1 GFINS_VM_CAN=vcan0 GFINS_VM_GPIO_CHIP=$gpiochip GFINS_VM_GPIO_OFFSET=0 \
  GFINS_VM_GPIO_PULL=$pull "$prog" >/tmp/backend.log 2>&1
rc=$?
# The test program's verdict lines, and the first failures in full.
grep -E '^\[ *(OK|FAILED|SKIPPED|PASSED) *\]' /tmp/backend.log | sed 's/^/VBOARD-LOG backend: /'
grep -A 6 -m 3 'Failure' /tmp/backend.log | sed 's/^/VBOARD-LOG backend: /' 
ran=$(sed -n 's/.*\[==========\] \([0-9]*\) tests\? from .* ran.*/\1/p' /tmp/backend.log)
skipped=$(grep -c '^\[  SKIPPED \]' /tmp/backend.log)
check backend-vm-check "drivers_linux_vm_check exit $rc, ${ran:-0} tests ran, $skipped skipped" \
  [ $rc -eq 0 -a "${ran:-0}" -gt 0 -a "$skipped" -eq 0 ]
