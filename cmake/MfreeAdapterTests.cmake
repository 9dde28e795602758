# Test helpers shared by the adapters' test folders (tests/{mpi,petsc,suitesparse,
# sundials}); included by tests/CMakeLists.txt.

# Open MPI refuses to run as root (CI does) without the first two; CI has 2 cores, so
# ranks oversubscribe. MPI and PETSc are not instrumented and keep memory until exit:
# under the sanitizers, leak detection is off for the tests run by mpirun (every other
# ASan/UBSan check stays; mpirun passes the environment on to the ranks).
set(MFREE_MPI_TEST_ENV OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
    OMPI_MCA_rmaps_base_oversubscribe=1 "ASAN_OPTIONS=detect_leaks=0:abort_on_error=0"
    "UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1")

# mfree_add_mpi_test(<name> TARGET <executable target> RANKS <n>... [LABELS <label>...]
#                    [TIMEOUT <seconds>] [ARGS <argument>...])
# One test <name>-np<n> per rank count: the program under mpirun --oversubscribe, with
# the environment above and a timeout (default 120 s), so that a rank left waiting fails
# the test instead of hanging CI. Labels default to "mpi".
function(mfree_add_mpi_test name)
  cmake_parse_arguments(PARSE_ARGV 1 A "" "TARGET;TIMEOUT" "RANKS;LABELS;ARGS")
  if(NOT MFREE_MPIEXEC)
    find_program(MFREE_MPIEXEC NAMES mpirun mpiexec HINTS ${MPIEXEC_EXECUTABLE})
  endif()
  if(NOT MFREE_MPIEXEC)
    message(STATUS "mpirun not found: ${name} is not registered (install openmpi-bin)")
    return()
  endif()
  if(NOT A_TIMEOUT)
    set(A_TIMEOUT 120)
  endif()
  if(NOT A_LABELS)
    set(A_LABELS mpi)
  endif()
  foreach(np IN LISTS A_RANKS)
    add_test(NAME ${name}-np${np}
      COMMAND ${MFREE_MPIEXEC} --oversubscribe -np ${np} $<TARGET_FILE:${A_TARGET}> ${A_ARGS})
    if(np GREATER 2)
      set(procs 2)
    else()
      set(procs ${np})
    endif()
    set_tests_properties(${name}-np${np} PROPERTIES
      LABELS "${A_LABELS}" TIMEOUT ${A_TIMEOUT} PROCESSORS ${procs} ENVIRONMENT "${MFREE_MPI_TEST_ENV}")
  endforeach()
endfunction()

# mfree_add_adapter_packaging_tests(<adapter> NUMBERS <c99> <cxx> <symbols> <layering>
#     <consumers> LABELS <label>... [INCLUDES <dir>...] [CXX_STD <year>] [CXX_FLAGS <flag>...]
#     LAYER_NAME <text> FORBIDDEN <regex> REQUIRED <library>...
#     CONSUMER_PREFIX <prefix> CONSUMER_OK <n> [CONSUMER_LIBS <flag>...]
#     [ENVIRONMENT <var=value>...])
# The packaging tests of libmfree_<adapter> (labels LABELS and packaging):
#  - t<c99>-<adapter>-header-c99, t<cxx>-<adapter>-header-cxx: its header
#    adapters/<adapter>/include/mfree_<adapter>.h compiled as strict C99 and C++ (C++11
#    unless CXX_STD says otherwise; CXX_FLAGS added) by tests/<adapter>/header_use.c,
#    with the include directories of its dependencies (INCLUDES);
#  - t<symbols>-<adapter>-abi-symbols: its exported symbols are
#    adapters/<adapter>/libmfree_<adapter>.symbols (Linux);
#  - t<layering>-<adapter>-layering: the core needs none of the libraries matching
#    FORBIDDEN, the adapter needs each of REQUIRED (Linux);
#  - t<consumers>-<adapter>-consumers (MFREE_TEST_PACKAGING): tests/<adapter>/consumer
#    built against `cmake --install` of this tree with pkg-config and with
#    find_package(mfree COMPONENTS <adapter>) (tests/packaging/adapter_consumers.sh),
#    expecting CONSUMER_OK lines "...: ok"; CONSUMER_LIBS are linked after pkg-config's.
function(mfree_add_adapter_packaging_tests adapter)
  cmake_parse_arguments(PARSE_ARGV 1 A "" "CXX_STD;LAYER_NAME;FORBIDDEN;CONSUMER_PREFIX;CONSUMER_OK"
                        "NUMBERS;LABELS;INCLUDES;CXX_FLAGS;REQUIRED;CONSUMER_LIBS;ENVIRONMENT")
  list(LENGTH A_NUMBERS count)
  if(NOT count EQUAL 5)
    message(FATAL_ERROR "mfree_add_adapter_packaging_tests(${adapter}): NUMBERS takes five test numbers")
  endif()
  list(GET A_NUMBERS 0 n_c99)
  list(GET A_NUMBERS 1 n_cxx)
  list(GET A_NUMBERS 2 n_symbols)
  list(GET A_NUMBERS 3 n_layering)
  list(GET A_NUMBERS 4 n_consumers)
  set(labels ${A_LABELS} packaging)
  set(check ${PROJECT_SOURCE_DIR}/tests/packaging)
  set(lib mfree_${adapter})

  set(includes ${PROJECT_SOURCE_DIR}/adapters/${adapter}/include ${PROJECT_SOURCE_DIR}/include
               ${PROJECT_BINARY_DIR}/include ${A_INCLUDES})
  if(NOT A_CXX_STD)
    set(A_CXX_STD 11)
  endif()
  set(cxx_flags -x c++ -std=c++${A_CXX_STD} -pedantic -Wall -Wextra -Werror ${A_CXX_FLAGS})
  add_test(NAME t${n_c99}-${adapter}-header-c99
    COMMAND ${CMAKE_COMMAND}
      -DCOMPILER=${CMAKE_C_COMPILER}
      "-DFLAGS=-std=c99;-pedantic;-Wall;-Wextra;-Werror"
      "-DINCLUDES=${includes}"
      -DSOURCE=${PROJECT_SOURCE_DIR}/tests/${adapter}/header_use.c
      -DHEADER=${PROJECT_SOURCE_DIR}/adapters/${adapter}/include/${lib}.h
      -P ${check}/check_header.cmake)
  add_test(NAME t${n_cxx}-${adapter}-header-cxx
    COMMAND ${CMAKE_COMMAND}
      -DCOMPILER=${CMAKE_CXX_COMPILER}
      "-DFLAGS=${cxx_flags}"
      "-DINCLUDES=${includes}"
      -DSOURCE=${PROJECT_SOURCE_DIR}/tests/${adapter}/header_use.c
      -P ${check}/check_header.cmake)
  set_tests_properties(t${n_c99}-${adapter}-header-c99 t${n_cxx}-${adapter}-header-cxx
                       PROPERTIES LABELS "${labels}")

  if(CMAKE_SYSTEM_NAME STREQUAL "Linux")
    add_test(NAME t${n_symbols}-${adapter}-abi-symbols
      COMMAND ${CMAKE_COMMAND}
        -DLIB=$<TARGET_FILE:${lib}>
        -DEXPECTED=${PROJECT_SOURCE_DIR}/adapters/${adapter}/lib${lib}.symbols
        -DNM=${CMAKE_NM}
        -P ${check}/check_symbols.cmake)
    add_test(NAME t${n_layering}-${adapter}-layering
      COMMAND ${CMAKE_COMMAND}
        -DCORE=$<TARGET_FILE:mfree>
        -DADAPTER=$<TARGET_FILE:${lib}>
        -DREADELF=${CMAKE_READELF} "-DNAME=${A_LAYER_NAME}"
        "-DFORBIDDEN=${A_FORBIDDEN}" "-DREQUIRED=${A_REQUIRED}"
        -P ${check}/check_layering.cmake)
    set_tests_properties(t${n_symbols}-${adapter}-abi-symbols t${n_layering}-${adapter}-layering
                         PROPERTIES LABELS "${labels}")
  endif()

  if(MFREE_TEST_PACKAGING)
    find_program(MFREE_BASH bash REQUIRED)
    add_test(NAME t${n_consumers}-${adapter}-consumers
      COMMAND ${MFREE_BASH} ${check}/adapter_consumers.sh
        ${PROJECT_BINARY_DIR} ${CMAKE_CURRENT_BINARY_DIR}/t${n_consumers} ${PROJECT_SOURCE_DIR}
        ${CMAKE_C_COMPILER} ${adapter} ${A_CONSUMER_PREFIX} ${A_CONSUMER_OK} ${A_CONSUMER_LIBS})
    set_tests_properties(t${n_consumers}-${adapter}-consumers PROPERTIES
      LABELS "${labels}"
      ENVIRONMENT "CMAKE=${CMAKE_COMMAND};${A_ENVIRONMENT}"
      RESOURCE_LOCK mfree_install
      TIMEOUT 600)
  endif()
endfunction()
