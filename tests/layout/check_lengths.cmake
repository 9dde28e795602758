# Files and functions of src/ short enough to read in one sitting (run with cmake -P):
#   cmake -DSRC=<repository>/src [-DMAX_FILE=800] [-DMAX_FUNCTION=150] -P check_lengths.cmake
#
# Fails, listing each, on
#   - a source or header under src/ longer than MAX_FILE lines (800), unless a comment in
#     its first 25 lines starts with "Length:" and says why it must be that long;
#   - a function longer than MAX_FUNCTION lines (150; from the first line of its signature
#     to its closing brace), unless the comment just above the signature, or one in the
#     first five lines of its body, starts with "Length:" and says why.
# For example:
#   // Length: one switch over the fifteen methods, each case a few lines; split, the
#   // cases would need the site's whole state passed around.
# The entries of `exceptions` below are tolerated for now (each is a to-do, not a
# licence): "path" for a file, "path:function" for a function, paths from src/.
#
# How functions are found: braces are counted line by line on the code (comments, string
# and character literals and preprocessor lines removed). A "{" outside any function
# opens a function when the statement before it holds a ")" and does not end with "=";
# namespace, extern "C", class, struct and union braces are transparent; any other brace
# (an initializer, an enum) is skipped whole. Lambdas and local classes count towards
# the function that holds them.
cmake_minimum_required(VERSION 3.25)
if(NOT DEFINED SRC OR NOT IS_DIRECTORY "${SRC}")
  message(FATAL_ERROR "usage: cmake -DSRC=<repository>/src -P check_lengths.cmake")
endif()
include("${CMAKE_CURRENT_LIST_DIR}/source_lines.cmake")
if(NOT DEFINED MAX_FILE)
  set(MAX_FILE 800)
endif()
if(NOT DEFINED MAX_FUNCTION)
  set(MAX_FUNCTION 150)
endif()

set(exceptions
  # none at present
)

file(GLOB_RECURSE files RELATIVE "${SRC}" LIST_DIRECTORIES false
     "${SRC}/*.h" "${SRC}/*.hpp" "${SRC}/*.c" "${SRC}/*.cpp" "${SRC}/*.inc")
list(SORT files)
set(problems "")
set(violations "")
set(excused "")
set(nfunc 0)
set(marker "^[ \t/*!]*Length:")
foreach(f IN LISTS files)
  layout_split_source("${SRC}/${f}" codes comments)
  list(LENGTH codes nlines)

  set(n 0)
  set(in_macro FALSE)    # a continued preprocessor line
  set(file_marker FALSE)
  set(run_marker FALSE)  # a Length: comment in the comment lines just above
  set(pending "")        # the statement since the last ; { or }
  set(pstart 0)          # its first line
  set(sig_marker FALSE)
  set(stack "")          # enclosing transparent scopes
  set(kind "")           # "" outside a function, F in one, O in a skipped brace
  set(depth 0)
  foreach(code comment IN ZIP_LISTS codes comments)
    math(EXPR n "${n} + 1")
    set(has_marker FALSE)
    if(comment MATCHES "${marker}" OR comment MATCHES "^[ \t]+Length:")
      set(has_marker TRUE)
    endif()
    if(has_marker AND n LESS_EQUAL 25)
      set(file_marker TRUE)
    endif()
    # preprocessor lines (and their continuations) are not code here
    if(in_macro OR code MATCHES "^[ \t]*#")
      set(in_macro FALSE)
      if(code MATCHES "@c[ \t]*$")
        set(in_macro TRUE)
      endif()
      continue()
    endif()
    string(STRIP "${code}" code)
    if(code STREQUAL "")
      if(has_marker)
        set(run_marker TRUE)
      endif()
      if(kind STREQUAL "F" AND has_marker AND n LESS_EQUAL fbody5)
        set(body_marker TRUE)
      endif()
      continue()
    endif()
    if(kind STREQUAL "F" AND has_marker AND n LESS_EQUAL fbody5)
      set(body_marker TRUE)
    endif()
    # the code, piece by piece: each piece ends at a ` { or }
    string(REGEX MATCHALL "[^{}`]*[{}`]|[^{}`]+$" pieces "${code}")
    foreach(p IN LISTS pieces)
      string(REGEX MATCH "[{}`]$" d "${p}")
      if(NOT d STREQUAL "")
        string(REGEX REPLACE "[{}`]$" "" p "${p}")
      endif()
      if(NOT kind STREQUAL "")
        # inside a function or a skipped brace: count
        if(d STREQUAL "{")
          math(EXPR depth "${depth} + 1")
        elseif(d STREQUAL "}")
          math(EXPR depth "${depth} - 1")
          if(depth EQUAL 0)
            if(kind STREQUAL "F")
              math(EXPR nfunc "${nfunc} + 1")
              math(EXPR len "${n} - ${fstart} + 1")
              if(len GREATER MAX_FUNCTION AND NOT fmarker AND NOT body_marker)
                list(FIND exceptions "${f}:${fname}" ex)
                if(ex EQUAL -1)
                  list(APPEND violations "${f}:${fname}")
                  string(APPEND problems "  src/${f}:${fstart}: function ${fname} is ${len} lines (more than ${MAX_FUNCTION}, no \"Length:\" comment)\n")
                else()
                  list(APPEND excused "${f}:${fname}")
                endif()
              endif()
            endif()
            set(kind "")
            set(pending "")
            set(run_marker FALSE)
          endif()
        endif()
        continue()
      endif()
      # outside functions: the statement grows until ; { or }
      string(STRIP "${p}" ps)
      if(NOT ps STREQUAL "")
        if(pending STREQUAL "")
          set(pstart ${n})
          set(sig_marker ${run_marker})
        endif()
        string(APPEND pending " ${ps}")
      endif()
      if(d STREQUAL "`")
        set(pending "")
      elseif(d STREQUAL "{")
        if(pending MATCHES "(^|[^A-Za-z0-9_])(namespace|extern)([^A-Za-z0-9_]|$)")
          list(APPEND stack N)
        elseif(pending MATCHES "(^|[^A-Za-z0-9_])(class|struct|union)[ \t]+[A-Za-z_]" AND NOT pending MATCHES "\\)[ \t]*(const|noexcept|override|final)?[ \t]*$")
          list(APPEND stack N)
        elseif(pending MATCHES "\\)" AND NOT pending MATCHES "=[ \t]*$")
          set(kind F)
          set(depth 1)
          set(fstart ${pstart})
          set(fmarker ${sig_marker})
          set(body_marker FALSE)
          math(EXPR fbody5 "${n} + 5")
          string(REGEX MATCH "(operator[^(]*|~?[A-Za-z_][A-Za-z0-9_:~]*)[ \t]*(<[^()]*>)?[ \t]*\\(" fname "${pending}")
          string(REGEX REPLACE "[ \t]*(<[^()]*>)?[ \t]*\\($" "" fname "${fname}")
          string(REGEX REPLACE "^.*::" "" fname_short "${fname}")
          if(NOT fname_short STREQUAL "")
            set(fname "${fname_short}")
          endif()
        else()
          set(kind O)
          set(depth 1)
        endif()
        set(pending "")
      elseif(d STREQUAL "}")
        if(NOT stack STREQUAL "")
          list(POP_BACK stack)
        endif()
        set(pending "")
      endif()
    endforeach()
    set(run_marker FALSE)
  endforeach()

  if(nlines GREATER MAX_FILE AND NOT file_marker)
    list(FIND exceptions "${f}" ex)
    if(ex EQUAL -1)
      list(APPEND violations "${f}")
      string(APPEND problems "  src/${f}: ${nlines} lines (more than ${MAX_FILE}, no \"Length:\" comment in its first 25 lines)\n")
    else()
      list(APPEND excused "${f}")
    endif()
  endif()
endforeach()

list(LENGTH files nf)
if(PRINT_EXCEPTIONS)
  # -DPRINT_EXCEPTIONS=ON: the entries that would make this pass, for the list above
  list(JOIN violations "\"\n  \"" v)
  message(STATUS "set(exceptions\n  \"${v}\")")
endif()
if(NOT problems STREQUAL "")
  message(FATAL_ERROR "files of src/ over ${MAX_FILE} lines or functions over ${MAX_FUNCTION} lines "
                      "without a \"Length:\" comment saying why (src/core/README.md):\n${problems}")
endif()
foreach(e IN LISTS exceptions)
  list(FIND excused "${e}" k)
  if(k EQUAL -1)
    message(STATUS "exception no longer needed, remove it from check_lengths.cmake: ${e}")
  endif()
endforeach()
list(LENGTH excused nx)
message(STATUS "src/: ${nf} files, ${nfunc} functions, none over ${MAX_FILE} / ${MAX_FUNCTION} lines "
               "without a reason (${nx} listed exceptions)")
