# Layering of the shared libraries (run with cmake -P):
#   -DCORE=<libmfree.so> -DADAPTER=<libmfree_sundials.so> [-DREADELF=<readelf>]
# libmfree needs no SUNDIALS library; libmfree_sundials needs libmfree and SUNDIALS'
# sparse matrix (the only SUNDIALS module it calls).
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
if(core MATCHES "\\[libsundials_")
  message(FATAL_ERROR "${CORE} depends on a SUNDIALS library: the core must not\n${core}")
endif()
needed("${ADAPTER}" adapter)
foreach(lib mfree sundials_sunmatrixsparse)
  if(NOT adapter MATCHES "\\[lib${lib}\\.so")
    message(FATAL_ERROR "${ADAPTER} does not depend on lib${lib}:\n${adapter}")
  endif()
endforeach()
message(STATUS "layering ok: core needs no SUNDIALS; the adapter needs libmfree and SUNDIALS")
