# The log tools and the live view: lagsim-log2csv against logs written by lcm-gen's
# Python encoder and against hostile logs; lagsim-plot; the log reader's fuzz target;
# lagsim-view opened in headless Chromium beside a running lagsimd, and attacked.
lagsim_fuzz_target(log2csv LIBS lagsim_log2csv)

find_program(LAGSIM_VIEW_PYTHON3 python3)
if(LAGSIM_VIEW_PYTHON3)
  foreach(case exact hostile injection plot)
    add_test(NAME view_log2csv_${case}
             COMMAND ${LAGSIM_VIEW_PYTHON3} ${CMAKE_CURRENT_LIST_DIR}/view/test_log2csv.py
                     --log2csv $<TARGET_FILE:lagsim-log2csv> --types ${CMAKE_BINARY_DIR}/python
                     ${case})
    set_tests_properties(view_log2csv_${case} PROPERTIES TIMEOUT 120 LABELS view)
  endforeach()
endif()

# lagsim-view: Chromium (Debian's chromium, installed by .ci/install-deps.sh) drives the
# page over the DevTools protocol. Without chromium the test fails, saying so: a view
# test that silently does not run proves nothing.
find_program(LAGSIM_CHROMIUM NAMES chromium chromium-browser)
if(LAGSIM_VIEW_PYTHON3)
  set(view_test ${LAGSIM_VIEW_PYTHON3} ${CMAKE_CURRENT_LIST_DIR}/view/test_view.py
      --lagsimd $<TARGET_FILE:lagsimd> --view $<TARGET_FILE:lagsim-view>
      --config ${PROJECT_SOURCE_DIR}/config/dipc.yaml)
  add_test(NAME view_browser COMMAND ${view_test} browser
           --screenshot ${CMAKE_BINARY_DIR}/view_browser.png)
  add_test(NAME view_hostile COMMAND ${view_test} hostile)
  add_test(NAME view_stick_flight COMMAND ${view_test} stick_flight)
  add_test(NAME view_cartpole COMMAND ${view_test} cartpole)
  set_tests_properties(view_browser view_hostile view_stick_flight view_cartpole PROPERTIES TIMEOUT 180 LABELS view)
  if(NOT LAGSIM_CHROMIUM)
    set_tests_properties(view_browser view_stick_flight view_cartpole PROPERTIES ENVIRONMENT "PATH=/nonexistent")
  endif()
endif()
