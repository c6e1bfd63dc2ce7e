# Installation and Debian packages (docs/deploy.md).
#
# `cmake --install <build> [--prefix P]` puts the programs in P/bin, the scenarios in
# P/share/gfins/scenarios (and P/share/gfins-fw/scenarios, the firmware's copy), the plot scripts
# in P/share/gfins/scripts, example inputs in P/share/gfins/examples and the documentation in
# P/share/doc/gfins-*. The programs find them relative to their own location (docs/install.md).
# The firmware's board files (configuration, state folder, systemd unit, udev rule) are placed
# when installing, by cmake/GfinsInstallBoardFiles.cmake, from the prefix of that installation:
# with prefix /usr (what CPack uses for the packages) their Debian places, /etc/gfins/gfins-fw.toml,
# /var/lib/gfins, /lib/systemd/system/gfins-fw.service, /lib/udev/rules.d/60-gfins-fw.rules;
# with any other prefix P, under P (P/etc/gfins, ...). So the layout does not depend on the
# CMAKE_INSTALL_PREFIX a tree was configured with: `cmake --install build/host-release --prefix P`
# and the packages made from the same host-release tree both come out right.
#
# `cpack --config <build>/CPackConfig.cmake` then makes one .deb per component:
#   gfins-fw     (component board): the firmware, its configuration, unit and udev rule
#   gfins-tools  (component tools): gfins-can and the other host programs, scenarios, scripts
# for the architecture of the build (amd64, arm64 or armhf), always installed under /usr.
include(GNUInstallDirs)

set(GFINS_PKG_DIR ${PROJECT_SOURCE_DIR}/packaging)
# The prefix of the Debian packages, whatever the build tree's CMAKE_INSTALL_PREFIX.
set(gfins_deb_prefix /usr)

# --- data: the same layout in the build tree ---------------------------------------------------
# The programs find their data relative to their own executable (host_sim/include/gfins/host_sim/
# data_paths.hpp): PREFIX/share/gfins/<scenarios|scripts|examples> for PREFIX one to three levels
# above the program's folder. An installed program in P/bin finds P/share/gfins; a program of the
# build tree (build/<preset>/<folder>/<program>) finds build/<preset>/share/gfins, which holds
# links to the sources made here. No path of the source or build tree is compiled into a program.
# The example inputs (a calibration CSV, a candump log) are the tests' golden files.
set(gfins_examples
    ${PROJECT_SOURCE_DIR}/tests/golden/paper_tables_4_5.csv  # gfins-calibrate --means (Tables 4/5)
    ${PROJECT_SOURCE_DIR}/tests/golden/can/clean.log)        # gfins-can decode / plot
set(gfins_build_share ${PROJECT_BINARY_DIR}/share/gfins)
file(MAKE_DIRECTORY ${gfins_build_share}/examples)
file(CREATE_LINK ${PROJECT_SOURCE_DIR}/host_sim/scenarios ${gfins_build_share}/scenarios SYMBOLIC)
file(CREATE_LINK ${PROJECT_SOURCE_DIR}/scripts ${gfins_build_share}/scripts SYMBOLIC)
foreach(f IN LISTS gfins_examples)
  get_filename_component(n ${f} NAME)
  file(CREATE_LINK ${f} ${gfins_build_share}/examples/${n} SYMBOLIC)
endforeach()

# --- board: the firmware ---------------------------------------------------------------------
set(gfins_components "")
if(TARGET gfins-fw)
  list(APPEND gfins_components board)
  install(TARGETS gfins-fw RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT board)
  set(gfins_default_config ${PROJECT_SOURCE_DIR}/firmware/app/gfins-fw.toml)
  if(NOT EXISTS ${gfins_default_config})
    message(FATAL_ERROR "gfins-fw is built but ${gfins_default_config} (its default "
                        "configuration, installed as /etc/gfins/gfins-fw.toml) is missing")
  endif()
  # Configuration, state folder, unit, udev rule: placed at install time from the install prefix
  # (see the top of this file).
  install(CODE "set(gfins_fw_config [[${gfins_default_config}]])
set(gfins_service_in [[${GFINS_PKG_DIR}/gfins-fw.service.in]])
set(gfins_udev_rules [[${GFINS_PKG_DIR}/60-gfins-fw.rules]])
set(gfins_stage_dir [[${PROJECT_BINARY_DIR}/packaging/install]])
include([[${PROJECT_SOURCE_DIR}/cmake/GfinsInstallBoardFiles.cmake]])"
          COMPONENT board)
  install(FILES docs/deploy.md DESTINATION ${CMAKE_INSTALL_DATADIR}/doc/gfins-fw COMPONENT board)
  # gfins-fw --sim NAME needs the scenarios without the host tools: the package carries its own
  # copy in share/gfins-fw/scenarios (gfins-tools has share/gfins/scenarios; two folders, so the
  # two packages never own the same file). The program looks in share/gfins first. A gfins-fw
  # without the simulated board (GFINS_SIM_BOARD=OFF: the Linux board presets) needs none.
  if(GFINS_SIM_BOARD)
    install(DIRECTORY host_sim/scenarios/ DESTINATION ${CMAKE_INSTALL_DATADIR}/gfins-fw/scenarios
            COMPONENT board FILES_MATCHING PATTERN "*.toml")
  endif()
endif()

# --- tools: host programs, scenarios, plot scripts, documentation ----------------------------
set(gfins_tool_targets "")
foreach(t IN ITEMS gfins-can gfins-can-gen gfins-sim gfins-calibrate gfins-replay)
  if(TARGET ${t})
    list(APPEND gfins_tool_targets ${t})
  endif()
endforeach()
if(gfins_tool_targets)
  list(APPEND gfins_components tools)
  install(TARGETS ${gfins_tool_targets} RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR}
          COMPONENT tools)
  install(DIRECTORY host_sim/scenarios/ DESTINATION ${CMAKE_INSTALL_DATADIR}/gfins/scenarios
          COMPONENT tools FILES_MATCHING PATTERN "*.toml")
  file(GLOB gfins_plot_scripts CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/scripts/*.py)
  # plot_common.py is a module the scripts import from their folder, not a program.
  list(FILTER gfins_plot_scripts EXCLUDE REGEX "/plot_common\\.py$")
  install(PROGRAMS ${gfins_plot_scripts} DESTINATION ${CMAKE_INSTALL_DATADIR}/gfins/scripts
          COMPONENT tools)
  install(FILES scripts/plot_common.py DESTINATION ${CMAKE_INSTALL_DATADIR}/gfins/scripts
          COMPONENT tools)
  install(FILES ${gfins_examples} DESTINATION ${CMAKE_INSTALL_DATADIR}/gfins/examples
          COMPONENT tools)
  install(DIRECTORY docs/ DESTINATION ${CMAKE_INSTALL_DATADIR}/doc/gfins-tools COMPONENT tools
          FILES_MATCHING PATTERN "*.md" PATTERN "*.png")
  install(FILES README.md DESTINATION ${CMAKE_INSTALL_DATADIR}/doc/gfins-tools COMPONENT tools)
endif()

# --- manual pages: each program's --help as a man page, made at build time --------------------
# help2man (Debian package help2man) runs the program; a cross-built one runs through the
# toolchain's emulator (CMAKE_CROSSCOMPILING_EMULATOR, qemu-user) by a wrapper script of the
# program's name. Without help2man (or a cross build without an emulator) there are none, and
# scripts/package.sh, which needs them, refuses to package.
find_program(GFINS_HELP2MAN help2man)
set(gfins_man_ok FALSE)
if(GFINS_HELP2MAN AND (NOT CMAKE_CROSSCOMPILING OR CMAKE_CROSSCOMPILING_EMULATOR))
  set(gfins_man_ok TRUE)
elseif(gfins_components)
  message(STATUS "gfins: no manual pages (help2man not found, or a cross build without an "
                 "emulator): apt-get install help2man")
endif()
function(gfins_man_page target component summary see_also)
  set(dir ${PROJECT_BINARY_DIR}/man)
  set(run $<TARGET_FILE:${target}>)
  if(CMAKE_CROSSCOMPILING)
    list(JOIN CMAKE_CROSSCOMPILING_EMULATOR " " emulator)
    file(GENERATE OUTPUT ${dir}/run/${target}
         CONTENT "#!/bin/sh\nexec ${emulator} $<TARGET_FILE:${target}> \"$@\"\n"
         FILE_PERMISSIONS OWNER_READ OWNER_WRITE OWNER_EXECUTE GROUP_READ GROUP_EXECUTE
                          WORLD_READ WORLD_EXECUTE)
    set(run ${dir}/run/${target})
  endif()
  file(WRITE ${dir}/${target}.h2m "[SEE ALSO]\n${see_also}\n")
  add_custom_command(
    OUTPUT ${dir}/${target}.1.gz
    COMMAND ${GFINS_HELP2MAN} --no-info --no-discard-stderr --version-string=${PROJECT_VERSION}
            --name=${summary} --include=${dir}/${target}.h2m --output=${dir}/${target}.1 ${run}
    COMMAND gzip -9n -f ${dir}/${target}.1
    DEPENDS ${target} ${dir}/${target}.h2m VERBATIM)
  add_custom_target(gfins_man_${target} ALL DEPENDS ${dir}/${target}.1.gz)
  add_dependencies(gfins_man_${component} gfins_man_${target})
  install(FILES ${dir}/${target}.1.gz DESTINATION ${CMAKE_INSTALL_MANDIR}/man1
          COMPONENT ${component})
endfunction()
if(gfins_man_ok)
  foreach(c IN LISTS gfins_components)
    add_custom_target(gfins_man_${c})
  endforeach()
  set(gfins_board_docs "The deployment guide: /usr/share/doc/gfins-fw/deploy.md (docs/deploy.md \
of the source tree); the CAN interface, the configuration keys and the simulation: \
docs/can-interface.md, docs/firmware.md, docs/simulation.md (also in /usr/share/doc/gfins-tools).")
  set(gfins_tools_docs "The documentation in /usr/share/doc/gfins-tools (docs/ of the source \
tree): README.md, simulation.md, replay.md, calibration.md, can-interface.md.")
  if(TARGET gfins-fw)
    gfins_man_page(gfins-fw board "gyro-free inertial navigation firmware" "${gfins_board_docs}")
  endif()
  set(gfins_tool_summaries
      "gfins-can=decode, plot and command the gfins CAN interface"
      "gfins-can-gen=generate the gfins DBC, ICD tables, bus budget and synthetic CAN logs"
      "gfins-sim=simulate the gyro-free INS: scenarios, Monte-Carlo, covariance"
      "gfins-calibrate=compute a gfins calibration file from pose means or recordings"
      "gfins-replay=navigate, print or average a gfins raw-sample recording")
  foreach(entry IN LISTS gfins_tool_summaries)
    string(FIND "${entry}" "=" eq)
    string(SUBSTRING "${entry}" 0 ${eq} t)
    math(EXPR from "${eq} + 1")
    string(SUBSTRING "${entry}" ${from} -1 summary)
    if(TARGET ${t})
      gfins_man_page(${t} tools "${summary}" "${gfins_tools_docs}")
    endif()
  endforeach()
endif()

# --- Debian packages (CPack DEB) ---------------------------------------------------------------
if(NOT gfins_components)
  return()
endif()
# Debian's name for the target architecture (cross builds set CMAKE_SYSTEM_PROCESSOR).
if(CMAKE_SYSTEM_PROCESSOR MATCHES "^(aarch64|arm64)$")
  set(gfins_deb_arch arm64)
elseif(CMAKE_SYSTEM_PROCESSOR MATCHES "^arm")
  set(gfins_deb_arch armhf)
elseif(CMAKE_SYSTEM_PROCESSOR MATCHES "^(x86_64|AMD64|amd64)$")
  set(gfins_deb_arch amd64)
else()
  set(gfins_deb_arch ${CMAKE_SYSTEM_PROCESSOR})
endif()

# Per-package copyright and a compressed changelog, as Debian policy §12.5 and §12.7 ask.
foreach(c IN LISTS gfins_components)
  if(c STREQUAL board)
    set(pkg gfins-fw)
  else()
    set(pkg gfins-tools)
  endif()
  install(FILES ${GFINS_PKG_DIR}/copyright DESTINATION ${CMAKE_INSTALL_DATADIR}/doc/${pkg}
          COMPONENT ${c})
  set(gz ${PROJECT_BINARY_DIR}/packaging/${pkg}/changelog.gz)
  add_custom_command(OUTPUT ${gz}
                     COMMAND ${CMAKE_COMMAND} -E make_directory ${PROJECT_BINARY_DIR}/packaging/${pkg}
                     COMMAND gzip -9n -c ${GFINS_PKG_DIR}/changelog > ${gz}
                     DEPENDS ${GFINS_PKG_DIR}/changelog VERBATIM)
  add_custom_target(gfins_changelog_${c} ALL DEPENDS ${gz})
  install(FILES ${gz} DESTINATION ${CMAKE_INSTALL_DATADIR}/doc/${pkg} COMPONENT ${c})
endforeach()

# What the packages hold and nothing else (scripts/package.sh builds this, not the tests).
set(gfins_package_deps ${gfins_tool_targets})
if(TARGET gfins-fw)
  list(APPEND gfins_package_deps gfins-fw)
endif()
foreach(c IN LISTS gfins_components)
  list(APPEND gfins_package_deps gfins_changelog_${c})
  if(gfins_man_ok)
    list(APPEND gfins_package_deps gfins_man_${c})
  endif()
endforeach()
add_custom_target(gfins_package_programs DEPENDS ${gfins_package_deps})

set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME gfins)
# Empty: each package's first description line is its summary (CPackDeb would otherwise put
# the project's description in front of every component's).
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "")
set(CPACK_PACKAGE_VENDOR "gfins")
set(CPACK_PACKAGE_CONTACT "gfins maintainers <maintainers@users.noreply.h-seed-37f600bd.example>")
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
# DESTDIR staging: the install scripts run with CMAKE_INSTALL_PREFIX=/usr (the package's own
# prefix; with CPACK_SET_DESTDIR, CPack takes it from CPACK_INSTALL_PREFIX, which would default to
# the build tree's prefix, /usr/local for host-release), which is what puts the board files in
# their Debian places (GfinsInstallBoardFiles.cmake).
set(CPACK_SET_DESTDIR ON)
set(CPACK_INSTALL_PREFIX ${gfins_deb_prefix})
set(CPACK_PACKAGING_INSTALL_PREFIX ${gfins_deb_prefix})
set(CPACK_COMPONENTS_ALL ${gfins_components})
set(CPACK_DEB_COMPONENT_INSTALL ON)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_ARCHITECTURE ${gfins_deb_arch})
set(CPACK_DEBIAN_PACKAGE_SECTION science)
set(CPACK_DEBIAN_PACKAGE_PRIORITY optional)
set(CPACK_STRIP_FILES ON)
set(CPACK_DEBIAN_PACKAGE_GENERATE_SHLIBS OFF)
# dpkg-shlibdeps derives the library dependencies; for a cross build it needs the target's
# objdump and the multiarch packages' shlibs (scripts/install-cross-deps.sh installs them).
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)

set(CPACK_DEBIAN_BOARD_PACKAGE_NAME gfins-fw)
set(CPACK_DEBIAN_BOARD_DESCRIPTION
    "gyro-free inertial navigation firmware for a Linux board
Reads six accelerometers through an ADS131M06 ADC (spidev and a GPIO
data-ready line), computes attitude, velocity and position without a
gyroscope and publishes them on SocketCAN. Runs as the systemd service
gfins-fw (Type=notify, watchdog, restart on failure) under its own user;
configuration in /etc/gfins, calibration in /var/lib/gfins.")
set(CPACK_DEBIAN_BOARD_PACKAGE_DEPENDS "adduser, init-system-helpers (>= 1.52)")
# The configuration is a conffile: dpkg keeps the administrator's edits over updates.
# (/etc/gfins: the place GfinsInstallBoardFiles.cmake gives it under the package prefix /usr)
file(WRITE ${PROJECT_BINARY_DIR}/packaging/gfins-fw/conffiles "/etc/gfins/gfins-fw.toml\n")
set(CPACK_DEBIAN_BOARD_PACKAGE_CONTROL_EXTRA
    "${GFINS_PKG_DIR}/deb/postinst;${GFINS_PKG_DIR}/deb/prerm;${GFINS_PKG_DIR}/deb/postrm;${PROJECT_BINARY_DIR}/packaging/gfins-fw/conffiles")
set(CPACK_DEBIAN_BOARD_PACKAGE_CONTROL_STRICT_PERMISSION ON)

set(CPACK_DEBIAN_TOOLS_PACKAGE_NAME gfins-tools)
set(CPACK_DEBIAN_TOOLS_DESCRIPTION
    "host tools of the gfins gyro-free inertial navigation system
gfins-can decodes the firmware's CAN frames (live SocketCAN or candump
logs); gfins-sim simulates trajectories through the sensor model and the
navigation core; gfins-calibrate computes a calibration file. Includes the
scenario files and the plot scripts.")
set(CPACK_DEBIAN_TOOLS_PACKAGE_RECOMMENDS "python3, python3-matplotlib, python3-numpy, can-utils")

include(CPack)
