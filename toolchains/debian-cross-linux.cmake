# Shared part of the Debian cross toolchains for Linux boards (included by
# aarch64-linux-gnu.cmake and arm-linux-gnueabihf.cmake after they set GFINS_CROSS_TRIPLE and
# CMAKE_SYSTEM_PROCESSOR).
#
# Debian cross-builds with multiarch: the cross compiler (apt install g++-<triple>) brings its
# libc in /usr/<triple>, and target libraries are the ordinary packages of the foreign
# architecture (dpkg --add-architecture arm64 && apt install libgpiod-dev:arm64), installed in
# /usr/lib/<triple> with their headers in the shared /usr/include. Debian's cross gcc already
# searches /usr/include and /usr/lib/<triple>; CMake is told the same here.
set(CMAKE_SYSTEM_NAME Linux)

set(CMAKE_C_COMPILER ${GFINS_CROSS_TRIPLE}-gcc)
set(CMAKE_CXX_COMPILER ${GFINS_CROSS_TRIPLE}-g++)
set(CMAKE_LIBRARY_ARCHITECTURE ${GFINS_CROSS_TRIPLE})

# Roots: the compiler's own tree, then / so that <prefix>/lib/<triple> (multiarch libraries),
# /usr/include and arch-independent CMake packages (/usr/share/eigen3/cmake) are found. Host
# libraries live in /usr/lib/x86_64-linux-gnu, which a search for this architecture never
# visits.
set(CMAKE_FIND_ROOT_PATH /usr/${GFINS_CROSS_TRIPLE} /)
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)

# pkg-config (FindPkgConfig, e.g. for libgpiod): only the target architecture's .pc files.
find_program(GFINS_CROSS_PKG_CONFIG NAMES ${GFINS_CROSS_TRIPLE}-pkg-config)
if(GFINS_CROSS_PKG_CONFIG)
  set(PKG_CONFIG_EXECUTABLE ${GFINS_CROSS_PKG_CONFIG} CACHE FILEPATH "")
else()
  set(ENV{PKG_CONFIG_LIBDIR} "/usr/lib/${GFINS_CROSS_TRIPLE}/pkgconfig:/usr/share/pkgconfig")
  set(ENV{PKG_CONFIG_SYSROOT_DIR} "")
endif()

# Programs built for the board cannot run here unless qemu-user is installed (then CTest and
# gtest_discover_tests can use it).
#
# The dynamic loader and libc.so.6 must come from the same glibc build: they share private
# state (the loader's _rtld_global, which pthread_create uses for its stack cache). With
# `-L /usr/<triple>` qemu-user takes the loader from the cross compiler's libc
# (libc6-<arch>-cross), but that loader reads the host's /etc/ld.so.cache, which lists the
# multiarch libc (libc6:<arch>, /lib/<triple>/libc.so.6) whenever it is installed; the two are
# different Debian revisions (2.36-8 and 2.36-9+deb12uN on Debian 12), and the first
# pthread_create then spins forever on aarch64 and crashes on armhf. So when the multiarch libc
# is present (scripts/install-cross-deps.sh installs it, and the binfmt handlers use it for
# programs the tests start), qemu-user runs without -L and takes loader and libc from there, as
# the board does; the cross compiler's sysroot is only used when nothing else is installed.
find_program(GFINS_CROSS_EMULATOR NAMES qemu-${CMAKE_SYSTEM_PROCESSOR}-static
                                        qemu-${CMAKE_SYSTEM_PROCESSOR})
if(GFINS_CROSS_EMULATOR)
  if(EXISTS /lib/${GFINS_CROSS_TRIPLE}/libc.so.6)
    set(CMAKE_CROSSCOMPILING_EMULATOR ${GFINS_CROSS_EMULATOR})
  else()
    set(CMAKE_CROSSCOMPILING_EMULATOR ${GFINS_CROSS_EMULATOR} -L /usr/${GFINS_CROSS_TRIPLE})
  endif()
endif()
