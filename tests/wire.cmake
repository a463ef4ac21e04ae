# The wire module (server/wire): bounded encoding/decoding of every lagsim message type and
# the bounded LCM log reader.
# Label wire; one ctest per case of each program's table.
add_executable(test_wire ${CMAKE_CURRENT_LIST_DIR}/wire/test_wire.c)
target_include_directories(test_wire PRIVATE ${CMAKE_CURRENT_LIST_DIR}/common)
target_link_libraries(test_wire PRIVATE lagsim_wire lagsim_lcmtypes)
lagsim_add_test_cases(test_wire wire wire 60 ${PROJECT_SOURCE_DIR}/lcmtypes)

add_executable(test_log ${CMAKE_CURRENT_LIST_DIR}/wire/test_log.c)
target_include_directories(test_log PRIVATE ${CMAKE_CURRENT_LIST_DIR}/common)
target_link_libraries(test_log PRIVATE lagsim_wire PkgConfig::LCM)
lagsim_add_test_cases(test_log wire_log wire 120)

# lagsimd --replay on good and hostile logs written by the test (no crash, no hang, no
# leak, no success reported without a check).
add_executable(test_replay ${CMAKE_CURRENT_LIST_DIR}/wire/test_replay.c)
target_include_directories(test_replay PRIVATE ${CMAKE_CURRENT_LIST_DIR}/common)
target_link_libraries(test_replay PRIVATE lagsim_scene lagsim_core lagsim_lcmtypes)
lagsim_add_test_cases(test_replay wire_replay wire 120 $<TARGET_FILE:lagsimd>
                      ${PROJECT_SOURCE_DIR}/config/dipc.yaml)

# Fuzz targets (tests/fuzz/fuzz_<name>.c; corpora and kept crash inputs under tests/fuzz/<name>/,
# written by tests/fuzz/make_corpora.py): the wire module's decoders and encoders, the log
# reader, and --replay end to end.
lagsim_fuzz_target(wire LIBS lagsim_wire)
lagsim_fuzz_target(log LIBS lagsim_wire)
lagsim_fuzz_target(replay LIBS lagsimd_internal)
target_compile_definitions(fuzz_replay PRIVATE LAGSIM_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
# The kept inputs above are messages of today's types: a field added to a .lcm file changes
# its fingerprint, and an input written before then stops at the fingerprint and tests
# nothing it is named for. make_corpora.py --check encodes each again with the types of this
# build and fails on every kept input that differs.
find_program(LAGSIM_PYTHON3 python3)
if(LAGSIM_PYTHON3)
  add_test(NAME fuzz_corpora_current
           COMMAND ${LAGSIM_PYTHON3} ${LAGSIM_FUZZ_DIR}/make_corpora.py ${CMAKE_BINARY_DIR} --check)
  set_tests_properties(fuzz_corpora_current PROPERTIES TIMEOUT 120 LABELS fuzz)
endif()

# The one LCM URL reader (server/wire/lagsim_url.c) and its two users, the plant's URLs and
# a scene's lcm.url, on one table of URLs (tests/wire/test_url.c).
add_executable(test_url ${CMAKE_CURRENT_LIST_DIR}/wire/test_url.c)
target_include_directories(test_url PRIVATE ${CMAKE_CURRENT_LIST_DIR}/common)
target_link_libraries(test_url PRIVATE lagsim_scene lagsim_wire_base)
foreach(case bus scene one_rule fields)
  add_test(NAME wire_url_${case} COMMAND test_url ${case})
  set_tests_properties(wire_url_${case} PROPERTIES TIMEOUT 30 LABELS wire)
endforeach()

# Pairs of UDP ports held by lock files (server/wire/lagsim_port.c), the evaluation tools'
# buses: never shared by two holders, across processes and users; never one a socket of
# this host is bound to; no hang on a lock file that cannot be one (tests/wire/test_port.c).
add_executable(test_port ${CMAKE_CURRENT_LIST_DIR}/wire/test_port.c)
target_include_directories(test_port PRIVATE ${CMAKE_CURRENT_LIST_DIR}/common)
target_link_libraries(test_port PRIVATE lagsim_wire_base)
lagsim_add_test_cases(test_port wire_port wire 120)

# How a number is printed to read back (server/wire/lagsim_num.c): the shortest decimal
# that strtod reads back to the same double (tests/wire/test_num.c).
add_executable(test_num ${CMAKE_CURRENT_LIST_DIR}/wire/test_num.c)
target_include_directories(test_num PRIVATE ${CMAKE_CURRENT_LIST_DIR}/common)
target_link_libraries(test_num PRIVATE lagsim_wire_base)
lagsim_add_test_cases(test_num wire_num wire 60)

# One clock, one URL reader, one table of channel suffixes in the wire layer
# (tests/wire/one_place.py): a second copy anywhere in server/, clients/ or bench/ fails.
find_program(LAGSIM_WIRE_PYTHON3 python3)
if(LAGSIM_WIRE_PYTHON3)
  foreach(check clock url channels num)
    add_test(NAME wire_one_place_${check}
             COMMAND ${LAGSIM_WIRE_PYTHON3} ${CMAKE_CURRENT_LIST_DIR}/wire/one_place.py
                     ${PROJECT_SOURCE_DIR} ${check})
    set_tests_properties(wire_one_place_${check} PROPERTIES TIMEOUT 30 LABELS wire)
  endforeach()
endif()
