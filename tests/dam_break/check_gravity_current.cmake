# examples/gravity_current --json (paper 003 Sect. 7.3: lock exchange of fluids of 1000
# and 1500 kg/m3 in a tank of depth D = 0.06 m): the run ends without a failure, the mass
# is exact, and the head speed over the example's fit window (0.05 <= t <= 0.2 s unless EXTRA sets one) lies
# within TOL of REF: "rs", Rottman & Simpson's 0.4 (g D drho / rho0)^(1/2) = 0.217 m/s (003
# eq 126; the paper reports about 0.2 m/s), or "inviscid", Benjamin's half-depth current
# 0.5 (g D drho / rho0)^(1/2) = 0.271 m/s, the value the long-tank set-up settles near over
# its free-slip walls; the plot of the head's travel is written when gnuplot is installed.
# EXTRA (optional): further options of the example in one string, e.g. the set-up and fit
# window of another reading of the paper.
# Usage: cmake -DEXE=<mfree_gravity_current> -DOUT=<dir> -DNZ=<n> -DREF=rs|inviscid -DTOL=<rel>
#              [-DEXTRA="<options>"] -P check_gravity_current.cmake
cmake_minimum_required(VERSION 3.20)
include(${CMAKE_CURRENT_LIST_DIR}/../examples/json_checks.cmake)
file(MAKE_DIRECTORY ${OUT})
file(REMOVE ${OUT}/head.png)
separate_arguments(extra UNIX_COMMAND "${EXTRA}")
run_json(j --json --quiet --nz ${NZ} --vtu-every 0.1 --out ${OUT} ${extra})
string(JSON status GET "${j}" status)
string(JSON speed GET "${j}" head_speed)
if(REF STREQUAL "inviscid")
  string(JSON dev GET "${j}" rel_dev_inviscid)
  set(_ref "Benjamin's inviscid 0.5 (g D drho / rho0)^(1/2) = 0.271 m/s")
else()
  string(JSON dev GET "${j}" rel_dev)
  set(_ref "paper 003 Sect. 7.3, eq 126: Rottman & Simpson's 0.217 m/s")
endif()
string(JSON dev_rs GET "${j}" rel_dev)
string(JSON nfit GET "${j}" fit_points)
string(JSON mass GET "${j}" mass_rel_error)
expect_equal("${status}" "0" "paper 003 Sect. 7.3 gravity current: the run ends without a failure")
expect_range(${mass} 0 1e-12 "examples/gravity_current: total mass exact")
expect_range(${nfit} 10 1000 "examples/gravity_current: enough head positions in the window")
expect_range(${dev} -${TOL} ${TOL} "${_ref}: head speed within ${TOL}")
if(NOT EXISTS ${OUT}/head.csv OR NOT EXISTS ${OUT}/gravity_current.pvd)
  message(SEND_ERROR "examples/gravity_current did not write head.csv and its VTU series")
endif()
expect_plot(${OUT}/head.png)
message(STATUS "gravity current (nz = ${NZ}): head speed ${speed} m/s, ${dev} from the reference (${REF}), ${dev_rs} from 0.217 m/s")
