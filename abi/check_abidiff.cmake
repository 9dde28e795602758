# Compare a built shared library with its checked-in abidw baseline (run with cmake -P).
#   -DABIDIFF=<abidiff> -DBASELINE=<abi/libX.abi> -DLIB=<path of libX.so>
#   -DSUPPRESSIONS=<abi/opaque-handles.suppr>
# Fails on an incompatible change: a removed function or variable, or a changed one
# (parameter, return or exported type changed). Passes on additions (new functions,
# enumerators appended to an enum): those are compatible, and the symbol list
# (abi/libmfree.symbols, t901) records them. See ABI.md.
#
# abidiff's exit status is a bit set: 1 tool error, 2 usage error, 4 ABI change,
# 8 incompatible ABI change (removals). Bit 4 alone also covers changed functions,
# which are breaks for us, so the report's summary lines decide that case. Harmless
# changes (enumerators added at the end) are filtered out by abidiff by default.
cmake_minimum_required(VERSION 3.25)  # policies of a -P script
foreach(v ABIDIFF BASELINE LIB SUPPRESSIONS)
  if(NOT DEFINED ${v})
    message(FATAL_ERROR "check_abidiff.cmake: -D${v}=... is required")
  endif()
endforeach()
if(NOT EXISTS "${BASELINE}")
  message(FATAL_ERROR "no ABI baseline ${BASELINE}: create it as ABI.md explains")
endif()

# No --headers-dir2: it would hide changes of types from system headers (int32_t ->
# int64_t of a parameter). The suppressions keep the opaque handles' definitions out.
execute_process(COMMAND "${ABIDIFF}" --exported-interfaces-only --suppressions "${SUPPRESSIONS}"
                        "${BASELINE}" "${LIB}"
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc MATCHES "^[0-9]+$")
  message(FATAL_ERROR "abidiff did not run (${rc}):\n${err}")
endif()
math(EXPR tool_error "${rc} & 3")
math(EXPR incompatible "${rc} & 8")
math(EXPR changed "${rc} & 4")
get_filename_component(libname "${LIB}" NAME)
if(tool_error)
  message(FATAL_ERROR "abidiff ${BASELINE} ${LIB} failed (status ${rc}):\n${err}\n${out}")
endif()
if(incompatible)
  message(FATAL_ERROR "INCOMPATIBLE ABI change in ${libname} against ${BASELINE} "
                      "(removed functions or variables; restore them, or follow the "
                      "major-version rule of ABI.md):\n${out}")
endif()
if(changed)
  # "Functions changes summary: 0 Removed, 1 Changed (2 filtered out), 3 Added functions"
  set(breaks "")
  foreach(kind "Functions" "Variables")
    if(out MATCHES "${kind} changes summary: ([0-9]+) Removed[^,]*, ([0-9]+) Changed")
      if(NOT CMAKE_MATCH_1 EQUAL 0 OR NOT CMAKE_MATCH_2 EQUAL 0)
        string(APPEND breaks " ${kind}: ${CMAKE_MATCH_1} removed, ${CMAKE_MATCH_2} changed;")
      endif()
    endif()
  endforeach()
  if(out MATCHES "([0-9]+) Removed function symbols? not referenced by debug info")
    if(NOT CMAKE_MATCH_1 EQUAL 0)
      string(APPEND breaks " ${CMAKE_MATCH_1} removed ELF function symbols;")
    endif()
  endif()
  if(breaks)
    message(FATAL_ERROR "INCOMPATIBLE ABI change in ${libname} against ${BASELINE}:${breaks}"
                        "\n(a changed function is a break: add a new function instead, or "
                        "follow the major-version rule of ABI.md)\n${out}")
  endif()
  message(STATUS "${libname}: only compatible additions against ${BASELINE}:\n${out}")
else()
  message(STATUS "${libname}: ABI identical to ${BASELINE}")
endif()
