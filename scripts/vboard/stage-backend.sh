# Stage "backend" of the in-VM test (sourced by vm-test.sh): the Linux backends' own real-kernel
# test program (tests/drivers_linux/vm_check.cpp) against vcan0 and the gpio-sim line.
# needs: build:tests/drivers_linux/drivers_linux_vm_check
prog=/opt/gfins/bin/drivers_linux_vm_check
GFINS_VM=1 GFINS_VM_CAN=vcan0 GFINS_VM_GPIO_CHIP=$gpiochip GFINS_VM_GPIO_OFFSET=0 \
  GFINS_VM_GPIO_PULL=$pull "$prog" >/tmp/backend.log 2>&1
rc=$?
sed 's/^/VBOARD-LOG backend: /' /tmp/backend.log | grep -E 'OK|FAILED|SKIPPED|PASSED|Failure|error' | head -n 60
ran=$(sed -n 's/.*\[==========\] \([0-9]*\) tests\? from .* ran.*/\1/p' /tmp/backend.log)
skipped=$(grep -c '^\[  SKIPPED \]' /tmp/backend.log)
check backend-vm-check "drivers_linux_vm_check exit $rc, ${ran:-0} tests ran, $skipped skipped" \
  [ $rc -eq 0 -a "${ran:-0}" -gt 0 -a "$skipped" -eq 0 ]
