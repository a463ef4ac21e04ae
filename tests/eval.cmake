# Controller evaluation: the metrics library (server/eval) against closed forms of first-
# and second-order responses, and the --require parser. One ctest per case (eval.metrics.<case>).
include(${CMAKE_CURRENT_LIST_DIR}/common/cases.cmake)
add_executable(test_eval_metrics ${CMAKE_CURRENT_LIST_DIR}/eval/test_metrics.c)
target_include_directories(test_eval_metrics PRIVATE ${CMAKE_CURRENT_LIST_DIR}/common)
target_compile_definitions(test_eval_metrics PRIVATE LAGSIM_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
target_link_libraries(test_eval_metrics PRIVATE lagsim_metrics m)
lagsim_add_test_cases(test_eval_metrics eval.metrics eval 60)
