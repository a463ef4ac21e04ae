# One ctest per case of a test program, made from the program's own case table.
#
#   lagsim_add_test_cases(TARGET PREFIX LABEL TIMEOUT [ARG...])
#
# After TARGET is built, `TARGET --list` prints its cases ("name" or "name slow"); each
# becomes the ctest PREFIX_name running `TARGET name ARG...` (ARGs may be generator
# expressions, e.g. $<TARGET_FILE:lagsimd>), labelled LABEL (plus "slow" where the
# program says so) and its tier (tests/common/tiers.cmake, read by ctest). A case added to a program's table (or a model added to the core's
# table, for programs whose cases are made from it) is therefore a ctest without being
# listed here. Until the program is built, a single PREFIX_not_built test fails.
# Test names: lowercase words joined by "_", never "." (the ctest structure_names holds
# every name to that rule).
include_guard(GLOBAL)

function(lagsim_add_test_cases target prefix label timeout)
  set(cases_file ${CMAKE_CURRENT_BINARY_DIR}/${target}_cases.cmake)
  set(include_file ${CMAKE_CURRENT_BINARY_DIR}/${target}_include.cmake)
  add_custom_command(TARGET ${target} POST_BUILD
    COMMAND ${CMAKE_COMMAND} -D EXE=$<TARGET_FILE:${target}> -D OUT=${cases_file}
            -P ${CMAKE_CURRENT_FUNCTION_LIST_DIR}/discover.cmake
    BYPRODUCTS ${cases_file}
    VERBATIM)
  set(args "")
  foreach(a IN LISTS ARGN)
    string(APPEND args " [==[${a}]==]")
  endforeach()
  # Read by ctest: the case list the program printed, one add_test per case.
  file(GENERATE OUTPUT ${include_file} CONTENT
"include(\"${CMAKE_CURRENT_FUNCTION_LIST_DIR}/tiers.cmake\")
if(EXISTS \"${cases_file}\")
  include(\"${cases_file}\")
  foreach(lt_line IN LISTS lt_cases)
    string(REPLACE \" \" \";\" lt_words \"\${lt_line}\")
    list(GET lt_words 0 lt_case)
    string(REPLACE \".\" \"_\" lt_name \"${prefix}_\${lt_case}\")
    set(lt_labels ${label})
    list(LENGTH lt_words lt_nwords)
    if(lt_nwords GREATER 1)
      list(GET lt_words 1 lt_extra)
      list(APPEND lt_labels \${lt_extra})
    endif()
    lagsim_tier_of(\${lt_name} \"\${lt_labels}\" lt_tier)
    lagsim_tier_run(\"\${lt_tier}\" lt_run)
    list(APPEND lt_labels \${lt_tier})
    list(REMOVE_DUPLICATES lt_labels)
    add_test(\${lt_name} \"$<TARGET_FILE:${target}>\" \${lt_case}${args})
    set_tests_properties(\${lt_name} PROPERTIES TIMEOUT ${timeout} SKIP_RETURN_CODE 77
                         LABELS \"\${lt_labels}\" \${lt_run})
  endforeach()
else()
  add_test(${prefix}_not_built \"${CMAKE_COMMAND}\" -E false)
  lagsim_tier_of(${prefix}_not_built \"${label}\" lt_tier)
  set_tests_properties(${prefix}_not_built PROPERTIES LABELS \"${label};\${lt_tier}\")
endif()
")
  set_property(DIRECTORY APPEND PROPERTY TEST_INCLUDE_FILES ${include_file})
endfunction()
