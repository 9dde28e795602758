# A free-surface flow example whose run stops on an error (here: a particle leaves the
# tank) exits with status 3, says so on stderr ("error: the run stopped at ..."), and its
# JSON summary (stdout and file) records the status and the library's message.
# Usage: cmake -DEXE=<program> -DNAME=<name> -DOUT=<dir> -DARGS=<a,b,..> -P check_error.cmake
cmake_minimum_required(VERSION 3.20)
include(${CMAKE_CURRENT_LIST_DIR}/../examples/json_checks.cmake)
string(REPLACE "," ";" ARGS "${ARGS}")
file(REMOVE_RECURSE ${OUT})
execute_process(COMMAND ${EXE} ${ARGS} --no-plot --json --out ${OUT} RESULT_VARIABLE rc
                OUTPUT_VARIABLE stdout ERROR_VARIABLE stderr)
expect_equal("${rc}" "3" "${NAME}: exit status of a run stopped by an error")
if(NOT stderr MATCHES "mfree_${NAME}: error: the run stopped at [^\n]*left the box")
  message(SEND_ERROR "${NAME}: no clear message on stderr:\n${stderr}")
endif()
string(STRIP "${stdout}" stdout)
string(JSON status ERROR_VARIABLE err GET "${stdout}" status)
if(err)
  message(FATAL_ERROR "${NAME}: no JSON summary on stdout (${err}):\n${stdout}")
endif()
expect_range(${status} 1 1000 "${NAME}: the summary's status is the library's positive failure")
string(JSON msg GET "${stdout}" error)
if(NOT msg MATCHES "left the box")
  message(SEND_ERROR "${NAME}: the summary's error is '${msg}'")
endif()
if(NOT EXISTS ${OUT}/${NAME}.json)
  message(SEND_ERROR "${NAME}: no summary file ${OUT}/${NAME}.json after the failure")
endif()
message(STATUS "${NAME}: stopped run, exit status ${rc}, status ${status}: ${msg}")
