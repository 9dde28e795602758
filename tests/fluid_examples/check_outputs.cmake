# The outputs every free-surface flow example writes (issue of fluid run quality): runs
# EXE twice with ARGS (a short run) and checks
#  - without --vtu: exit status 0, the JSON summary OUT/plain/NAME.json parses and holds
#    KEYS, no VTU series (it is opt-in), and no progress bar on stderr (not a terminal:
#    no carriage return);
#  - with --vtu DIR --vtu-every EVERY --json-file F --json: the summary on stdout equals
#    the file, the PVD lists existing VTU files, and every VTU is well formed: as many
#    points and vertex cells as PARTICLES, every data array holding PARTICLES x its
#    components numbers, the document closed.
# Usage: cmake -DEXE=<program> -DNAME=<name> -DOUT=<dir> -DARGS=<a,b,..> -DPARTICLES=<n>
#              -DEVERY=<interval> -DKEYS=<k1,k2,..> -P check_outputs.cmake
cmake_minimum_required(VERSION 3.20)
include(${CMAKE_CURRENT_LIST_DIR}/../examples/json_checks.cmake)
string(REPLACE "," ";" ARGS "${ARGS}")
string(REPLACE "," ";" KEYS "${KEYS}")
file(REMOVE_RECURSE ${OUT})
file(MAKE_DIRECTORY ${OUT})

# 1. default outputs
execute_process(COMMAND ${EXE} ${ARGS} --no-plot --out ${OUT}/plain RESULT_VARIABLE rc
                OUTPUT_VARIABLE stdout ERROR_VARIABLE stderr)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "${EXE} ${ARGS} exited with ${rc}: ${stderr}")
endif()
if(stderr MATCHES "\r")
  message(SEND_ERROR "${NAME}: a progress bar was drawn on stderr, which is not a terminal")
endif()
if(NOT EXISTS ${OUT}/plain/${NAME}.json)
  message(FATAL_ERROR "${NAME}: no JSON summary at ${OUT}/plain/${NAME}.json")
endif()
file(READ ${OUT}/plain/${NAME}.json summary)
string(JSON type ERROR_VARIABLE err TYPE "${summary}")
if(err OR NOT type STREQUAL "OBJECT")
  message(FATAL_ERROR "${NAME}: the summary is not a JSON object (${err}):\n${summary}")
endif()
foreach(k ${KEYS})
  string(JSON v ERROR_VARIABLE err GET "${summary}" ${k})
  if(err)
    message(SEND_ERROR "${NAME}: the JSON summary lacks \"${k}\"")
  endif()
endforeach()
string(JSON status GET "${summary}" status)
expect_equal("${status}" "0" "${NAME}: the summary's status of a run without failure")
file(GLOB stray ${OUT}/plain/*.vtu ${OUT}/plain/*.pvd)
if(stray)
  message(SEND_ERROR "${NAME}: VTU files written without --vtu: ${stray}")
endif()

# 2. the VTU series and the summary at a chosen path
run_json(j ${ARGS} --no-plot --out ${OUT}/run --vtu ${OUT}/vtu --vtu-every ${EVERY}
         --json-file ${OUT}/summary.json --json)
file(READ ${OUT}/summary.json filed)
string(STRIP "${filed}" filed)
expect_equal("${filed}" "${j}" "${NAME}: --json prints the summary that --json-file writes")
string(JSON particles GET "${j}" particles)
expect_equal("${particles}" "${PARTICLES}" "${NAME}: particles")
if(NOT EXISTS ${OUT}/vtu/${NAME}.pvd)
  message(FATAL_ERROR "${NAME}: --vtu wrote no ${OUT}/vtu/${NAME}.pvd")
endif()
file(READ ${OUT}/vtu/${NAME}.pvd pvd)
if(NOT pvd MATCHES "</Collection>\n</VTKFile>\n$")
  message(SEND_ERROR "${NAME}: the PVD is not closed")
endif()
string(REGEX MATCHALL "file=\"[^\"]+\"" files "${pvd}")
list(LENGTH files nfiles)
expect_range(${nfiles} 2 100000 "${NAME}: at least two VTU snapshots")
foreach(f ${files})
  string(REGEX REPLACE "file=\"([^\"]+)\"" "\\1" f "${f}")
  if(NOT EXISTS ${OUT}/vtu/${f})
    message(SEND_ERROR "${NAME}: the PVD names ${f}, which does not exist")
    continue()
  endif()
  file(READ ${OUT}/vtu/${f} vtu)
  if(NOT vtu MATCHES "^<\\?xml[^\n]*\n<VTKFile type=\"UnstructuredGrid\"" OR NOT vtu MATCHES "</VTKFile>\n$")
    message(SEND_ERROR "${NAME}: ${f} is not a closed VTK UnstructuredGrid file")
  endif()
  string(REGEX MATCH "NumberOfPoints=\"([0-9]+)\" NumberOfCells=\"([0-9]+)\"" _ "${vtu}")
  expect_equal("${CMAKE_MATCH_1}/${CMAKE_MATCH_2}" "${PARTICLES}/${PARTICLES}"
               "${NAME}: ${f}: points/cells = particles")
  string(REGEX MATCHALL "<DataArray[^>]*>[^<]*</DataArray>" arrays "${vtu}")
  list(LENGTH arrays narrays)
  expect_range(${narrays} 7 100 "${NAME}: ${f}: points, 3 cell arrays, velocity, pressure, density")
  foreach(a ${arrays})
    set(ncomp 1)
    if(a MATCHES "NumberOfComponents=\"([0-9]+)\"")
      set(ncomp ${CMAKE_MATCH_1})
    endif()
    string(REGEX MATCH "Name=\"[^\"]*\"" aname "${a}")
    string(REGEX REPLACE "^<DataArray[^>]*>" "" body "${a}")
    string(REGEX MATCHALL "[^ \n]+" values "${body}")
    list(LENGTH values nvalues)
    math(EXPR want "${PARTICLES} * ${ncomp} + 1") # + the closing tag
    expect_equal("${nvalues}" "${want}" "${NAME}: ${f}: values of the array ${aname} (+1)")
  endforeach()
endforeach()
message(STATUS "${NAME}: summary with ${KEYS}; ${nfiles} VTU snapshots of ${PARTICLES} particles")
