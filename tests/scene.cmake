# Scene loader, lagsimd's command line and offline runs.
# Shell scripts in tests/scene/ drive the lagsimd binary; bad-scene fixtures in
# tests/scene/bad/ carry their own expectations ("# expect-at: L:C", "# expect: ...").
find_program(LAGSIM_BASH bash REQUIRED)
set(scene_dir ${CMAKE_CURRENT_SOURCE_DIR}/scene)
set(scene_cfg ${CMAKE_SOURCE_DIR}/config)

file(GLOB scene_bad_fixtures CONFIGURE_DEPENDS ${scene_dir}/bad/*.yaml)
list(SORT scene_bad_fixtures)
foreach(f ${scene_bad_fixtures})
  get_filename_component(name ${f} NAME_WE)
  add_test(NAME scene_bad_${name}
           COMMAND ${LAGSIM_BASH} ${scene_dir}/expect_error.sh $<TARGET_FILE:lagsimd> ${f})
  set_tests_properties(scene_bad_${name} PROPERTIES TIMEOUT 20 LABELS scene)
endforeach()

add_test(NAME scene_set_overrides
         COMMAND ${LAGSIM_BASH} ${scene_dir}/set_overrides.sh $<TARGET_FILE:lagsimd>
                 ${scene_cfg} ${scene_dir}/expect_error.sh)
add_test(NAME scene_offline_csv
         COMMAND ${LAGSIM_BASH} ${scene_dir}/offline_csv.sh $<TARGET_FILE:lagsimd> ${scene_cfg})
add_test(NAME scene_determinism
         COMMAND ${LAGSIM_BASH} ${scene_dir}/determinism.sh $<TARGET_FILE:lagsimd>
                 ${scene_cfg}/dipc.yaml)
add_test(NAME scene_limits
         COMMAND ${LAGSIM_BASH} ${scene_dir}/limits.sh $<TARGET_FILE:lagsimd> ${scene_dir}/expect_error.sh)
add_test(NAME scene_cli
         COMMAND ${LAGSIM_BASH} ${scene_dir}/cli.sh $<TARGET_FILE:lagsimd> ${scene_cfg}/dipc.yaml)
add_test(NAME scene_accuracy
         COMMAND ${LAGSIM_BASH} ${scene_dir}/accuracy.sh $<TARGET_FILE:lagsimd> ${scene_cfg})
# every shipped scene at three errors, lagsimd --offline with integrator.error alone against
# an independent reference (its calibration is timed: not in the sanitizer build, whose
# CPU budget it would spend before reaching the finest settings)
if(NOT LAGSIM_SANITIZE)
  add_test(NAME scene_accuracy_all
           COMMAND ${LAGSIM_BASH} ${scene_dir}/accuracy_all.sh $<TARGET_FILE:lagsimd> ${scene_cfg})
  set_tests_properties(scene_accuracy_all PROPERTIES TIMEOUT 300 LABELS "scene;accuracy")
endif()
# every scene in config/ (listed when the test runs) waits at t = 0 for the first command
add_test(NAME scene_shipped_wait
         COMMAND ${LAGSIM_BASH} ${scene_dir}/shipped_wait.sh $<TARGET_FILE:lagsimd> ${scene_cfg})
set_tests_properties(scene_set_overrides scene_offline_csv scene_determinism scene_cli scene_limits
                     scene_accuracy scene_shipped_wait PROPERTIES TIMEOUT 60 LABELS scene)

# The loader under libFuzzer (tests/fuzz/fuzz_scene.c): file bytes plus --set overrides,
# then the core on what was accepted. Inputs: tests/fuzz/scene/{corpus,crash}, written by
# tests/fuzz/scene/make_inputs.sh.
lagsim_fuzz_target(scene LIBS lagsim_scene)

# Every numeric key of the loader's tables, for every model, refuses +-1e300 at its
# file:line:column (tests/scene/test_ranges.c).
add_executable(test_scene_ranges ${scene_dir}/test_ranges.c)
target_include_directories(test_scene_ranges PRIVATE ${CMAKE_CURRENT_LIST_DIR}/common)
target_link_libraries(test_scene_ranges PRIVATE lagsim_scene)
lagsim_add_test_cases(test_scene_ranges scene scene 60)

# The core's effect table against its consumers: the loader's keys, the scene message,
# what replay takes as stateless, the browser view, the docs' tables (tests/scene/test_tables.c).
add_executable(test_scene_tables ${scene_dir}/test_tables.c)
target_include_directories(test_scene_tables PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/common)
target_compile_definitions(test_scene_tables PRIVATE LAGSIM_SOURCE_DIR="${CMAKE_SOURCE_DIR}")
target_link_libraries(test_scene_tables PRIVATE lagsimd_internal)
lagsim_add_test_cases(test_scene_tables scene_tables scene 60)

# One rule, one place: a value the core refuses is refused with the core's message at the
# key's file:line:column, for every numeric key and model (tests/scene/test_checks.c).
add_executable(test_scene_checks ${scene_dir}/test_checks.c)
target_include_directories(test_scene_checks PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/common)
target_link_libraries(test_scene_checks PRIVATE lagsim_scene)
lagsim_add_test_cases(test_scene_checks scene_checks scene 60)
