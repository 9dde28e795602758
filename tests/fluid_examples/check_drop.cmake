# examples/drop --json (paper 003 Sect. 7.4 (a): a circular drop falling at 2 m/s onto
# water at rest), the checks before the impact (drop and pool farther apart than the
# support radius 2h): total mass exact (constant particle masses, lumped masses summing to
# the total, 003 eq 57); the drop's momentum equal to P(0) + M_d g t to round-off (gravity
# is the only force on it); the internal forces of the whole fluid carrying no momentum
# (sum_i M_i a_i = M g to round-off without the walls), so that the walls' impulse is
# P(t) - P(0) - M g t: vertical, within 3 % of the pool's weight times t (the floor
# carries the pool at rest), horizontally zero (a symmetric tank); the drop's centre of
# mass on the free-fall curve to 1 % of the distance fallen; the impact no later than the
# free-fall contact. The run continues past the impact without a failure.
# Usage: cmake -DEXE=<mfree_drop> -DOUT=<dir> -DNZ=<n> -DTEND=<s> -P check_drop.cmake
cmake_minimum_required(VERSION 3.20)
include(${CMAKE_CURRENT_LIST_DIR}/../examples/json_checks.cmake)
file(REMOVE_RECURSE ${OUT})
file(MAKE_DIRECTORY ${OUT})
run_json(j --json --quiet --nz ${NZ} --tend ${TEND} --out ${OUT})
foreach(k status mass_rel_error impact_time contact_time_reference last_sample_before_impact
          drop_momentum_dev internal_force_dev free_fall_dev wall_impulse_ratio wall_impulse_x_rel t)
  string(JSON ${k} GET "${j}" ${k})
endforeach()
expect_equal("${status}" "0" "paper 003 Sect. 7.4 drop: the run ends without a failure")
expect_range(${t} ${TEND} 1 "examples/drop: runs to --tend, past the impact")
expect_range(${mass_rel_error} 0 1e-12 "examples/drop: total mass exact (003 eq 57)")
expect_range(${impact_time} 0.02 ${contact_time_reference} "examples/drop: impact (within 2h) before the free-fall contact")
expect_range(${last_sample_before_impact} 0.02 1 "examples/drop: a free fall of at least 0.02 s is checked")
expect_range(${drop_momentum_dev} 0 1e-12 "examples/drop: drop momentum = P(0) + M g t to round-off")
expect_range(${internal_force_dev} 0 1e-12 "examples/drop: internal forces carry no momentum (docs/papers.md, paper 003, derived results 1)")
expect_range(${free_fall_dev} 0 0.01 "examples/drop: centre of mass on the free-fall curve to 1 %")
expect_range(${wall_impulse_ratio} 0.97 1.03 "examples/drop: walls' vertical impulse within 3 % of the pool's weight x t")
expect_range(${wall_impulse_x_rel} 0 1e-6 "examples/drop: no horizontal impulse from the symmetric walls")
expect_plot(${OUT}/drop.png)
message(STATUS "drop (nz = ${NZ}): impact at ${impact_time} s; drop momentum ${drop_momentum_dev}, internal forces ${internal_force_dev}, free fall ${free_fall_dev}, walls/weight ${wall_impulse_ratio}")
