# `cmake --install <build> [--prefix /usr/local]`: everything a user of lagsim needs, laid
# out as a Debian tool's files (GNUInstallDirs):
#   bin/                     lagsimd, lagsimctl, lagsim-view, lagsim-log2csv, lagsim-plot,
#                            lagsim-eval, lagsim-sweep and the C example controllers
#                            (each when the build has it)
#   include/lagsim/          lagsim_client.h, lagsim_client.hpp, result.h and the version
#                            header the build writes from version.h.in (the client
#                            library); lagsim.h (the core), lagsim_controller.h,
#                            lagsim_wire.h, lagsim_log.h, lagsim_bus.h, the generated C types
#   lib/                     liblagsim_client.so.<ABI> (SONAME) and .so, liblagsim_client.a;
#                            liblagsim_controller.a, liblagsim_core.a and what they link
#   lib/pkgconfig/           lagsim-client.pc (the client library), lagsim-core.pc (the
#                            core and the C examples' setup, static, no stable ABI)
#   lib/python3.X/dist-packages/   lagsim (lcm-gen types), lagsim_lcm, lagsim_client,
#                            lagsim_controller
#                            (on Debian's sys.path for prefix /usr/local; for prefix /usr,
#                            lib/python3/dist-packages)
#   share/lua/5.2/           lagsim (lcm-gen types), lagsim_lcm, lagsim_controller
#                            (on lua5.2's default path for prefix /usr/local)
#   lib/lua/5.2/             lagsim_client.so, the client library's Lua module (on lua5.2's
#                            default C path for /usr/local and /usr)
#   share/java/              lagsim_types.jar, lagsim_examples.jar
#   share/lagsim/            config/*.yaml, lcmtypes/*.lcm, examples/{python,lua}/,
#                            slurm/lagsim-sweep-array.sh
#   share/lagsim/octave/     the MATLAB/Octave controllers (clients/octave/CMakeLists.txt:
#                            LAGSIM_OCTAVE_INSTALL_DIR)
#   share/man/man1/          a page for each program of bin/
#   lib/systemd/system/      lagsimd@.service (a plant per /etc/lagsim/NAME.yaml)
# The .pc files find their prefix from their own place, so the tree can be moved.
# Included last from the top-level CMakeLists.txt, so every target exists already.
include(GNUInstallDirs)

set(_programs lagsimd lagsimctl lagsim-view lagsim-log2csv lagsim-eval lagsim-sweep
              dipc_lqr lqr_balance manipulator_pd manipulator_ct stick_push)
foreach(t ${_programs})
  if(TARGET ${t})
    install(TARGETS ${t} RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
  endif()
endforeach()
foreach(s server/tools/lagsim-plot)  # scripts, where the tree has them
  if(EXISTS ${PROJECT_SOURCE_DIR}/${s})
    install(PROGRAMS ${PROJECT_SOURCE_DIR}/${s} DESTINATION ${CMAKE_INSTALL_BINDIR})
  endif()
endforeach()

# C: the client library, shared (liblagsim_client.so.<ABI> with its links) and static, its
# headers (lagsim_client.h, lagsim_client.hpp, lagsim/version.h, lagsim/result.h) and
# lagsim-client.pc: the library with a stable ABI, all a controller links. Beside it, the
# static libraries of the core and of the C examples' shared setup (lagsim_controller.h,
# lagsim.h, lagsim_wire.h, ...) and lagsim-core.pc: for building lagsim's own examples
# against an install, without a stable ABI (docs/clients.md, "The ABI").
# (A sanitizer build installs the uninstrumented copy the bindings load: installed Python
# and Lua controllers run in interpreters without a sanitizer runtime; a C program built
# against it with the sanitizers' flags has their runtime itself.)
if(LAGSIM_SANITIZE)
  install(TARGETS lagsim_client_bindings LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR})
else()
  install(TARGETS lagsim_client_shared LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR})
endif()
foreach(t lagsim_client lagsim_controller lagsim_wire lagsim_wire_base lagsim_lcmtypes lagsim_core)
  install(TARGETS ${t} ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
endforeach()
install(FILES ${PROJECT_SOURCE_DIR}/server/include/lagsim/lagsim.h
              ${PROJECT_SOURCE_DIR}/server/include/lagsim/result.h
              ${PROJECT_BINARY_DIR}/include/lagsim/version.h
              ${PROJECT_SOURCE_DIR}/clients/lagsim_client.h
              ${PROJECT_SOURCE_DIR}/clients/lagsim_client.hpp
              ${PROJECT_SOURCE_DIR}/clients/lagsim_controller.h
              ${PROJECT_SOURCE_DIR}/server/wire/lagsim_wire.h
              ${PROJECT_SOURCE_DIR}/server/wire/lagsim_log.h
              ${PROJECT_SOURCE_DIR}/server/wire/lagsim_bus.h
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/lagsim)
install(DIRECTORY ${CMAKE_BINARY_DIR}/lcmtypes/c/lagsim/
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/lagsim FILES_MATCHING PATTERN "*.h")
# pkg-config: the installed files (their prefix from their own place: the tree can be
# moved), and in <build>/pkgconfig the same packages for the build tree, by pkg-config's
# convention for uninstalled packages (NAME-uninstalled.pc, preferred when found; NAME.pc
# there too, the same, for PKG_CONFIG_DISABLE_UNINSTALLED): PKG_CONFIG_PATH=<build>/pkgconfig
# builds a controller against the build tree, which it then runs from (a run path to
# <build>/lib).
foreach(pc lagsim-client lagsim-core)
  configure_file(${CMAKE_CURRENT_LIST_DIR}/${pc}.pc.in ${CMAKE_BINARY_DIR}/pc-install/${pc}.pc @ONLY)
  install(FILES ${CMAKE_BINARY_DIR}/pc-install/${pc}.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
  configure_file(${CMAKE_CURRENT_LIST_DIR}/${pc}-uninstalled.pc.in
                 ${CMAKE_BINARY_DIR}/pc-uninstalled/${pc}.pc.in @ONLY)
  foreach(name ${pc}-uninstalled ${pc})
    file(GENERATE OUTPUT ${CMAKE_BINARY_DIR}/pkgconfig/${name}.pc
         INPUT ${CMAKE_BINARY_DIR}/pc-uninstalled/${pc}.pc.in)
  endforeach()
endforeach()

# Message definitions, scenes, man page.
file(GLOB _lcm ${PROJECT_SOURCE_DIR}/lcmtypes/*.lcm)
install(FILES ${_lcm} DESTINATION ${CMAKE_INSTALL_DATADIR}/lagsim/lcmtypes)
file(GLOB _cfg ${PROJECT_SOURCE_DIR}/config/*.yaml)
install(FILES ${_cfg} DESTINATION ${CMAKE_INSTALL_DATADIR}/lagsim/config)
# lagsim-sweep's Slurm job array (docs/evaluation.md)
install(PROGRAMS ${PROJECT_SOURCE_DIR}/server/tools/slurm/lagsim-sweep-array.sh
        DESTINATION ${CMAKE_INSTALL_DATADIR}/lagsim/slurm)
# one page per program in bin/ (tests/install/check_man.py holds each to its --help), as
# the build wrote it: docs/man/*.1 with its lists generated from the tables (server/lists)
install(FILES ${LAGSIM_MAN_PAGES} DESTINATION ${CMAKE_INSTALL_MANDIR}/man1)

# The systemd template unit lagsimd@NAME (/etc/lagsim/NAME.yaml), naming the lagsimd of
# the prefix it is installed into: made at install time, since `cpack` installs into
# /usr whatever the build was configured with. <prefix>/lib/systemd/system is on
# systemd's unit path for /usr and /usr/local.
# Configured into a directory of its own per destination: `cpack` (into /usr) and a
# `cmake --install --prefix` may run at the same time from one build directory.
install(CODE "set(LAGSIMD \"\${CMAKE_INSTALL_PREFIX}/${CMAKE_INSTALL_BINDIR}/lagsimd\")
  string(MD5 _dest \"\$ENV{DESTDIR}\${CMAKE_INSTALL_PREFIX}\")
  configure_file(\"${PROJECT_SOURCE_DIR}/server/daemon/lagsimd@.service.in\"
                 \"${CMAKE_BINARY_DIR}/systemd/\${_dest}/lagsimd@.service\" @ONLY)
  file(INSTALL DESTINATION \"\${CMAKE_INSTALL_PREFIX}/lib/systemd/system\" TYPE FILE
       FILES \"${CMAKE_BINARY_DIR}/systemd/\${_dest}/lagsimd@.service\")")

# Python: types and helpers in the site directory, examples in share/lagsim/examples.
find_program(LAGSIM_PYTHON3 python3)
if(LAGSIM_PYTHON3)
  execute_process(COMMAND ${LAGSIM_PYTHON3} -c "import sys; print('%d.%d' % sys.version_info[:2])"
                  OUTPUT_VARIABLE _pyver OUTPUT_STRIP_TRAILING_WHITESPACE)
  # Debian's sys.path: /usr/lib/python3/dist-packages for packaged modules (prefix /usr,
  # as `cpack -G DEB` installs), <prefix>/lib/python3.X/dist-packages for /usr/local.
  # Chosen at install time, as the prefix is; a value set here wins.
  set(LAGSIM_PYTHON_SITEDIR "" CACHE STRING
      "where the Python types and helpers go, relative to the prefix (empty: Debian's place for the prefix)")
  if(LAGSIM_PYTHON_SITEDIR)
    install(CODE "set(_lagsim_pydir \"${LAGSIM_PYTHON_SITEDIR}\")")
  else()
    install(CODE "if(CMAKE_INSTALL_PREFIX STREQUAL \"/usr\")
        set(_lagsim_pydir lib/python3/dist-packages)
      else()
        set(_lagsim_pydir ${CMAKE_INSTALL_LIBDIR}/python${_pyver}/dist-packages)
      endif()")
  endif()
  install(DIRECTORY ${CMAKE_BINARY_DIR}/python/
          DESTINATION "\${_lagsim_pydir}" FILES_MATCHING PATTERN "*.py"
          PATTERN "__pycache__" EXCLUDE PATTERN "lagsim_client_path.py" EXCLUDE)
  # lagsim_client.py's pointer to the installed library (the build tree's is not installed)
  install(CODE "set(_lagsim_lib \"\${CMAKE_INSTALL_PREFIX}/${CMAKE_INSTALL_LIBDIR}/liblagsim_client.so.${LAGSIM_CLIENT_ABI}\")
    file(WRITE \"\$ENV{DESTDIR}\${CMAKE_INSTALL_PREFIX}/\${_lagsim_pydir}/lagsim_client_path.py\"
      \"# Where lagsim_client.py finds the client library: the installed one (written by cmake --install).\\nLIBRARY = \\\"\${_lagsim_lib}\\\"\\n\")
    message(STATUS \"Installing: \$ENV{DESTDIR}\${CMAKE_INSTALL_PREFIX}/\${_lagsim_pydir}/lagsim_client_path.py\")")
  install(PROGRAMS ${PROJECT_SOURCE_DIR}/clients/python/dipc_balance.py
                   ${PROJECT_SOURCE_DIR}/clients/python/manipulator_pd.py
          DESTINATION ${CMAKE_INSTALL_DATADIR}/lagsim/examples/python)
endif()

# Lua 5.2: types and helpers where lua5.2 looks, examples in share/lagsim/examples.
install(DIRECTORY ${CMAKE_BINARY_DIR}/lua/ DESTINATION ${CMAKE_INSTALL_DATADIR}/lua/5.2
        FILES_MATCHING PATTERN "*.lua" PATTERN "lagsim_client_path.lua" EXCLUDE)
# The client library's Lua module (an architecture's file: in the library directory's
# lua/5.2, where lua5.2 looks for C modules under /usr/local and /usr), and lagsim_lcm.lua's
# pointer to it (the build tree's is not installed)
if(TARGET lagsim_client_lua)
  install(TARGETS lagsim_client_lua LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}/lua/5.2)
  install(CODE "file(WRITE \"\$ENV{DESTDIR}\${CMAKE_INSTALL_PREFIX}/${CMAKE_INSTALL_DATADIR}/lua/5.2/lagsim_client_path.lua\"
      \"-- Where lagsim_lcm.lua finds the client library's Lua module: the installed one (written by cmake --install).\\nreturn '\${CMAKE_INSTALL_PREFIX}/${CMAKE_INSTALL_LIBDIR}/lua/5.2/lagsim_client.so'\\n\")
    message(STATUS \"Installing: \$ENV{DESTDIR}\${CMAKE_INSTALL_PREFIX}/${CMAKE_INSTALL_DATADIR}/lua/5.2/lagsim_client_path.lua\")")
endif()
install(FILES ${PROJECT_SOURCE_DIR}/clients/lua/dipc_balance.lua
              ${PROJECT_SOURCE_DIR}/clients/lua/manipulator_pd.lua
        DESTINATION ${CMAKE_INSTALL_DATADIR}/lagsim/examples/lua)

# Java: the types jar and the examples jar, beside Debian's lcm.jar.
if(TARGET lagsim_lcmtypes_java)
  install(FILES ${CMAKE_BINARY_DIR}/lagsim_types.jar DESTINATION ${CMAKE_INSTALL_DATADIR}/java)
endif()
if(TARGET lagsim_examples_java)
  install(FILES ${CMAKE_BINARY_DIR}/lagsim_examples.jar DESTINATION ${CMAKE_INSTALL_DATADIR}/java)
endif()
