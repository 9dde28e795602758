# Paper 004 Example B through examples/mpfem_1d --json (label mpfem):
#  - with 3 Gauss points, the reproduced values (docs/papers.md, paper 004, reproduction)
#    at h = 0.002 to 1e-3 relative: FEM L2 2.5006e-4, H1 3.9548e-1; MPFEM L2 2.0602e-5, H1(22) 6.1361e-2;
#  - the paper's rates (Sect. 3.2) on the last pair of spacings: L2 2 +- 0.15 for both,
#    MPFEM H1 in [1.5, 2], FEM H1 about 1;
#  - with 6 Gauss points (the coarse meshes' load quadrature resolved), MPFEM L2 below
#    FEM's at every spacing.
# Usage: cmake -DEXE=<mfree_mpfem_1d> -DOUT=<dir> -P check_mpfem_1d.cmake
cmake_minimum_required(VERSION 3.20)
include(${CMAKE_CURRENT_LIST_DIR}/../examples/json_checks.cmake)
file(MAKE_DIRECTORY ${OUT})

run_json(j --json --no-plot --out ${OUT})
string(JSON n LENGTH "${j}" h)
expect_equal(${n} 6 "004 Example B: h = 0.1 .. 0.002 (six spacings)")
string(JSON fl2 GET "${j}" fem L2 5)
string(JSON fh1 GET "${j}" fem H1 5)
string(JSON ml2 GET "${j}" mpfem L2 5)
string(JSON mh1 GET "${j}" mpfem H1 5)
expect_range(${fl2} 2.4981e-4 2.5031e-4 "004 Example B, reproduced: FEM L2 at h = 0.002 = 2.5006e-4")
expect_range(${fh1} 0.39508 0.39588 "004 Example B, reproduced: FEM H1 at h = 0.002 = 3.9548e-1")
expect_range(${ml2} 2.0581e-5 2.0623e-5 "004 Example B, reproduced: MPFEM L2 at h = 0.002 = 2.0602e-5")
expect_range(${mh1} 0.061300 0.061422 "004 Example B, reproduced: MPFEM H1(22) at h = 0.002 = 6.1361e-2")
string(JSON rfl GET "${j}" rates fem L2 4)
string(JSON rfh GET "${j}" rates fem H1 4)
string(JSON rml GET "${j}" rates mpfem L2 4)
string(JSON rmh GET "${j}" rates mpfem H1 4)
expect_range(${rfl} 1.85 2.15 "004 Sect. 3.2: FEM L2 rate 2")
expect_range(${rml} 1.85 2.15 "004 Sect. 3.2: MPFEM L2 rate 2")
expect_range(${rmh} 1.5 2.0 "004 Sect. 3.2: MPFEM H1 rate between 1.5 and 2")
expect_range(${rfh} 0.9 1.1 "linear FEM H1 rate 1")

run_json(j6 --json --no-plot --gauss 6 --out ${OUT})
foreach(i RANGE 5)
  string(JSON a GET "${j6}" fem L2 ${i})
  string(JSON b GET "${j6}" mpfem L2 ${i})
  expect_less(${b} ${a} "004 Sect. 3.2: MPFEM L2 below FEM's at every spacing (6 Gauss points, level ${i})")
endforeach()
