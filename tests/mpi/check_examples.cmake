# Run an MPI example on 1 and on NP ranks (cmake -P): both must exit 0 and print the same
# "checksum" line (the gradient bits keyed by global id).
#   -DMPIEXEC=<mpirun> -DPROGRAM=<example> -DNP=<ranks> "-DARGS=<;-list>"
cmake_minimum_required(VERSION 3.25)
set(sums "")
foreach(np 1 ${NP})
  execute_process(COMMAND "${MPIEXEC}" --oversubscribe -np ${np} "${PROGRAM}" ${ARGS}
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 100)
  message(STATUS "${np} ranks:\n${out}")
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${PROGRAM} on ${np} ranks failed (${rc}):\n${out}\n${err}")
  endif()
  if(NOT out MATCHES "checksum ([0-9A-Fa-f]+)")
    message(FATAL_ERROR "${PROGRAM} on ${np} ranks printed no checksum:\n${out}")
  endif()
  list(APPEND sums "${CMAKE_MATCH_1}")
endforeach()
list(GET sums 0 one)
list(GET sums 1 many)
if(NOT one STREQUAL many)
  message(FATAL_ERROR "checksums differ: 1 rank ${one}, ${NP} ranks ${many}")
endif()
message(STATUS "same bits on 1 and ${NP} ranks: ${one}")
