# examples/dam_break --json at nx = NX (default 10: 200 particles; NX = default runs the
# example's own default resolution, nx = 24, 1152 particles): the run reaches T = 3.2 without a
# failure, the mass is exact (constant particle masses, none lost through a wall, and the
# Galerkin lumped masses of 003 eq 57 summing to the total), and the surge front
# Z = z/a lies within 20 % of Martin & Moyce (1952, Phil. Trans. R. Soc. A 244, Fig. 3,
# n^2 = 2; data/martin_moyce_1952.csv of the repository) at their points with 1 <= T <= 3;
# over 0.5 <= T <= 3 the experiment lags the model by less than 0.25 in T (the JSON's
# time_offset), at nx = 24 by 0.10 to 0.20 at every point (a lag, not a speed difference).
# Usage: cmake -DEXE=<mfree_dam_break> -DOUT=<dir> -DDATA=<csv> [-DNX=<n>|default] -P check_dam_break.cmake
cmake_minimum_required(VERSION 3.20)
include(${CMAKE_CURRENT_LIST_DIR}/../examples/json_checks.cmake)
file(MAKE_DIRECTORY ${OUT})
if(NOT EXISTS "${DATA}")
  message(FATAL_ERROR "Martin & Moyce data not found at ${DATA} (data/ of the repository)")
endif()
set(_data --data ${DATA})
if(NOT DEFINED NX)
  set(NX 10)
endif()
if(NX STREQUAL "default")
  set(_nx)
  set(_particles 1152) # the example's default nx = 24: 24 x 48
else()
  set(_nx --nx ${NX})
  math(EXPR _particles "2 * ${NX} * ${NX}")
endif()
file(REMOVE ${OUT}/front.png)
if(NX STREQUAL "default")
  set(_plot --no-plot)  # the coarse run checks the plot
else()
  set(_plot "")
endif()
run_json(j --json --quiet ${_plot} ${_nx} --vtu-every 1 --out ${OUT} ${_data})
string(JSON status GET "${j}" status)
string(JSON particles GET "${j}" particles)
string(JSON t_end GET "${j}" t_end)
string(JSON mass GET "${j}" mass_rel_error)
string(JSON dev GET "${j}" max_rel_dev)
string(JSON compared GET "${j}" compared)
string(JSON nfront LENGTH "${j}" front)
expect_equal("${status}" "0" "examples/dam_break: the run ends without a failure")
expect_equal("${particles}" "${_particles}" "examples/dam_break (nx ${NX}): nx x 2 nx particles")
expect_range(${t_end} 3.19 3.21 "examples/dam_break: reaches T = 3.2")
expect_range(${nfront} 60 70 "examples/dam_break: front every 0.05 in T")
expect_range(${mass} 0 1e-12 "examples/dam_break: total mass exact (003 eq 57)")
foreach(f front.csv dam_break.pvd dam_break_0000.vtu)
  if(NOT EXISTS ${OUT}/${f})
    message(SEND_ERROR "examples/dam_break did not write ${f}")
  endif()
endforeach()
expect_equal("${compared}" "3" "Martin & Moyce points with 1 <= T <= 3 (T = 1.219, 1.997, 2.547)")
# SPH fronts typically run 10-15 % ahead of this experiment; measured 3.97 % at nx = 10,
# 10.05 % at the default nx = 24
expect_range(${dev} 0 0.20 "Martin & Moyce (1952) Fig. 3, n^2 = 2: front within 20 % for 1 <= T <= 3")
# Over the issue's range 0.5 <= T <= 3 (4 points) the deviation is a lag of the experiment,
# nearly constant in T: the simulated front moves at the experiment's speed (measured at
# nx = 24: 0.133 to 0.166 in T, mean 0.147; 10.1 % at most, at T = 1.219).
string(JSON compared_wide GET "${j}" compared_wide)
string(JSON lag GET "${j}" time_offset 0)
string(JSON lag_min GET "${j}" time_offset 1)
string(JSON lag_max GET "${j}" time_offset 2)
expect_equal("${compared_wide}" "4" "Martin & Moyce points with 0.5 <= T <= 3")
expect_range(${lag} 0 0.25 "examples/dam_break: the experiment lags the model by less than 0.25 in T")
if(NX STREQUAL "default")
  expect_range(${lag_min} 0.10 0.20 "examples/dam_break: the smallest lag at nx = 24")
  expect_range(${lag_max} 0.10 0.20 "examples/dam_break: the largest lag at nx = 24")
else()
  expect_plot(${OUT}/front.png)
endif()
message(STATUS "dam break front: max relative deviation from Martin & Moyce ${dev} (${compared} points); lag of the experiment ${lag} (${lag_min} to ${lag_max})")
