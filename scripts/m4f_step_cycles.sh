#!/usr/bin/env bash
# Instructions and estimated Cortex-M4F cycles of one navigation step (gfins_nav_step: read a
# frame, NavPipeline<float>::process with the exact compensator, write the state out).
#
# Usage: scripts/m4f_step_cycles.sh [build-dir]        (default: build/cortex-m4f)
#   Build first:  cmake --preset cortex-m4f && cmake --build --preset cortex-m4f
#   Needs qemu-system-arm (Debian package qemu-system-arm, in scripts/install-deps.sh).
#
# Method. QEMU's mps2-an386 board (a Cortex-M4 with FPU) runs gfins_nav_qemu.elf, the size probe
# with a start-up and 999 steps on the benchmarks' 1 kHz samples of the manoeuvre
# (nav_core/baremetal/probe_samples.hpp: real converter codes, different at every step), one
# instruction per translation block, logging the address of every executed instruction
# (-singlestep -d exec,nochain). Every step is analysed; the figures are the spread over them. QEMU does not model cycles (its
# icount counts instructions), so the cycles are an estimate: each executed instruction is
# looked up in the disassembly and costed with the Cortex-M4 Technical Reference Manual's timing
# (ARM DDI 0439B, Table 3-1 for the integer instructions, Table 7-1 for the FPU), under the
# assumptions printed with the result. Branch direction comes from the trace itself.
set -euo pipefail

# shellcheck source=scripts/measure_common.sh source-path=SCRIPTDIR
source "$(dirname "${BASH_SOURCE[0]}")/measure_common.sh"
gfins_build_dir "$@" build/cortex-m4f
elf="${gfins_build}/nav_core/baremetal/gfins_nav_qemu.elf"
prefix="${GFINS_ARM_PREFIX:-arm-none-eabi-}"
gfins_need_file "${elf}" "build the cortex-m4f preset first"
gfins_need_command qemu-system-arm "apt-get install qemu-system-arm"

gfins_scratch_dir
work="${gfins_scratch}"
timeout 600 qemu-system-arm -M mps2-an386 -nographic -monitor none -serial none \
  -semihosting-config enable=on,target=native -kernel "${elf}" \
  -singlestep -d exec,nochain -D "${work}/trace.log" >"${work}/out.txt" 2>&1
"${prefix}objdump" -d "${elf}" >"${work}/disasm.txt"
"${prefix}nm" -S "${elf}" >"${work}/nm.txt"

samples_hpp="$(dirname "${BASH_SOURCE[0]}")/../nav_core/baremetal/probe_samples.hpp"
python3 - "${work}/trace.log" "${work}/disasm.txt" "${work}/nm.txt" "${work}/out.txt" \
  "${samples_hpp}" <<'PY'
import collections, re, struct, sys

trace_path, disasm_path, nm_path, out_path, samples_path = sys.argv[1:6]

# The run must have navigated the manoeuvre: its final state (printed through semihosting as
# float bit patterns) against the x86 float pipeline on the same samples (probe_samples.hpp).
got = None
for line in open(out_path):
    if line.startswith("OUT "):
        got = [int(x, 16) for x in line.split()[1:]]
m = re.search(r"kExpectedOutBits = \{([^}]*)\}", open(samples_path).read())
want = [int(x.strip().rstrip("u"), 16) for x in m.group(1).split(",")] if m else None
if got is None or want is None or len(got) != len(want):
    sys.exit("m4f_step_cycles.sh: no final state from the QEMU run (or none expected in %s)"
             % samples_path)
f32 = lambda b: struct.unpack("<f", struct.pack("<I", b))[0]
names = ["q_w", "q_x", "q_y", "q_z", "v_n", "v_e", "v_d", "r_n", "r_e", "r_d"]
diff = [abs(f32(a) - f32(b)) for a, b in zip(got, want)]
same = sum(a == b for a, b in zip(got, want))
print("final state after the last step (QEMU Cortex-M4F vs x86 float, same samples): "
      "%d of %d values bit-identical, largest difference %.3g (%s)"
      % (same, len(got), max(diff), names[diff.index(max(diff))]))
print("  r_n = %.6f %.6f %.6f m, v_n = %.6f %.6f %.6f m/s" % tuple(f32(b) for b in got[7:10] + got[4:7]))
# Rounding differences between the two compilers (contraction, library functions) may grow over
# the 999 steps, but a probe that misread its samples or skipped steps would be off by metres
# (the manoeuvre travels about 2.9 m in that second): 1e-3 (m, m/s, quaternion units) separates
# the two by three orders of magnitude either way.
if max(diff) > 1e-3:
    sys.exit("m4f_step_cycles.sh: the QEMU run did not navigate the samples as x86 does")
print()
P = 2  # pipeline refill after a taken branch: 1..3 cycles (TRM 3.3.1); 2 assumed

insn = {}  # address -> (size in bytes, mnemonic, operands)
line_re = re.compile(r"^\s*([0-9a-f]+):\s+((?:[0-9a-f]{4}\s)+)\s*(\S+)\s*([^;<]*)")
for line in open(disasm_path):
    m = line_re.match(line)
    if m:
        raw = m.group(2).split()
        insn[int(m.group(1), 16)] = (2 * len(raw), m.group(3), m.group(4).strip())

sym = {}
for line in open(nm_path):
    parts = line.split()
    if len(parts) == 4:
        sym[parts[3]] = (int(parts[0], 16), int(parts[1], 16))
step_addr = sym["gfins_nav_step"][0]
main_lo, main_size = sym["main"]

pcs = []
pc_re = re.compile(r"^Trace \d+: \S+ \[[0-9a-f]+/([0-9a-f]+)/")
for line in open(trace_path):
    m = pc_re.match(line)
    if m:
        pcs.append(int(m.group(1), 16) & ~1)

conds = ("eq", "ne", "cs", "cc", "hs", "lo", "mi", "pl", "vs", "vc", "hi", "ls", "ge", "lt", "gt",
         "le", "al")

def base(mn):
    mn = mn.split(".")[0]
    for c in conds:  # condition suffix of an instruction in an IT block or a conditional branch
        if mn.endswith(c) and len(mn) > len(c) and mn not in ("vcmpe", "bl", "teq", "vmls", "mls", "vnmls"):
            stem = mn[: -len(c)]
            if stem in ("b", "mov", "add", "sub", "ldr", "str", "vmov", "it", "bx", "vmul", "vadd",
                        "vsub", "orr", "and", "cmp", "movs", "adds", "subs", "ldrb", "strb", "vstr",
                        "vldr", "vneg", "vmla", "vdiv", "mvn", "rsb", "lsl", "lsr", "asr"):
                return stem
    return mn

def reglist_count(ops):
    m = re.search(r"\{([^}]*)\}", ops)
    if not m:
        return 1
    n = 0
    for part in m.group(1).split(","):
        part = part.strip()
        r = re.match(r"([rsd])(\d+)-[rsd](\d+)", part)
        if r:
            k = int(r.group(3)) - int(r.group(2)) + 1
            n += 2 * k if r.group(1) == "d" else k
        elif part:
            n += 2 if part.startswith("d") else 1
    return n

def cost(mn, ops, taken, prev_mem):
    b = base(mn)
    if b in ("vldr", "vstr"):
        return 2, "FPU load/store"
    if b in ("vpush", "vpop") or b.startswith("vldm") or b.startswith("vstm"):
        return 1 + reglist_count(ops), "FPU load/store"
    if b in ("vdiv", "vsqrt"):
        return 14, "FPU divide/sqrt"
    if b in ("vmla", "vmls", "vnmla", "vnmls", "vfma", "vfms", "vfnma", "vfnms"):
        return 3, "FPU multiply-accumulate"
    if b == "vmov":
        return (2 if ops.count(",") >= 3 else 1), "FPU move"
    if b.startswith("v"):
        return 1, "FPU add/sub/mul/cmp/cvt"
    if b in ("push", "pop") or b.startswith("ldm") or b.startswith("stm"):
        n = reglist_count(ops)
        return 1 + n + (P if "pc" in ops and b in ("pop", "ldm", "ldmia") else 0), "load/store multiple"
    if b in ("ldrd", "strd"):
        return 3, "load/store"
    if b.startswith("ldr") or b.startswith("str"):
        return (1 if prev_mem else 2), "load/store"
    if b in ("b", "bl", "bx", "blx", "cbz", "cbnz"):
        return (1 + P if taken else 1), "branch"
    if b.startswith("it"):
        return 1, "IT"
    if b in ("sdiv", "udiv"):
        return 12, "divide"
    if b in ("mla", "mls"):
        return 2, "multiply"
    if b in ("mul", "muls", "smull", "umull", "smlal", "umlal"):
        return 1, "multiply"
    return 1, "integer"

def segments(entry, caller_lo, caller_size):
    """Index runs of the trace from each entry to `entry` until the PC is back in the caller."""
    out = []
    i = 0
    while i < len(pcs):
        if pcs[i] != entry:
            i += 1
            continue
        j = i
        seq = []
        while j < len(pcs) and not (caller_lo <= pcs[j] < caller_lo + caller_size):
            seq.append(j)
            j += 1
        out.append(seq)
        i = j
    return out

steps = segments(step_addr, main_lo, main_size)

if len(steps) < 10:
    sys.exit("m4f_step_cycles.sh: fewer than 10 steps in the trace (%d)" % len(steps))

def analyse(seq):
    cyc, n = 0, 0
    classes = collections.Counter()
    ccount = collections.Counter()
    prev_mem = False
    for k in seq:
        pc = pcs[k]
        size, mn, ops = insn.get(pc, (2, "?", ""))
        nxt = pcs[k + 1] if k + 1 < len(pcs) else None
        taken = nxt is not None and nxt != pc + size
        c, cls = cost(mn, ops, taken, prev_mem)
        prev_mem = cls == "load/store"
        cyc += c
        n += 1
        classes[cls] += c
        ccount[cls] += 1
    return n, cyc, classes, ccount

# Every traced step: the inputs change at every sample, so the branches taken (and the libm
# paths) may too; the spread shows whether they do.
results = [analyse(s) for s in steps]
by_cycles = sorted(results, key=lambda r: r[1])
ns = sorted(r[0] for r in results)
cs = [r[1] for r in by_cycles]
mid = len(results) // 2
n, cyc, classes, ccount = by_cycles[mid]
mean_n = sum(ns) / len(ns)
mean_c = sum(cs) / len(cs)
print("steps traced: %d (consecutive 1 kHz samples of the manoeuvre, different codes at each)"
      % len(results))
print("instructions per step: min %d, median %d, max %d, mean %.1f; %d different counts"
      % (ns[0], ns[mid], ns[-1], mean_n, len(set(ns))))
print("estimated cycles per step: min %d, median %d, max %d, mean %.1f"
      % (cs[0], cs[mid], cs[-1], mean_c))
print()
print("median step: %d instructions, %d estimated cycles (%.1f us at 168 MHz, %.2f %% of a"
      " 1 kHz period); worst step %d cycles (%.1f us)"
      % (n, cyc, cyc / 168.0, cyc / 168.0 / 10.0, cs[-1], cs[-1] / 168.0))
print()
print("%-28s %8s %8s" % ("class (median step)", "instr", "cycles"))
for cls, c in sorted(classes.items(), key=lambda kv: -kv[1]):
    print("%-28s %8d %8d" % (cls, ccount[cls], c))
print()
# The aided filter's operations (filter_rig.hpp), traced after the steps: the run announces them
# as "FILTER-OPS calls name name ...", then makes `calls` calls of gfins_filter_op per operation
# in that order.
announced = None
for line in open(out_path):
    if line.startswith("FILTER-OPS "):
        announced = line.split()[1:]
if announced is None or "gfins_filter_op" not in sym or "gfins_run_filter_ops" not in sym:
    sys.exit("m4f_step_cycles.sh: the run traced no filter operations (an old image?)")
calls, op_names = int(announced[0]), announced[1:]
runner_lo, runner_size = sym["gfins_run_filter_ops"]
op_runs = segments(sym["gfins_filter_op"][0], runner_lo, runner_size)
if len(op_runs) != calls * len(op_names):
    sys.exit("m4f_step_cycles.sh: %d filter operation calls in the trace, %d announced"
             % (len(op_runs), calls * len(op_names)))
print("aided filter, one call (18 states, float32; %d calls of each, the same rig as the host's"
      " callgrind figures):" % calls)
print("%-16s %12s %12s %12s %10s" % ("operation", "instructions", "est. cycles", "spread", "us@168MHz"))
for k, name in enumerate(op_names):
    res = [analyse(s) for s in op_runs[k * calls:(k + 1) * calls]]
    ins = sorted(r[0] for r in res)
    cyc = sorted(r[1] for r in res)
    print("%-16s %12d %12d %12s %10.1f" % (name, ins[len(ins) // 2], cyc[len(cyc) // 2],
                                            "%d..%d" % (cyc[0], cyc[-1]), cyc[len(cyc) // 2] / 168.0))
print()
print("assumptions: zero-wait-state memory (code and data in SRAM, or flash behind a prefetch")
print("accelerator that hits); taken branch 1+P with P = %d; LDR/STR 2 cycles, 1 when it follows" % P)
print("another load/store (address/data phase pipelining); LDRD/STRD 3; LDM/STM/PUSH/POP 1+N;")
print("VLDR/VSTR 2; VPUSH/VPOP/VLDM/VSTM 1+N; VADD/VSUB/VMUL/VCMP/VCVT 1; VMLA/VMLS/VFMA 3;")
print("VDIV/VSQRT 14; IT 1 (not folded); SDIV/UDIV 12 (worst case); no FPU result stalls modelled.")
PY
