# The dam break on ranks (examples/mpi/dam_break) against examples/dam_break (cmake -P):
# the serial example, then the MPI example on each of RANKS ranks (Zoltan RCB, and HSFC on
# the largest count), the same ARGS, with leap-frog; then both with the predictor-corrector
# (the MPI example on 2 ranks, HSFC), and both with the acoustic step at CFL 0.75 (the MPI
# example on the largest count, RCB). Each MPI run must exit 0 with status 0, its front
# history Z(T), the floor's front and the sample times bitwise the serial run's (the
# summaries' digests of the doubles; docs/fluid-ranks.md: up to 1,024 particles the fluid
# on ranks is the one-process fluid bit for bit), the same steps and comparison with Martin
# & Moyce, at least two Zoltan partitions, every rank's count within 10 % of the mean after
# each, and particles moved between ranks on more than one rank. The head speed (the
# slope of the front over 1 <= T <= 3) is the serial run's, and that within 10 % of the
# same fit through the experiment's points. The same with no-slip walls (--no-slip 1:
# dummy particles) on 2 ranks (RCB) against the serial no-slip run. Then a run that fails on
# one rank (walls on the fluid's edge: a negative density after a few steps at the
# particle next to the corner, owned by one rank) must exit 3 on every rank with the
# agreed status in the summary, and a bad option must exit 2.
#   -DMPIEXEC=<mpirun> -DSERIAL=<mfree_dam_break> -DPROGRAM=<mfree_mpi_dam_break>
#   -DOUT=<work directory> "-DRANKS=1;2;4" "-DARGS=<;-list>"
cmake_minimum_required(VERSION 3.25)

function(json_get out file)
  file(READ "${file}" text)
  string(JSON value ERROR_VARIABLE err GET "${text}" ${ARGN})
  if(err)
    message(FATAL_ERROR "${file}: no ${ARGN}: ${err}")
  endif()
  set(${out} "${value}" PARENT_SCOPE)
endfunction()

file(REMOVE_RECURSE "${OUT}")
file(MAKE_DIRECTORY "${OUT}")
# the serial example's run with the scheme's arguments (a list), its summary's keys into ref_<key>
set(keys time_digest front_digest front_floor_digest steps compared max_rel_dev head_speed head_fit_points)
macro(serial_reference name)
  execute_process(COMMAND "${SERIAL}" ${ARGS} ${ARGN} --out "${OUT}/${name}" --no-plot --quiet
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 200)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "the serial example (${name}) failed (${rc}):\n${out}\n${err}")
  endif()
  foreach(k ${keys})
    json_get(ref_${k} "${OUT}/${name}/dam_break.json" ${k})
  endforeach()
  # the head speed dZ/dT, fitted over 1 <= T <= 3, within 10 % of the same fit through
  # Martin & Moyce's points there (1.139: 1.025 to 1.253)
  json_get(exp_head "${OUT}/${name}/dam_break.json" head_speed_experiment)
  if(NOT ref_head_fit_points GREATER 2 OR NOT ref_head_speed GREATER 1.025 OR NOT ref_head_speed LESS 1.253
     OR NOT exp_head GREATER 1.139 OR NOT exp_head LESS 1.1392)
    message(FATAL_ERROR "the serial example (${name}): head speed ${ref_head_speed} over ${ref_head_fit_points} "
                        "samples, the experiment's ${exp_head}")
  endif()
  message(STATUS "serial (${name}): ${ref_steps} steps, front ${ref_front_digest}, max |Z - Z_exp| / Z_exp "
                 "${ref_max_rel_dev}, head speed ${ref_head_speed}")
endmacro()

# the MPI example on np ranks with Zoltan's method and the extra arguments, against ref_<key>
function(ranks_run np method name)
  set(dir "${OUT}/np${np}-${method}-${name}")
  execute_process(COMMAND "${MPIEXEC}" --oversubscribe -np ${np} "${PROGRAM}" ${ARGS} ${ARGN} --partitioner ${method}
                          --out "${dir}" --no-plot --quiet
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 400)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${np} ranks (${method}, ${name}) failed (${rc}):\n${out}\n${err}")
  endif()
  set(js "${dir}/mpi_dam_break.json")
  json_get(status "${js}" status)
  json_get(ranks "${js}" ranks)
  if(NOT status EQUAL 0 OR NOT ranks EQUAL np)
    message(FATAL_ERROR "${np} ranks (${method}, ${name}): status ${status}, ${ranks} ranks in ${js}")
  endif()
  foreach(k ${keys})
    json_get(v "${js}" ${k})
    if(NOT v STREQUAL ref_${k})
      message(FATAL_ERROR "${np} ranks (${method}, ${name}): ${k} is ${v}, the serial example's ${ref_${k}}")
    endif()
  endforeach()
  json_get(balanced "${js}" balanced)
  json_get(partitions "${js}" partitions)
  json_get(worst "${js}" max_count_ratio)
  json_get(least "${js}" min_count_ratio)
  json_get(moved "${js}" moved)
  if(NOT balanced EQUAL 1 OR partitions LESS 2 OR worst GREATER 1.10 OR least LESS 0.90)
    message(FATAL_ERROR "${np} ranks (${method}, ${name}): ${partitions} partitions, counts ${least} to ${worst} "
                        "x the mean")
  endif()
  if(np GREATER 1 AND NOT moved GREATER 0)
    message(FATAL_ERROR "${np} ranks (${method}, ${name}): no particle moved between ranks")
  endif()
  message(STATUS "${np} ranks (${method}, ${name}): the serial front's bits; ${partitions} partitions, counts "
                 "${least} to ${worst} x the mean, ${moved} particles moved")
endfunction()

serial_reference(leapfrog)
list(GET RANKS -1 np_last)
foreach(np ${RANKS})
  ranks_run(${np} rcb leapfrog)
endforeach()
ranks_run(${np_last} hsfc leapfrog)
serial_reference(pc --scheme pc)
ranks_run(2 hsfc pc --scheme pc)
serial_reference(noslip --no-slip 1)
ranks_run(2 rcb noslip --no-slip 1)
# the acoustic step (its power iteration on ranks) at CFL 0.75, where it bounds the step
serial_reference(acoustic --acoustic-step 1 --cfl 0.75)
ranks_run(${np_last} rcb acoustic --acoustic-step 1 --cfl 0.75)

# a failure on one rank: every rank stops with the same status
set(dir "${OUT}/fault")
execute_process(COMMAND "${MPIEXEC}" --oversubscribe -np ${np_last} "${PROGRAM}" ${ARGS} --offset 0 --out "${dir}"
                        --no-plot --quiet
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 200)
if(NOT rc EQUAL 3 OR NOT err MATCHES "the run stopped at T = [^\n]*density")
  message(FATAL_ERROR "walls on the fluid's edge on ${np_last} ranks: exit ${rc}, want 3 with the message:\n${out}\n${err}")
endif()
json_get(status "${dir}/mpi_dam_break.json" status)
if(status EQUAL 0)
  message(FATAL_ERROR "walls on the fluid's edge: status 0 in the summary")
endif()
message(STATUS "walls on the fluid's edge on ${np_last} ranks: exit 3, status ${status}")

execute_process(COMMAND "${MPIEXEC}" --oversubscribe -np 2 "${PROGRAM}" --partitioner metis
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 100)
if(NOT rc EQUAL 2 OR NOT err MATCHES "bad or unknown option|usage")
  message(FATAL_ERROR "--partitioner metis: exit ${rc}, want 2:\n${out}\n${err}")
endif()
message(STATUS "bad option: exit 2")
