# Header hygiene of the public C ABI (run with cmake -P).
#   -DCOMPILER=<C or C++ compiler> -DSOURCE=<file including mfree.h>
#   -DFLAGS=<;-list of flags> -DINCLUDES=<;-list of include dirs>
#   -DHEADER=<path of mfree.h>: when set, also check the ABI types of ../shared/STYLE.md
#     (no bool, no long, no varargs) in the header with its comments removed.
cmake_minimum_required(VERSION 3.25)  # policies of a -P script
foreach(v COMPILER SOURCE FLAGS INCLUDES)
  if(NOT DEFINED ${v})
    message(FATAL_ERROR "check_header.cmake: -D${v}=... is required")
  endif()
endforeach()

if(DEFINED HEADER AND NOT HEADER STREQUAL "")
  file(READ "${HEADER}" text)
  # Drop /* ... */ and // comments: prose may say "long" or "...".
  set(code "")
  while(TRUE)
    string(FIND "${text}" "/*" open)
    if(open EQUAL -1)
      string(APPEND code "${text}")
      break()
    endif()
    string(SUBSTRING "${text}" 0 ${open} before)
    string(APPEND code "${before} ")
    math(EXPR after "${open} + 2")
    string(SUBSTRING "${text}" ${after} -1 text)
    string(FIND "${text}" "*/" close)
    if(close EQUAL -1)
      message(FATAL_ERROR "${HEADER}: unterminated comment")
    endif()
    math(EXPR after "${close} + 2")
    string(SUBSTRING "${text}" ${after} -1 text)
  endwhile()
  string(REGEX REPLACE "//[^\n]*" "" code "${code}")

  set(problems "")
  # [^A-Za-z0-9_] on both sides stands for a word boundary.
  if(code MATCHES "(^|[^A-Za-z0-9_])(bool|_Bool)([^A-Za-z0-9_]|$)")
    string(APPEND problems "\n  - uses bool/_Bool (pass int32_t flags)")
  endif()
  if(code MATCHES "(^|[^A-Za-z0-9_])long([^A-Za-z0-9_]|$)")
    string(APPEND problems "\n  - uses long (its width differs between platforms: use int32_t/int64_t)")
  endif()
  if(code MATCHES "\\.\\.\\.")
    string(APPEND problems "\n  - declares a variadic function (...), which Fortran cannot bind")
  endif()
  if(problems)
    message(FATAL_ERROR "${HEADER} breaks the ABI type rules of STYLE.md:${problems}")
  endif()
  message(STATUS "${HEADER}: no bool, long or varargs")
endif()

set(incflags "")
foreach(d IN LISTS INCLUDES)
  list(APPEND incflags "-I${d}")
endforeach()
execute_process(COMMAND "${COMPILER}" ${FLAGS} ${incflags} -fsyntax-only "${SOURCE}"
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
if(NOT rc EQUAL 0)
  string(REPLACE ";" " " shown "${COMPILER} ${FLAGS} ${incflags} -fsyntax-only ${SOURCE}")
  message(FATAL_ERROR "the public header does not compile cleanly:\n  ${shown}\n${out}")
endif()
message(STATUS "mfree.h compiles cleanly with: ${FLAGS}")
