# examples/bore --json (paper 003 Sect. 7.2: water at rest at depths h1 = 0.1 m and
# h0 = 0.05 m released at t = 0): the run ends without a failure, the mass is exact, and the
# bore speed lies within 10 % of the shallow-water bore of the wet-bed Riemann problem
# (Stoker; S^2 = g h_m (h_m + h0) / (2 h0) with the middle depth h_m, 0.9354 m/s for the
# depth ratio 0.5), and so does the depth behind it (h_m = 0.0727 m, measured before the
# reflection of the rarefaction reaches it); the plots of the bore's position and of the
# surface are written when gnuplot is installed.
# Usage: cmake -DEXE=<mfree_bore> -DOUT=<dir> -DNZ=<n> -DCFL=<c> -P check_bore.cmake
cmake_minimum_required(VERSION 3.20)
include(${CMAKE_CURRENT_LIST_DIR}/../examples/json_checks.cmake)
file(REMOVE_RECURSE ${OUT})
file(MAKE_DIRECTORY ${OUT})
run_json(j --json --quiet --nz ${NZ} --cfl ${CFL} --out ${OUT})
string(JSON status GET "${j}" status)
string(JSON speed GET "${j}" bore_speed)
string(JSON ref GET "${j}" reference)
string(JSON dev GET "${j}" rel_dev)
string(JSON nfit GET "${j}" fit_points)
string(JSON mass GET "${j}" mass_rel_error)
string(JSON hm GET "${j}" h_m)
string(JSON hm_dev GET "${j}" h_m_rel_dev)
expect_equal("${status}" "0" "paper 003 Sect. 7.2 bore: the run ends without a failure")
expect_range(${mass} 0 1e-12 "examples/bore: total mass exact (003 eq 57)")
expect_range(${ref} 0.935 0.936 "shallow-water bore speed for depths 0.1 and 0.05 m")
expect_range(${nfit} 10 1000 "examples/bore: bore positions in the fit window")
expect_range(${dev} -0.10 0.10 "paper 003 Sect. 7.2: bore speed within 10 % of the shallow-water bore")
expect_range(${hm_dev} -0.10 0.10 "examples/bore: depth behind the bore within 10 % of the shallow-water h_m")
expect_plot(${OUT}/bore.png)
expect_plot(${OUT}/profile.png)
message(STATUS "bore (nz = ${NZ}, CFL ${CFL}): ${speed} m/s, ${dev} from ${ref} m/s; depth behind it ${hm} m (${hm_dev})")
