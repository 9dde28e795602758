# Layering of the shared libraries (run with cmake -P):
#   -DCORE=<libmfree.so> -DADAPTER=<libmfree_mpi.so> [-DREADELF=<readelf>]
# libmfree needs no MPI library (the core never calls MPI); libmfree_mpi needs libmfree
# and libmpi.
cmake_minimum_required(VERSION 3.25)
if(NOT DEFINED READELF OR READELF STREQUAL "")
  set(READELF readelf)
endif()
function(needed lib out)
  execute_process(COMMAND "${READELF}" -d "${lib}" RESULT_VARIABLE rc OUTPUT_VARIABLE text
                  ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${READELF} -d ${lib} failed:\n${err}")
  endif()
  string(REGEX MATCHALL "Shared library: \\[[^]]+\\]" found "${text}")
  set(${out} "${found}" PARENT_SCOPE)
endfunction()

needed("${CORE}" core)
if(core MATCHES "\\[lib(mpi|open-pal|open-rte|mpich)[^]]*\\.so")
  message(FATAL_ERROR "${CORE} depends on MPI: the core must not\n${core}")
endif()
needed("${ADAPTER}" adapter)
foreach(lib mfree mpi)
  if(NOT adapter MATCHES "\\[lib${lib}\\.so")
    message(FATAL_ERROR "${ADAPTER} does not depend on lib${lib}:\n${adapter}")
  endif()
endforeach()
message(STATUS "layering ok: core needs no MPI; the adapter needs libmfree and MPI")
