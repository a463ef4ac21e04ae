# The log tools and the live view: lagsim-log2csv against logs written by lcm-gen's
# Python encoder and against hostile logs; lagsim-plot; the log reader's fuzz target;
# lagsim-view opened in headless Chromium beside a running lagsimd, and attacked.
lagsim_fuzz_target(log2csv LIBS lagsim_log2csv)
# lagsim-view's JSON and server-sent events from hostile text, its HTTP side, its Host check
lagsim_fuzz_target(view LIBS lagsim_view_internal)

find_program(LAGSIM_VIEW_PYTHON3 python3)
if(LAGSIM_VIEW_PYTHON3)
  foreach(case exact hostile injection plot)
    add_test(NAME view_log2csv_${case}
             COMMAND ${LAGSIM_VIEW_PYTHON3} ${CMAKE_CURRENT_LIST_DIR}/view/test_log2csv.py
                     --log2csv $<TARGET_FILE:lagsim-log2csv> --types ${CMAKE_BINARY_DIR}/python
                     ${case})
    set_tests_properties(view_log2csv_${case} PROPERTIES TIMEOUT 120 LABELS view)
  endforeach()
  # a real run's state CSV loaded as docs/view.md says: Octave's importdata and csvread,
  # Python's csv, pandas (tests/view/test_log2csv_load.py)
  add_test(NAME view_log2csv_load
           COMMAND ${LAGSIM_VIEW_PYTHON3} ${CMAKE_CURRENT_LIST_DIR}/view/test_log2csv_load.py
                   --bin $<TARGET_FILE_DIR:lagsimd> --source ${PROJECT_SOURCE_DIR})
  set_tests_properties(view_log2csv_load PROPERTIES TIMEOUT 180 LABELS view)
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
  add_test(NAME view_reference COMMAND ${view_test} reference
           --screenshot ${CMAKE_BINARY_DIR}/view_reference.png)
  add_test(NAME view_charts COMMAND ${view_test} charts)
  add_test(NAME view_history COMMAND ${view_test} history)
  # every model of the core's table drawn, from its shipped scene
  add_test(NAME view_models COMMAND ${view_test} models)
  set_tests_properties(view_browser view_hostile view_stick_flight view_cartpole view_reference
                       view_charts view_history view_models PROPERTIES TIMEOUT 180 LABELS view)
  if(NOT LAGSIM_CHROMIUM)
    set_tests_properties(view_browser view_stick_flight view_cartpole view_reference view_charts
                         view_models PROPERTIES ENVIRONMENT "PATH=/nonexistent")
  endif()
endif()

# lagsim-view attacked by one local process, one LAN host and one browser tab
# (tests/view/test_view_attacks.py): forged text at the wire's worst, streams that never
# read, a slowloris, Host headers, other hosts' datagrams (network namespaces: root, else
# skipped). Each starts its own lagsim-view on ports of its own.
if(LAGSIM_VIEW_PYTHON3)
  set(view_attacks ${LAGSIM_VIEW_PYTHON3} ${CMAKE_CURRENT_LIST_DIR}/view/test_view_attacks.py
      --view $<TARGET_FILE:lagsim-view> --lagsimd $<TARGET_FILE:lagsimd>
      --config ${PROJECT_SOURCE_DIR}/config/dipc.yaml --types ${CMAKE_BINARY_DIR}/python)
  foreach(case forged stalled slowloris host lan)
    add_test(NAME view_attack_${case} COMMAND ${view_attacks} ${case})
    set_tests_properties(view_attack_${case} PROPERTIES TIMEOUT 180 LABELS view SKIP_RETURN_CODE 77)
  endforeach()
  if(NOT LAGSIM_CHROMIUM)
    set_tests_properties(view_attack_forged view_attack_stalled view_attack_host PROPERTIES
                         ENVIRONMENT "PATH=/nonexistent")
  endif()
endif()

# lagsim-view stopped by SIGINT or SIGTERM while browsers hold streams, six times each
# (tests/view/test_view_stop.py): exit 0, no abort in libmicrohttpd, each stream ended.
if(LAGSIM_VIEW_PYTHON3)
  foreach(case sigint sigterm)
    add_test(NAME view_stop_${case}
             COMMAND ${LAGSIM_VIEW_PYTHON3} ${CMAKE_CURRENT_LIST_DIR}/view/test_view_stop.py
                     --view $<TARGET_FILE:lagsim-view> --lagsimd $<TARGET_FILE:lagsimd>
                     --config ${PROJECT_SOURCE_DIR}/config/dipc.yaml
                     --types ${CMAKE_BINARY_DIR}/python ${case})
    set_tests_properties(view_stop_${case} PROPERTIES TIMEOUT 180 LABELS view)
  endforeach()
endif()
