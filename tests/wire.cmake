# The wire module (server/wire): bounded encoding/decoding of every lagsim message type and
# the bounded LCM log reader.
add_executable(test_wire ${CMAKE_CURRENT_LIST_DIR}/wire/test_wire.c)
target_link_libraries(test_wire PRIVATE lagsim_wire lagsim_lcmtypes)
add_test(NAME wire_messages COMMAND test_wire ${PROJECT_SOURCE_DIR}/lcmtypes)
set_tests_properties(wire_messages PROPERTIES TIMEOUT 60)
