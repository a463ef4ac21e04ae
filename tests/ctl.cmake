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

# A run whose parameters were changed while it ran (lagsimctl set), replayed from its logs
# (lcm-logger's, and lagsimd --log's when it has one) with difference 0; without the set
# events it is not (tests/ctl/test_set_replay.py).
find_program(LCM_LOGGER lcm-logger)
if(LAGSIM_PYTHON3)
  add_test(NAME ctl_set_replay
    COMMAND ${LAGSIM_PYTHON3} ${CMAKE_CURRENT_SOURCE_DIR}/ctl/test_set_replay.py
            --bin $<TARGET_FILE_DIR:lagsimd> --source ${PROJECT_SOURCE_DIR}
            --lcm-logger "${LCM_LOGGER}")
  set_tests_properties(ctl_set_replay PROPERTIES TIMEOUT 120 LABELS clients)
endif()

# Kicks (lagsimctl kick) against the impulse-momentum theorem on the stick's free x: an
# impulse changes m x_dot by itself, two kicks add, a reset ends them; reset names the
# changes it keeps, reset --scene undoes them; --replay of the log gives difference 0 and
# the log without its events does not (tests/ctl/test_kick.py).
if(LAGSIM_PYTHON3)
  add_test(NAME ctl_kick
    COMMAND ${LAGSIM_PYTHON3} ${CMAKE_CURRENT_SOURCE_DIR}/ctl/test_kick.py
            --bin $<TARGET_FILE_DIR:lagsimd> --source ${PROJECT_SOURCE_DIR})
  set_tests_properties(ctl_kick PROPERTIES TIMEOUT 120 LABELS clients)
endif()

# Tools find the plant: lagsimctl list (prefix, model, mode, run state, host, URL) and
# lagsimctl, lqr_balance, dipc_lqr, manipulator_pd, the Python dipc_balance.py and
# lagsim-view without --prefix, with one plant on the bus, with three, with none of the
# controller's model (tests/ctl/test_discover.py).
if(LAGSIM_PYTHON3)
  add_test(NAME ctl_discover
    COMMAND ${LAGSIM_PYTHON3} ${CMAKE_CURRENT_SOURCE_DIR}/ctl/test_discover.py
            --bin $<TARGET_FILE_DIR:lagsimd> --source ${PROJECT_SOURCE_DIR})
  set_tests_properties(ctl_discover PROPERTIES TIMEOUT 120 LABELS clients)
endif()

# A prefix nobody has (a misspelt one): lagsimctl, manipulator_pd in C and in Python and
# manipulator_ct in C++ name
# the plants heard and the one meant; the plant's wait line and status name the requests
# for the misspelt prefixes and its own on the wrong port, never another plant's
# (tests/ctl/test_misspelt.py).
if(LAGSIM_PYTHON3)
  add_test(NAME ctl_misspelt_prefix
    COMMAND ${LAGSIM_PYTHON3} ${CMAKE_CURRENT_SOURCE_DIR}/ctl/test_misspelt.py
            --bin $<TARGET_FILE_DIR:lagsimd> --source ${PROJECT_SOURCE_DIR})
  set_tests_properties(ctl_misspelt_prefix PROPERTIES TIMEOUT 120 LABELS clients)
endif()

# A reset that waits for the first command (lagsimctl reset --wait, RESET/RESET_TO count
# bit 2): the real-time DIPC run by dipc_lqr, the controller stopped, reset --wait: the
# plant waits at sim time 0 republishing its state until the next dipc_lqr starts the run;
# reset --scene --wait while paused and in the fault, reset-to --wait: waiting; other count
# bits refused with control_rejected; --replay of the log exact
# (tests/ctl/test_reset_wait.py).
if(LAGSIM_PYTHON3)
  add_test(NAME ctl_reset_wait
    COMMAND ${LAGSIM_PYTHON3} ${CMAKE_CURRENT_SOURCE_DIR}/ctl/test_reset_wait.py
            --bin $<TARGET_FILE_DIR:lagsimd> --source ${PROJECT_SOURCE_DIR}
            --types ${CMAKE_BINARY_DIR}/python)
  set_tests_properties(ctl_reset_wait PROPERTIES TIMEOUT 120 LABELS clients)
endif()
