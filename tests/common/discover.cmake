# cmake -D EXE=... -D OUT=... -P discover.cmake
# Writes the cases `EXE --list` prints (see cases.cmake) as the list lt_cases, which the
# program's include file (cases.cmake) turns into one add_test each.
execute_process(COMMAND ${EXE} --list OUTPUT_VARIABLE listing RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "${EXE} --list failed (${rc})")
endif()
string(REPLACE "\n" ";" lines "${listing}")
set(cases "")
foreach(line IN LISTS lines)
  if(NOT line STREQUAL "")
    list(APPEND cases "${line}")
  endif()
endforeach()
if(cases STREQUAL "")
  message(FATAL_ERROR "${EXE} --list printed no case")
endif()
file(WRITE ${OUT} "set(lt_cases \"${cases}\")\n")
