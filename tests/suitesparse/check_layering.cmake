# Layering of the shared libraries (run with cmake -P):
#   -DCORE=<libmfree.so> -DADAPTER=<libmfree_suitesparse.so> [-DREADELF=<readelf>]
# libmfree needs no SuiteSparse library; libmfree_suitesparse needs libmfree and the
# three solvers.
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
foreach(ss cholmod umfpack klu amd camd colamd ccolamd btf suitesparseconfig)
  if(core MATCHES "\\[lib${ss}\\.so")
    message(FATAL_ERROR "${CORE} depends on lib${ss}: the core must not need SuiteSparse\n${core}")
  endif()
endforeach()
needed("${ADAPTER}" adapter)
foreach(lib mfree cholmod umfpack klu)
  if(NOT adapter MATCHES "\\[lib${lib}\\.so")
    message(FATAL_ERROR "${ADAPTER} does not depend on lib${lib}:\n${adapter}")
  endif()
endforeach()
message(STATUS "layering ok: core needs no SuiteSparse; the adapter needs libmfree and SuiteSparse")
