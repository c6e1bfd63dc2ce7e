#!/usr/bin/env bash
# Debian packages per architecture (docs/deploy.md): configures and builds each preset, makes
# its .deb files with CPack into out/deb/ and runs lintian on them; fails on any lintian error.
#
#   scripts/package.sh [preset[:board]...]   default: host-release aarch64-linux armhf-linux
#
# PRESET:board makes only the board's package (gfins-fw) of that preset: what scripts/test.sh
# makes for arm64 (the host tools for arm64 are `scripts/package.sh aarch64-linux`).
#
# amd64 comes from host-release, the tree scripts/test.sh has already built (the packages' layout
# is decided when installing, from the package prefix /usr: cmake/GfinsInstall.cmake), so making
# the amd64 packages compiles nothing more. The cross presets need scripts/install-cross-deps.sh
# first. GFINS_JOBS sets the parallelism.
set -euo pipefail
cd "$(dirname "$0")/.."
jobs=${GFINS_JOBS:-$(nproc)}
presets=("$@")
[ ${#presets[@]} -gt 0 ] || presets=(host-release aarch64-linux armhf-linux)
out=out/deb
mkdir -p "$out"
command -v help2man >/dev/null ||
  { echo "package.sh: help2man missing: install Debian package 'help2man' (the manual pages; scripts/install-deps.sh does)" >&2; exit 1; }
command -v lintian >/dev/null ||
  { echo "package.sh: lintian missing: install Debian package 'lintian' (scripts/install-deps.sh does)" >&2; exit 1; }
command -v dpkg-shlibdeps >/dev/null ||
  { echo "package.sh: dpkg-shlibdeps missing: install Debian package 'dpkg-dev' (scripts/install-deps.sh does)" >&2; exit 1; }

made=()
for spec in "${presets[@]}"; do
  p=${spec%%:*}
  part=${spec#"$p"}
  case "$part" in
    "") targets=(gfins_package_programs) cpack_args=() ;;
    :board) targets=(gfins-fw gfins_changelog_board gfins_man_board) cpack_args=(-D CPACK_COMPONENTS_ALL=board) ;;
    *) echo "package.sh: $spec: expected PRESET or PRESET:board" >&2; exit 2 ;;
  esac
  echo "=== package: $spec"
  cmake --preset "$p" >/dev/null
  # Only what goes into the packages (a preset's tests are built and run by its own step).
  cmake --build --preset "$p" -j "$jobs" --target "${targets[@]}"
  # A fresh CPack folder: a .deb left there by an earlier version must not be copied again.
  rm -rf "build/$p/cpack"
  cpack --config "build/$p/CPackConfig.cmake" -B "build/$p/cpack" "${cpack_args[@]}" >/dev/null
  debs_made=("build/$p/cpack"/*.deb)
  [ -e "${debs_made[0]}" ] || { echo "package.sh: cpack made no .deb for $p" >&2; exit 1; }
  for deb in "${debs_made[@]}"; do
    name=$(dpkg-deb -f "$deb" Package)
    arch=$(dpkg-deb -f "$deb" Architecture)
    # out/deb holds one version per package and architecture: the one just made.
    rm -f "$out/${name}_"*"_${arch}.deb"
    cp "$deb" "$out/"
    made+=("$out/$(basename "$deb")")
    echo "  $(basename "$deb")"
  done
done

echo "=== lintian ${#made[@]} package(s) made by this run"
# --fail-on error: warnings are shown but only errors fail the build, except a program without
# its manual page (made from its --help at build time: a missing one is a broken build step).
lintian_log="$out/lintian.log"
lintian --fail-on error --tag-display-limit 0 "${made[@]}" | tee "$lintian_log"
if grep -q 'no-manual-page' "$lintian_log"; then
  echo "package.sh: a program has no manual page (is help2man installed, and the cross emulator?)" >&2
  exit 1
fi
echo "package.sh: ${#made[@]} package(s) in $out, lintian: no errors, every program has its manual page"
