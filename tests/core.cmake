# Physics tests of the core: models vs T and U, structure (SPD, skew, power), conservation,
# convergence orders, determinism. Plain C programs, see tests/core/; one ctest per case of
# each program (core_<program>_<case>), the cases listed by the programs themselves.
foreach(t models structure conservation convergence determinism validate faults events)
  add_executable(test_core_${t} ${CMAKE_CURRENT_SOURCE_DIR}/core/test_${t}.c)
  # server/core: the unit tests of the core's internals (tables, event engine) read its
  # private header
  target_include_directories(test_core_${t} PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/core
                                                    ${CMAKE_CURRENT_SOURCE_DIR}/common
                                                    ${PROJECT_SOURCE_DIR}/server/core)
  target_link_libraries(test_core_${t} PRIVATE lagsim_core m)
  lagsim_add_test_cases(test_core_${t} core_${t} core 300)
endforeach()

# The core from definitions made of arbitrary bytes (tests/fuzz/fuzz_sim.c): its corpus
# inputs and every input that once crashed or hung it, each build; fuzzed for a bounded
# time under LAGSIM_FUZZ=ON (tests/fuzz/fuzz.cmake).
lagsim_fuzz_target(sim LIBS lagsim_core m)
