# A plant on a network (server/wire/lagsim_bus, the daemon's receive filter and plant
# watch, tests/net): the URL rule in every language, and two hosts on one machine.
add_executable(test_bus ${CMAKE_CURRENT_LIST_DIR}/net/test_bus.c)
target_link_libraries(test_bus PRIVATE lagsim_wire)
add_test(NAME net_plant_urls_c COMMAND test_bus ${CMAKE_CURRENT_LIST_DIR}/net/plant_urls.txt)
set_tests_properties(net_plant_urls_c PROPERTIES TIMEOUT 30 LABELS net)
# The same rule in Python, Lua and Java, against the same table.
find_program(LAGSIM_NET_PYTHON3 python3)
find_program(LAGSIM_NET_LUA52 lua5.2)
find_program(LAGSIM_NET_JAVA java)
if(LAGSIM_NET_PYTHON3)
  add_test(NAME net_plant_urls_python
    COMMAND ${CMAKE_COMMAND} -E env --unset=LCM_DEFAULT_URL ${LAGSIM_NET_PYTHON3}
            ${CMAKE_CURRENT_LIST_DIR}/net/plant_urls.py ${CMAKE_CURRENT_LIST_DIR}/net/plant_urls.txt
            ${PROJECT_SOURCE_DIR}/clients/python)
  set_tests_properties(net_plant_urls_python PROPERTIES TIMEOUT 30 LABELS net)
endif()
if(LAGSIM_NET_LUA52)
  add_test(NAME net_plant_urls_lua
    COMMAND ${CMAKE_COMMAND} -E env --unset=LCM_DEFAULT_URL
            "LUA_PATH=${PROJECT_SOURCE_DIR}/clients/lua/?.lua;;"
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
