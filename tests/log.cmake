# lagsimd --log: the log writer beside the loop (made-up clock, memq://, a FIFO for a disk
# that stalls, /dev/full for one that is full).
add_executable(test_rt_log ${CMAKE_CURRENT_LIST_DIR}/log/test_rt_log.c)
target_link_libraries(test_rt_log PRIVATE lagsimd_internal)
foreach(case file clock realtime_stalled fast_stalled lockstep_stalled full flood_in)
  add_test(NAME log_rt_${case} COMMAND test_rt_log ${case})
  set_tests_properties(log_rt_${case} PROPERTIES TIMEOUT 120 LABELS log)
endforeach()

