# The warning set of STYLE.md, applied per target so third-party code is not affected.
add_library(gfins_warnings INTERFACE)
add_library(gfins::warnings ALIAS gfins_warnings)
target_compile_options(gfins_warnings INTERFACE
  -Wall -Wextra -Wpedantic -Wshadow -Wconversion -Wdouble-promotion
  $<$<COMPILE_LANGUAGE:CXX>:-Wold-style-cast -Wnon-virtual-dtor>)
if(GFINS_WERROR)
  target_compile_options(gfins_warnings INTERFACE -Werror)
endif()
