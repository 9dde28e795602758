# mfree_doxyfile(<out> OUTPUT <dir> WARNINGS <log> [STRICT] [HEADERS_ONLY]): write a
# Doxyfile from docs/Doxyfile.in. The default input is the site: the guide (docs/), the
# project documents, the public headers and the Fortran modules. HEADERS_ONLY reads the C
# headers alone, and STRICT warns for any undocumented member, parameter or return value
# (the check that every public function is fully documented; the Fortran modules document
# only their own additions, so they are not held to it).
function(mfree_doxyfile out)
  cmake_parse_arguments(D "STRICT;HEADERS_ONLY" "OUTPUT;WARNINGS" "" ${ARGN})
  set(src ${PROJECT_SOURCE_DIR})
  set(inputs ${src}/include/mfree.h ${src}/adapters/sundials/include/mfree_sundials.h
             ${src}/adapters/suitesparse/include/mfree_suitesparse.h
             ${src}/adapters/mpi/include/mfree_mpi.h
             ${src}/adapters/petsc/include/mfree_petsc.h)
  if(NOT D_HEADERS_ONLY)
    file(GLOB top CONFIGURE_DEPENDS ${src}/*.md)
    list(FILTER top EXCLUDE REGEX "/README\\.md$")  # the repository's front page, not the site's
    file(GLOB readmes CONFIGURE_DEPENDS ${src}/data/README.md ${src}/tests/README.md
         ${src}/bench/README.md ${src}/adapters/*/README.md ${src}/bindings/*/README.md)
    file(GLOB modules CONFIGURE_DEPENDS ${src}/bindings/fortran/*.f90)
    list(APPEND inputs ${src}/docs ${top} ${readmes} ${modules})
  endif()
  string(REPLACE ";" " " MFREE_DOCS_INPUT "${inputs}")
  set(MFREE_DOCS_OUTPUT ${D_OUTPUT})
  set(MFREE_DOCS_WARNINGS ${D_WARNINGS})
  set(MFREE_DOCS_HTML YES)
  if(D_STRICT)
    set(MFREE_DOCS_STRICT YES)
  else()
    set(MFREE_DOCS_STRICT NO)
  endif()
  configure_file(${src}/docs/Doxyfile.in ${out} @ONLY)
endfunction()
