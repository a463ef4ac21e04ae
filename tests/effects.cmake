# Effects and hard cases: each effect against an independent expectation, and the "hard
# cases stay numerically stable" suite. Plain C programs, see tests/effects/; one ctest per
# case (effects_<case>, hard_<case>), the cases listed by the programs themselves. Cases
# the program marks slow (hard_long_horizon) carry the label "slow", which the sanitizer
# pass of tests/run.sh skips. Timeouts leave room for the sanitizer build on a loaded
# 2-core machine (hard_spin alone takes some 130 s there).
foreach(t effects hard flight)
  add_executable(test_${t} ${CMAKE_CURRENT_SOURCE_DIR}/effects/test_${t}.c)
  target_include_directories(test_${t} PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/effects
                                               ${CMAKE_CURRENT_SOURCE_DIR}/common)
  target_link_libraries(test_${t} PRIVATE lagsim_core m)
endforeach()
lagsim_add_test_cases(test_effects effects effects 300)
lagsim_add_test_cases(test_hard hard effects 900)
lagsim_add_test_cases(test_flight effects_flight effects 600)
