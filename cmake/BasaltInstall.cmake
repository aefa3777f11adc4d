# What `cmake --install` places (README, "On a kiosk").
#
#   cmake --build build --target basalt && cmake --install build       the files, under the prefix
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
# is enough to install.

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
