# Install-time part of cmake/GfinsInstall.cmake (component board): the firmware's configuration,
# state folder, systemd unit and udev rule. It runs inside `cmake --install` / CPack, where
# CMAKE_INSTALL_PREFIX is the prefix of THIS installation (`--prefix P`, or /usr for the Debian
# packages), not the one the build tree was configured with; so one build tree (host-release)
# serves both a relocatable install and the packages.
#
#   prefix /usr (the packages): the Debian places (FHS): /etc/gfins/gfins-fw.toml, /var/lib/gfins,
#                               /lib/systemd/system/gfins-fw.service, /lib/udev/rules.d/
#   any other prefix P:         everything under P: P/etc/gfins, P/var/lib/gfins,
#                               P/lib/systemd/system, P/lib/udev/rules.d
#
# The unit names the installed program and configuration by absolute path, so it is configured
# here too, for the prefix being installed. DESTDIR (CPack stages with it) is honoured by
# file(INSTALL). Inputs, set by the install(CODE) that includes this file: gfins_fw_config,
# gfins_service_in, gfins_udev_rules, gfins_stage_dir (a folder of the build tree for the
# configured unit, as install_manifest.txt is written into the build tree).
cmake_minimum_required(VERSION 3.25)

if(CMAKE_INSTALL_PREFIX MATCHES "^/usr/?$")
  set(gfins_conf_dest /etc/gfins)
  set(gfins_state_dest /var/lib/gfins)
  set(gfins_unit_dest /lib/systemd/system)
  set(gfins_udev_dest /lib/udev/rules.d)
  set(gfins_prefix /usr)
else()
  string(REGEX REPLACE "/+$" "" gfins_prefix "${CMAKE_INSTALL_PREFIX}")
  set(gfins_conf_dest ${gfins_prefix}/etc/gfins)
  set(gfins_state_dest ${gfins_prefix}/var/lib/gfins)
  set(gfins_unit_dest ${gfins_prefix}/lib/systemd/system)
  set(gfins_udev_dest ${gfins_prefix}/lib/udev/rules.d)
endif()

# The unit's @...@ values (packaging/gfins-fw.service.in).
set(GFINS_FULL_BINDIR ${gfins_prefix}/bin)
set(GFINS_FULL_CONFDIR ${gfins_conf_dest})
set(GFINS_DOC_DIR ${gfins_prefix}/share/doc/gfins-fw)
# One staging folder per prefix: two installs of the same tree into different prefixes (the
# install test does that) never share a configured unit.
string(MD5 gfins_prefix_hash "${gfins_prefix}")
set(gfins_unit_file ${gfins_stage_dir}/${gfins_prefix_hash}/gfins-fw.service)
configure_file(${gfins_service_in} ${gfins_unit_file} @ONLY)

file(INSTALL DESTINATION ${gfins_conf_dest} TYPE FILE FILES ${gfins_fw_config})
file(INSTALL DESTINATION ${gfins_unit_dest} TYPE FILE FILES ${gfins_unit_file})
file(INSTALL DESTINATION ${gfins_udev_dest} TYPE FILE FILES ${gfins_udev_rules})
# The calibration file's folder, empty (what install(DIRECTORY DESTINATION d) generates).
file(INSTALL DESTINATION ${gfins_state_dest} TYPE DIRECTORY FILES "")
