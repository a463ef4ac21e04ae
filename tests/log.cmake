# lagsimd --log: the log writer beside the loop (made-up clock, memq://, a FIFO for a disk
# that stalls, /dev/full for one that is full).
add_executable(test_rt_log ${CMAKE_CURRENT_LIST_DIR}/log/test_rt_log.c)
target_include_directories(test_rt_log PRIVATE ${CMAKE_CURRENT_LIST_DIR}/common)
target_link_libraries(test_rt_log PRIVATE lagsimd_internal)
lagsim_add_test_cases(test_rt_log log_rt log 120)

# End to end: dipc_lqr in lockstep with lagsimd --log, the log read back by this test's own
# reader, liblcm's, lcm.jar's and lcm-logplayer; --replay on it, on a changed copy and on
# copies that lost states; the options. (The README's record recipe: clients_readme_recipes.)
find_program(LAGSIM_LOG_PYTHON3 python3)
if(LAGSIM_LOG_PYTHON3)
  foreach(case lqr lqr_effects gaps readers cli flood flood_applied)
    add_test(NAME log_${case}
             COMMAND ${LAGSIM_LOG_PYTHON3} ${CMAKE_CURRENT_LIST_DIR}/log/test_log.py
                     --bin ${CMAKE_BINARY_DIR}/bin --types ${CMAKE_BINARY_DIR}/python
                     --source ${PROJECT_SOURCE_DIR} ${case})
    set_tests_properties(log_${case} PROPERTIES TIMEOUT 300 LABELS log)
  endforeach()
endif()

# The daemon on a terminal: a pseudo-terminal as its stderr, a controller of the test's own.
if(LAGSIM_LOG_PYTHON3)
  foreach(case live effects quiet pipe waits stalled)
    add_test(NAME log_term_${case}
             COMMAND ${LAGSIM_LOG_PYTHON3} ${CMAKE_CURRENT_LIST_DIR}/log/test_term.py
                     --bin ${CMAKE_BINARY_DIR}/bin --python ${CMAKE_BINARY_DIR}/python
                     --source ${PROJECT_SOURCE_DIR} ${case})
    set_tests_properties(log_term_${case} PROPERTIES TIMEOUT 120 LABELS log)
  endforeach()
endif()

# Every output path by one set of rules (lagsim_out.h): no symbolic link followed, no input
# written, no existing file replaced without --force.
if(LAGSIM_LOG_PYTHON3)
  foreach(writer lagsimd_log lagsimd_csv log2csv plot)
    add_test(NAME log_outputs_${writer}
             COMMAND ${LAGSIM_LOG_PYTHON3} ${CMAKE_CURRENT_LIST_DIR}/log/test_outputs.py
                     --bin ${CMAKE_BINARY_DIR}/bin --source ${PROJECT_SOURCE_DIR} ${writer})
    set_tests_properties(log_outputs_${writer} PROPERTIES TIMEOUT 120 LABELS log)
  endforeach()
endif()

# A log written by lagsim 0.1.0 (tests/log/fixtures): --replay and lagsim-log2csv read it.
if(LAGSIM_LOG_PYTHON3)
  foreach(case replay log2csv)
    add_test(NAME log_old_version_${case}
             COMMAND ${LAGSIM_LOG_PYTHON3} ${CMAKE_CURRENT_LIST_DIR}/log/test_old_log.py
                     ${CMAKE_BINARY_DIR}/bin ${PROJECT_SOURCE_DIR} ${case})
    set_tests_properties(log_old_version_${case} PROPERTIES TIMEOUT 120 LABELS log)
  endforeach()
endif()

# lagsimd --log FILE --increment: the series FILE.000000, ... (lagsim_out.h): numbering that
# never runs out, --keep removing only the series' own oldest, --split-mb, a file-size limit.
if(LAGSIM_LOG_PYTHON3)
  foreach(case numbering keep split options)
    add_test(NAME log_series_${case}
             COMMAND ${LAGSIM_LOG_PYTHON3} ${CMAKE_CURRENT_LIST_DIR}/log/test_series.py
                     --bin ${CMAKE_BINARY_DIR}/bin --types ${CMAKE_BINARY_DIR}/python
                     --source ${PROJECT_SOURCE_DIR} ${case})
    set_tests_properties(log_series_${case} PROPERTIES TIMEOUT 120 LABELS log)
  endforeach()
endif()
