# What `cmake --install` puts where (FHS), and the Debian package CPack makes
# of it: `cpack -G DEB` in the build tree (docs/deployment.md). Included by
# the top-level CMakeLists.txt after the syncplc target.
#
#   PREFIX/bin/syncplc                         the command
#   PREFIX/share/syncplc/hmi/                  the HMI's built files (hmi_web/dist)
#   PREFIX/share/doc/syncplc/                  blocks.md (syncplc blocks --markdown), deployment.md
#   PREFIX/lib/systemd/system/syncplc.service  the unit (ExecStart names PREFIX/bin/syncplc)
#   PREFIX/lib/udev/rules.d/60-syncplc.rules   /dev/cpu_dma_latency for the group syncplc
#
# The package's prefix is /usr; `cmake --install` keeps CMAKE_INSTALL_PREFIX
# (/usr/local by default: systemd reads /usr/local/lib/systemd/system too).

set(SYNCPLC_SYSTEMD_UNIT_DIR "lib/systemd/system" CACHE STRING "where the systemd unit goes (relative to the prefix)")
set(SYNCPLC_UDEV_RULES_DIR "lib/udev/rules.d" CACHE STRING "where the udev rule goes (relative to the prefix)")

install(TARGETS syncplc RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
# The HMI is built by scripts/build_hmi.sh, not by CMake: its files are taken
# as they are at install time. Without them the install stops here, rather
# than making a package whose HMI says "not built".
install(CODE "
  if(NOT EXISTS \"${CMAKE_CURRENT_SOURCE_DIR}/hmi_web/dist/index.html\")
    message(FATAL_ERROR \"hmi_web/dist is not built: run scripts/build_hmi.sh before installing or packaging\")
  endif()")
install(DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR}/hmi_web/dist/ DESTINATION ${SYNCPLC_HMI_INSTALL_DIR}
        PATTERN "*.map" EXCLUDE)
install(FILES ${CMAKE_CURRENT_SOURCE_DIR}/docs/blocks.md ${CMAKE_CURRENT_SOURCE_DIR}/docs/deployment.md
        DESTINATION ${CMAKE_INSTALL_DOCDIR})
install(FILES ${CMAKE_CURRENT_SOURCE_DIR}/packaging/60-syncplc.rules DESTINATION ${SYNCPLC_UDEV_RULES_DIR})
# The unit names the binary and the documentation by their installed paths, known only at install time
# (cpack installs into /usr, `cmake --install --prefix P` into P): written
# then, from packaging/syncplc.service.in.
install(CODE "
  set(SYNCPLC_BINDIR \"\${CMAKE_INSTALL_PREFIX}/${CMAKE_INSTALL_BINDIR}\")
  set(SYNCPLC_DOCDIR \"\${CMAKE_INSTALL_PREFIX}/${CMAKE_INSTALL_DOCDIR}\")
  configure_file(\"${CMAKE_CURRENT_SOURCE_DIR}/packaging/syncplc.service.in\"
                 \"${CMAKE_CURRENT_BINARY_DIR}/packaging/syncplc.service\" @ONLY)
  file(INSTALL DESTINATION \"\${CMAKE_INSTALL_PREFIX}/${SYNCPLC_SYSTEMD_UNIT_DIR}\" TYPE FILE
       FILES \"${CMAKE_CURRENT_BINARY_DIR}/packaging/syncplc.service\")")

# The Debian package: syncplc_VERSION_ARCH.deb.
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME syncplc)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "soft-PLC for synchronized multi-axis motion")
set(CPACK_PACKAGE_DESCRIPTION
    "An IEC 61131-3 function-block runtime with a cyclic, scan-based scheduler,\nModbus TCP server and client, an HTTP API and a web HMI. The systemd unit\nsyncplc.service starts the PLC's boot project.")
set(SYNCPLC_PACKAGE_MAINTAINER "Seed c3dac3c9 maintainers <maintainers@users.noreply.h-seed-c3dac3c9.example>"
    CACHE STRING "the Debian package's Maintainer field")
set(CPACK_PACKAGE_CONTACT "${SYNCPLC_PACKAGE_MAINTAINER}")
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION misc)
set(CPACK_DEBIAN_PACKAGE_PRIORITY optional)
# The shared libraries' packages (libmodbus5, libsodium23, libssl3, ...) from
# dpkg-shlibdeps, so apt-get install ./syncplc_*.deb brings them; adduser
# for the system user the postinst makes, procps for the unit's
# ExecReload=/bin/kill (not an essential package).
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_DEBIAN_PACKAGE_DEPENDS "adduser, procps")
# Debug information stays in the build tree; the package's binary is stripped.
set(CPACK_STRIP_FILES ON)
set(CPACK_DEBIAN_PACKAGE_CONTROL_EXTRA
    ${CMAKE_CURRENT_SOURCE_DIR}/packaging/postinst ${CMAKE_CURRENT_SOURCE_DIR}/packaging/prerm
    ${CMAKE_CURRENT_SOURCE_DIR}/packaging/postrm)
set(CPACK_DEBIAN_PACKAGE_CONTROL_STRICT_PERMISSION ON)
include(CPack)
