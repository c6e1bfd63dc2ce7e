# shellcheck shell=bash
# Sourced (never run) by the measurement scripts: callgrind_per_sample.sh, callgrind_baseline.sh,
# m4f_step_cycles.sh, embedded_size.sh. Gives them the repository root, the build folder from
# their first argument, checks that name what is missing (exit status 2, as each script's usage
# says) and a scratch folder removed on exit.
#
#   source "$(dirname "${BASH_SOURCE[0]}")/measure_common.sh"
#   gfins_build_dir "$@" build/host-release     # sets gfins_build (argument 1 or the default)

gfins_script="$(basename "$0")"
gfins_root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"

# The variables these functions set (gfins_build, gfins_scratch) are read by the sourcing script.
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
