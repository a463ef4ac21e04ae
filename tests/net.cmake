# A plant on a network (server/wire/lagsim_bus, the daemon's receive filter and plant
# watch, tests/net): the URL rule in every language, and two hosts on one machine.
add_executable(test_bus ${CMAKE_CURRENT_LIST_DIR}/net/test_bus.c)
target_include_directories(test_bus PRIVATE ${CMAKE_CURRENT_LIST_DIR}/common)
target_link_libraries(test_bus PRIVATE lagsim_wire)
lagsim_add_test_cases(test_bus net net 30 ${CMAKE_CURRENT_LIST_DIR}/net/plant_urls.txt)
# The same rule in Python, Lua and Java, against the same table.
find_program(LAGSIM_NET_PYTHON3 python3)
find_program(LAGSIM_NET_LUA52 lua5.2)
find_program(LAGSIM_NET_JAVA java)
if(LAGSIM_NET_PYTHON3)
  add_test(NAME net_plant_urls_python
    COMMAND ${CMAKE_COMMAND} -E env --unset=LCM_DEFAULT_URL ${LAGSIM_NET_PYTHON3}
            ${CMAKE_CURRENT_LIST_DIR}/net/plant_urls.py ${CMAKE_CURRENT_LIST_DIR}/net/plant_urls.txt
            ${CMAKE_BINARY_DIR}/python)  # the build's modules, which name the build's library
  set_tests_properties(net_plant_urls_python PROPERTIES TIMEOUT 30 LABELS net)
endif()
if(LAGSIM_NET_LUA52 AND TARGET lagsim_client_lua)
  add_test(NAME net_plant_urls_lua
    COMMAND ${CMAKE_COMMAND} -E env --unset=LCM_DEFAULT_URL
            "LUA_PATH=${CMAKE_BINARY_DIR}/lua/?.lua;;"  # the build's modules, which name its C module
            ${LAGSIM_NET_LUA52} ${CMAKE_CURRENT_LIST_DIR}/net/plant_urls.lua
            ${CMAKE_CURRENT_LIST_DIR}/net/plant_urls.txt)
  set_tests_properties(net_plant_urls_lua PROPERTIES TIMEOUT 30 LABELS net)
endif()
if(LAGSIM_NET_JAVA AND TARGET lagsim_examples_java)
  add_test(NAME net_plant_urls_java
    COMMAND ${CMAKE_COMMAND} -E env --unset=LCM_DEFAULT_URL ${LAGSIM_NET_JAVA}
            -cp /usr/share/java/lcm.jar:${CMAKE_BINARY_DIR}/lagsim_types.jar:${CMAKE_BINARY_DIR}/lagsim_examples.jar
            lagsim.examples.PlantUrls ${CMAKE_CURRENT_LIST_DIR}/net/plant_urls.txt)
  set_tests_properties(net_plant_urls_java PROPERTIES TIMEOUT 60 LABELS net)
endif()
find_program(LAGSIM_NET_OCTAVE octave)
if(LAGSIM_NET_OCTAVE AND TARGET lagsim_examples_java)   # MATLAB/Octave's lagsim_plant_urls
  add_test(NAME net_plant_urls_octave
    COMMAND ${CMAKE_COMMAND} -E env --unset=LCM_DEFAULT_URL ${LAGSIM_NET_OCTAVE} --no-gui --quiet --no-window-system
            --no-init-file --path ${CMAKE_BINARY_DIR}/octave --path ${CMAKE_CURRENT_LIST_DIR}/net
            --eval "plant_urls_octave('${CMAKE_CURRENT_LIST_DIR}/net/plant_urls.txt')")
  set_tests_properties(net_plant_urls_octave PROPERTIES TIMEOUT 60 LABELS net)
endif()

# The daemon's receive-socket filter, its sync marker and the route to the group, on this
# host (tests/net/test_net.c); one ctest per case.
add_executable(test_net ${CMAKE_CURRENT_LIST_DIR}/net/test_net.c)
target_include_directories(test_net PRIVATE ${CMAKE_CURRENT_LIST_DIR}/common)
target_link_libraries(test_net PRIVATE lagsimd_internal)
lagsim_add_test_cases(test_net net_filter net 60)

# Two hosts on one machine (tests/net/two_hosts.sh): network namespaces joined by a veth
# pair, lagsimd in one, peers in the other, nftables for packet loss. Needs root; skipped
# (exit 77) with the reason where namespaces cannot be made.
set(LAGSIM_TWO_HOSTS_CASES host_local lockstep_loss lockstep_loss_octave realtime_loss two_daemons)
foreach(case ${LAGSIM_TWO_HOSTS_CASES})
  add_test(NAME net_two_hosts_${case}
           COMMAND bash ${CMAKE_CURRENT_LIST_DIR}/net/two_hosts.sh ${case} ${CMAKE_BINARY_DIR}
                   ${PROJECT_SOURCE_DIR})
  set_tests_properties(net_two_hosts_${case} PROPERTIES TIMEOUT 300 LABELS net SKIP_RETURN_CODE 77)
endforeach()
