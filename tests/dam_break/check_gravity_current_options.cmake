# examples/gravity_current's diagnostic options in a short run (nz = 12 to t = 0.06 s): a
# lighter heavy fluid (--heavy 1100) under a free-slip lid (--lid 1), the consistent
# integration, the Shepard condition, the lumped-mass step and an explicit fit window.
# The run ends without a failure, the mass is exact, the summary echoes the settings, and
# the reference speeds are eq 126 and Benjamin's with drho = 100 kg/m3: 0.4 and 0.5 times
# (g D drho / rho1)^(1/2) = 0.24261 m/s (paper 003 Sect. 7.3, eq 126).
# Usage: cmake -DEXE=<mfree_gravity_current> -DOUT=<dir> -P check_gravity_current_options.cmake
cmake_minimum_required(VERSION 3.20)
include(${CMAKE_CURRENT_LIST_DIR}/../examples/json_checks.cmake)
file(MAKE_DIRECTORY ${OUT})
run_json(j --json --quiet --no-plot --nz 12 --heavy 1100 --lid 1 --consistent 1 --shepard-cond 20
         --lumped-step 1 --fit-from 0.01 --fit-to 0.06 --vtu-every 0 --out ${OUT})
foreach(k status mass_rel_error fit_points heavy_density lid consistent_integration shepard_condition
          lumped_mass_step reference inviscid_reference t)
  string(JSON ${k} GET "${j}" ${k})
endforeach()
string(JSON w0 GET "${j}" fit_window 0)
string(JSON w1 GET "${j}" fit_window 1)
expect_equal("${status}" "0" "examples/gravity_current with the diagnostic options: the run ends without a failure")
expect_range(${mass_rel_error} 0 1e-12 "examples/gravity_current --lid 1: total mass exact")
expect_range(${t} 0.0599999 0.0600001 "examples/gravity_current: the run ends at the fit window's end")
expect_range(${fit_points} 11 11 "examples/gravity_current: head samples every 0.005 s in [0.01, 0.06]")
expect_range(${w0} 0.0099999 0.0100001 "examples/gravity_current --fit-from 0.01")
expect_range(${w1} 0.0599999 0.0600001 "examples/gravity_current --fit-to 0.06")
expect_range(${heavy_density} 1100 1100 "examples/gravity_current --heavy 1100")
expect_equal("${lid}" "1" "examples/gravity_current --lid 1")
expect_equal("${consistent_integration}" "1" "examples/gravity_current --consistent 1")
expect_range(${shepard_condition} 20 20 "examples/gravity_current --shepard-cond 20")
expect_equal("${lumped_mass_step}" "1" "examples/gravity_current --lumped-step 1")
expect_range(${reference} 0.097042 0.097046 "paper 003 eq 126 with drho = 100 kg/m3: 0.4 x 0.24261 m/s")
expect_range(${inviscid_reference} 0.121303 0.121307 "Benjamin's half-depth current with drho = 100 kg/m3: 0.5 x 0.24261 m/s")
