# Physics tests of the core (issue 2): models vs T and U, structure (SPD, skew, power),
# conservation, convergence orders, determinism. Plain C programs, see tests/core/.
set(LAGSIM_CORE_TESTS models structure conservation convergence determinism)
foreach(t ${LAGSIM_CORE_TESTS})
  if(EXISTS ${CMAKE_CURRENT_SOURCE_DIR}/core/test_${t}.c)
    add_executable(test_core_${t} ${CMAKE_CURRENT_SOURCE_DIR}/core/test_${t}.c)
    target_include_directories(test_core_${t} PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/core)
    target_link_libraries(test_core_${t} PRIVATE lagsim_core m)
  endif()
endforeach()

# models: one ctest per model so a failure names the model
if(TARGET test_core_models)
  foreach(arg info stick manipulator dipc)
    add_test(NAME core.models.${arg} COMMAND test_core_models ${arg})
    set_tests_properties(core.models.${arg} PROPERTIES TIMEOUT 60 LABELS core)
  endforeach()
endif()
foreach(t structure conservation convergence determinism)
  if(TARGET test_core_${t})
    add_test(NAME core.${t} COMMAND test_core_${t})
    set_tests_properties(core.${t} PROPERTIES TIMEOUT 120 LABELS core)
  endif()
endforeach()
