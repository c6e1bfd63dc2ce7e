# Bare-metal Cortex-M4F (STM32F4-class): arm-none-eabi-gcc 12 (Debian gcc-arm-none-eabi),
# Thumb-2, single-precision FPU with the hard-float ABI, newlib-nano without system calls.
#
# Used by the `cortex-m4f` preset, which builds only the navigation core (GFINS_NAV_CORE_ONLY)
# and the size/soft-double probe in nav_core/baremetal. Never add -ffast-math here: the
# integrator's compensated (Kahan) sums and the NaN checks need IEEE arithmetic as written.
#
#   cmake --preset cortex-m4f && cmake --build --preset cortex-m4f
#   scripts/embedded_size.sh
set(CMAKE_SYSTEM_NAME Generic)
set(CMAKE_SYSTEM_PROCESSOR arm)

set(GFINS_ARM_TRIPLE arm-none-eabi)
set(CMAKE_C_COMPILER ${GFINS_ARM_TRIPLE}-gcc)
set(CMAKE_CXX_COMPILER ${GFINS_ARM_TRIPLE}-g++)
set(CMAKE_ASM_COMPILER ${GFINS_ARM_TRIPLE}-gcc)
# gcc-ar/gcc-ranlib: the archive index must see the LTO objects (link-time optimisation below).
set(CMAKE_AR ${GFINS_ARM_TRIPLE}-gcc-ar CACHE FILEPATH "")
set(CMAKE_RANLIB ${GFINS_ARM_TRIPLE}-gcc-ranlib CACHE FILEPATH "")
set(CMAKE_OBJCOPY ${GFINS_ARM_TRIPLE}-objcopy CACHE FILEPATH "")
set(CMAKE_SIZE ${GFINS_ARM_TRIPLE}-size CACHE FILEPATH "")

# There is no OS to run a test executable: let try_compile build a static library instead.
set(CMAKE_TRY_COMPILE_TARGET_TYPE STATIC_LIBRARY)

# -fsingle-precision-constant is deliberately NOT used: it would hide double literals that
# -Wdouble-promotion must report in the float path.
set(GFINS_M4F_CPU_FLAGS "-mcpu=cortex-m4 -mthumb -mfloat-abi=hard -mfpu=fpv4-sp-d16")
# -flto: the core is templates instantiated explicitly in nav_core/src (extern template elsewhere),
# so without link-time optimisation the program cannot inline across that boundary and keeps
# out-of-line copies of small Eigen kernels; with it the probe is 4.0 KB smaller (27.4 → 23.4 KB of
# flash, docs/performance.md). LTO changes inlining decisions, not the floating-point options.
set(GFINS_M4F_COMMON_FLAGS "${GFINS_M4F_CPU_FLAGS} -ffunction-sections -fdata-sections -flto")
set(CMAKE_C_FLAGS_INIT "${GFINS_M4F_COMMON_FLAGS}")
# -Wno-psabi: GCC's note that passing some Eigen structs by value changed ABI in GCC 7.1 is about
# linking with objects from GCC < 7, which this build never does.
set(CMAKE_CXX_FLAGS_INIT
    "${GFINS_M4F_COMMON_FLAGS} -fno-exceptions -fno-rtti -fno-threadsafe-statics -fno-use-cxa-atexit -Wno-psabi")
set(CMAKE_ASM_FLAGS_INIT "${GFINS_M4F_CPU_FLAGS}")
# newlib-nano (small printf/malloc) and stub system calls: nothing here calls them, but the C
# runtime start files (crt0) need an implementation to link a program at all.
set(CMAKE_EXE_LINKER_FLAGS_INIT
    "${GFINS_M4F_CPU_FLAGS} -flto --specs=nano.specs --specs=nosys.specs -Wl,--gc-sections")

# Search only the toolchain's own tree for libraries and headers; host programs (cmake, python)
# still come from the host.
set(CMAKE_FIND_ROOT_PATH /usr/lib/${GFINS_ARM_TRIPLE})
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)

# Eigen is header-only and architecture-independent, so the host's Debian package
# (libeigen3-dev) serves the target too. Point find_package(Eigen3 NO_MODULE) at its config
# file; an explicit <Pkg>_DIR is used as given, not re-rooted into CMAKE_FIND_ROOT_PATH.
# Override with -DEigen3_DIR=... for an Eigen elsewhere.
if(NOT DEFINED Eigen3_DIR AND EXISTS /usr/share/eigen3/cmake/Eigen3Config.cmake)
  set(Eigen3_DIR /usr/share/eigen3/cmake CACHE PATH "Eigen3Config.cmake of the host's Eigen")
endif()
