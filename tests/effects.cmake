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

# Hard cases. long_horizon (10^8 ticks, ~8 s here, minutes under the sanitizers) is
# labelled slow so that the sanitizer pass of tests/run.sh skips it.
if(TARGET test_hard)
  foreach(arg chaos spin release tiny_inertia manip_limits stiff friction_driven long_horizon)
    add_test(NAME hard.${arg} COMMAND test_hard ${arg})
    set_tests_properties(hard.${arg} PROPERTIES TIMEOUT 300 LABELS effects)
  endforeach()
  set_tests_properties(hard.long_horizon PROPERTIES LABELS "effects;slow")
endif()
