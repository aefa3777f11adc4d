# What `cmake --install` places, and the Debian package CPack makes of it (README, "On a kiosk").
#
#   cmake --build build --target basalt && cmake --install build       the files, under the prefix
#   (cd build && cpack -G DEB)                                          basalt_VERSION_ARCH.deb
#
# With the default prefix, /usr:
#   bin/basalt                                 the program (the unit's ExecStart)
#   lib/<multiarch>/basalt/libbasalt_oiio.so   the OpenImageIO module (media/image_io.cpp finds it)
#   lib/systemd/system/basalt.service          the kiosk service
#   lib/udev/rules.d/70-basalt.rules           device access for the service user
#   lib/sysusers.d/basalt.conf                 the service user "basalt" and its groups
#   lib/tmpfiles.d/basalt.conf                 /srv/basalt (the show) and /etc/basalt (the token)
#   share/basalt/shows/                        the example shows and the manifest reference
#   share/basalt/systemd/network-online.conf   a drop-in for a status server beyond loopback
#   share/man/man1/basalt.1                    the manual page
#   share/doc/basalt/                          README, ARCHITECTURE, ENV_VARS, the script reference
# Nothing here needs a target other than `basalt` (and the module it brings): `make run`'s build
# is enough to install and to package.

install(TARGETS basalt RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(TARGETS basalt_oiio LIBRARY DESTINATION ${BASALT_MODULE_INSTALL_DIR})

# systemd and udev read these folders under /usr (and /lib, the same on a merged-/usr Debian).
set(BASALT_SYSTEMD_UNIT_DIR lib/systemd/system)
install(FILES configs/systemd/basalt.service DESTINATION ${BASALT_SYSTEMD_UNIT_DIR})
install(FILES configs/udev/70-basalt.rules DESTINATION lib/udev/rules.d)
install(FILES configs/systemd/basalt-sysusers.conf DESTINATION lib/sysusers.d RENAME basalt.conf)
install(FILES configs/systemd/basalt-tmpfiles.conf DESTINATION lib/tmpfiles.d RENAME basalt.conf)
install(FILES configs/systemd/network-online.conf DESTINATION ${CMAKE_INSTALL_DATADIR}/basalt/systemd)
install(DIRECTORY configs/shows/ DESTINATION ${CMAKE_INSTALL_DATADIR}/basalt/shows)

# The manual page names the installed paths: filled in at configure time, so installing needs no
# build step.
configure_file(docs/basalt.1.in ${PROJECT_BINARY_DIR}/basalt.1 @ONLY)
install(FILES ${PROJECT_BINARY_DIR}/basalt.1 DESTINATION ${CMAKE_INSTALL_MANDIR}/man1)
install(FILES README.md ARCHITECTURE.md ENV_VARS.md docs/script-reference.md DESTINATION ${CMAKE_INSTALL_DOCDIR})
install(FILES configs/README.md DESTINATION ${CMAKE_INSTALL_DOCDIR} RENAME configs.md)
# Debian keeps a package's licence as its copyright file.
install(FILES LICENSE DESTINATION ${CMAKE_INSTALL_DOCDIR} RENAME copyright)

# ---- The Debian package -------------------------------------------------------------------------
# Depends: the shared libraries the program and its module link (dpkg-shlibdeps finds them and
# their packages), and what Basalt opens at run time without linking it: Mesa's EGL and DRI
# drivers (through glvnd), and the GStreamer plugins that play, decode and record movies and play
# their sound (scripts/packages.txt says which plugin does what). Nothing of the build or the tests.
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME basalt)
set(CPACK_PACKAGE_VENDOR "Basalt contributors")
set(CPACK_PACKAGE_CONTACT "Basalt contributors <dev@basalt.invalid>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "runtime for unattended 3D and video installations")
set(CPACK_PACKAGE_DESCRIPTION
    "Basalt plays shows on a display node: a fullscreen OpenGL ES renderer fed by dial boxes,
cameras, capture cards and video files, run as a sandboxed systemd service that boots
straight into the show, with a status and control server.")
set(CPACK_RESOURCE_FILE_LICENSE ${PROJECT_SOURCE_DIR}/LICENSE)
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_STRIP_FILES ON)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION video)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_DEBIAN_PACKAGE_DEPENDS
    "systemd, libegl-mesa0, libgl1-mesa-dri, gstreamer1.0-plugins-base, gstreamer1.0-plugins-good, gstreamer1.0-plugins-bad, gstreamer1.0-plugins-ugly, gstreamer1.0-libav, gstreamer1.0-alsa")
set(CPACK_DEBIAN_PACKAGE_CONTROL_EXTRA
    ${PROJECT_SOURCE_DIR}/configs/debian/postinst ${PROJECT_SOURCE_DIR}/configs/debian/prerm
    ${PROJECT_SOURCE_DIR}/configs/debian/postrm)
set(CPACK_DEBIAN_PACKAGE_CONTROL_STRICT_PERMISSION ON)
include(CPack)
