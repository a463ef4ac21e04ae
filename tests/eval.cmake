# Controller evaluation (server/eval): reference signals against their closed forms and
# their rates against differences; the metrics against closed forms of first- and
# second-order responses; the --require parser. One ctest per case (eval_<program>_<case>).
foreach(t metrics reference)
  add_executable(test_eval_${t} ${CMAKE_CURRENT_LIST_DIR}/eval/test_${t}.c)
  target_include_directories(test_eval_${t} PRIVATE ${CMAKE_CURRENT_LIST_DIR}/common)
  target_compile_definitions(test_eval_${t} PRIVATE LAGSIM_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
  target_link_libraries(test_eval_${t} PRIVATE lagsim_eval m)
  lagsim_add_test_cases(test_eval_${t} eval_${t} eval 60)
endforeach()

# lagsim-sweep's CSV without a sweep: rows against their header, --shard's parser, the
# identity lines, the scene's SHA-256 against FIPS 180-2's vectors.
add_executable(test_eval_sweep_csv ${CMAKE_CURRENT_LIST_DIR}/eval/test_sweep_csv.c)
target_include_directories(test_eval_sweep_csv PRIVATE ${CMAKE_CURRENT_LIST_DIR}/common)
target_compile_definitions(test_eval_sweep_csv PRIVATE LAGSIM_VERSION="${PROJECT_VERSION}")
target_link_libraries(test_eval_sweep_csv PRIVATE lagsim_sweepcsv)
lagsim_add_test_cases(test_eval_sweep_csv eval_sweep_csv eval 60)
# merge on arbitrary bytes as a shard (fuzz_sweep_merge_corpus; fuzz_sweep_merge_run)
lagsim_fuzz_target(sweep_merge LIBS lagsim_sweepcsv)

# lagsim-eval end to end: the cart-pole held by lqr_balance through a small case set
# (tests/eval/cartpole_cases.yaml); metrics against the logged states, --require's exit
# codes, case files with mistakes.
find_program(LAGSIM_PYTHON3 python3)
if(LAGSIM_PYTHON3)
  foreach(c metrics require errors scene owned outputs bus notes waits stderr)
    add_test(NAME eval_lagsim_eval_${c}
      COMMAND ${LAGSIM_PYTHON3} ${CMAKE_CURRENT_LIST_DIR}/eval/test_eval.py
              $<TARGET_FILE_DIR:lagsim-eval> ${PROJECT_SOURCE_DIR} ${c})
    set_tests_properties(eval_lagsim_eval_${c} PROPERTIES LABELS eval TIMEOUT 300)
  endforeach()
endif()

# A controller that reads its gains from every scene (lagsim-sweep's scene_* cases).
add_executable(scene_pd ${CMAKE_CURRENT_LIST_DIR}/eval/scene_pd.c)
target_link_libraries(scene_pd PRIVATE lagsim_controller)

# lagsim-sweep end to end: 8 runs of the cart-pole over its masses; the CSV the same for
# -j1, -j2, two shards run by GNU parallel and merged, and a Slurm job array's two tasks
# run here with Slurm's variables (no cluster needed); merge's refusals.
find_program(LAGSIM_GNU_PARALLEL parallel)
if(LAGSIM_PYTHON3 AND LAGSIM_GNU_PARALLEL)
  # scene_*, unanswered: a scene-reactive controller (tests/eval/scene_pd.c, scene_pd.py)
  # over m2, one that leaves the paused state unanswered (mute_pd.py)
  foreach(c same slurm merge merge_rows merge_foreign shard kept kept_python loss stalled ssh
          vary scene_c scene_python scene_loss unanswered notes controller_exit
          slow_start progress interrupt tmpdir)
    add_test(NAME eval_lagsim_sweep_${c}
      COMMAND ${LAGSIM_PYTHON3} ${CMAKE_CURRENT_LIST_DIR}/eval/test_sweep.py
              $<TARGET_FILE_DIR:lagsim-sweep> ${PROJECT_SOURCE_DIR} ${c})
    set_tests_properties(eval_lagsim_sweep_${c} PROPERTIES LABELS eval TIMEOUT 600
                         SKIP_RETURN_CODE 77)
  endforeach()
endif()

# Nothing lagsim-eval or lagsim-sweep (-j 2, kept workers) starts outlives it: SIGINT to
# its process group, SIGTERM, SIGKILL, SIGKILL to its group, a stalled run killed (the
# controller deaf to SIGTERM; the sweep's workers stopped) and SIGTERM while gnuplot runs,
# each sent once the run's daemon publishes and its controller answers; 0 processes left
# (found by a marker in their environment), the temporary directory removed on a signal.
if(LAGSIM_PYTHON3)
  foreach(tool eval sweep)
    foreach(how sigint sigterm sigkill groupkill stalled gnuplot)
      add_test(NAME eval_procs_${tool}_${how}
        COMMAND ${LAGSIM_PYTHON3} ${CMAKE_CURRENT_LIST_DIR}/eval/test_procs.py
                $<TARGET_FILE_DIR:lagsim-eval> ${PROJECT_SOURCE_DIR} ${tool} ${how})
      set_tests_properties(eval_procs_${tool}_${how} PROPERTIES LABELS eval TIMEOUT 300)
    endforeach()
  endforeach()
endif()

# docs/evaluation.md's controllers in Python and MATLAB/Octave, run as written
# (tests/clients/readme_recipes.py): the shipped Python DIPC example and the Octave cart-pole
# under lagsim-eval and lagsim-sweep, {prefix} inside Octave's quotes inside the shell's.
# Octave starts a JVM for each case and worker: not in the sanitizer pass (label slow).
if(LAGSIM_PYTHON3)
  add_test(NAME eval_lagsim_eval_docs_python
    COMMAND ${LAGSIM_PYTHON3} ${PROJECT_SOURCE_DIR}/tests/clients/readme_recipes.py
            --build ${CMAKE_BINARY_DIR} --source ${PROJECT_SOURCE_DIR} --timeout 240 eval-python)
  set_tests_properties(eval_lagsim_eval_docs_python PROPERTIES LABELS eval TIMEOUT 300)
  find_program(LAGSIM_EVAL_OCTAVE octave)
  if(LAGSIM_EVAL_OCTAVE AND TARGET lagsim_examples_java)
    add_test(NAME eval_lagsim_eval_docs_octave
      COMMAND ${LAGSIM_PYTHON3} ${PROJECT_SOURCE_DIR}/tests/clients/readme_recipes.py
              --build ${CMAKE_BINARY_DIR} --source ${PROJECT_SOURCE_DIR} --timeout 240 eval-octave)
    set_tests_properties(eval_lagsim_eval_docs_octave PROPERTIES LABELS "eval;slow" TIMEOUT 300)
  endif()
endif()
