# The project's structure rules (tests/structure/check_structure.py), label structure:
# one test harness for the C tests, one naming rule for ctests (lowercase words joined by
# "_", a label and one tier on each), docs that name only ctests and files that exist and
# docs/testing.md's tier and label tables, functions of at most 80 lines in server/,
# clients/, bench/, and time to ticks converted by the core's helpers alone.
find_program(LAGSIM_STRUCTURE_PYTHON3 python3)
if(LAGSIM_STRUCTURE_PYTHON3)
  set(structure_check ${LAGSIM_STRUCTURE_PYTHON3} ${CMAKE_CURRENT_LIST_DIR}/structure/check_structure.py)
  add_test(NAME structure_harness COMMAND ${structure_check} harness ${PROJECT_SOURCE_DIR})
  add_test(NAME structure_names
           COMMAND ${structure_check} names ${CMAKE_BINARY_DIR} --ctest ${CMAKE_CTEST_COMMAND}
                   --tiers ${CMAKE_CURRENT_LIST_DIR}/common/tiers.cmake)
  # the Go controllers' tests are defined only where go is found, never in a sanitizer
  # build (clients/go/CMakeLists.txt): elsewhere the docs may name them
  set(structure_docs_absent)
  find_program(LAGSIM_GO go)
  if(NOT LAGSIM_GO OR LAGSIM_SANITIZE)
    set(structure_docs_absent --absent "clients_go_*" --absent "clients_readme_go*"
                              --absent "protocol_go_*")
  endif()
  add_test(NAME structure_docs
           COMMAND ${structure_check} docs ${PROJECT_SOURCE_DIR} ${CMAKE_BINARY_DIR}
                   --ctest ${CMAKE_CTEST_COMMAND} ${structure_docs_absent})
  # universal-ctags (.ci/install-deps.sh) finds each function's first and last line.
  add_test(NAME structure_function_length
           COMMAND ${structure_check} function_length ${PROJECT_SOURCE_DIR} --max 80)
  # time to ticks only through the core's helpers (lag_ticks_*), outside server/core
  add_test(NAME structure_ticks COMMAND ${structure_check} ticks ${PROJECT_SOURCE_DIR})
  set_tests_properties(structure_harness structure_names structure_docs
                       structure_function_length structure_ticks
                       PROPERTIES TIMEOUT 120 LABELS structure)
endif()

# Every generated list in the committed docs, man pages, .lcm comments and scenes is what
# the core's tables give (server/lists); a stale block fails, naming itself and the command
# that rewrites it (cmake --build BUILD --target lists). Every model has a shipped scene.
add_test(NAME structure_lists
         COMMAND lagsim_lists check ${PROJECT_SOURCE_DIR} ${CMAKE_BINARY_DIR})
set_tests_properties(structure_lists PROPERTIES TIMEOUT 60 LABELS structure)
# .ci/install-deps.sh reads: every profile lists its packages (a quote the table's string
# lost broke tests/run.sh and CI at their first line)
find_program(LAGSIM_BASH_FOR_DEPS bash REQUIRED)
add_test(NAME structure_install_deps
         COMMAND ${LAGSIM_BASH_FOR_DEPS} -c
           "for p in runtime tests ci dev; do ${PROJECT_SOURCE_DIR}/.ci/install-deps.sh --list $p >/dev/null || exit 1; done")
set_tests_properties(structure_install_deps PROPERTIES TIMEOUT 60 LABELS structure)
# tests/run.sh refuses what it cannot do (a --tier or --label without a value, a tier
# tiers.cmake lacks, --sanitize alone) with exit 2 and a line, and takes every tier
add_test(NAME structure_run_usage
         COMMAND ${LAGSIM_BASH_FOR_DEPS} ${CMAKE_CURRENT_LIST_DIR}/structure/run_usage.sh
                 ${PROJECT_SOURCE_DIR})
set_tests_properties(structure_run_usage PROPERTIES TIMEOUT 60 LABELS structure)
