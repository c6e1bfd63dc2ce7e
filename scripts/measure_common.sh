# shellcheck shell=bash
# Sourced (never run) by the measurement scripts: callgrind_per_sample.sh, callgrind_filter.sh,
# callgrind_baseline.sh, m4f_step_cycles.sh, embedded_size.sh. Gives them the repository root,
# the build folder from their first argument, checks that name what is missing (exit status 2,
# as each script's usage says), a scratch folder removed on exit, and the callgrind difference
# of two run lengths.
#
#   source "$(dirname "${BASH_SOURCE[0]}")/measure_common.sh"
#   gfins_build_dir "$@" build/host-release     # sets gfins_build (argument 1 or the default)

gfins_script="$(basename "$0")"
gfins_root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"

# The variables these functions set (gfins_build, gfins_scratch, gfins_ir1, gfins_ir2,
# gfins_per_unit) are read by the sourcing script.
# shellcheck disable=SC2034

# gfins_build_dir [args...] DEFAULT: gfins_build = the first argument, else ROOT/DEFAULT.
gfins_build_dir() {
  local default="${!#}"
  if (($# > 1)) && [[ -n "$1" ]]; then
    gfins_build="$1"
  else
    gfins_build="${gfins_root}/${default}"
  fi
}

# gfins_need_file PATH HINT: exits 2 naming PATH and what to do when it is not a file.
gfins_need_file() {
  if [[ ! -f "$1" ]]; then
    echo "${gfins_script}: $1 not found; $2" >&2
    exit 2
  fi
}

# gfins_need_command NAME HINT: exits 2 naming the program and its package when it is missing.
gfins_need_command() {
  if ! command -v "$1" >/dev/null; then
    echo "${gfins_script}: $1 not found ($2)" >&2
    exit 2
  fi
}

# gfins_scratch_dir: gfins_scratch = a new empty folder, removed when the script exits.
gfins_scratch_dir() {
  gfins_scratch="$(mktemp -d)"
  trap 'rm -rf "${gfins_scratch}"' EXIT
}

# gfins_total_ir <callgrind.out>: the file's "summary:" (or "totals:") instruction count.
gfins_total_ir() {
  awk '/^(summary|totals):/ { print $2; exit }' "$1"
}

# gfins_need_counts N1 N2: exits 2 unless 0 < N1 < N2 (the two run lengths of a difference).
gfins_need_counts() {
  if ! (($2 > $1 && $1 > 0)); then
    echo "${gfins_script}: need 0 < N1 < N2" >&2
    exit 2
  fi
}

# gfins_ir_per_unit OUT N1 N2 COMMAND...: runs "COMMAND... N" under callgrind for N = N1 and N2
# (files OUT.N1.out and OUT.N2.out; a run that fails ends the script with its log, exit 1) and
# sets gfins_ir1 and gfins_ir2 to their instruction counts and gfins_per_unit to
# (ir2 − ir1) / (N2 − N1): what the program does once per unit, its start-up cancelled.
gfins_ir_per_unit() {
  local out="$1" n1="$2" n2="$3"
  shift 3
  local tag n f
  for tag in N1 N2; do
    n="${n1}"
    [[ "${tag}" == N2 ]] && n="${n2}"
    f="${out}.${tag}.out"
    if ! valgrind --tool=callgrind --callgrind-out-file="${f}" "$@" "${n}" >/dev/null 2>"${f}.log"; then
      echo "${gfins_script}: $* ${n} failed:" >&2
      cat "${f}.log" >&2
      exit 1
    fi
    if [[ "${tag}" == N1 ]]; then gfins_ir1="$(gfins_total_ir "${f}")"; else gfins_ir2="$(gfins_total_ir "${f}")"; fi
  done
  gfins_per_unit="$(awk -v a="${gfins_ir1}" -v b="${gfins_ir2}" -v n1="${n1}" -v n2="${n2}" \
    'BEGIN { printf "%.1f", (b - a) / (n2 - n1) }')"
}
