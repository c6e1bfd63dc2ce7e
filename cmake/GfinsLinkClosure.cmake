# The layering the build enforces (docs/architecture.md, "Rules the build enforces"): a target's
# link closure, every target it links directly or through others' PUBLIC/INTERFACE libraries,
# must not reach a folder above it. Checked at configure time, so a forbidden link fails every
# build on every preset.

# gfins_link_closure(<target> <out-var> [COMPILE]): the targets (ALIAS names resolved) in the
# closure. With COMPILE, only those whose usage requirements (include folders, definitions) reach
# <target>'s compile: its own links and, through them, their interface links, not a static
# library's private links ($<LINK_ONLY:...>), which reach only the link.
function(gfins_link_closure target out)
  set(compile_only OFF)
  if(ARGC GREATER 2 AND ARGV2 STREQUAL "COMPILE")
    set(compile_only ON)
  endif()
  set(seen "")
  set(todo ${target})
  while(todo)
    list(POP_FRONT todo t)
    if(NOT TARGET ${t})
      continue()  # a plain library name (pthread, ...) or a generator expression
    endif()
    get_target_property(real ${t} ALIASED_TARGET)
    if(real)
      set(t ${real})
    endif()
    if(t IN_LIST seen)
      continue()
    endif()
    list(APPEND seen ${t})
    get_target_property(type ${t} TYPE)
    set(libs "")
    if(NOT type STREQUAL "INTERFACE_LIBRARY" AND (NOT compile_only OR t STREQUAL target))
      get_target_property(direct ${t} LINK_LIBRARIES)
      if(direct)
        list(APPEND libs ${direct})
      endif()
    endif()
    get_target_property(iface ${t} INTERFACE_LINK_LIBRARIES)
    if(iface)
      list(APPEND libs ${iface})
    endif()
    foreach(l IN LISTS libs)
      # $<LINK_ONLY:x> (static libraries' private links) still ends up in the link.
      if(NOT compile_only)
        string(REGEX REPLACE "^\\$<LINK_ONLY:(.*)>$" "\\1" l "${l}")
      endif()
      list(APPEND todo ${l})
    endforeach()
  endwhile()
  if(compile_only)
    list(REMOVE_ITEM seen ${target})
  endif()
  set(${out} ${seen} PARENT_SCOPE)
endfunction()

# gfins_forbid_link(<target> <folder> <why>): fails the configuration when a target of the
# closure of <target> is defined under <folder> (relative to the source tree).
function(gfins_forbid_link target folder why)
  gfins_link_closure(${target} closure)
  set(bad "")
  foreach(t IN LISTS closure)
    get_target_property(dir ${t} SOURCE_DIR)
    file(RELATIVE_PATH rel ${PROJECT_SOURCE_DIR} ${dir})
    if(rel STREQUAL folder OR rel MATCHES "^${folder}/")
      list(APPEND bad "${t} (${rel})")
    endif()
  endforeach()
  if(bad)
    list(JOIN bad ", " bad)
    message(FATAL_ERROR "${target} links ${bad}: ${why}")
  endif()
endfunction()
