#!/usr/bin/env bash
# Flash/RAM footprint of the float32 navigation core on a bare-metal Cortex-M4F, and the proof
# that the image holds no soft-float double routine (set-up included) and that the per-sample
# step reaches none. Enforces the limits: flash (text + data) <= 48 KiB, static RAM (data + bss)
# <= 8 KiB (the navigation core's 24 KiB / 4 KiB doubled for the aided filter, which the probe
# program instantiates too), no soft-double symbol anywhere in the program.
#
# Usage: scripts/embedded_size.sh [build-dir]      (default: build/cortex-m4f)
#   Build first:  cmake --preset cortex-m4f && cmake --build --preset cortex-m4f
#
# Prints
#   1. `size` (text/data/bss) of the probe program nav_core/baremetal (gfins_nav_baremetal.elf)
#      and of the objects of libgfins_nav_core.a (which hold both the float and the double
#      instantiations; the program links only the float one, with --gc-sections);
#   2. the largest symbols of the program;
#   3. every soft-float double routine (__aeabi_d*, __*df2/3, __aeabi_f2d, ...) and double libm
#      function the program contains (there must be none), with the call path that reaches it
#      from main, and then the same walk from the per-sample step gfins_nav_step(); and libgcc's
#      soft-float single routines (__aeabi_fadd, __aeabi_l2f, ...: the FPU does single precision,
#      so none belongs in the image either);
#   4. the limits check.
# Exit status: 0 within the limits and free of double arithmetic, 1 when a limit is exceeded or a
# soft-double routine is present, 2 on usage errors. Limits: the build folder's cache
# (GFINS_M4F_FLASH_LIMIT, GFINS_M4F_RAM_LIMIT: nav_core/baremetal/CMakeLists.txt, the one place
# they are set); GFINS_FLASH_LIMIT / GFINS_RAM_LIMIT (bytes) override them.
set -euo pipefail

# shellcheck source=scripts/measure_common.sh source-path=SCRIPTDIR
source "$(dirname "${BASH_SOURCE[0]}")/measure_common.sh"
gfins_build_dir "$@" build/cortex-m4f
elf="${gfins_build}/nav_core/baremetal/gfins_nav_baremetal.elf"
lib="${gfins_build}/nav_core/libgfins_nav_core.a"
prefix="${GFINS_ARM_PREFIX:-arm-none-eabi-}"

for f in "${elf}" "${lib}"; do
  gfins_need_file "${f}" "build the cortex-m4f preset first"
done

# A limit as the build folder's CMake cache holds it ("NAME:STRING=value").
cache_limit() {
  [ -f "${gfins_build}/CMakeCache.txt" ] || return 0
  sed -n "s/^$1:[A-Z]*=\([0-9][0-9]*\)\$/\1/p" "${gfins_build}/CMakeCache.txt" | head -n 1
}
flash_limit="${GFINS_FLASH_LIMIT:-$(cache_limit GFINS_M4F_FLASH_LIMIT)}"
ram_limit="${GFINS_RAM_LIMIT:-$(cache_limit GFINS_M4F_RAM_LIMIT)}"
[ -n "${flash_limit}" ] && [ -n "${ram_limit}" ] || {
  echo "embedded_size: no GFINS_M4F_FLASH_LIMIT / GFINS_M4F_RAM_LIMIT in ${gfins_build}/CMakeCache.txt" \
    "(configure with preset cortex-m4f) and no GFINS_FLASH_LIMIT / GFINS_RAM_LIMIT" >&2
  exit 2
}

echo "== Probe program (float32 pipeline, exact compensator, one geometry, static storage) =="
"${prefix}size" "${elf}"
echo
echo "== Navigation core library objects (float: the preset compiles no double instantiation) =="
# With -flto (the preset's toolchain) the archive holds GIMPLE only and `size` would print zeros:
# the code exists only once linked, so the program's figures above are the ones that count.
if "${prefix}objdump" -h "${lib}" 2>/dev/null | grep -c '\.gnu\.lto_' >/dev/null; then
  echo "  (link-time-optimised objects: no machine code before the link; see the program above)"
else
  "${prefix}size" -t "${lib}"
fi
echo
echo "== Largest symbols of the program (bytes, type, name) =="
"${prefix}nm" -C --size-sort -S --radix=d "${elf}" | tail -n 15 | cut -c 10-160
echo

echo "== Code bytes by origin (text symbols) =="
"${prefix}nm" -C -S --radix=d "${elf}" | python3 -c '
import re, sys
cats = {}
soft = re.compile(r"^(__aeabi_(c?d|cdr|[a-z0-9]+2d|d2)|__[a-z]+df[23]$|__extendsfdf2|__truncdfsf2)")
for line in sys.stdin:
    parts = line.split(None, 3)
    if len(parts) < 4 or parts[2] not in "TtWw":
        continue
    size, name = int(parts[1]), parts[3].strip()
    if "gfins" in name or name == "main":
        cat = "gfins (navigation core + probe main)"
    elif "Eigen::" in name and "double" in name:
        cat = "Eigen in double (set-up: SVD and solver construction)"
    elif "Eigen::" in name:
        cat = "Eigen in float (kernels -Os did not inline)"
    elif soft.match(name):
        cat = "soft-float double (libgcc; set-up only)"
    elif re.match(r"^(__ieee754_|__kernel_)?[a-z0-9_]+f$|^__kernel_rem_pio2f$|^__ieee754_rem_pio2f$", name):
        cat = "libm single precision (sqrtf, sinf, cosf, atan2f)"
    else:
        cat = "C runtime, libm double, other"
    cats[cat] = cats.get(cat, 0) + size
for cat, size in sorted(cats.items(), key=lambda kv: -kv[1]):
    print("  %7d  %s" % (size, cat))
'
echo

# Call graph from the disassembly: direct calls (bl) and tail calls (b.w / b to the start of
# another function). Indirect calls (blx rN) cannot be followed and are reported.
read -r -d '' callgraph_py <<'PY' || true
import re, sys

func_re = re.compile(r"^[0-9a-f]+ <([^>]+)>:$")
call_re = re.compile(r"^\s*[0-9a-f]+:\s+(b[a-z.]*|bl|blx)\s+[0-9a-f]+ <([^>+]+)>")
indirect_re = re.compile(r"^\s*[0-9a-f]+:\s+blx\s+r\d+")
graph, indirect, cur = {}, set(), None
for line in sys.stdin:
    m = func_re.match(line.strip())
    if m:
        cur = m.group(1)
        graph.setdefault(cur, set())
        continue
    if cur is None:
        continue
    m = call_re.match(line)
    if m and m.group(2) != cur:
        graph[cur].add(m.group(2))
    elif indirect_re.match(line):
        indirect.add(cur)

soft_double = re.compile(
    r"^(__aeabi_(c?d[a-z0-9]+|cdr[a-z0-9]+|[a-z0-9]+2d)|__[a-z]+df[23]|__extendsfdf2|"
    r"__truncdfsf2|__float[a-z]*df|__fix[a-z]*df[a-z]*|"
    r"(sin|cos|tan|asin|acos|atan|atan2|sqrt|exp|log|pow|fmod|hypot|floor|ceil|round)|"
    r"(__ieee754_|__kernel_)\w*[^f])$")

def walk(root):
    """Breadth-first: the first path found to each reachable function."""
    parent, order = {root: None}, [root]
    for f in order:
        for g in sorted(graph.get(f, ())):
            if g not in parent:
                parent[g] = f
                order.append(g)
    return parent

def path(parent, f):
    p = []
    while f is not None:
        p.append(f)
        f = parent[f]
    return " <- ".join(p)

def demangle_all(names):
    import subprocess
    out = subprocess.run(["c++filt"], input="\n".join(names), capture_output=True, text=True)
    return out.stdout.split("\n")

present = sorted(f for f in graph if soft_double.match(f))
print("== Soft-float double routines in the program (there must be none, set-up included) ==")
print("  " + (" ".join(present) if present else "(none)"))
print()
print("== Functions that call them, reached from main ==")
from_main = walk("main")
users = sorted(f for f in from_main
               if not soft_double.match(f) and any(soft_double.match(g) for g in graph[f]))
for name, dem in zip(users, demangle_all(users)):
    print("  " + dem[:150])
print()
print("== Reached from the per-sample step gfins_nav_step ==")
from_step = walk("gfins_nav_step")
bad = [f for f in present if f in from_step]
print("  functions reachable from the step: %d" % len(from_step))
verbose = len(sys.argv) > 1 and sys.argv[1] == "-v"
for f, dem in zip(sorted(from_step), demangle_all(sorted(from_step))):
    if verbose:
        print("    " + dem[:150])
    if f in indirect:
        print("  note: %s makes an indirect call (not followed)" % f)
if bad:
    for f in bad:
        print("  SOFT DOUBLE: " + path(from_step, f))
    sys.exit(1)
print("  no soft-float double routine is reachable: the step runs on the FPU in single precision")
# libgcc's single-precision soft-float set (add, subtract, multiply, divide, 64-bit integer
# conversions) has no place on an FPU either: one static_cast<float>(int64) (__aeabi_l2f) drags
# the whole object in, 668 B of flash (math.hpp, from_int64).
soft_single = re.compile(r"^(__aeabi_(f(add|sub|rsub|mul|div)|u?l2f|f2u?lz)|__(add|sub|mul|div)sf3|"
                         r"__float(un)?disf|__fix(uns)?sfdi)$")
singles = sorted(f for f in graph if soft_single.match(f))
print()
print("== Soft-float single routines in the program (there must be none) ==")
print("  " + (" ".join(singles) if singles else "(none)"))
for f in singles:
    callers = sorted(g for g in graph if f in graph[g])
    for dem in demangle_all(callers):
        if dem:
            print("    called by " + dem[:150])
if present or singles:
    sys.exit(1)
PY
status=0
"${prefix}objdump" -d --no-show-raw-insn "${elf}" |
  python3 -c "${callgraph_py}" ${GFINS_SIZE_VERBOSE:+-v} || status=1

# Limits: flash holds text and the initial values of data; static RAM holds data and bss.
read -r text data bss _ < <("${prefix}size" "${elf}" | awk 'NR == 2')
flash=$((text + data))
ram=$((data + bss))
echo
echo "== Limits =="
printf '  flash (text + data) %6d B, limit %6d B\n' "${flash}" "${flash_limit}"
printf '  RAM   (data + bss)  %6d B, limit %6d B\n' "${ram}" "${ram_limit}"
if (( flash > flash_limit )); then
  echo "  FAIL: flash above the limit" >&2
  status=1
fi
if (( ram > ram_limit )); then
  echo "  FAIL: static RAM above the limit" >&2
  status=1
fi
if (( status != 0 )); then
  echo "  FAIL: see above (limits, soft-float double or single)" >&2
  exit 1
fi
echo "  OK: within the limits, no soft-float double or single routine in the image"
