# examples/ramp --json (paper 003 Sect. 7.1: breaking dam down a ramp of slope 0.5, 0.1 m
# square column, mu = 0.5, kappa of eq 125, hydrostatic densities of eq 65): the run
# passes t = 0.152 s (the time of the paper's Fig. 7) without a failure (no non-finite
# state, no negative density, no particle leaving the tank), no particle crosses a wall
# (every particle above the floor/ramp line and inside the side walls), the mass is
# exact, and the front has run down the ramp (it starts at x = 0.1 m).
# Usage: cmake -DEXE=<mfree_ramp> -DOUT=<dir> -DNX=<n> -DTEND=<s> -P check_ramp.cmake
cmake_minimum_required(VERSION 3.20)
include(${CMAKE_CURRENT_LIST_DIR}/../examples/json_checks.cmake)
file(MAKE_DIRECTORY ${OUT})
run_json(j --json --quiet --nx ${NX} --tend ${TEND} --vtu-every 0.05 --out ${OUT})
string(JSON status GET "${j}" status)
string(JSON t GET "${j}" t)
string(JSON particles GET "${j}" particles)
string(JSON mass GET "${j}" mass_rel_error)
string(JSON front GET "${j}" front_x)
string(JSON clear GET "${j}" min_clearance)
math(EXPR n "${NX} * ${NX}")
expect_equal("${status}" "0" "paper 003 Sect. 7.1 ramp: the run ends without a failure")
expect_equal("${particles}" "${n}" "examples/ramp --nx ${NX}")
expect_range(${t} 0.152 ${TEND} "paper 003 Sect. 7.1, Fig. 7: runs stably past t = 0.152 s")
expect_range(${mass} 0 1e-12 "examples/ramp: total mass exact (003 eq 57)")
expect_range(${clear} 0 1 "examples/ramp: no particle crosses the floor, ramp or side walls")
expect_range(${front} 0.2 1.0 "examples/ramp: the front has run down the ramp (from x = 0.1 m)")
if(NOT EXISTS ${OUT}/ramp.pvd OR NOT EXISTS ${OUT}/ramp_0000.vtu)
  message(SEND_ERROR "examples/ramp did not write its VTU series")
endif()
message(STATUS "ramp (${n} particles): t = ${t} s, front x = ${front} m, clearance ${clear} m")
