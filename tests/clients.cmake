# Clients (issue 3): LQR design unit test, and end-to-end runs of lagsimd with the C
# LQR client (lockstep and real time) and the Python manipulator controller.
add_executable(test_lqr ${CMAKE_CURRENT_SOURCE_DIR}/clients/test_lqr.c)
target_link_libraries(test_lqr PRIVATE lagsim_lqr lagsim_core m)
add_test(NAME clients_lqr COMMAND test_lqr)
set_tests_properties(clients_lqr PROPERTIES TIMEOUT 30)
