# The real-time LCM server (issue 3): end-to-end over real LCM (default udpm URL, ttl=0),
# one lagsimd child per case with a unique channel prefix.
add_executable(server_test ${CMAKE_CURRENT_LIST_DIR}/server/server_test.c)
target_link_libraries(server_test PRIVATE lagsim_scene lagsim_core lagsim_lcmtypes PkgConfig::LCM)
find_program(LCM_LOGGER lcm-logger)
set(LAGSIM_SERVER_CASES control hostile watchdog lockstep_timeout two_daemons fault sigterm
    bad_scene effects)
if(LCM_LOGGER)
  list(APPEND LAGSIM_SERVER_CASES replay replay_dopri5 replay_effects)
endif()
foreach(case ${LAGSIM_SERVER_CASES})
  add_test(NAME server_${case}
           COMMAND server_test $<TARGET_FILE:lagsimd> ${case} ${LCM_LOGGER})
  set_tests_properties(server_${case} PROPERTIES TIMEOUT 60 LABELS server)
endforeach()
