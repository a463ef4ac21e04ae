# The log tools and the live view: lagsim-log2csv against logs written by lcm-gen's
# Python encoder and against hostile logs; lagsim-plot; the log reader's fuzz target.
lagsim_fuzz_target(log2csv LIBS lagsim_log2csv)

find_program(LAGSIM_VIEW_PYTHON3 python3)
if(LAGSIM_VIEW_PYTHON3)
  foreach(case exact hostile)
    add_test(NAME view_log2csv_${case}
             COMMAND ${LAGSIM_VIEW_PYTHON3} ${CMAKE_CURRENT_LIST_DIR}/view/test_log2csv.py
                     --log2csv $<TARGET_FILE:lagsim-log2csv> --types ${CMAKE_BINARY_DIR}/python
                     ${case})
    set_tests_properties(view_log2csv_${case} PROPERTIES TIMEOUT 120 LABELS view)
  endforeach()
endif()
