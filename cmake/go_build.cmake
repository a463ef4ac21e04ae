# cmake -DGO=go -DOUTPUT=FILE -DSOURCE=FILE.go "-DINPUTS=HEADER|...|LIBRARY" "-DENV=K=V|..."
#       -P go_build.cmake        (lists joined by |: a ; would split the custom command's word)
# `go build -o OUTPUT SOURCE` with the environment ENV, its cgo objects keyed on the C files
# cgo reads or links outside the Go package (INPUTS: the client library's headers and the
# library). Go's build cache hashes the Go sources, the package directory's C files and
# the cgo flags, but not a header included from another directory nor a library linked:
# after a new lagsim_client.h (another LAGSIM_VERSION_NUMBER, a struct grown), a plain
# `go build` reuses the cgo objects compiled against the old one. The SHA-256 of INPUTS goes
# into CGO_CPPFLAGS as -DLAGSIM_CGO_INPUTS=<hash>, which the cache key includes: changed
# inputs are compiled again, unchanged ones still come from the cache (`go build -a` would
# rebuild the standard library every time).
foreach(v GO OUTPUT SOURCE INPUTS)
  if(NOT DEFINED ${v})
    message(FATAL_ERROR "go_build.cmake: -D${v}=... is required")
  endif()
endforeach()
string(REPLACE "|" ";" INPUTS "${INPUTS}")
string(REPLACE "|" ";" ENV "${ENV}")
set(key "")
foreach(f IN LISTS INPUTS)
  if(NOT EXISTS "${f}")
    message(FATAL_ERROR "go_build.cmake: ${f}: no such file")
  endif()
  file(SHA256 "${f}" h)
  string(APPEND key "${f}=${h};")
endforeach()
string(SHA256 key "${key}")
string(SUBSTRING "${key}" 0 32 key)
execute_process(
  COMMAND ${CMAKE_COMMAND} -E env ${ENV} "CGO_CPPFLAGS=-DLAGSIM_CGO_INPUTS=${key}"
          ${GO} build -o ${OUTPUT} ${SOURCE}
  RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "go build ${SOURCE}: failed (${rc})")
endif()
