# Comments say why, not when or how fast (run with cmake -P):  -DROOT=<repository>
#
# Fails, listing file and line, on a comment of a C, C++ or Fortran source, header or
# CMake script that holds
#   - a timing: a number with ms, us, µs or ns, or micro-, milli- or nanoseconds at all;
#   - a speed comparison: "N % faster", "N x slower", "N times faster", "N % of a search";
#   - an issue or pull-request number: "issue 8", "issue-8", "#12", "PR 3".
# Measurements belong in BENCHMARKS.md (with the command that reproduces them), history
# in git. The library and the benchmarks (src, adapters, bench) are held to all three;
# tests, examples, fuzz harnesses and bindings to the last only, because their comments
# state physical times of the problems they run ("a 3 us pulse"). The comment text is
# what follows // (C, C++), # (CMake) or ! (Fortran) on a line, or lies between /* and */.
cmake_minimum_required(VERSION 3.25)
if(NOT DEFINED ROOT OR NOT IS_DIRECTORY "${ROOT}")
  message(FATAL_ERROR "usage: cmake -DROOT=<repository> -P check_comments.cmake")
endif()
set(all_dirs src adapters bench)
set(history_dirs tests examples fuzz bindings)

set(history_patterns
  "issues? ?[-#]? ?[0-9]"
  "(^|[^a-z0-9&])#[0-9]+"
  "(^|[^a-z])(pr|pull request) ?#?[0-9]")
set(speed_patterns
  "[0-9] ?(ms|us|µs|ns)([^a-z0-9]|$)"
  "(^|[^a-z])(micro|milli|nano)-?seconds?([^a-z]|$)"
  "[0-9] ?(%|x|times) (faster|slower)"
  "[0-9] ?% of [^.;]*(search|setup|step|run|work|time)")

set(problems "")
set(nf 0)
foreach(dir IN LISTS all_dirs history_dirs)
  if(NOT IS_DIRECTORY "${ROOT}/${dir}")
    continue()
  endif()
  if(dir IN_LIST all_dirs)
    set(patterns ${history_patterns} ${speed_patterns})
  else()
    set(patterns ${history_patterns})
  endif()
  file(GLOB_RECURSE files RELATIVE "${ROOT}" LIST_DIRECTORIES false
       "${ROOT}/${dir}/*.h" "${ROOT}/${dir}/*.hpp" "${ROOT}/${dir}/*.c" "${ROOT}/${dir}/*.cpp"
       "${ROOT}/${dir}/*.inc" "${ROOT}/${dir}/*.f90" "${ROOT}/${dir}/*.F90"
       "${ROOT}/${dir}/*.cmake" "${ROOT}/${dir}/CMakeLists.txt")
  # this script names the patterns it looks for
  list(REMOVE_ITEM files "tests/layout/check_comments.cmake")
  list(SORT files)
  foreach(f IN LISTS files)
    math(EXPR nf "${nf} + 1")
    if(f MATCHES "(\\.cmake|CMakeLists\\.txt)$")
      set(line_mark "#")
    elseif(f MATCHES "\\.[fF]90$")
      set(line_mark "!")
    else()
      set(line_mark "//")
    endif()
    # one list element per line: characters that CMake's lists treat specially (; [ ] \)
    # become harmless ones first (the patterns do not need them)
    file(READ "${ROOT}/${f}" text)
    string(REPLACE ";" "," text "${text}")
    string(REPLACE "[" "(" text "${text}")
    string(REPLACE "]" ")" text "${text}")
    string(REPLACE "\\" "/" text "${text}")
    string(REPLACE "\n" ";" lines "${text}")
    set(in_block FALSE)
    set(n 0)
    foreach(line IN LISTS lines)
      math(EXPR n "${n} + 1")
      set(comment "")
      if(in_block)
        string(FIND "${line}" "*/" e)
        if(e EQUAL -1)
          set(comment "${line}")
        else()
          string(SUBSTRING "${line}" 0 ${e} comment)
          set(in_block FALSE)
        endif()
      else()
        string(FIND "${line}" "${line_mark}" s)
        if(line_mark STREQUAL "//")
          string(FIND "${line}" "/*" b)
        else()
          set(b -1)
        endif()
        if(NOT s EQUAL -1 AND (b EQUAL -1 OR s LESS b))
          string(LENGTH "${line_mark}" ml)
          math(EXPR s "${s} + ${ml}")
          string(SUBSTRING "${line}" ${s} -1 comment)
        elseif(NOT b EQUAL -1)
          math(EXPR b "${b} + 2")
          string(SUBSTRING "${line}" ${b} -1 rest)
          string(FIND "${rest}" "*/" e)
          if(e EQUAL -1)
            set(comment "${rest}")
            set(in_block TRUE)
          else()
            string(SUBSTRING "${rest}" 0 ${e} comment)
          endif()
        endif()
      endif()
      if(comment STREQUAL "")
        continue()
      endif()
      string(TOLOWER "${comment}" low)
      foreach(re IN LISTS patterns)
        if(low MATCHES "${re}")
          string(STRIP "${comment}" shown)
          string(APPEND problems "  ${f}:${n}: ${shown}\n")
          break()
        endif()
      endforeach()
    endforeach()
  endforeach()
endforeach()

if(NOT problems STREQUAL "")
  message(FATAL_ERROR "comments with timings, speed figures or issue numbers "
                      "(measurements go to BENCHMARKS.md, history to git):\n${problems}")
endif()
message(STATUS "comments: ${nf} files, no timings, speed figures or issue numbers")
