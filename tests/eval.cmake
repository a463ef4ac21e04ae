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

# lagsim-eval end to end: the cart-pole held by lqr_balance through a small case set
# (tests/eval/cartpole_cases.yaml); metrics against the logged states, --require's exit
# codes, case files with mistakes.
find_program(LAGSIM_PYTHON3 python3)
if(LAGSIM_PYTHON3)
  foreach(c metrics require errors)
    add_test(NAME eval_lagsim_eval_${c}
      COMMAND ${LAGSIM_PYTHON3} ${CMAKE_CURRENT_LIST_DIR}/eval/test_eval.py
              $<TARGET_FILE_DIR:lagsim-eval> ${PROJECT_SOURCE_DIR} ${c})
    set_tests_properties(eval_lagsim_eval_${c} PROPERTIES LABELS eval TIMEOUT 300)
  endforeach()
endif()
