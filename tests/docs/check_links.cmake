# Link check of the Markdown documents (run with cmake -P; -DROOT=<source tree>):
#  - every relative link [text](target) of README.md, the other top-level documents,
#    docs/*.md and the READMEs of the sub-folders resolves to a file or folder inside the
#    repository, and its #anchor, if any, to a heading of the target document (GitHub's
#    heading ids: lower case, punctuation dropped, spaces to hyphens, -1, -2 for repeats);
#  - no document, source, script or build file refers to a path outside the repository
#    (the project's shared folder beside it, or the absolute path of a checkout);
#  - the public headers name no test ids and cite papers by their docs/references.md key;
#  - no document, source, script or message cites the team's private notes on the papers
#    (a "spec" cited by its seed number, section, note or claim, or the notes' numbered
#    claims): a reader has the papers' own numbers and docs/papers.md
#    (t909 is the documents check as a whole: links, paths, headers, citations).
# Links inside code blocks and code spans are not links and are skipped, as are URLs.
cmake_minimum_required(VERSION 3.25)
if(NOT DEFINED ROOT)
  message(FATAL_ERROR "check_links.cmake: -DROOT=<source tree> is required")
endif()
get_filename_component(ROOT "${ROOT}" REALPATH)

set(errors "")
set(nlinks 0)

# Lines of a file, code blocks blanked (so line numbers stay right), code spans removed;
# brackets stay written as @LB@ and @RB@ (a CMake list does not split inside [ ]).
function(prose_lines file out)
  file(READ "${file}" text)
  string(REPLACE ";" "@SEMI@" text "${text}")
  string(REPLACE "[" "@LB@" text "${text}")
  string(REPLACE "]" "@RB@" text "${text}")
  string(REPLACE "\n" ";" lines "${text}")
  set(result "")
  set(fence FALSE)
  foreach(line IN LISTS lines)
    if(line MATCHES "^[ ]*(```|~~~)")
      if(fence)
        set(fence FALSE)
      else()
        set(fence TRUE)
      endif()
      set(line "")
    elseif(fence)
      set(line "")
    else()
      string(REGEX REPLACE "`[^`]*`" "" line "${line}")
    endif()
    list(APPEND result "${line}")
  endforeach()
  set(${out} "${result}" PARENT_SCOPE)
endfunction()

# GitHub's ids of the headings of a Markdown file.
function(heading_ids file out)
  prose_lines("${file}" lines)
  set(ids "")
  foreach(line IN LISTS lines)
    if(line MATCHES "^#+[ \t]+(.*)$")
      set(h "${CMAKE_MATCH_1}")
      string(REGEX REPLACE "[ \t]+#+[ \t]*$" "" h "${h}")
      string(REGEX REPLACE "@SEMI@" "" h "${h}")
      string(TOLOWER "${h}" h)
      string(REGEX REPLACE "@RB@\\([^)]*\\)" "" h "${h}")  # [text](url): the text stays
      string(REGEX REPLACE "@[LR]B@" "" h "${h}")
      string(REGEX REPLACE "[^a-z0-9 _-]" "" h "${h}")
      string(REPLACE " " "-" h "${h}")
      set(id "${h}")
      set(k 1)
      while(id IN_LIST ids)
        set(id "${h}-${k}")
        math(EXPR k "${k} + 1")
      endwhile()
      list(APPEND ids "${id}")
    endif()
  endforeach()
  set(${out} "${ids}" PARENT_SCOPE)
endfunction()

file(GLOB documents ${ROOT}/*.md ${ROOT}/docs/*.md ${ROOT}/*/README.md ${ROOT}/*/*/README.md)
list(FILTER documents EXCLUDE REGEX "^${ROOT}/build")
list(SORT documents)
foreach(doc IN LISTS documents)
  file(RELATIVE_PATH rel "${ROOT}" "${doc}")
  get_filename_component(dir "${doc}" DIRECTORY)
  prose_lines("${doc}" lines)
  set(lineno 0)
  foreach(line IN LISTS lines)
    math(EXPR lineno "${lineno} + 1")
    string(REGEX MATCHALL "@RB@\\([^) \t]+\\)" links "${line}")
    foreach(link IN LISTS links)
      string(REGEX REPLACE "^@RB@\\((.*)\\)$" "\\1" target "${link}")
      if(target MATCHES "^[a-zA-Z][a-zA-Z0-9+.-]*:")  # https:, mailto:, ...
        continue()
      endif()
      math(EXPR nlinks "${nlinks} + 1")
      set(anchor "")
      if(target MATCHES "^([^#]*)#(.*)$")
        set(target "${CMAKE_MATCH_1}")
        set(anchor "${CMAKE_MATCH_2}")
      endif()
      if(target STREQUAL "")
        set(path "${doc}")
      else()
        get_filename_component(path "${target}" ABSOLUTE BASE_DIR "${dir}")
      endif()
      string(FIND "${path}/" "${ROOT}/" at)
      if(NOT at EQUAL 0)
        string(APPEND errors "  ${rel}:${lineno}: ${target} lies outside the repository\n")
        continue()
      endif()
      if(NOT EXISTS "${path}")
        string(APPEND errors "  ${rel}:${lineno}: ${target} does not exist\n")
        continue()
      endif()
      if(NOT anchor STREQUAL "")
        if(NOT path MATCHES "\\.md$")
          string(APPEND errors "  ${rel}:${lineno}: #${anchor} in a file that is not Markdown\n")
        else()
          heading_ids("${path}" ids)
          if(NOT anchor IN_LIST ids)
            if(target STREQUAL "")
              set(target "${rel}")
            endif()
            string(APPEND errors "  ${rel}:${lineno}: no heading #${anchor} in ${target}\n")
          endif()
        endif()
      endif()
    endforeach()
  endforeach()
endforeach()

# Paths outside the repository, in every tracked kind of text file.
file(GLOB_RECURSE sources LIST_DIRECTORIES false
     ${ROOT}/*.md ${ROOT}/*.c ${ROOT}/*.h ${ROOT}/*.cpp ${ROOT}/*.hpp ${ROOT}/*.inc
     ${ROOT}/*.f90 ${ROOT}/*.cmake ${ROOT}/*.in ${ROOT}/*.txt ${ROOT}/*.sh ${ROOT}/*.json
     ${ROOT}/*.nml ${ROOT}/*.csv)
list(FILTER sources EXCLUDE REGEX "^${ROOT}/(build|\\.git)/")
foreach(f IN LISTS sources)
  # (the patterns are written so that this file does not match itself)
  file(STRINGS "${f}" hits REGEX "[.][.]/shar[e]d|/wor[k]/")
  if(hits)
    file(RELATIVE_PATH rel "${ROOT}" "${f}")
    list(GET hits 0 first)
    string(APPEND errors "  ${rel}: refers to a path outside the repository: ${first}\n")
  endif()
  # the notes are not in the repository: cite the paper's section, equation or table, or
  # docs/papers.md for errata and reproduction choices (written so as not to match here)
  # Paper 000 has no sections numbered 4.5 to 4.11 or 5.4 to 5.7: those are the notes'
  # numbers for its 4.4.x, 5.2.x and 5.3.
  file(STRINGS "${f}" hits REGEX "[Ss]pe[c] ([0-9]|note|claim|section)|[Ss]pe[c]'s|00[0-9] section[s]? [0-9]|clai[m]s? ([0-9]+[.][0-9A-Z]|[A-Z][0-9])|(^|[^0-9])00[0-9] [A-Z][0-9]([^0-9]|$)|(000|Belytschko1998])[^;]?[^;]?[^;]?[^;]?[^;]?[^;]?[^;]?[^;]?[^;]?[^;]?[^;]?[^;]?Sects?[.] (4[.]([5-9]|1[01])|5[.][4-7])")
  if(hits)
    file(RELATIVE_PATH rel "${ROOT}" "${f}")
    list(GET hits 0 first)
    string(APPEND errors "  ${rel}: cites the team's private notes on the papers (cite the paper or docs/papers.md): ${first}\n")
  endif()
endforeach()

# The public headers are self-contained: papers cited by their key of docs/references.md,
# not by the project's seed numbers, and no test named as evidence.
file(GLOB headers ${ROOT}/include/*.h ${ROOT}/adapters/*/include/*.h)
foreach(h IN LISTS headers)
  file(STRINGS "${h}" hits REGEX "(^|[^A-Za-z0-9_])t[0-9][0-9][0-9]([^0-9]|$)|(paper|spec) 00[0-9]|00[0-9] (eq|eqs|Sect|Table)")
  if(hits)
    file(RELATIVE_PATH rel "${ROOT}" "${h}")
    list(GET hits 0 first)
    string(APPEND errors "  ${rel}: a test id or a seed-number citation (cite docs/references.md keys): ${first}\n")
  endif()
endforeach()

list(LENGTH documents ndocs)
if(errors)
  message(FATAL_ERROR "broken or outside links:\n${errors}")
endif()
message(STATUS "${nlinks} relative links in ${ndocs} documents resolve; no path outside the repository")
