# lagsimctl against a running lagsimd: every command, its output and exit status
# (tests/ctl/test_lagsimctl.py explains each check). Real LCM, a prefix per process.
find_program(LAGSIM_PYTHON3 python3)
if(LAGSIM_PYTHON3)
  add_test(NAME ctl_lagsimctl
    COMMAND ${LAGSIM_PYTHON3} ${CMAKE_CURRENT_SOURCE_DIR}/ctl/test_lagsimctl.py
            --lagsimctl $<TARGET_FILE:lagsimctl> --lagsimd $<TARGET_FILE:lagsimd>
            --source ${PROJECT_SOURCE_DIR})
  set_tests_properties(ctl_lagsimctl PROPERTIES TIMEOUT 120 LABELS clients)
endif()
