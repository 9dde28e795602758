# examples/mould --json (paper 003 Sect. 7.5: a circular mould with a core filled through
# a gate at 18 m/s): the mass entering through the gate equal to the released particles'
# mass to round-off and to rho U W t within 1 % once 50 rows have entered (the rows enter
# at (k + 1/2) d / U: half a row at most); the total mass exact (the lumped masses of the
# active particles summing to the particle masses, 003 eq 57, and those to the entered
# mass plus the buffer's); the two jets round the core mirror images of each other to
# within a particle spacing (their fronts' arc lengths and their centroids); the jet
# reaching the core before 3 ms (18 m/s over 35 mm: 1.9 ms); the run ending without a
# failure and the plot of the entered mass beside rho U W t.
# Usage: cmake -DEXE=<mfree_mould> -DOUT=<dir> -DNW=<n> -DTEND=<s> -P check_mould.cmake
cmake_minimum_required(VERSION 3.20)
include(${CMAKE_CURRENT_LIST_DIR}/../examples/json_checks.cmake)
file(REMOVE_RECURSE ${OUT})
file(MAKE_DIRECTORY ${OUT})
run_json(j --json --quiet --nw ${NW} --tend ${TEND} --out ${OUT})
foreach(k status t mass_in mass_in_reference mass_in_dev mass_count_dev mass_rel_error impact_time front_dev
          centroid_dev symmetry_dev released)
  string(JSON ${k} GET "${j}" ${k})
endforeach()
expect_equal("${status}" "0" "paper 003 Sect. 7.5 mould filling: the run ends without a failure")
expect_range(${t} ${TEND} 1 "examples/mould: runs to --tend")
expect_range(${mass_count_dev} 0 1e-12 "examples/mould: entered mass = released particles x their mass")
expect_range(${mass_in_dev} 0 0.01 "examples/mould: entered mass = rho U W t within 1 % (issue: paper 003 Sect. 7.5)")
expect_range(${mass_rel_error} 0 1e-12 "examples/mould: total mass exact (003 eq 57)")
expect_range(${impact_time} 0.0015 0.003 "examples/mould: the jet reaches the core")
expect_range(${front_dev} 0 1 "examples/mould: the two jets' fronts mirror images to within a spacing")
expect_range(${centroid_dev} 0 1 "examples/mould: the two jets' centroids mirror images to within a spacing")
expect_plot(${OUT}/mould.png)
message(STATUS "mould (nw = ${NW}): ${released} particles in, mass ${mass_in} vs ${mass_in_reference} (max dev ${mass_in_dev}); jets: fronts ${front_dev}, centroids ${centroid_dev}, particles ${symmetry_dev} spacings")
