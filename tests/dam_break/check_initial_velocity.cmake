# examples/initial_velocity --json (paper 003 eq 99 through libmfree_suitesparse, UMFPACK):
# with the solved velocity parameters the interpolated velocity equals the prescribed
# field to round-off; with the field itself as parameters it misses by the MLS smoothing
# error (the reason eq 99 exists).
# Usage: cmake -DEXE=<mfree_initial_velocity> -P check_initial_velocity.cmake
cmake_minimum_required(VERSION 3.20)
include(${CMAKE_CURRENT_LIST_DIR}/../examples/json_checks.cmake)
run_json(j --json --n 20)
string(JSON solved GET "${j}" rel_error_solved)
string(JSON naive GET "${j}" rel_error_naive)
string(JSON particles GET "${j}" particles)
expect_equal("${particles}" "400" "examples/initial_velocity --n 20")
expect_range(${solved} 0 1e-10 "003 eq 99: S v = u solved, v_hat(x_k) = u(x_k) to round-off")
expect_range(${naive} 1e-3 1 "003 eq 99: v = u leaves the MLS smoothing error (non-interpolating N_j)")
message(STATUS "initial velocity: solved ${solved}, naive ${naive} (relative to U)")
