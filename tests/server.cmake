# The real-time LCM server: end-to-end over real LCM (default udpm URL, ttl=0),
# one lagsimd child per case with a unique channel prefix.
add_executable(server_test ${CMAKE_CURRENT_LIST_DIR}/server/server_test.c)
target_link_libraries(server_test PRIVATE lagsim_scene lagsim_core lagsim_wire lagsim_lcmtypes PkgConfig::LCM)
find_program(LCM_LOGGER lcm-logger)
set(LAGSIM_SERVER_CASES control hostile watchdog lockstep_timeout two_daemons fault sigterm
    bad_scene effects control_flood step_flood lockstep_huge status_rate rate_huge long_period
    duration_huge signals effort_absurd ttl_warning offline_signal command_flood_ports same_prefix
    plant_conflict)
if(LCM_LOGGER)
  list(APPEND LAGSIM_SERVER_CASES replay replay_dopri5 replay_effects replay_flight
       plant_conflict_logplayer)
endif()
foreach(case ${LAGSIM_SERVER_CASES})
  add_test(NAME server_${case}
           COMMAND server_test $<TARGET_FILE:lagsimd> ${case} ${LCM_LOGGER})
  set_tests_properties(server_${case} PROPERTIES TIMEOUT 60 LABELS server)
endforeach()

# The loop's arithmetic (rt_pace.c) with made-up clocks, and the loop itself with a
# made-up clock on LCM's in-process memq:// provider: exact, and independent of load.
add_executable(test_pace ${CMAKE_CURRENT_LIST_DIR}/server/test_pace.c)
target_link_libraries(test_pace PRIVATE lagsimd_internal)
foreach(case convert ticks pace burst rebase skip limit)
  add_test(NAME server_pace_${case} COMMAND test_pace ${case})
  set_tests_properties(server_pace_${case} PROPERTIES TIMEOUT 30 LABELS server)
endforeach()
add_executable(test_loop ${CMAKE_CURRENT_LIST_DIR}/server/test_loop.c)
target_link_libraries(test_loop PRIVATE lagsimd_internal)
foreach(case pacing rate_huge status_hz lockstep_wait start set long_period chunks step_paced
        control_flood command_flood duration signals fault_effort lockstep_retry lockstep_loss
        other_plant set_replay messages reject_names waits live_error)
  add_test(NAME server_loop_${case} COMMAND test_loop ${case})
  set_tests_properties(server_loop_${case} PROPERTIES TIMEOUT 60 LABELS server)
endforeach()

# Fuzz target: the command and control handlers and the loop in every mode and run state,
# on memq:// with a made-up clock (tests/fuzz/fuzz_rt.c; kept inputs in tests/fuzz/rt/).
lagsim_fuzz_target(rt LIBS lagsimd_internal)

# The scene's reference on <PREFIX>_REFERENCE in every mode, against its closed form; --log,
# --replay (difference 0, a changed reference fails), SET while running, offline CSV columns
# (tests/server/test_reference.py).
find_program(LAGSIM_REF_PYTHON3 python3)
if(LAGSIM_REF_PYTHON3)
  foreach(case fast realtime lockstep set offline manipulator)
    add_test(NAME server_reference_${case}
             COMMAND ${LAGSIM_REF_PYTHON3} ${CMAKE_CURRENT_LIST_DIR}/server/test_reference.py
                     --bin ${CMAKE_BINARY_DIR}/bin --types ${CMAKE_BINARY_DIR}/python
                     --source ${PROJECT_SOURCE_DIR} ${case})
    set_tests_properties(server_reference_${case} PROPERTIES TIMEOUT 120 LABELS server)
  endforeach()
endif()

# The daemon's files stand on floors: no circle of calls or includes between
# server/daemon/*.c, and only the loop (realtime.c) includes its header rt_server.h.
find_program(LAGSIM_PYTHON3 python3)
if(LAGSIM_PYTHON3)
  add_test(NAME server_daemon_floors
           COMMAND ${LAGSIM_PYTHON3} ${CMAKE_CURRENT_LIST_DIR}/server/daemon_floors.py
                   ${PROJECT_SOURCE_DIR}/server/daemon)
  set_tests_properties(server_daemon_floors PROPERTIES TIMEOUT 30 LABELS server)
endif()
