# Precompiled headers for the host libraries and programs in the clang trees (host-debug,
# host-tsan): Eigen, spdlog, the project's toml++ include and the standard headers take 1.5-4 s to
# parse in each of their translation units, 30-45 % of a unit's compile time under the sanitizers
# (`-ftime-trace`; firmware/app/src/config.cpp: 5.9 s without, 3.5 s with). One header per target,
# compiled with that target's own flags and definitions (the fuzzer instrumentation of some, the
# toml++ settings of others), so no target has to match another's; a target of fewer than three
# translation units gains less than its header costs and gets none. The GCC trees (host-release,
# the board builds) compile without, so an include a file forgot still fails a build there
# (clang-tidy and cppcheck read the release tree's commands too). The navigation core and the
# freestanding libraries are not listed: few units, spent instantiating templates, not parsing
# (docs/ci.md, "Precompiled headers for the libraries").
include(GfinsLinkClosure)
option(GFINS_LIB_PCH "Precompiled headers for the host libraries and programs (clang)" ON)

# gfins_library_pch(<target>...): each target gets its precompiled header, with what its compile
# closure makes available (Eigen, spdlog, the TOML include).
function(gfins_library_pch)
  if(NOT GFINS_LIB_PCH OR NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
    return()
  endif()
  foreach(t IN LISTS ARGN)
    if(NOT TARGET ${t})
      continue()
    endif()
    get_target_property(sources ${t} SOURCES)
    list(FILTER sources INCLUDE REGEX "\\.cpp$")
    list(LENGTH sources units)
    if(units LESS 3)
      continue()
    endif()
    gfins_link_closure(${t} closure COMPILE)
    set(headers <algorithm> <array> <atomic> <chrono> <cmath> <cstdint> <cstdio> <cstring>
                <filesystem> <fstream> <functional> <memory> <mutex> <optional> <span>
                <sstream> <string> <string_view> <thread> <utility> <vector>)
    if("Eigen3::Eigen" IN_LIST closure)
      list(APPEND headers <Eigen/Core> <Eigen/Dense> <Eigen/Geometry>)
    endif()
    if("spdlog::spdlog" IN_LIST closure)
      list(APPEND headers <spdlog/spdlog.h>)
    endif()
    if("gfins_toml_safe" IN_LIST closure)
      list(APPEND headers <gfins/toml/toml.hpp>)
    endif()
    target_precompile_headers(${t} PRIVATE ${headers})
  endforeach()
endfunction()
