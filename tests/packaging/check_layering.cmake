# Layering of an adapter's shared library (run with cmake -P):
#   -DCORE=<libmfree.so> -DADAPTER=<libmfree_X.so> -DNAME=<what X wraps>
#   "-DFORBIDDEN=<;-list of regexes>" "-DREQUIRED=<;-list of library names>"
#   [-DREADELF=<readelf>]
# libmfree needs no library that matches a FORBIDDEN regex (applied to "[libNAME.so"),
# the adapter needs libmfree and each REQUIRED library (libNAME.so).
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
foreach(re IN LISTS FORBIDDEN)
  if(core MATCHES "\\[lib${re}")
    message(FATAL_ERROR "${CORE} depends on ${NAME} (lib${re}): the core must not\n${core}")
  endif()
endforeach()
needed("${ADAPTER}" adapter)
foreach(lib mfree ${REQUIRED})
  if(NOT adapter MATCHES "\\[lib${lib}\\.so")
    message(FATAL_ERROR "${ADAPTER} does not depend on lib${lib}:\n${adapter}")
  endif()
endforeach()
message(STATUS "layering ok: core needs no ${NAME}; the adapter needs libmfree and ${NAME}")
