# Comments in src/ say why, not when or how fast (run with cmake -P):  -DSRC=<repository>/src
#
# Fails, listing file and line, on a comment of a source or header under src/ that holds
#   - a timing: a number with ms, us, µs or ns;
#   - a speed comparison: "N % faster", "N x slower", "N times faster", "N % of a search";
#   - an issue or pull-request number: "issue 8", "issue-8", "#12", "PR 3".
# Measurements belong in BENCHMARKS.md (with the command that reproduces them), history
# in git. The comment text is what follows // on a line, or lies between /* and */.
cmake_minimum_required(VERSION 3.25)
if(NOT DEFINED SRC OR NOT IS_DIRECTORY "${SRC}")
  message(FATAL_ERROR "usage: cmake -DSRC=<repository>/src -P check_comments.cmake")
endif()

set(patterns
  "[0-9] ?(ms|us|µs|ns)([^a-z0-9]|$)"
  "[0-9] ?(%|x|times) (faster|slower)"
  "[0-9] ?% of [^.;]*(search|setup|step|run|work|time)"
  "issues? ?[-#]? ?[0-9]"
  "(^|[^a-z0-9&])#[0-9]+"
  "(^|[^a-z])(pr|pull request) ?#?[0-9]")

file(GLOB_RECURSE files RELATIVE "${SRC}" LIST_DIRECTORIES false
     "${SRC}/*.h" "${SRC}/*.hpp" "${SRC}/*.c" "${SRC}/*.cpp" "${SRC}/*.inc")
list(SORT files)
set(problems "")
foreach(f IN LISTS files)
  # one list element per line: characters that CMake's lists treat specially (; [ ] \)
  # become harmless ones first (the patterns do not need them)
  file(READ "${SRC}/${f}" text)
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
      set(rest "${line}")
      string(FIND "${rest}" "*/" e)
      if(e EQUAL -1)
        set(comment "${rest}")
      else()
        string(SUBSTRING "${rest}" 0 ${e} comment)
        set(in_block FALSE)
      endif()
    else()
      string(FIND "${line}" "//" s)
      string(FIND "${line}" "/*" b)
      if(NOT s EQUAL -1 AND (b EQUAL -1 OR s LESS b))
        math(EXPR s "${s} + 2")
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
        string(APPEND problems "  src/${f}:${n}: ${shown}\n")
        break()
      endif()
    endforeach()
  endforeach()
endforeach()

list(LENGTH files nf)
if(NOT problems STREQUAL "")
  message(FATAL_ERROR "comments in src/ with timings, speed figures or issue numbers "
                      "(measurements go to BENCHMARKS.md, history to git):\n${problems}")
endif()
message(STATUS "comments in src/: ${nf} files, no timings, speed figures or issue numbers")
