# Controller evaluation (server/eval): reference signals against their closed forms and
# their rates against differences; the metrics against closed forms of first- and
# second-order responses; the --require parser. One ctest per case (eval.<program>.<case>).
include(${CMAKE_CURRENT_LIST_DIR}/common/cases.cmake)
foreach(t metrics reference)
  add_executable(test_eval_${t} ${CMAKE_CURRENT_LIST_DIR}/eval/test_${t}.c)
  target_include_directories(test_eval_${t} PRIVATE ${CMAKE_CURRENT_LIST_DIR}/common)
  target_compile_definitions(test_eval_${t} PRIVATE LAGSIM_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
  target_link_libraries(test_eval_${t} PRIVATE lagsim_eval m)
  lagsim_add_test_cases(test_eval_${t} eval.${t} eval 60)
endforeach()
