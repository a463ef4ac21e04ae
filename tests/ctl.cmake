# lagsimctl, and the tools that find a plant, against a running lagsimd: real LCM, a prefix
# per process. lagsim_ctl_test(NAME SCRIPT ARG...) runs python3 tests/ctl/SCRIPT ARG...,
# 120 s at most, label clients; most take the build's bin directory and the source tree.
find_program(LAGSIM_PYTHON3 python3)
find_program(LCM_LOGGER lcm-logger)
function(lagsim_ctl_test name script)
  add_test(NAME ${name}
    COMMAND ${LAGSIM_PYTHON3} ${CMAKE_CURRENT_SOURCE_DIR}/ctl/${script} ${ARGN})
  set_tests_properties(${name} PROPERTIES TIMEOUT 120 LABELS clients)
endfunction()
if(LAGSIM_PYTHON3)
  set(ctl_tree --bin $<TARGET_FILE_DIR:lagsimd> --source ${PROJECT_SOURCE_DIR})
  # Every command, its output and exit status (tests/ctl/test_lagsimctl.py explains each
  # check).
  lagsim_ctl_test(ctl_lagsimctl test_lagsimctl.py
    --lagsimctl $<TARGET_FILE:lagsimctl> --lagsimd $<TARGET_FILE:lagsimd>
    --source ${PROJECT_SOURCE_DIR})
  # A run whose parameters were changed while it ran (lagsimctl set), replayed from its
  # logs (lcm-logger's, and lagsimd --log's when it has one) with difference 0; without
  # the set events it is not (tests/ctl/test_set_replay.py).
  lagsim_ctl_test(ctl_set_replay test_set_replay.py ${ctl_tree} --lcm-logger "${LCM_LOGGER}")
  # Kicks (lagsimctl kick) against the impulse-momentum theorem on the stick's free x: an
  # impulse changes m x_dot by itself, two kicks add, a reset ends them; reset names the
  # changes it keeps, reset --scene undoes them; --replay of the log gives difference 0
  # and the log without its events does not (tests/ctl/test_kick.py).
  lagsim_ctl_test(ctl_kick test_kick.py ${ctl_tree})
  # Tools find the plant: lagsimctl list (prefix, model, mode, run state, host, URL) and
  # lagsimctl, lqr_balance, dipc_lqr, manipulator_pd, the Python dipc_balance.py and
  # lagsim-view without --prefix, with one plant on the bus, with three, with none of the
  # controller's model (tests/ctl/test_discover.py).
  lagsim_ctl_test(ctl_discover test_discover.py ${ctl_tree})
  # A prefix nobody has (a misspelt one): lagsimctl, manipulator_pd in C and in Python and
  # manipulator_ct in C++ name the plants heard and the one meant; the plant's wait line
  # and status name the requests for the misspelt prefixes and its own on the wrong port,
  # never another plant's (tests/ctl/test_misspelt.py).
  lagsim_ctl_test(ctl_misspelt_prefix test_misspelt.py ${ctl_tree})
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
