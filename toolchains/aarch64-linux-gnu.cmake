# 64-bit Arm Linux board (Cortex-A53/A55/A72 class), Debian's cross compiler:
#   apt install g++-aarch64-linux-gnu
#   dpkg --add-architecture arm64 && apt update && apt install libgpiod-dev:arm64
#   cmake --preset aarch64-linux && cmake --build --preset aarch64-linux
# The compiler's default is armv8-a, which every 64-bit board runs; tune for one core with
# -DCMAKE_CXX_FLAGS=-mcpu=cortex-a53 (never -ffast-math: nav_core needs IEEE arithmetic).
set(CMAKE_SYSTEM_PROCESSOR aarch64)
set(GFINS_CROSS_TRIPLE aarch64-linux-gnu)
include(${CMAKE_CURRENT_LIST_DIR}/debian-cross-linux.cmake)
