# The real-time LCM server: end-to-end over real LCM (default udpm URL, ttl=0),
# one lagsimd child per case with a unique channel prefix.
# One ctest per case of server_test's table (server_<case>); the cases that record a run
# with lcm-logger are skipped where it is not installed.
add_executable(server_test ${CMAKE_CURRENT_LIST_DIR}/server/server_test.c)
target_include_directories(server_test PRIVATE ${CMAKE_CURRENT_LIST_DIR}/common)
target_link_libraries(server_test PRIVATE lagsim_scene lagsim_core lagsim_wire lagsim_lcmtypes PkgConfig::LCM)
find_program(LCM_LOGGER lcm-logger)
if(LCM_LOGGER)
  lagsim_add_test_cases(server_test server server 60 $<TARGET_FILE:lagsimd> ${LCM_LOGGER})
else()
  lagsim_add_test_cases(server_test server server 60 $<TARGET_FILE:lagsimd>)
endif()

# The loop's arithmetic (rt_pace.c) with made-up clocks, and the loop itself with a
# made-up clock on LCM's in-process memq:// provider: exact, and independent of load.
add_executable(test_pace ${CMAKE_CURRENT_LIST_DIR}/server/test_pace.c)
target_include_directories(test_pace PRIVATE ${CMAKE_CURRENT_LIST_DIR}/common)
target_link_libraries(test_pace PRIVATE lagsimd_internal)
lagsim_add_test_cases(test_pace server_pace server 30)
# A plant's input read by the loop (rt_rx.c) against LCM's own datagrams.
add_executable(test_rx ${CMAKE_CURRENT_LIST_DIR}/server/test_rx.c)
target_include_directories(test_rx PRIVATE ${CMAKE_CURRENT_LIST_DIR}/common)
target_link_libraries(test_rx PRIVATE lagsimd_internal)
lagsim_add_test_cases(test_rx server_rx server 30)
add_executable(test_loop ${CMAKE_CURRENT_LIST_DIR}/server/test_loop.c)
target_include_directories(test_loop PRIVATE ${CMAKE_CURRENT_LIST_DIR}/common)
target_link_libraries(test_loop PRIVATE lagsimd_internal)
lagsim_add_test_cases(test_loop server_loop server 60)

# Fuzz target: the command and control handlers and the loop in every mode and run state,
# on memq:// with a made-up clock (tests/fuzz/fuzz_rt.c; kept inputs in tests/fuzz/rt/).
lagsim_fuzz_target(rt LIBS lagsimd_internal)

# The scene's reference on <PREFIX>_REFERENCE in every mode, against its closed form; --log,
# --replay (difference 0, a changed reference fails), SET while running, offline CSV columns
# (tests/server/test_reference.py).
find_program(LAGSIM_REF_PYTHON3 python3)
if(LAGSIM_REF_PYTHON3)
  foreach(case fast realtime lockstep set offline manipulator retry)
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

# A host of plants (lagsimd --plants DIR, several --config) over real LCM, each case on port
# pairs of its own held by lock files (tests/server/test_host.py): isolation from a hostile
# neighbour (states bit for bit those of the plant alone; the neighbour's input budget),
# bad scenes skipped, a directory's files added, changed and removed while running, a
# file that failed for want of its port tried again on SIGHUP,
# lagsimctl list through the host's directory; a starting daemon's look for another plant
# waits, never spins (strace's count of its epoll_wait calls; skipped, 77, where this host
# denies ptrace).
if(LAGSIM_PYTHON3)
  foreach(case isolation bad_scene reload list many foreign own_flood quiet look)
    add_test(NAME server_host_${case}
             COMMAND ${LAGSIM_PYTHON3} ${CMAKE_CURRENT_LIST_DIR}/server/test_host.py
                     --bin ${CMAKE_BINARY_DIR}/bin --types ${CMAKE_BINARY_DIR}/python
                     --source ${PROJECT_SOURCE_DIR} ${case})
    set_tests_properties(server_host_${case} PROPERTIES TIMEOUT 240 LABELS server
                         SKIP_RETURN_CODE 77)
  endforeach()
endif()
