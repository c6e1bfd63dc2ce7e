#!/usr/bin/env bash
# cppcheck (Debian 12's 2.10) beside clang-tidy: every translation unit a configured build folder
# compiles (default build/host-release), the tests included, checks `warning`, `performance` and
# `portability`. Exits 1 on any finding or when cppcheck fails to run (docs/ci.md).
#   Third-party headers (the compile database's -isystem folders: Eigen, toml++, spdlog, CLI11,
#   GoogleTest) are left out of cppcheck's include path: it checks the project's code, their
#   declarations come from --library where cppcheck has one, and parsing them cost a third of its
#   CPU (275 CPU s against 194 for the 251 files; a planted out-of-bounds index in a file that
#   includes Eigen is found either way: docs/ci.md, "cppcheck without the third-party headers").
#   useInitializationList is off: a style preference, and cppcheck 2.10 takes an assignment inside
#   a lambda written in a constructor for one in the constructor's body (the fake kernels of the
#   Linux backend tests); missingIncludeSystem: system headers are not analysed.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build/host-release}
[ -f "$build/compile_commands.json" ] || {
  echo "check-cppcheck: no $build/compile_commands.json" >&2
  exit 1
}
db_dir=$(mktemp -d)
trap 'rm -rf "$db_dir"' EXIT
# One entry per source file of the tree (a file two targets compile has two; generated sources in
# the build folder are not ours).
python3 - "$build/compile_commands.json" "$db_dir/compile_commands.json" "$PWD" <<'PY'
import json, os, re, sys
entries, out, root = json.load(open(sys.argv[1])), sys.argv[2], os.path.realpath(sys.argv[3])
first = {}
for e in entries:
    f = os.path.realpath(os.path.join(e["directory"], e["file"]))
    if f.startswith(root + "/build/") or not f.startswith(root + "/") or "/baremetal/" in f:
        continue
    if f not in first:  # CMake writes each entry's "command" as one string
        first[f] = dict(e, command=re.sub(r" -isystem +\S+", "", e["command"]))
json.dump(list(first.values()), open(out, "w"))
print(f"check-cppcheck: {len(first)} files", file=sys.stderr)
PY
cppcheck --project="$db_dir/compile_commands.json" --std=c++20 \
  --enable=warning,performance,portability \
  --library=googletest --library=posix --library=tests/cppcheck/googletest-typed.cfg \
  --suppress=missingIncludeSystem --suppress=useInitializationList \
  --inline-suppr --error-exitcode=1 -q -j "${GFINS_JOBS:-$(nproc)}"
echo "check-cppcheck: no findings"
