# `cmake --install` into a temporary prefix, then the installed daemon with the installed
# controllers (C, a C program built through pkg-config, Python, Lua, Java).
find_program(LAGSIM_PYTHON3 python3)
if(LAGSIM_PYTHON3)
  # a sanitizer build's libraries need the same runtime when the test links against them
  set(inst_flags "")
  if(LAGSIM_SANITIZE)
    set(inst_flags "-fsanitize=address,undefined,float-cast-overflow")
  endif()
  if(LAGSIM_FUZZ)
    string(APPEND inst_flags " -fsanitize=fuzzer-no-link")
  endif()
  add_test(NAME install_and_run
    COMMAND ${LAGSIM_PYTHON3} ${CMAKE_CURRENT_SOURCE_DIR}/install/check_install.py
            --build ${CMAKE_BINARY_DIR} --source ${PROJECT_SOURCE_DIR} --cc ${CMAKE_C_COMPILER}
            --cxx ${CMAKE_CXX_COMPILER} --abi ${LAGSIM_CLIENT_ABI} "--cflags=${inst_flags}")
  set_tests_properties(install_and_run PROPERTIES TIMEOUT 180 LABELS clients)
endif()

# Each installed program's man page against its --help; every list of models (--help, man
# pages, .lcm comments) against the core's table.
add_executable(lagsim_model_names ${CMAKE_CURRENT_SOURCE_DIR}/install/model_names.c)
target_link_libraries(lagsim_model_names PRIVATE lagsim_core)
if(LAGSIM_PYTHON3)
  foreach(case pages models)
    add_test(NAME install_man_${case}
      COMMAND ${LAGSIM_PYTHON3} ${CMAKE_CURRENT_SOURCE_DIR}/install/check_man.py
              --build ${CMAKE_BINARY_DIR} --source ${PROJECT_SOURCE_DIR}
              --models $<TARGET_FILE:lagsim_model_names> ${case})
    set_tests_properties(install_man_${case} PROPERTIES TIMEOUT 120 LABELS clients)
  endforeach()
endif()

# A build for users (-DBUILD_TESTING=OFF): the programs, libraries, types and man pages,
# no test, fuzz or benchmark target (configured only: tests/install/check_build_testing_off.py).
if(LAGSIM_PYTHON3)
  add_test(NAME install_build_testing_off
    COMMAND ${LAGSIM_PYTHON3} ${CMAKE_CURRENT_SOURCE_DIR}/install/check_build_testing_off.py
            --source ${PROJECT_SOURCE_DIR} --build ${CMAKE_BINARY_DIR})
  set_tests_properties(install_build_testing_off PROPERTIES TIMEOUT 120 LABELS clients)
endif()
