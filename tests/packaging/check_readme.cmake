# Compile and run the C example of README.md against the build tree, so that the
# README cannot drift from the API (run with cmake -P).
#   -DREADME=<README.md> -DWORKDIR=<scratch dir> -DCOMPILER=<C compiler>
#   -DINCLUDES=<;-list> -DLIB=<path of libmfree.so>
#   [-DCFLAGS=<string>] [-DLDFLAGS=<string>]  (the build's flags, e.g. sanitizers)
cmake_minimum_required(VERSION 3.25)  # policies of a -P script
foreach(v README WORKDIR COMPILER INCLUDES LIB)
  if(NOT DEFINED ${v})
    message(FATAL_ERROR "check_readme.cmake: -D${v}=... is required")
  endif()
endforeach()

# The first block fenced with ```c ... ``` is the example.
file(STRINGS "${README}" lines)
set(state before)
set(code "")
foreach(line IN LISTS lines)
  if(state STREQUAL "before" AND line MATCHES "^```c[ \t]*$")
    set(state inside)
  elseif(state STREQUAL "inside")
    if(line MATCHES "^```")
      set(state after)
      break()
    endif()
    string(APPEND code "${line}\n")
  endif()
endforeach()
if(NOT state STREQUAL "after")
  message(FATAL_ERROR "${README}: no complete ```c fenced block found")
endif()
# file(STRINGS) turns ; into list separators: restore them.
string(REPLACE "\\;" ";" code "${code}")

file(MAKE_DIRECTORY "${WORKDIR}")
set(src "${WORKDIR}/readme_example.c")
set(exe "${WORKDIR}/readme_example")
file(WRITE "${src}" "${code}")
file(REMOVE "${exe}")

separate_arguments(cflags UNIX_COMMAND "${CFLAGS}")
separate_arguments(ldflags UNIX_COMMAND "${LDFLAGS}")
set(incflags "")
foreach(d IN LISTS INCLUDES)
  list(APPEND incflags "-I${d}")
endforeach()
get_filename_component(libdir "${LIB}" DIRECTORY)
set(cmd "${COMPILER}" -std=c99 -pedantic -Wall -Wextra -Werror ${cflags} ${incflags}
        -o "${exe}" "${src}" ${ldflags} "${LIB}" "-Wl,-rpath,${libdir}" -lm)
execute_process(COMMAND ${cmd} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
if(NOT rc EQUAL 0)
  list(JOIN cmd " " shown)
  message(FATAL_ERROR "the C example of ${README} (extracted to ${src}) does not compile:\n"
                      "  ${shown}\n${out}")
endif()
execute_process(COMMAND "${exe}" RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
message(STATUS "output of the README example:\n${out}")
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "the C example of ${README} exited with status ${rc}")
endif()
