# Compare the dynamic symbols exported by libmfree.so with the checked-in list
# abi/libmfree.symbols (run with cmake -P).
#   -DLIB=<path of libmfree.so> -DEXPECTED=<abi/libmfree.symbols> [-DNM=<nm>]
# A removed symbol breaks every host linked against an older libmfree.so.0: always an
# error. An added symbol is fine for the ABI but must be recorded in the list in the
# same change, so that the list stays the reviewed statement of the ABI.
cmake_minimum_required(VERSION 3.25)  # policies of a -P script
foreach(v LIB EXPECTED)
  if(NOT DEFINED ${v})
    message(FATAL_ERROR "check_symbols.cmake: -D${v}=... is required")
  endif()
endforeach()
if(NOT DEFINED NM OR NM STREQUAL "")
  set(NM nm)
endif()

execute_process(COMMAND "${NM}" -D --defined-only "${LIB}"
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "${NM} -D --defined-only ${LIB} failed:\n${err}")
endif()

# Lines are "<address> <type> <name>[@@VERSION]". Keep functions and data (T, D, B, R,
# weak W/V, indirect i); the version node itself (MFREE_0, type A) is not a symbol.
set(actual "")
string(REPLACE "\n" ";" lines "${out}")
foreach(line IN LISTS lines)
  if(line MATCHES "^[0-9a-fA-F]* *([TDBRWVitdbr]) ([^ ]+)$")
    set(name "${CMAKE_MATCH_2}")
    string(REGEX REPLACE "@.*$" "" name "${name}")
    if(NOT name MATCHES "^MFREE_[0-9._]+$")
      list(APPEND actual "${name}")
    endif()
  endif()
endforeach()
list(REMOVE_DUPLICATES actual)
list(SORT actual)
if(NOT actual)
  message(FATAL_ERROR "no exported symbols found in ${LIB}: is it the shared library?")
endif()

file(STRINGS "${EXPECTED}" expected REGEX "[^ \t]")
set(sorted ${expected})
list(SORT sorted)
list(REMOVE_DUPLICATES sorted)
if(NOT sorted STREQUAL expected)
  message(FATAL_ERROR "${EXPECTED} must hold one symbol per line, sorted (LC_ALL=C sort -u)")
endif()

set(removed ${expected})
list(REMOVE_ITEM removed ${actual})
set(added ${actual})
list(REMOVE_ITEM added ${expected})
set(unprefixed "")
foreach(s IN LISTS actual)
  if(NOT s MATCHES "^mfree_")
    list(APPEND unprefixed "${s}")
  endif()
endforeach()

set(report "")
if(removed)
  list(JOIN removed "\n    " t)
  string(APPEND report "\nsymbols REMOVED from libmfree.so (this breaks hosts linked against "
                       "libmfree.so.0; restore them):\n    ${t}\n")
endif()
if(added)
  list(JOIN added "\n    " t)
  get_filename_component(listname "${EXPECTED}" NAME)
  string(APPEND report "\nsymbols ADDED to libmfree.so but missing from ${listname} "
                       "(add these lines to ${EXPECTED}, keeping it sorted, in the same change):"
                       "\n    ${t}\n")
endif()
if(unprefixed)
  list(JOIN unprefixed "\n    " t)
  string(APPEND report "\nexported symbols WITHOUT the mfree_ prefix (hide them: MFREE_API "
                       "only on the C ABI, src/mfree.map exports mfree_* only):\n    ${t}\n")
endif()
if(report)
  message(FATAL_ERROR "ABI check of ${LIB} against ${EXPECTED} failed:${report}")
endif()
list(LENGTH actual count)
message(STATUS "libmfree.so exports exactly the ${count} symbols of ${EXPECTED}")
