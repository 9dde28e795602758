# examples/gravity_current's defaults are paper 003 Sect. 7.3's set-up as docs/fluid.md reads
# it with the paper's other experiments, the run t760 checks against eq 126: two
# compartments 0.06 m long (Fig. 10's labels "0.06 m", "0.06 m"), mu = 0.5 Pa s (Sects. 7.1,
# 7.2, 7.4 a), 51 particles over the depth (2 x 51 x 51 = 5,202, the paper's 5,100), the
# paper's CFL 0.5 and the fit window 0.05 <= t <= 0.2 s. A run of a few steps with no
# set-up option: the summary echoes these, the head starts at the lock (x = 0.06 m), and
# the mass is exact.
# Usage: cmake -DEXE=<mfree_gravity_current> -DOUT=<dir> -P check_gravity_current_defaults.cmake
cmake_minimum_required(VERSION 3.20)
include(${CMAKE_CURRENT_LIST_DIR}/../examples/json_checks.cmake)
file(MAKE_DIRECTORY ${OUT})
run_json(j --json --quiet --no-plot --tend 0.001 --vtu-every 0 --out ${OUT})
foreach(k status particles mass_rel_error light_length heavy_density mu cfl lid no_slip
          lumped_mass_step acoustic_step)
  string(JSON ${k} GET "${j}" ${k})
endforeach()
string(JSON w0 GET "${j}" fit_window 0)
string(JSON w1 GET "${j}" fit_window 1)
string(JSON t0 GET "${j}" head 0 0)
string(JSON x0 GET "${j}" head 0 1)
expect_equal("${status}" "0" "examples/gravity_current defaults: the run ends without a failure")
expect_equal("${particles}" "5202" "examples/gravity_current defaults: 2 x 51 x 51 particles (paper 003 Sect. 7.3: 5,100)")
expect_range(${mass_rel_error} 0 1e-12 "examples/gravity_current defaults: total mass exact")
expect_range(${light_length} 0.06 0.06 "paper 003 Fig. 10: fluid 1 over 0.06 m")
expect_range(${heavy_density} 1500 1500 "paper 003 Sect. 7.3: fluid 2 at 1500 kg/m3")
expect_range(${mu} 0.5 0.5 "paper 003 Sects. 7.1, 7.2, 7.4 a: mu = 0.5 Pa s")
expect_range(${cfl} 0.5 0.5 "paper 003 Sect. 7: CFL 0.5")
expect_range(${w0} 0.0499999 0.0500001 "examples/gravity_current: fit window from 0.05 s")
expect_range(${w1} 0.1999999 0.2000001 "examples/gravity_current: fit window to 0.2 s")
expect_equal("${lid}${no_slip}${lumped_mass_step}${acoustic_step}" "0000"
             "examples/gravity_current defaults: the paper's free surface, walls and step")
expect_range(${t0} 0 0 "examples/gravity_current: the head's first sample at t = 0")
expect_range(${x0} 0.059999999 0.060000001 "examples/gravity_current: the head starts at the lock, 0.06 m")
