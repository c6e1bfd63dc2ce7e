# The project's warning set, applied per target so third-party code is not affected.
add_library(gfins_warnings INTERFACE)
add_library(gfins::warnings ALIAS gfins_warnings)
target_compile_options(gfins_warnings INTERFACE
  -Wall -Wextra -Wpedantic -Wshadow -Wconversion -Wdouble-promotion
  $<$<COMPILE_LANGUAGE:CXX>:-Wold-style-cast -Wnon-virtual-dtor>)
if(GFINS_WERROR)
  target_compile_options(gfins_warnings INTERFACE -Werror)
endif()
# GCC 12 reports impossible -Wrestrict overlaps inside libstdc++'s std::string at -O3 (GCC bug
# 105329, fixed in GCC 13): a false positive in the standard library, not in our code.
if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU" AND CMAKE_CXX_COMPILER_VERSION VERSION_LESS 13)
  target_compile_options(gfins_warnings INTERFACE $<$<COMPILE_LANGUAGE:CXX>:-Wno-restrict>)
endif()
