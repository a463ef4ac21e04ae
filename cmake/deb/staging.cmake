# CPack pre-build script (CPACK_PRE_BUILD_SCRIPTS, cmake/LagsimPackage.cmake): what
# debhelper would do to the staged tree before it becomes a .deb. The install rules stay
# as `cmake --install` runs them; this adds only what Debian asks of a package:
#   - man pages gzipped with -9n (dh_compress; lintian: uncompressed-manual-page);
#   - /usr/share/doc/lagsim/copyright and changelog.gz (lintian: no-copyright-file,
#     no-changelog).
set(root "${CPACK_TEMPORARY_DIRECTORY}")
if(NOT IS_DIRECTORY "${root}/usr/bin")
  message(FATAL_ERROR "lagsim staging: ${root}/usr/bin missing (CPack's staging layout changed?)")
endif()

file(GLOB_RECURSE man "${root}/usr/share/man/*.[1-9]")
foreach(m ${man})
  execute_process(COMMAND gzip -9nf "${m}" RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "lagsim staging: gzip ${m} failed")
  endif()
endforeach()

set(doc "${root}/usr/share/doc/lagsim")
file(MAKE_DIRECTORY "${doc}")
string(TIMESTAMP year "%Y" UTC)
file(WRITE "${doc}/copyright" "lagsim: a real-time simulation server for Lagrangian models over LCM.

Copyright (C) ${year} the lagsim authors.

License: the project has not stated a license yet.

The Debian package was made with CPack from the lagsim source tree
(cmake/LagsimPackage.cmake).
")
string(TIMESTAMP date "%a, %d %b %Y %H:%M:%S +0000" UTC)   # honours SOURCE_DATE_EPOCH
file(WRITE "${doc}/changelog" "lagsim (${CPACK_PACKAGE_VERSION}) unstable; urgency=medium

  * Built from the lagsim source tree with CPack.

 -- ${CPACK_LAGSIM_MAINTAINER}  ${date}
")
execute_process(COMMAND gzip -9nf "${doc}/changelog" RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "lagsim staging: gzip changelog failed")
endif()
file(CHMOD "${doc}" DIRECTORY_PERMISSIONS OWNER_READ OWNER_WRITE OWNER_EXECUTE
     GROUP_READ GROUP_EXECUTE WORLD_READ WORLD_EXECUTE)
file(CHMOD "${doc}/copyright" "${doc}/changelog.gz" PERMISSIONS OWNER_READ OWNER_WRITE
     GROUP_READ WORLD_READ)
