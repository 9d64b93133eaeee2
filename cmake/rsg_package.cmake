# make package: the Debian package rsg_<version>_<arch>.deb, by CPack's DEB generator (docs/service.md).
#
# What the .deb holds is the install component `runtime` (the tools, profiles, IDL, dissector: what
# `make install` installs too) plus `deb`, which only a component install takes (EXCLUDE_FROM_ALL,
# so that `make install PREFIX=...` never writes to /etc or the system's unit directory): the systemd
# template unit, the example configuration as a conffile, the realtime drop-in, the manual pages and
# Debian's copyright and changelog files. The headers, static libraries and CMake package (component
# `dev`) are not packaged: an rsg-dev's Depends would be -dev packages that no tool computes.
#
# The version is the project's (project(rsg VERSION ...)), the Depends are dpkg-shlibdeps' reading
# of the binaries, plus docker/packages/run.txt, the one list of what the tools need beyond their
# libraries (rsg_view's Chart.js).

# Debian's man pages: help2man on each tool's --help at build time (cmake/rsg_man_page.cmake), so
# that a page cannot say what the tool does not. `make package` builds the rsg_man target.
# RSG_TOOLS: the installed tools (CMakeLists.txt).
set(RSG_PROFILES_INSTALLED ${CMAKE_INSTALL_FULL_DATADIR}/rsg/xml_profiles)
find_program(HELP2MAN help2man)
set(man_pages)
foreach(tool ${RSG_TOOLS})
  if(TARGET ${tool})
    set(page ${CMAKE_BINARY_DIR}/man/${tool}.1.gz)
    if(HELP2MAN)
      add_custom_command(OUTPUT ${page}
        COMMAND ${CMAKE_COMMAND} -DTOOL=$<TARGET_FILE:${tool}> -DVERSION=${PROJECT_VERSION} -DHELP2MAN=${HELP2MAN}
                -DOUT=${page} -DPROFILES=${RSG_PROFILES_INSTALLED} -P ${PROJECT_SOURCE_DIR}/cmake/rsg_man_page.cmake
        DEPENDS ${tool} ${PROJECT_SOURCE_DIR}/cmake/rsg_man_page.cmake
        COMMENT "help2man ${tool}")
    endif()
    list(APPEND man_pages ${page})
  endif()
endforeach()
if(HELP2MAN)
  add_custom_target(rsg_man DEPENDS ${man_pages})
else()
  add_custom_target(rsg_man COMMAND ${CMAKE_COMMAND} -E echo "help2man is missing: apt-get install help2man"
                            COMMAND ${CMAKE_COMMAND} -E false)
endif()
install(FILES ${man_pages} DESTINATION ${CMAKE_INSTALL_MANDIR}/man1 COMPONENT deb EXCLUDE_FROM_ALL)

# The systemd unit where the distribution's systemd looks for packaged units: /lib/systemd/system
# on Debian 12 (its systemd.pc says so), /usr/lib/systemd/system on Debian 13.
find_package(PkgConfig QUIET)
if(PkgConfig_FOUND)
  pkg_get_variable(RSG_SYSTEMD_UNIT_DIR systemd systemdsystemunitdir)
endif()
if(NOT RSG_SYSTEMD_UNIT_DIR)
  set(RSG_SYSTEMD_UNIT_DIR /lib/systemd/system)
endif()
set(RSG_SYSTEMD_UNIT_DIR ${RSG_SYSTEMD_UNIT_DIR} CACHE PATH "Where the package installs rsg-gateway@.service")
install(FILES deploy/systemd/rsg-gateway@.service DESTINATION ${RSG_SYSTEMD_UNIT_DIR} COMPONENT deb EXCLUDE_FROM_ALL)
install(FILES deploy/systemd/realtime.conf DESTINATION ${CMAKE_INSTALL_DATADIR}/rsg/systemd COMPONENT deb
        EXCLUDE_FROM_ALL)
# The example configuration: /etc/rsg/robot1.yaml, a conffile (dpkg keeps the operator's edits on upgrade).
install(FILES deploy/systemd/robot1.yaml DESTINATION /etc/rsg COMPONENT deb EXCLUDE_FROM_ALL)
# ... and as it was shipped, to start a second robot's from.
install(FILES deploy/systemd/robot1.yaml DESTINATION ${CMAKE_INSTALL_DATADIR}/rsg/examples COMPONENT deb EXCLUDE_FROM_ALL)

# Debian's copyright file (machine-readable, pointing at the system's Apache-2.0 text rather than
# holding it) and changelog: a native package's is /usr/share/doc/rsg/changelog.gz, with the user's
# changelog beside it.
set(pkg_dir ${CMAKE_BINARY_DIR}/deb)
file(WRITE ${pkg_dir}/copyright
  "Format: https://www.debian.org/doc/packaging-manuals/copyright-format/1.0/\n"
  "Upstream-Name: rsg\n\n"
  "Files: *\nCopyright: 2026 the rsg authors\nLicense: Apache-2.0\n\n"
  "License: Apache-2.0\n"
  " On Debian systems, the full text of the Apache License, Version 2.0 is in\n"
  " /usr/share/common-licenses/Apache-2.0.\n")
# The Maintainer field: whoever builds the package answers for it. -DRSG_PACKAGE_MAINTAINER="Name <address>",
# else Debian's DEBFULLNAME and DEBEMAIL (as dch reads them), else the checkout's git user.name and
# user.email; make package (its rsg_man target) fails rather than ship a made-up address, while a
# plain build configures without one.
if(NOT RSG_PACKAGE_MAINTAINER)
  if(DEFINED ENV{DEBFULLNAME} AND DEFINED ENV{DEBEMAIL})
    set(maintainer "$ENV{DEBFULLNAME} <$ENV{DEBEMAIL}>")
  else()
    execute_process(COMMAND git -C ${PROJECT_SOURCE_DIR} config user.name OUTPUT_VARIABLE git_name
                    OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
    execute_process(COMMAND git -C ${PROJECT_SOURCE_DIR} config user.email OUTPUT_VARIABLE git_email
                    OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
    if(git_name AND git_email)
      set(maintainer "${git_name} <${git_email}>")
    endif()
  endif()
  set(RSG_PACKAGE_MAINTAINER "${maintainer}" CACHE STRING "The Maintainer field of the .deb: Name <address>" FORCE)
endif()
if(RSG_PACKAGE_MAINTAINER MATCHES "^[^<>]+ <[^<>@ ]+@[^<>@ ]+>$")
  add_custom_target(rsg_maintainer_check)
else()
  add_custom_target(rsg_maintainer_check
    COMMAND ${CMAKE_COMMAND} -E echo "make package: the .deb needs a maintainer, 'Name <address>': -DRSG_PACKAGE_MAINTAINER=..., DEBFULLNAME and DEBEMAIL, or git config user.name and user.email (got '${RSG_PACKAGE_MAINTAINER}')"
    COMMAND ${CMAKE_COMMAND} -E false)
endif()
# The date of the changelog entry: the last commit's (SOURCE_DATE_EPOCH when set), so that two builds
# of one commit make the same file.
if(DEFINED ENV{SOURCE_DATE_EPOCH})
  set(changelog_epoch $ENV{SOURCE_DATE_EPOCH})
else()
  execute_process(COMMAND git -C ${PROJECT_SOURCE_DIR} log -1 --format=%ct OUTPUT_VARIABLE changelog_epoch
                  OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
endif()
if(NOT changelog_epoch)
  set(changelog_epoch 0)
endif()
execute_process(COMMAND date -u -R -d @${changelog_epoch} OUTPUT_VARIABLE changelog_date OUTPUT_STRIP_TRAILING_WHITESPACE)
configure_file(${PROJECT_SOURCE_DIR}/deploy/debian/changelog.in ${pkg_dir}/changelog @ONLY)
add_custom_command(OUTPUT ${pkg_dir}/changelog.gz ${pkg_dir}/CHANGELOG.md.gz
  COMMAND gzip -9nc ${pkg_dir}/changelog > ${pkg_dir}/changelog.gz
  COMMAND gzip -9nc ${PROJECT_SOURCE_DIR}/CHANGELOG.md > ${pkg_dir}/CHANGELOG.md.gz
  DEPENDS ${pkg_dir}/changelog ${PROJECT_SOURCE_DIR}/CHANGELOG.md)
# The guides an operator of the service reads, which the unit's Documentation= names: compressed,
# as Debian's policy wants anything of /usr/share/doc over 4 KB.
set(RSG_DEB_GUIDES service troubleshooting configuration operating security)
set(guide_files)
foreach(guide ${RSG_DEB_GUIDES})
  add_custom_command(OUTPUT ${pkg_dir}/${guide}.md.gz
    COMMAND gzip -9nc ${PROJECT_SOURCE_DIR}/docs/${guide}.md > ${pkg_dir}/${guide}.md.gz
    DEPENDS ${PROJECT_SOURCE_DIR}/docs/${guide}.md)
  list(APPEND guide_files ${pkg_dir}/${guide}.md.gz)
endforeach()
add_custom_target(rsg_deb_docs DEPENDS ${pkg_dir}/changelog.gz ${pkg_dir}/CHANGELOG.md.gz ${guide_files})
add_dependencies(rsg_man rsg_deb_docs rsg_maintainer_check)
install(FILES ${pkg_dir}/copyright ${pkg_dir}/changelog.gz ${pkg_dir}/CHANGELOG.md.gz ${guide_files}
        DESTINATION ${CMAKE_INSTALL_DATADIR}/doc/rsg COMPONENT deb EXCLUDE_FROM_ALL)
# The alert rules and the dashboard, for Prometheus' rule_files and Grafana's file provisioning.
install(FILES deploy/prometheus/rsg-alerts.yml DESTINATION ${CMAKE_INSTALL_DATADIR}/rsg/prometheus COMPONENT deb
        EXCLUDE_FROM_ALL)
install(FILES deploy/grafana/rsg-fleet.json DESTINATION ${CMAKE_INSTALL_DATADIR}/rsg/grafana COMPONENT deb
        EXCLUDE_FROM_ALL)

# Maintainer scripts: no system user (the unit has DynamicUser=yes); systemd reloaded, running
# instances restarted on upgrade and stopped on removal; purge removes what systemd made for the
# unit (its StateDirectory), the operator's enablement and drop-ins, and /etc/rsg once empty.
foreach(script postinst prerm postrm)
  configure_file(${PROJECT_SOURCE_DIR}/deploy/debian/${script} ${pkg_dir}/control/${script} COPYONLY)
endforeach()
file(WRITE ${pkg_dir}/control/conffiles "/etc/rsg/robot1.yaml\n")

# What the tools need beyond their shared libraries: docker/packages/run.txt, as the image installs it.
file(STRINGS ${PROJECT_SOURCE_DIR}/docker/packages/run.txt run_packages REGEX "^[a-z0-9]")
list(JOIN run_packages ", " run_depends)

set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME rsg)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_DEB_COMPONENT_INSTALL ON)
set(CPACK_COMPONENTS_ALL runtime deb)
set(CPACK_COMPONENTS_GROUPING ALL_COMPONENTS_IN_ONE)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_NAME rsg)
set(CPACK_DEBIAN_PACKAGE_MAINTAINER ${RSG_PACKAGE_MAINTAINER})
set(CPACK_DEBIAN_PACKAGE_SECTION net)
set(CPACK_DEBIAN_PACKAGE_PRIORITY optional)
set(CPACK_DEBIAN_PACKAGE_HOMEPAGE https://github.com/rsg/rsg)
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "robot-state gateway: UDP frames from a robot to DDS")
# CPack puts the summary first: the description is the extended part only (lines under 80 columns).
set(CPACK_DEBIAN_PACKAGE_DESCRIPTION "rsg_gateway receives a robot's SEND_BUF state frames over UDP, checks
them and publishes them as DDS RobotState samples (Fast DDS), with a
Prometheus metrics endpoint and a systemd template unit,
rsg-gateway@.service, one instance per robot. The package also has the
tools around it: rsg_sim, rsg_echo, rsg_frame, rsg_record, rsg_replay and
rsg_view.")
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_DEBIAN_PACKAGE_DEPENDS "${run_depends}")
set(CPACK_DEBIAN_PACKAGE_CONTROL_EXTRA ${pkg_dir}/control/postinst ${pkg_dir}/control/prerm
    ${pkg_dir}/control/postrm ${pkg_dir}/control/conffiles)
set(CPACK_DEBIAN_PACKAGE_CONTROL_STRICT_PERMISSION ON)
set(CPACK_STRIP_FILES ON)
set(CPACK_PACKAGE_DIRECTORY ${CMAKE_BINARY_DIR}/packages)
include(CPack)
