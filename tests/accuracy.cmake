# Accuracy as a setting (server/accuracy): the integrator setting chosen for an error E on
# every shipped scene stays within E of an independent reference (tests/accuracy/).
add_executable(test_accuracy_cost ${CMAKE_CURRENT_LIST_DIR}/accuracy/test_cost.c)
target_include_directories(test_accuracy_cost PRIVATE ${CMAKE_CURRENT_LIST_DIR}/common)
target_compile_definitions(test_accuracy_cost PRIVATE LAGSIM_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
target_link_libraries(test_accuracy_cost PRIVATE lagsim_accuracy lagsim_scene lagsim_core m)
lagsim_add_test_cases(test_accuracy_cost accuracy_cost accuracy 300)

# The live error estimate against the true per-period error (tests/accuracy/test_live_error.c).
add_executable(test_accuracy_live ${CMAKE_CURRENT_LIST_DIR}/accuracy/test_live_error.c)
target_include_directories(test_accuracy_live PRIVATE ${CMAKE_CURRENT_LIST_DIR}/common)
target_compile_definitions(test_accuracy_live PRIVATE LAGSIM_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
target_link_libraries(test_accuracy_live PRIVATE lagsim_scene lagsim_core m)
lagsim_add_test_cases(test_accuracy_live accuracy_live accuracy 300)

# What accuracy cannot know, through lagsimd (tests/accuracy/horizon.sh): a horizon beyond
# the scene's predictability refused in real time with the horizon it can honour, --cost
# over that horizon, --plot of a scene that asks for no error. Its calibrations are timed:
# not in the sanitizer build, whose CPU budget they would spend before the finest settings.
if(NOT LAGSIM_SANITIZE)
  add_test(NAME accuracy_horizon
           COMMAND ${LAGSIM_BASH} ${CMAKE_CURRENT_LIST_DIR}/accuracy/horizon.sh
                   $<TARGET_FILE:lagsimd> ${PROJECT_SOURCE_DIR}/config)
  set_tests_properties(accuracy_horizon PROPERTIES TIMEOUT 300 LABELS accuracy)
endif()
