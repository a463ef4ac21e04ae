# The wire protocol's conformance traces (docs/protocol.md): tests/protocol/play.py plays
# the daemon's side of each trace of tests/protocol/traces/ against each language's
# conformance controller (tests/protocol/conformance/: the conformance law written with
# that language's client library), one ctest per language and trace,
# protocol_<language>_<trace>. A binding added later adds its controller with
# protocol_conformance(<language> <command line with {prefix} and {url}>).
# tests/protocol/minimal.py, a controller written from docs/protocol.md alone, passes
# every trace (protocol_minimal_<trace>); broken on purpose (--break RULE) it must fail each
# trace at the step that guards that rule (protocol_broken_<trace>_<rule>).
# Label clients; the JVM's and Octave's, minimal.py's and the broken ones also slow: they
# run no C code of lagsim (the sanitizer pass would check nothing in them, so it leaves them
# out), and the JVM's start a JVM each.
if(NOT LAGSIM_PYTHON3)
  return()
endif()
set(proto_dir ${CMAKE_CURRENT_SOURCE_DIR}/protocol)
set(proto_play ${LAGSIM_PYTHON3} ${proto_dir}/play.py --types ${CMAKE_BINARY_DIR}/python -q)
file(GLOB proto_traces CONFIGURE_DEPENDS ${proto_dir}/traces/*.trace)
list(FILTER proto_traces EXCLUDE REGEX "/common\\.trace$")

# protocol_conformance(LANG LABELS COMMAND...): a ctest per trace for LANG's controller.
function(protocol_conformance lang labels)
  foreach(trace IN LISTS proto_traces)
    get_filename_component(name ${trace} NAME_WE)
    add_test(NAME protocol_${lang}_${name} COMMAND ${proto_play} ${trace} -- ${ARGN})
    set_tests_properties(protocol_${lang}_${name} PROPERTIES TIMEOUT 120 LABELS "${labels}")
  endforeach()
endfunction()

# The C client library (clients/lagsim_client.h)
add_executable(conformance_c ${proto_dir}/conformance/conformance.c)
target_link_libraries(conformance_c PRIVATE lagsim_client)
protocol_conformance(c clients $<TARGET_FILE:conformance_c> --prefix {prefix} --url {url})

# C++ (clients/lagsim_client.hpp over the C library)
add_executable(conformance_cpp ${proto_dir}/conformance/conformance.cpp)
target_link_libraries(conformance_cpp PRIVATE lagsim_client)
protocol_conformance(cpp clients $<TARGET_FILE:conformance_cpp> --prefix {prefix} --url {url})

# Python (clients/python/lagsim_controller.py)
protocol_conformance(python clients ${LAGSIM_PYTHON3} ${proto_dir}/conformance/conformance.py
  --types ${CMAKE_BINARY_DIR}/python --prefix {prefix} --url {url})

# Lua 5.2 (clients/lua/lagsim_controller.lua)
if(LAGSIM_LUA52 AND EXISTS /usr/lib/lua/5.2/lcm.so AND TARGET lagsim_client_lua)
  protocol_conformance(lua clients ${LAGSIM_LUA52} ${proto_dir}/conformance/conformance.lua
    --types ${CMAKE_BINARY_DIR}/lua --prefix {prefix} --url {url})
endif()

# Go, through the C ABI alone (cgo over liblagsim_client.so.1: clients/go/CMakeLists.txt);
# built when the go command is found (Debian golang-go), as the Go example is
if(COMMAND lagsim_go_program)
  lagsim_go_program(conformance_go ${CMAKE_CURRENT_BINARY_DIR}/conformance_go
                    ${proto_dir}/conformance/conformance.go)
  protocol_conformance(go clients ${CMAKE_CURRENT_BINARY_DIR}/conformance_go --prefix {prefix} --url {url})
endif()

# Java (lagsim.examples.Controller), compiled as the examples are (lint as errors)
if(TARGET lagsim_examples_java)
  set(proto_classes ${CMAKE_CURRENT_BINARY_DIR}/protocol_java)
  add_custom_command(
    OUTPUT ${proto_classes}/Conformance.class
    COMMAND ${CMAKE_COMMAND} -E make_directory ${proto_classes}
    COMMAND ${JAVAC} --release ${LAGSIM_JAVA_RELEASE} -Xlint:all -Werror
            -cp /usr/share/java/lcm.jar:${CMAKE_BINARY_DIR}/lagsim_types.jar:${LAGSIM_EXAMPLES_JAR}
            -d ${proto_classes} ${proto_dir}/conformance/Conformance.java
    DEPENDS ${proto_dir}/conformance/Conformance.java ${LAGSIM_EXAMPLES_JAR}
    COMMENT "javac: the Java conformance controller")
  add_custom_target(conformance_java ALL DEPENDS ${proto_classes}/Conformance.class)
  add_dependencies(conformance_java lagsim_examples_java)
  protocol_conformance(java "clients;slow" java -cp
    /usr/share/java/lcm.jar:${CMAKE_BINARY_DIR}/lagsim_types.jar:${CMAKE_BINARY_DIR}/lagsim_examples.jar:${proto_classes}
    Conformance --prefix {prefix} --url {url})
  # MATLAB/Octave (clients/octave/lagsim_controller.m), under GNU Octave
  if(LAGSIM_OCTAVE)
    protocol_conformance(octave "clients;slow" ${LAGSIM_OCTAVE} --no-gui --quiet --no-window-system
      --no-init-file --path ${CMAKE_BINARY_DIR}/octave --path ${proto_dir}/conformance
      --eval "conformance('--prefix', '{prefix}', '--url', '{url}')")
  endif()
endif()

# A controller from docs/protocol.md alone passes every trace ...
set(proto_minimal ${LAGSIM_PYTHON3} ${proto_dir}/minimal.py --types ${CMAKE_BINARY_DIR}/python
    --prefix {prefix} --url {url})
protocol_conformance(minimal "clients;slow" ${proto_minimal})
# ... and, broken on purpose, fails each at the step that guards the rule it breaks:
# TRACE:RULE:STEP
foreach(neg
    "start:describe:asks_scene"
    "lockstep:stamp:answer_s0"
    "copies:copies:copy_same_bytes"
    "lost:silent:lost_answer_again"
    "new_generation:generation:new_generation_answered"
    "scene_lost:hold:held_until_scene"
    "set:generation:set_answered_anew"
    "stale_generation:forever:stops_asking"
    "forged:trailing:forged_states_dropped"
    "forged:nan:forged_states_dropped"
    "foreign:foreign:foreign_dropped"
    "old_version:old:old_dropped"
    "stop:stop:ends_on_stop"
    "faults:events:runs_on"
    "directory:directory:asks_plant_url")
  string(REPLACE ":" ";" n "${neg}")
  list(GET n 0 trace)
  list(GET n 1 rule)
  list(GET n 2 step)
  add_test(NAME protocol_broken_${trace}_${rule}
    COMMAND ${proto_play} --expect-failure ${step} ${proto_dir}/traces/${trace}.trace
      -- ${proto_minimal} --break ${rule})
  set_tests_properties(protocol_broken_${trace}_${rule} PROPERTIES TIMEOUT 120 LABELS "clients;slow")
endforeach()

# The traces read, use only play.py's steps and their own messages; docs/protocol.md's
# tables of traces and of steps are the directory's and the player's; every trace has its
# negative test above, with the rule the table names; the earlier versions' fingerprints
# forged are docs/wire.md's (tests/protocol/check_traces.py).
add_test(NAME protocol_traces COMMAND ${LAGSIM_PYTHON3} ${proto_dir}/check_traces.py ${PROJECT_SOURCE_DIR})
set_tests_properties(protocol_traces PROPERTIES TIMEOUT 30 LABELS clients)
