# examples/dam_break's densities over every step (t762): nx = 20 with the no-slip walls
# (--no-slip 1) and the acoustic step (--acoustic-step 1), to the example's T = 3.2.
# 1. "density_range_steps" (the extremes over every accepted step) holds the output times'
#    "density_range" (an exact identity: the output states are accepted steps' states);
# 2. the densities stay within 7 % of rho0 = 1000 over every step (measured 954.5-1049.5).
#    With eq 120's step alone the same run goes through a period-two mode at the top of the
#    water the left wall holds (docs/fluid.md, the no-slip run's low density): 761.7 over
#    the steps to T = 3.14 (954.7 at the output times), then a negative density at
#    T = 3.147 stops it;
# 3. "density_lowest" names that minimum: a particle index, a time within the run, a
#    position inside the tank.
# Usage: cmake -DEXE=<mfree_dam_break> -DOUT=<dir> -P check_dam_break_density.cmake
cmake_minimum_required(VERSION 3.20)
include(${CMAKE_CURRENT_LIST_DIR}/../examples/json_checks.cmake)
file(MAKE_DIRECTORY ${OUT})
run_json(j --json --quiet --no-plot --out ${OUT} --nx 20 --no-slip 1 --acoustic-step 1)
string(JSON status GET "${j}" status)
string(JSON n GET "${j}" particles)
string(JSON t_end GET "${j}" t_end)
string(JSON lo GET "${j}" density_range 0)
string(JSON hi GET "${j}" density_range 1)
string(JSON slo GET "${j}" density_range_steps 0)
string(JSON shi GET "${j}" density_range_steps 1)
string(JSON T_lo GET "${j}" density_lowest 0)
string(JSON q_lo GET "${j}" density_lowest 1)
string(JSON x_lo GET "${j}" density_lowest 2)
string(JSON z_lo GET "${j}" density_lowest 3)
expect_equal("${status}" "0" "examples/dam_break --nx 20 --no-slip 1 --acoustic-step 1: the run ends without a failure")
expect_equal("${n}" "800" "examples/dam_break --nx 20: 20 x 40 particles")
expect_range(${t_end} 3.19 3.21 "examples/dam_break: the run reaches its T = 3.2")
expect_range(${slo} -1e300 ${lo} "density_range_steps: its minimum at most the output times' minimum")
expect_range(${shi} ${hi} 1e300 "density_range_steps: its maximum at least the output times' maximum")
expect_range(${slo} 930 1070 "no-slip walls with the acoustic step: densities within 7 % of rho0 over every step")
expect_range(${shi} 930 1070 "no-slip walls with the acoustic step: densities within 7 % of rho0 over every step")
expect_range(${q_lo} 0 799 "density_lowest: a particle index")
if(NOT q_lo MATCHES "^[0-9]+$")
  message(SEND_ERROR "density_lowest: the particle '${q_lo}' is not an integer")
endif()
expect_range(${T_lo} 0 ${t_end} "density_lowest: a time within the run")
# the tank: a = 0.05715 m, length 5a = 0.28575 m; the water below 2a = 0.1143 m
expect_range(${x_lo} 0 0.28575 "density_lowest: x inside the tank")
expect_range(${z_lo} 0 0.1143 "density_lowest: z inside the tank, below the column's height")
message(STATUS "dam break nx = 20, no-slip, acoustic step: densities ${slo} to ${shi} over every step "
               "(${lo} to ${hi} at the output times); the lowest at particle ${q_lo}, T = ${T_lo}")
