// Start-up for running the bare-metal probe under QEMU's mps2-an386 (Cortex-M4 with FPU):
// a vector table at address 0, a reset handler that enables the FPU and enters newlib's crt0,
// and the semihosting exit that ends the run. Only scripts/m4f_step_cycles.sh uses it; the size
// probe (gfins_nav_baremetal) has no start-up code.
#include <bit>
#include <cstdint>

extern "C" {
void _start();  // newlib crt0: zero .bss, run constructors, call main
[[noreturn]] void gfins_qemu_reset();
[[noreturn]] void gfins_qemu_fault();
[[noreturn]] void gfins_probe_exit(int code);
void gfins_probe_report(const volatile float* values, int n);
void gfins_probe_print(const char* text);
}

// ARMv7-M vector table (ARMv7-M ARM, B1.5.3): initial SP, then reset, NMI, HardFault,
// MemManage, BusFault, UsageFault. `.word` of a Thumb function sets bit 0, as the table needs.
asm(R"(
  .section .vectors, "a"
  .global gfins_qemu_vectors
  .align 2
gfins_qemu_vectors:
  .word _stack
  .word gfins_qemu_reset
  .word gfins_qemu_fault
  .word gfins_qemu_fault
  .word gfins_qemu_fault
  .word gfins_qemu_fault
  .word gfins_qemu_fault
  .text
)");

// [[gnu::used]]: referenced only from the asm table above, which LTO does not see.
extern "C" [[noreturn, gnu::used]] void gfins_qemu_reset() {
  // CPACR (ARMv7-M ARM, B3.2.20): full access to CP10 and CP11, the FPU, before any FP
  // instruction runs; the FPU is off after reset.
  constexpr std::uintptr_t kCpacr = 0xE000ED88u;
  *reinterpret_cast<volatile std::uint32_t*>(kCpacr) |= 0xFu << 20;
  asm volatile("dsb\n\tisb" ::: "memory");
  _start();
  gfins_probe_exit(2);
}

extern "C" [[noreturn, gnu::used]] void gfins_qemu_fault() { gfins_probe_exit(3); }

// Semihosting SYS_WRITE0 (operation 0x04, r1 = a NUL-terminated string): QEMU prints it on its
// standard output. The values go out as the hexadecimal bit patterns of the floats, so that the
// script can compare them exactly without any float formatting in the image.
extern "C" void gfins_probe_report(const volatile float* values, int n) {
  char line[16 * 9 + 8];
  const char* digits = "0123456789abcdef";
  int pos = 0;
  const char* tag = "OUT";
  while (*tag != 0) line[pos++] = *tag++;
  for (int i = 0; i < n && i < 16; ++i) {
    const auto bits = std::bit_cast<std::uint32_t>(static_cast<float>(values[i]));
    line[pos++] = ' ';
    for (int k = 7; k >= 0; --k) line[pos++] = digits[(bits >> (4 * k)) & 0xFu];
  }
  line[pos++] = '\n';
  line[pos] = 0;
  gfins_probe_print(line);
}

// A NUL-terminated text on QEMU's standard output (SYS_WRITE0).
extern "C" void gfins_probe_print(const char* text) {
  register std::uint32_t r0 asm("r0") = 0x04;
  register const char* r1 asm("r1") = text;
  asm volatile("bkpt 0xab" : : "r"(r0), "r"(r1) : "memory");
}

// Semihosting SYS_EXIT (operation 0x18) with ADP_Stopped_ApplicationExit (0x20026): QEMU ends
// (the status is not passed on with this form; the trace is what the script reads).
extern "C" [[noreturn]] void gfins_probe_exit(int code) {
  (void)code;
  register std::uint32_t r0 asm("r0") = 0x18;
  register std::uint32_t r1 asm("r1") = 0x20026;
  asm volatile("bkpt 0xab" : : "r"(r0), "r"(r1) : "memory");
  for (;;) {
  }
}
