# Typed handles (run with cmake -P): a program that passes a particle set where an
# approximant is expected must not compile, while the same program with the right handle
# compiles. -DFC=<Fortran compiler> -DMODDIR=<directory of mfree.mod> -DWORKDIR=<dir>
cmake_minimum_required(VERSION 3.25)
foreach(v FC MODDIR WORKDIR)
  if(NOT DEFINED ${v})
    message(FATAL_ERROR "check_typed_handles.cmake: -D${v}=... is required")
  endif()
endforeach()
file(MAKE_DIRECTORY "${WORKDIR}")

function(try_source name arg out_rc out_log)
  file(WRITE "${WORKDIR}/${name}.f90" "program ${name}
  use, intrinsic :: iso_c_binding, only: c_int
  use mfree
  implicit none
  type(mfree_context) :: ctx
  type(mfree_particles) :: ps
  type(mfree_approximant) :: a
  integer(c_int) :: st
  st = mfree_context_create(ctx)
  st = mfree_approximant_setup(${arg})
  st = mfree_particles_destroy(ps)
  st = mfree_approximant_destroy(a)
end program ${name}
")
  execute_process(COMMAND "${FC}" -std=f2008 -fsyntax-only -I "${MODDIR}" "${name}.f90"
                  WORKING_DIRECTORY "${WORKDIR}"
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  set(${out_rc} "${rc}" PARENT_SCOPE)
  set(${out_log} "${out}${err}" PARENT_SCOPE)
endfunction()

try_source(right_handle a rc log)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "the program with the right handle does not compile:\n${log}")
endif()
try_source(wrong_handle ps rc log)
if(rc EQUAL 0)
  message(FATAL_ERROR "a particle set was accepted where an approximant is expected")
endif()
if(NOT log MATCHES "[Tt]ype mismatch|TYPE\\(mfree_particles\\)|mfree_particles")
  message(FATAL_ERROR "compilation failed, but not for the handle type:\n${log}")
endif()
message(STATUS "wrong handle type rejected at compile time:\n${log}")
