# gfins::version (docs/install.md, "Versions"): the project version and the git revision of the
# sources, `git describe --always --dirty` run at every build (not only at configure time, so a
# new commit or an edit shows without re-running cmake), "unknown" outside a git checkout.
# The generated file changes only when the revision does, so an unchanged tree rebuilds nothing.
set(gfins_version_cpp ${PROJECT_BINARY_DIR}/generated/gfins_version.cpp)
add_custom_target(gfins_version_stamp
  COMMAND ${CMAKE_COMMAND} -DGFINS_SOURCE_DIR=${PROJECT_SOURCE_DIR}
          -DGFINS_VERSION=${PROJECT_VERSION} -DGFINS_OUT=${gfins_version_cpp}
          -P ${CMAKE_CURRENT_LIST_DIR}/GfinsVersionStamp.cmake
  BYPRODUCTS ${gfins_version_cpp}
  COMMENT "gfins: git revision for --version"
  VERBATIM)
add_library(gfins_version STATIC ${gfins_version_cpp})
add_library(gfins::version ALIAS gfins_version)
add_dependencies(gfins_version gfins_version_stamp)
# The header is a std-only vocabulary header beside status/ and sample/ (nav_core/include).
target_include_directories(gfins_version PUBLIC ${PROJECT_SOURCE_DIR}/nav_core/include)
