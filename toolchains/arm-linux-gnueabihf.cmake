# 32-bit Arm Linux board (Debian armhf: ARMv7-A, Thumb-2, VFPv3-D16, hard-float ABI), Debian's
# cross compiler:
#   apt install g++-arm-linux-gnueabihf
#   dpkg --add-architecture armhf && apt update && apt install libgpiod-dev:armhf
#   cmake -S . -B build/armhf -G Ninja -DCMAKE_BUILD_TYPE=Release \
#         -DCMAKE_TOOLCHAIN_FILE=toolchains/arm-linux-gnueabihf.cmake -DGFINS_BUILD_TESTS=OFF \
#         -DGFINS_BUILD_BENCHMARKS=OFF
# The compiler's defaults are the armhf baseline; a Cortex-A7 board may add
# -DCMAKE_CXX_FLAGS="-mcpu=cortex-a7 -mfpu=neon-vfpv4" (never -ffast-math).
set(CMAKE_SYSTEM_PROCESSOR arm)
# GCC's note that passing some Eigen structs by value changed ABI in GCC 7.1 concerns linking
# with objects from GCC < 7, which a Debian 12 build never does.
set(CMAKE_CXX_FLAGS_INIT "-Wno-psabi")
set(GFINS_CROSS_TRIPLE arm-linux-gnueabihf)
include(${CMAKE_CURRENT_LIST_DIR}/debian-cross-linux.cmake)
