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
#   - the cubic spline written out: its derivative's coefficient 9/4 (2.25; within the
#     kernels' file other kernels may use the number too);
#   - the small dense SPD factorisation: Eigen's dense LDLT / LLT, or a function whose
#     name says spd, ldl(t) or chol(esky) (the sparse SimplicialLDLT of the global
#     systems is another thing and not counted);
#   - the minimum reciprocal condition number of the local solves: a constant whose name
#     holds "rcond" or "min...cond", given a number.
# The entries of `exceptions` ("<item>|<file from src/>") are tolerated for now: each is
# a to-do, not a licence.
cmake_minimum_required(VERSION 3.25)
if(NOT DEFINED SRC OR NOT IS_DIRECTORY "${SRC}")
  message(FATAL_ERROR "usage: cmake -DSRC=<repository>/src -P check_single_definitions.cmake")
endif()

set(items normalisation cubic_spline spd threshold)
set(what_normalisation "the smoothing kernels' normalisation constant")
set(what_cubic_spline "the cubic spline's formula (its coefficient 2.25)")
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
set(re_cubic_spline "(^|[^0-9.])2\\.25([^0-9]|$)")
set(re_spd
  "(^|[^A-Za-z0-9_])(Eigen::)?L(D)?LT${S}<"
  "\\.l(d)?lt${S}\\(${S}\\)"
  "(^|[ \t])[A-Za-z_][A-Za-z0-9_:<>]*[ \t]+[*&]?${S}[a-z0-9_]*(spd|ldlt|ldl|cholesky|chol)[a-z0-9_]*${S}(<[^()]*>)?${S}\\(")
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
  file(READ "${SRC}/${f}" text)
  # the code alone: comments and string literals removed (a /* */ comment in one piece)
  string(REPLACE "\\\\" "@b" text "${text}")
  string(REPLACE "\\\"" "@q" text "${text}")
  string(REPLACE "\\" "/" text "${text}")
  string(REPLACE ";" "`" text "${text}")
  string(REPLACE "[" "(" text "${text}")
  string(REPLACE "]" ")" text "${text}")
  string(REPLACE "\n" ";" lines "${text}")
  set(n 0)
  set(in_block FALSE)
  foreach(line IN LISTS lines)
    math(EXPR n "${n} + 1")
    set(code "")
    set(rest "${line}")
    while(NOT rest STREQUAL "")
      if(in_block)
        string(FIND "${rest}" "*/" e)
        if(e EQUAL -1)
          set(rest "")
        else()
          math(EXPR e "${e} + 2")
          string(SUBSTRING "${rest}" ${e} -1 rest)
          set(in_block FALSE)
        endif()
      else()
        string(REGEX REPLACE "\"[^\"]*\"" "\"\"" rest "${rest}")
        string(FIND "${rest}" "//" s)
        string(FIND "${rest}" "/*" b)
        if(NOT s EQUAL -1 AND (b EQUAL -1 OR s LESS b))
          string(SUBSTRING "${rest}" 0 ${s} c)
          string(APPEND code "${c}")
          set(rest "")
        elseif(NOT b EQUAL -1)
          string(SUBSTRING "${rest}" 0 ${b} c)
          string(APPEND code "${c} ")
          math(EXPR b "${b} + 2")
          string(SUBSTRING "${rest}" ${b} -1 rest)
          set(in_block TRUE)
        else()
          string(APPEND code "${rest}")
          set(rest "")
        endif()
      endif()
    endwhile()
    if(code MATCHES "^[ \t]*$")
      continue()
    endif()
    foreach(it IN LISTS items)
      foreach(re IN LISTS re_${it})
        if(code MATCHES "${re}")
          math(EXPR count_${it} "${count_${it}} + 1")
          list(APPEND files_${it} "${f}")
          string(STRIP "${code}" shown)
          string(REPLACE "`" ";" shown "${shown}")
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
