# The Debian package (cmake/LagsimPackage.cmake) and its systemd unit: ctest -L package.
# package_build: cpack, the contents, lintian, systemd-analyze (any user).
# package_install: installed with apt-get, run, purged (root only; skipped otherwise).
# package_service: installed, lagsimd@NAME started by systemd (as PID 1 of a namespace of
# its own), a controller, restart, stop, journal, state directory; purged (root only).
# Both install in a mount namespace of their own, over overlays of /usr, /etc and /var, so
# that no other test picks up the package's modules or library by mistake: they run beside
# the others (one at a time: dpkg, one package name).
# Not in a sanitizer build: the package ships the release build's programs.
find_program(LAGSIM_PYTHON3 python3)
if(LAGSIM_PYTHON3 AND NOT LAGSIM_SANITIZE)
  set(pkg_check ${LAGSIM_PYTHON3} ${CMAKE_CURRENT_SOURCE_DIR}/package/check_package.py)
  add_test(NAME package_build
    COMMAND ${pkg_check} build --build ${CMAKE_BINARY_DIR} --source ${PROJECT_SOURCE_DIR})
  set_tests_properties(package_build PROPERTIES TIMEOUT 180 LABELS package
    FIXTURES_SETUP lagsim_deb RESOURCE_LOCK lagsim_deb SKIP_RETURN_CODE 77)
  add_test(NAME package_install
    COMMAND ${pkg_check} install --build ${CMAKE_BINARY_DIR} --source ${PROJECT_SOURCE_DIR})
  set_tests_properties(package_install PROPERTIES TIMEOUT 240 LABELS package
    FIXTURES_REQUIRED lagsim_deb RESOURCE_LOCK lagsim_deb SKIP_RETURN_CODE 77)
  add_test(NAME package_service
    COMMAND ${pkg_check} service --build ${CMAKE_BINARY_DIR} --source ${PROJECT_SOURCE_DIR})
  set_tests_properties(package_service PROPERTIES TIMEOUT 240 LABELS package
    FIXTURES_REQUIRED lagsim_deb RESOURCE_LOCK lagsim_deb SKIP_RETURN_CODE 77)
endif()
