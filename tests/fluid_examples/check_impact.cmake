# examples/impact --json (paper 003 Sect. 7.4 (b): a drop of 0.05 m at 2 m/s onto a rigid
# plate made of wall particles): the run ends without a failure, the mass is exact, the
# plate is hit (a first contact, a positive peak force), and the impulse of the force the
# plate exerts, summed over the steps from mfree_system_get_wall_force, equals the fluid's
# momentum change less gravity's (P_z(t) - P_z(0) + M g t, from the lumped masses) within
# TOL (the issue's 2 % at the default resolution); the impulse brings the drop to rest
# vertically without a large rebound (0.9 to 1.3 of M (2 + g t)); the force history and
# impulse plots are written when gnuplot is installed.
# Usage: cmake -DEXE=<mfree_impact> -DOUT=<dir> -DND=<n> -DTOL=<rel> -P check_impact.cmake
cmake_minimum_required(VERSION 3.20)
include(${CMAKE_CURRENT_LIST_DIR}/../examples/json_checks.cmake)
file(REMOVE_RECURSE ${OUT})
file(MAKE_DIRECTORY ${OUT})
run_json(j --json --quiet --nd ${ND} --out ${OUT})
foreach(k status mass_rel_error impulse_dev impulse_over_momentum peak_force impact_time t)
  string(JSON ${k} GET "${j}" ${k})
endforeach()
string(JSON nforce LENGTH "${j}" force)
expect_equal("${status}" "0" "paper 003 Sect. 7.4 impact on a structure: the run ends without a failure")
expect_range(${t} 0.0399 1 "examples/impact: runs to --tend")
expect_range(${mass_rel_error} 0 1e-12 "examples/impact: total mass exact (003 eq 57)")
expect_range(${impact_time} 0 0.003 "examples/impact: the plate is hit (the drop starts 2 d above it)")
expect_range(${peak_force} 100 1e6 "examples/impact: a positive peak force on the plate")
expect_range(${nforce} 70 90 "examples/impact: the mean force every 0.5 ms")
expect_range(${impulse_dev} 0 ${TOL} "examples/impact: impulse = fluid momentum change less gravity's")
expect_range(${impulse_over_momentum} 0.9 1.3 "examples/impact: the impulse stops the drop vertically")
expect_plot(${OUT}/force.png)
expect_plot(${OUT}/impulse.png)
message(STATUS "impact (nd = ${ND}): impulse against momentum change ${impulse_dev}, impulse / M (2 + g t) ${impulse_over_momentum}, peak force ${peak_force} N/m")
