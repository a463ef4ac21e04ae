# One ctest per case of a test program, made from the program's own case table.
#
#   lagsim_add_test_cases(TARGET PREFIX LABEL TIMEOUT)
#
# After TARGET is built, `TARGET --list` prints its cases ("name" or "name slow"); each
# becomes the ctest PREFIX.name running `TARGET name`, labelled LABEL (plus "slow" where
# the program says so). A case added to a program's table (or a model added to the
# core's table, for programs whose cases are made from it) is therefore a ctest without
# being listed here. Until the program is built, a single PREFIX.NOT_BUILT test fails.
include_guard(GLOBAL)

function(lagsim_add_test_cases target prefix label timeout)
  set(cases_file ${CMAKE_CURRENT_BINARY_DIR}/${target}_cases.cmake)
  set(include_file ${CMAKE_CURRENT_BINARY_DIR}/${target}_include.cmake)
  add_custom_command(TARGET ${target} POST_BUILD
    COMMAND ${CMAKE_COMMAND} -D EXE=$<TARGET_FILE:${target}> -D OUT=${cases_file}
            -D PREFIX=${prefix} -D LABEL=${label} -D TIMEOUT=${timeout}
            -P ${CMAKE_CURRENT_FUNCTION_LIST_DIR}/discover.cmake
    BYPRODUCTS ${cases_file}
    VERBATIM)
  file(WRITE ${include_file}
    "if(EXISTS \"${cases_file}\")\n"
    "  include(\"${cases_file}\")\n"
    "else()\n"
    "  add_test(${prefix}.NOT_BUILT \"${CMAKE_COMMAND}\" -E false)\n"
    "endif()\n")
  set_property(DIRECTORY APPEND PROPERTY TEST_INCLUDE_FILES ${include_file})
endfunction()
