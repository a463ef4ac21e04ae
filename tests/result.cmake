# The one result-code space (server/include/lagsim/result.h): its table, the loader's and
# the client's codes in it, and every program's documented exit statuses against it.
find_program(LAGSIM_PYTHON3 python3 REQUIRED)
add_executable(test_result ${CMAKE_CURRENT_SOURCE_DIR}/result/test_result.c)
target_include_directories(test_result PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/common)
target_link_libraries(test_result PRIVATE lagsimd_internal lagsim_client)
add_test(NAME result_codes COMMAND test_result)
add_test(NAME result_exit_docs
         COMMAND ${LAGSIM_PYTHON3} ${CMAKE_CURRENT_SOURCE_DIR}/result/exit_docs.py
                 $<TARGET_FILE:test_result> ${CMAKE_BINARY_DIR}/bin ${CMAKE_SOURCE_DIR}/docs/man
                 ${CMAKE_SOURCE_DIR})
add_test(NAME result_returns
         COMMAND ${LAGSIM_PYTHON3} ${CMAKE_CURRENT_SOURCE_DIR}/result/returns.py
                 ${CMAKE_SOURCE_DIR})
set_tests_properties(result_codes result_exit_docs result_returns PROPERTIES TIMEOUT 60
                     LABELS result)
