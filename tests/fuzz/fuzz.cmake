# Fuzz targets and their kept inputs (SQLite's habit: every input that once crashed stays a
# regression test). A target is tests/fuzz/fuzz_<name>.c defining LLVMFuzzerTestOneInput;
# its inputs are tests/fuzz/<name>/corpus/ (starting corpus) and tests/fuzz/<name>/crash/
# (inputs that once crashed, hung or leaked).
#
#   lagsim_fuzz_target(<name> [SOURCES extra.c ...] [LIBS target ...])
#
# Every build: fuzz_<name> linked with a small replay driver, and the ctest
# fuzz_<name>_corpus that runs every kept input once. With LAGSIM_FUZZ=ON (clang): the
# target is linked with libFuzzer, and fuzz_<name>_run fuzzes for LAGSIM_FUZZ_SECONDS
# from a copy of the corpus in the build tree (new inputs never dirty the checkout).
set(LAGSIM_FUZZ_DIR ${CMAKE_CURRENT_LIST_DIR})
set(LAGSIM_FUZZ_SECONDS 25 CACHE STRING "seconds each fuzz_<name>_run test fuzzes (LAGSIM_FUZZ=ON)")

function(lagsim_fuzz_target name)
  cmake_parse_arguments(F "" "" "SOURCES;LIBS" ${ARGN})
  set(src ${LAGSIM_FUZZ_DIR}/fuzz_${name}.c)
  set(corpus ${LAGSIM_FUZZ_DIR}/${name}/corpus)
  set(crash ${LAGSIM_FUZZ_DIR}/${name}/crash)
  if(NOT EXISTS ${src})
    message(FATAL_ERROR "lagsim_fuzz_target(${name}): ${src} does not exist")
  endif()
  if(NOT EXISTS ${corpus})
    message(FATAL_ERROR "lagsim_fuzz_target(${name}): no corpus at ${corpus}")
  endif()
  set(dirs ${corpus})
  if(EXISTS ${crash})
    list(APPEND dirs ${crash})
  endif()

  if(LAGSIM_FUZZ)
    add_executable(fuzz_${name} ${src} ${F_SOURCES})
    target_link_options(fuzz_${name} PRIVATE -fsanitize=fuzzer)
  else()
    add_executable(fuzz_${name} ${src} ${F_SOURCES} ${LAGSIM_FUZZ_DIR}/replay_main.c)
  endif()
  target_link_libraries(fuzz_${name} PRIVATE ${F_LIBS})

  # Every kept input, once. libFuzzer runs the inputs given when told -runs=0; the replay
  # driver ignores flags.
  add_test(NAME fuzz_${name}_corpus COMMAND fuzz_${name} -runs=0 ${dirs})
  set_tests_properties(fuzz_${name}_corpus PROPERTIES TIMEOUT 300 LABELS fuzz)

  if(LAGSIM_FUZZ)
    # -timeout=25: an input is a hang when one run takes 25 s. Every target runs an input
    # in well under a millisecond; 5 s tripped on machine stalls alone (load average 17).
    set(work ${CMAKE_BINARY_DIR}/fuzz/${name})
    file(MAKE_DIRECTORY ${work}/corpus ${work}/artifacts)
    add_test(NAME fuzz_${name}_run
             COMMAND fuzz_${name} -max_total_time=${LAGSIM_FUZZ_SECONDS} -timeout=25
                     -rss_limit_mb=2048 -print_final_stats=1
                     -artifact_prefix=${work}/artifacts/ ${work}/corpus ${dirs})
    math(EXPR limit "${LAGSIM_FUZZ_SECONDS} * 3 + 120")
    # one at a time, beside the pass's other tests (tests/common/tiers.cmake: fuzz_run)
    set_tests_properties(fuzz_${name}_run PROPERTIES TIMEOUT ${limit} LABELS "fuzz;fuzz_run"
                         RESOURCE_LOCK lagsim_fuzz_run)
  endif()
endfunction()
