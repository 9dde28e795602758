# Every context a bench/ program creates opts in to the library's page hints through
# bench_page_hints (bench/bench_util.h), as beb1e93 and earlier did by default: a program
# that forgets it times the library on small pages and compares unlike with like
# (scripts/bench-compare.sh, BENCHMARKS.md). Run with cmake -P:  -DBENCH=<repository>/bench
#
# Fails, naming the file, when a source of bench/ has more mfree_context_create calls than
# bench_page_hints calls.
cmake_minimum_required(VERSION 3.25)
if(NOT DEFINED BENCH OR NOT IS_DIRECTORY "${BENCH}")
  message(FATAL_ERROR "usage: cmake -DBENCH=<repository>/bench -P check_bench_page_hints.cmake")
endif()

file(GLOB files RELATIVE "${BENCH}" LIST_DIRECTORIES false "${BENCH}/*.c" "${BENCH}/*.cpp")
list(SORT files)
set(problems "")
set(checked 0)
foreach(f IN LISTS files)
  file(READ "${BENCH}/${f}" text)
  string(REGEX MATCHALL "mfree_context_create\\(" creates "${text}")
  string(REGEX MATCHALL "bench_page_hints\\(" hints "${text}")
  list(LENGTH creates nc)
  list(LENGTH hints nh)
  if(nc GREATER 0)
    math(EXPR checked "${checked} + 1")
  endif()
  if(nc GREATER nh)
    string(APPEND problems "  bench/${f}: ${nc} mfree_context_create, ${nh} bench_page_hints\n")
  endif()
endforeach()
if(checked EQUAL 0)
  message(FATAL_ERROR "no bench/ source creates a context: wrong directory ${BENCH}?")
endif()
if(problems)
  message(FATAL_ERROR "contexts of bench/ programs without the page-hints opt-in "
                      "(call bench_page_hints(ctx) after mfree_context_create):\n${problems}")
endif()
message(STATUS "${checked} bench/ programs, every context opts in to the page hints")
