# cmake -DDIR=<python dir> -P py_bool_lists.cmake: lcm-gen 1.3.1's Python decoder returns a
# boolean array as `map(bool, ...)`, which under Python 3 is a one-shot iterator, not the
# list every other array is (scene_t.actuated printed as "<map object at 0x...>", read
# once, then empty). Every such line of the generated types becomes list(map(bool, ...)).
file(GLOB _files ${DIR}/lagsim/*.py)
foreach(f ${_files})
  file(READ ${f} s)
  string(REGEX REPLACE "= map\\(bool, ([^\n]*)\n" "= list(map(bool, \\1)\n" t "${s}")
  if(NOT t STREQUAL s)
    file(WRITE ${f} "${t}")
  endif()
endforeach()
