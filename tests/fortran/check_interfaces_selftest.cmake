# The checker itself must fail on each kind of mismatch (run with cmake -P):
#   -DCHECKER=<check_interfaces.cmake> -DHEADER=<mfree.h> -DFORTRAN=<mfree.f90>
#   -DWORKDIR=<scratch directory>
# Each case mutates a copy of the header or of the module and expects the checker to
# exit non-zero with the expected complaint; the unmutated pair must pass.
cmake_minimum_required(VERSION 3.25)
foreach(v CHECKER HEADER FORTRAN WORKDIR)
  if(NOT DEFINED ${v})
    message(FATAL_ERROR "check_interfaces_selftest.cmake: -D${v}=... is required")
  endif()
endforeach()
file(MAKE_DIRECTORY "${WORKDIR}")
file(READ "${HEADER}" h0)
file(READ "${FORTRAN}" f0)

function(run_case name header_text fortran_text expect)
  set(hf "${WORKDIR}/${name}.h")
  set(ff "${WORKDIR}/${name}.f90")
  file(WRITE "${hf}" "${header_text}")
  file(WRITE "${ff}" "${fortran_text}")
  execute_process(COMMAND "${CMAKE_COMMAND}" -DHEADER=${hf} -DFORTRAN=${ff} -P "${CHECKER}"
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(expect STREQUAL "")
    if(NOT rc EQUAL 0)
      message(FATAL_ERROR "case ${name}: the checker failed on matching files:\n${err}")
    endif()
  else()
    if(rc EQUAL 0)
      message(FATAL_ERROR "case ${name}: the checker accepted a mismatch (${expect})")
    endif()
    string(REGEX REPLACE "[ \n]+" " " flat "${err}")
    string(FIND "${flat}" "${expect}" at)
    if(at EQUAL -1)
      message(FATAL_ERROR "case ${name}: expected '${expect}' in:\n${err}")
    endif()
  endif()
  message(STATUS "case ${name}: ok")
endfunction()

function(mutate text from to out)
  string(FIND "${text}" "${from}" at)
  if(at EQUAL -1)
    message(FATAL_ERROR "mutation source '${from}' not found")
  endif()
  string(REPLACE "${from}" "${to}" text "${text}")
  set(${out} "${text}" PARENT_SCOPE)
endfunction()

run_case(identity "${h0}" "${f0}" "")

# A new C function without a Fortran interface.
mutate("${h0}" "#endif /* MFREE_H */"
       "MFREE_API mfree_status_t mfree_fake_added(int32_t n);\n#endif /* MFREE_H */" h)
run_case(missing_function "${h}" "${f0}" "mfree_fake_added: no interface")

# A Fortran interface left behind after a C function disappeared.
mutate("${f0}" "bind(C, name=\"mfree_particles_setup\")"
       "bind(C, name=\"mfree_particles_setup_gone\")" f)
run_case(stale_binding "${h0}" "${f}" "mfree_particles_setup_gone: bound in Fortran but not declared")

# An enumerator whose value differs.
mutate("${f0}" "MFREE_KERNEL_QUINTIC_SPLINE = 3" "MFREE_KERNEL_QUINTIC_SPLINE = 4" f)
run_case(enum_value "${h0}" "${f}" "enumerator MFREE_KERNEL_QUINTIC_SPLINE: C value 3, Fortran value 4")

# An enumerator the module does not define.
mutate("${h0}" "MFREE_BC_NITSCHE = 4" "MFREE_BC_NITSCHE = 4, MFREE_BC_FAKE = 5" h)
string(REPLACE ", MFREE_BC_FAKE = 5" ",\n  MFREE_BC_FAKE = 5" h "${h}")
run_case(enum_missing "${h}" "${f0}" "enumerator MFREE_BC_FAKE = 5 has no Fortran parameter")

# An int64_t leading dimension bound as a 32-bit integer.
string(REGEX REPLACE "(mfree_particles_set_positions_c[^!]*)integer\\(c_int64_t\\), value :: ld"
       "\\1integer(c_int32_t), value :: ld" f "${f0}")
run_case(argument_kind "${h0}" "${f}" "mfree_particles_set_positions: argument 4 (ld) is C 'i64' but Fortran 'i32'")
