# Helpers for the example checks: run a program that prints one JSON object, compare
# numbers with ranges. Every check names its source (paper, table, row).

set(_failures 0)

# run_json(<out-var> <args>...): runs ${EXE} with the arguments; the program must exit
# with 0 and print exactly one JSON object (one line) on stdout.
function(run_json out)
  execute_process(COMMAND ${EXE} ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE stdout
                  ERROR_VARIABLE stderr)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${EXE} ${ARGN} exited with ${rc}: ${stderr}")
  endif()
  string(STRIP "${stdout}" stdout)
  string(FIND "${stdout}" "\n" nl)
  if(NOT nl EQUAL -1 OR NOT stdout MATCHES "^{.*}$")
    message(FATAL_ERROR "${EXE} --json did not print exactly one JSON object:\n${stdout}")
  endif()
  string(JSON type ERROR_VARIABLE err TYPE "${stdout}")
  if(err OR NOT type STREQUAL "OBJECT")
    message(FATAL_ERROR "${EXE} printed invalid JSON (${err}):\n${stdout}")
  endif()
  set(${out} "${stdout}" PARENT_SCOPE)
endfunction()

# expect_range(<value> <lo> <hi> <source>): lo <= value <= hi.
function(expect_range value lo hi source)
  if(value LESS lo OR value GREATER hi OR NOT value MATCHES "^-?[0-9]")
    message(SEND_ERROR "${source}: ${value} is outside [${lo}, ${hi}]")
  endif()
endfunction()

# expect_less(<a> <b> <source>): a < b.
function(expect_less a b source)
  if(NOT a LESS b)
    message(SEND_ERROR "${source}: expected ${a} < ${b}")
  endif()
endfunction()

# expect_equal(<a> <b> <source>): same string.
function(expect_equal a b source)
  if(NOT "${a}" STREQUAL "${b}")
    message(SEND_ERROR "${source}: got '${a}', expected '${b}'")
  endif()
endfunction()

# expect_plot(<png>): when gnuplot is installed (and MFREE_NO_PLOT is not set), the example
# must have written the PNG; without gnuplot there is nothing to check.
function(expect_plot png)
  find_program(_gnuplot gnuplot)
  if(NOT _gnuplot OR ("$ENV{MFREE_NO_PLOT}" AND NOT "$ENV{MFREE_NO_PLOT}" STREQUAL "0"))
    message(STATUS "no gnuplot: ${png} not checked")
    return()
  endif()
  if(NOT EXISTS "${png}")
    message(SEND_ERROR "gnuplot is installed but ${png} was not written")
    return()
  endif()
  file(SIZE "${png}" size)
  if(size LESS 1000)
    message(SEND_ERROR "${png} is only ${size} bytes")
  endif()
  message(STATUS "plot: ${png} (${size} bytes)")
endfunction()
