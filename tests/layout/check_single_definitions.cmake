# One implementation of each numerical kernel in src/ (run with cmake -P):
#   cmake -DSRC=<repository>/src -P check_single_definitions.cmake
#
# A fix to a kernel constant or a threshold must be made in one place. For each item
# below, the code of src/ (comments and string literals removed) is searched for the
# item's patterns, and every match must lie in ONE file (the threshold: one match). A
# fast path specialises the one definition by template or inlining; a second file
# writing the same numbers out is a copy.
#   - the smoothing kernels' normalisation: the constant c of W = c / h^dim f(q),
#     computed from the kernel's integral, or written as a number (10/(7 pi), 1/pi,
#     21/(16 pi), 7/(4 pi), 7/(478 pi), 0.4547..., 0.3183..., M_1_PI);
#   - the cubic spline written out: its coefficients -1.5 and 0.75 on one line (named or
#     folded into vector constants), 1 - 1.5 q^2 + 0.75 q^3, -3 q + 2.25 q^2, 0.25 t^3,
#     0.75 t^2 or a vector constant 2.25 (its derivative's 9/4);
#   - the small dense SPD factorisation: a function defined in src/ whose name says spd,
#     ldl(t) or chol(esky), unless its body only returns the same function of another
#     namespace (an out-of-line instance of the one definition). Eigen's factorisations
#     are Eigen's, not defined here: the reference path uses them as the independent
#     oracle (and the sparse SimplicialLDLT of the global systems is another thing);
#   - the minimum reciprocal condition number of the local solves: a constant whose name
#     holds "rcond" or "min...cond", given a number.
# The entries of `exceptions` ("<item>|<file from src/>") are tolerated for now: each is
# a to-do, not a licence.
cmake_minimum_required(VERSION 3.25)
if(NOT DEFINED SRC OR NOT IS_DIRECTORY "${SRC}")
  message(FATAL_ERROR "usage: cmake -DSRC=<repository>/src -P check_single_definitions.cmake")
endif()
include("${CMAKE_CURRENT_LIST_DIR}/source_lines.cmake")

set(items normalisation cubic_spline spd threshold)
set(what_normalisation "the smoothing kernels' normalisation constant")
set(what_cubic_spline "the cubic spline's formula")
set(what_spd "the small SPD factorisation")
set(what_threshold "the condition threshold of the local solves")
set(S "[ \t]*")
set(re_normalisation
  "surface${S}\\*${S}integral"
  "integral${S}\\*${S}surface"
  "(^|[^0-9.])10(\\.0*)?${S}/${S}\\(?${S}7(\\.0*)?${S}\\*"
  "(^|[^0-9.])21(\\.0*)?${S}/${S}\\(?${S}16(\\.0*)?${S}\\*"
  "(^|[^0-9.])7(\\.0*)?${S}/${S}\\(?${S}(4|64|478)(\\.0*)?${S}\\*"
  "(^|[^0-9.])1(\\.0*)?${S}/${S}(k?[Pp][Ii]|M_PI)([^A-Za-z0-9_*]|$)"
  "0\\.4547284"
  "0\\.3183098"
  "M_1_PI")
set(re_cubic_spline
  "(^|[^0-9.])1\\.5${S}\\*${S}q${S}\\*${S}q${S}\\+${S}0\\.75([^0-9]|$)"
  "(^|[^0-9.])3(\\.0*)?${S}\\*${S}q${S}\\+${S}2\\.25${S}\\*${S}q"
  "-${S}1\\.5([^0-9].*[^0-9.]|[^0-9.])0\\.75([^0-9]|$)"
  "(^|[^0-9.])0\\.75([^0-9].*[^0-9]|[^0-9])-${S}1\\.5([^0-9]|$)"
  "(^|[^0-9.])0\\.25${S}\\*${S}t${S}\\*${S}t${S}\\*${S}t"
  "(^|[^0-9.])0\\.75${S}\\*${S}t${S}\\*${S}t"
  "set1_pd${S}\\(${S}2\\.25${S}\\)")
set(re_spd
  "(^|[ \t])[A-Za-z_][A-Za-z0-9_:<>]*[ \t]+[*&]?${S}[a-z0-9_]*(spd|ldlt|ldl|cholesky|chol)[a-z0-9_]*${S}(<[^()]*>)?${S}\\(")
# a line matching the item's pattern and one of these is not counted
set(not_spd "Eigen::")
set(re_threshold
  "[A-Za-z0-9_]*[Rr][Cc][Oo][Nn][Dd][A-Za-z0-9_]*${S}=${S}[0-9]"
  "[Mm][Ii][Nn][A-Za-z0-9_]*[Cc][Oo][Nn][Dd][A-Za-z0-9_]*${S}=${S}[0-9]")

set(exceptions
)

file(GLOB_RECURSE files RELATIVE "${SRC}" LIST_DIRECTORIES false
     "${SRC}/*.h" "${SRC}/*.hpp" "${SRC}/*.c" "${SRC}/*.cpp" "${SRC}/*.inc")
list(SORT files)
foreach(it IN LISTS items)
  set(files_${it} "")
  set(hits_${it} "")
  set(count_${it} 0)
endforeach()
foreach(f IN LISTS files)
  layout_split_source("${SRC}/${f}" codes comments)
  set(n 0)
  set(forward "")  # a definition by name waiting for its body's first line
  foreach(code IN LISTS codes)
    math(EXPR n "${n} + 1")
    if(code MATCHES "^[ \t]*$")
      continue()
    endif()
    string(STRIP "${code}" shown)
    string(REPLACE "`" ";" shown "${shown}")
    if(NOT forward STREQUAL "")
      # the line after a definition by name: a forwarder's body is one return of the
      # same name from another namespace
      list(GET forward 0 it)
      list(GET forward 1 name)
      list(GET forward 2 at)
      list(GET forward 3 sig)
      set(forward "")
      if(NOT code MATCHES "^[ \t]*return[ \t]+[A-Za-z_0-9:]*::${name}[ \t]*[<(]")
        math(EXPR count_${it} "${count_${it}} + 1")
        list(APPEND files_${it} "${f}")
        string(APPEND hits_${it} "    src/${f}:${at}: ${sig}\n")
      endif()
    endif()
    foreach(it IN LISTS items)
      foreach(re IN LISTS re_${it})
        if(code MATCHES "${re}")
          set(excluded FALSE)
          foreach(x IN LISTS not_${it})
            if(code MATCHES "${x}")
              set(excluded TRUE)
            endif()
          endforeach()
          if(excluded)
            break()
          endif()
          if(it STREQUAL "spd" AND code MATCHES "\\{[ \t]*$")
            # a definition whose body starts on the next line: decide there
            string(REGEX MATCH "[a-z0-9_]*(spd|ldlt|ldl|cholesky|chol)[a-z0-9_]*[ \t]*(<[^()]*>)?[ \t]*\\(" name "${code}")
            string(REGEX REPLACE "[ \t]*(<[^()]*>)?[ \t]*\\($" "" name "${name}")
            set(forward "${it};${name};${n};${shown}")
            break()
          endif()
          math(EXPR count_${it} "${count_${it}} + 1")
          list(APPEND files_${it} "${f}")
          string(APPEND hits_${it} "    src/${f}:${n}: ${shown}\n")
          break()
        endif()
      endforeach()
    endforeach()
  endforeach()
endforeach()

set(problems "")
set(summary "")
foreach(it IN LISTS items)
  list(REMOVE_DUPLICATES files_${it})
  # the tolerated files count as not there
  set(left "")
  foreach(g IN LISTS files_${it})
    list(FIND exceptions "${it}|${g}" ex)
    if(ex EQUAL -1)
      list(APPEND left "${g}")
    endif()
  endforeach()
  list(LENGTH left nl)
  list(LENGTH files_${it} nall)
  if(nl GREATER 1 OR (it STREQUAL "threshold" AND count_${it} GREATER 1 AND nall EQUAL nl))
    string(APPEND problems "  ${what_${it}} is defined in more than one place:\n${hits_${it}}")
  elseif(nall EQUAL 0)
    string(APPEND problems "  ${what_${it}}: no definition found (did its form change? update the patterns of this check)\n")
  endif()
  list(JOIN files_${it} ", " where)
  string(APPEND summary "  ${what_${it}}: ${where}\n")
endforeach()
foreach(e IN LISTS exceptions)
  string(REPLACE "|" ";" parts "${e}")
  list(GET parts 0 it)
  list(GET parts 1 g)
  list(FIND files_${it} "${g}" k)
  if(k EQUAL -1)
    message(STATUS "exception no longer needed, remove it from check_single_definitions.cmake: ${e}")
  endif()
endforeach()
if(NOT problems STREQUAL "")
  message(FATAL_ERROR "numerical kernels of src/ defined more than once (one implementation of "
                      "each, src/core/README.md):\n${problems}")
endif()
message(STATUS "numerical kernels of src/ defined once:\n${summary}")
