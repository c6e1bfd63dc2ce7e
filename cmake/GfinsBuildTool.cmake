# Fresh objects are the build tool's job, not the code's. An object compiled while one of its
# inputs was being edited ends with a newer time stamp than the edit; a build tool that compares
# time stamps only then never rebuilds it, and the program links an object made from the old
# header (docs/ci.md, "armhf: ... reported mode 0"). Ninja 1.11 records in .ninja_log when each
# command started and rebuilds an output whose inputs (the headers of its depfile included) are
# newer than that (ninja-build/ninja pull request 1943, "Provide resiliency against inputs
# changing during the build"). Require it; Debian 12 ships 1.11.1. It narrows the window, it does
# not close it: one case of a header rewritten mid-compile was still not rebuilt (docs/ci.md), so
# do not edit or merge while a build of the same tree runs; CI builds every tree from nothing.
set(GFINS_MIN_NINJA_VERSION 1.11)

if(CMAKE_GENERATOR MATCHES "Ninja")
  execute_process(COMMAND "${CMAKE_MAKE_PROGRAM}" --version
                  OUTPUT_VARIABLE gfins_ninja_version
                  OUTPUT_STRIP_TRAILING_WHITESPACE
                  RESULT_VARIABLE gfins_ninja_rc)
  if(NOT gfins_ninja_rc EQUAL 0)
    message(FATAL_ERROR "cannot run '${CMAKE_MAKE_PROGRAM} --version' to check the Ninja version "
                        "(at least ${GFINS_MIN_NINJA_VERSION} is needed)")
  endif()
  if(gfins_ninja_version VERSION_LESS GFINS_MIN_NINJA_VERSION)
    message(FATAL_ERROR
            "Ninja ${gfins_ninja_version} (${CMAKE_MAKE_PROGRAM}) does not rebuild an object "
            "whose inputs were edited while it compiled; at least ${GFINS_MIN_NINJA_VERSION} is "
            "needed (Debian 12: apt-get install ninja-build)")
  endif()
else()
  message(WARNING "generator ${CMAKE_GENERATOR}: it compares time stamps only, so an object "
                  "compiled while one of its inputs was edited is not rebuilt; use the presets "
                  "(Ninja ${GFINS_MIN_NINJA_VERSION} or later)")
endif()
