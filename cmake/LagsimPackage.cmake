# `cpack -G DEB` (in the build directory): lagsim_<version>_<arch>.deb, the files of
# `cmake --install` (cmake/LagsimInstall.cmake) under /usr, in Debian's places:
#   /usr/bin, /usr/include/lagsim, /usr/lib (liblagsim_client.so.<ABI> with its links, the
#   static libraries), /usr/lib/pkgconfig,
#   /usr/lib/python3/dist-packages, /usr/share/lua/5.2, /usr/share/java,
#   /usr/share/lagsim (scenes, .lcm files, examples), /usr/share/man/man1,
#   /usr/lib/systemd/system/lagsimd@.service,
# plus what debhelper would add (cmake/deb/staging.cmake): the man pages gzipped, and
# /usr/share/doc/lagsim/{copyright,changelog.gz}. Depends: the shared libraries of the
# programs (dpkg-shlibdeps) and the table below for what is not ELF. Checked by
# tests/package/ (ctest -L package): contents, lintian, install, run, purge.
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME lagsim)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_VENDOR "lagsim")
set(LAGSIM_DEB_MAINTAINER "lagsim maintainers <maintainers@lagsim.example>" CACHE STRING
    "the .deb's Maintainer field: who builds it (e.g. a lab's admin)")
set(CPACK_PACKAGE_CONTACT "${LAGSIM_DEB_MAINTAINER}")
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)          # lagsim_<version>_<arch>.deb
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "real-time simulation server for Lagrangian models over LCM")
# Debian's extended description (the summary above is its first line). Its list of models
# is the core's table's (lagsim_lists print SOURCE model-titles): the build writes
# <build>/description/description.cmake from the text below (@MODELS@ replaced, paragraphs
# wrapped at 72 columns, cmake/LagsimDescription.cmake), which cpack reads when it runs
# (CPACK_PROJECT_CONFIG_FILE); package_build compares the .deb's Description with the table.
set(LAGSIM_DEB_DESCRIPTION "lagsimd steps @MODELS@ in real time, publishes its joint \
states on LCM channels and takes effort commands from controllers in C, C++, \
Python, Lua, Java or MATLAB/Octave; runs are recorded whole and re-simulated \
bit for bit.
.
This package holds the daemon and its tools, the client library (shared, with \
a kept ABI, and static) with its C and C++ headers and pkg-config file, the \
message types for C, Python, Lua and Java, example controllers, the shipped \
scenes, and a systemd template unit, lagsimd@NAME, that runs \
/etc/lagsim/NAME.yaml as a service.")
file(WRITE ${PROJECT_BINARY_DIR}/description/description.in "${LAGSIM_DEB_DESCRIPTION}")
add_custom_command(OUTPUT ${PROJECT_BINARY_DIR}/description/description.cmake
  COMMAND ${CMAKE_COMMAND} -D LISTS=$<TARGET_FILE:lagsim_lists> -D SOURCE=${PROJECT_SOURCE_DIR}
          -D IN=${PROJECT_BINARY_DIR}/description/description.in
          -D OUT=${PROJECT_BINARY_DIR}/description/description.cmake
          -P ${CMAKE_CURRENT_LIST_DIR}/LagsimDescription.cmake
  DEPENDS lagsim_lists ${CMAKE_CURRENT_LIST_DIR}/LagsimDescription.cmake
          ${PROJECT_BINARY_DIR}/description/description.in
  COMMENT "the package's description, its models from the core's table")
add_custom_target(package_description ALL DEPENDS ${PROJECT_BINARY_DIR}/description/description.cmake)
set(CPACK_PROJECT_CONFIG_FILE ${PROJECT_BINARY_DIR}/description/description.cmake)
set(CPACK_DEBIAN_PACKAGE_SECTION science)
set(CPACK_DEBIAN_PACKAGE_PRIORITY optional)
set(CPACK_STRIP_FILES ON)                         # the programs; debug info stays in the build
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
# liblagsim_client.so.<ABI>: a shlibs file (a program linked against it depends on this
# version or later: the library keeps its ABI within its SONAME) and the ldconfig trigger
set(CPACK_DEBIAN_PACKAGE_GENERATE_SHLIBS ON)
set(CPACK_DEBIAN_PACKAGE_GENERATE_SHLIBS_POLICY ">=")

# What the package needs beyond the programs' shared libraries (found by dpkg-shlibdeps):
# relation # Debian package(s) # for
set(_lagsim_deb_needs
  "Depends # python3 # the Python modules in dist-packages (lagsim_lcm loads liblcm.so.1 with ctypes)"
  "Recommends # gnuplot-nox # lagsim-plot"
  "Recommends # liblcm-bin # lcm-logger and lcm-logplayer, to record and replay the bus"
  "Recommends # lua5.2, liblcm-lua # the Lua 5.2 modules in /usr/share/lua/5.2"
  "Recommends # liblcm-java, default-jre-headless | java-runtime-headless # lagsim_types.jar and lagsim_examples.jar (Java, MATLAB, Octave)"
  "Suggests # liblcm-dev, libglib2.0-dev # C controllers: lagsim-client.pc requires lcm.pc, which needs glib's"
  "Suggests # octave, octave-control # the Octave/MATLAB controllers (dlqr, lqr from octave-control)")
foreach(_rel Depends Recommends Suggests)
  set(_l "")
  foreach(_n ${_lagsim_deb_needs})
    string(REGEX REPLACE " *# *" ";" _f "${_n}")
    list(GET _f 0 _r)
    list(GET _f 1 _p)
    if(_r STREQUAL _rel)
      list(APPEND _l "${_p}")
    endif()
  endforeach()
  string(REPLACE ";" ", " _l "${_l}")
  string(TOUPPER ${_rel} _REL)
  set(CPACK_DEBIAN_PACKAGE_${_REL} "${_l}")
endforeach()

# maintainer scripts: systemd reloaded when it runs; instances stopped on removal; their
# state directories (records written by --log) and enablement links removed on purge
set(CPACK_DEBIAN_PACKAGE_CONTROL_EXTRA ${CMAKE_CURRENT_LIST_DIR}/deb/postinst
    ${CMAKE_CURRENT_LIST_DIR}/deb/prerm ${CMAKE_CURRENT_LIST_DIR}/deb/postrm
    ${CMAKE_CURRENT_LIST_DIR}/deb/triggers)  # ldconfig for liblagsim_client.so
set(CPACK_DEBIAN_PACKAGE_CONTROL_STRICT_PERMISSION TRUE)
# after the install into the staging directory, before the archive is made
set(CPACK_PRE_BUILD_SCRIPTS ${CMAKE_CURRENT_LIST_DIR}/deb/staging.cmake)
set(CPACK_LAGSIM_SOURCE_DIR ${PROJECT_SOURCE_DIR})
set(CPACK_LAGSIM_MAINTAINER "${CPACK_PACKAGE_CONTACT}")
include(CPack)
