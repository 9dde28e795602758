# Layering of the shared libraries (run with cmake -P):
#   -DCORE=<libmfree.so> -DADAPTER=<libmfree_petsc.so> [-DREADELF=<readelf>]
# libmfree needs neither PETSc nor MPI; libmfree_petsc needs libmfree, PETSc and MPI.
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
foreach(l petsc mpi)
  if(core MATCHES "\\[lib${l}[_.]")
    message(FATAL_ERROR "${CORE} depends on lib${l}: the core must need neither PETSc nor MPI\n${core}")
  endif()
endforeach()
needed("${ADAPTER}" adapter)
foreach(l mfree petsc mpi)
  if(NOT adapter MATCHES "\\[lib${l}[_.]")
    message(FATAL_ERROR "${ADAPTER} does not depend on lib${l}:\n${adapter}")
  endif()
endforeach()
