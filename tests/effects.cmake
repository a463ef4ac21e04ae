# Effects and hard cases (issue 4): each effect against an independent expectation, and
# the "hard cases stay numerically stable" suite. Plain C programs, see tests/effects/.
foreach(t effects hard)
  if(EXISTS ${CMAKE_CURRENT_SOURCE_DIR}/effects/test_${t}.c)
    add_executable(test_${t} ${CMAKE_CURRENT_SOURCE_DIR}/effects/test_${t}.c)
    target_include_directories(test_${t} PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/effects)
    target_link_libraries(test_${t} PRIVATE lagsim_core m)
  endif()
endforeach()

if(TARGET test_effects)
  foreach(arg damping friction limits floor actuator disturbance noise off)
    add_test(NAME effects.${arg} COMMAND test_effects ${arg})
    set_tests_properties(effects.${arg} PROPERTIES TIMEOUT 120 LABELS effects)
  endforeach()
endif()
