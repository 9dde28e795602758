# FindSuiteSparse
# ---------------
# Find SuiteSparse 5.x as Debian/Ubuntu ship it (libsuitesparse-dev: headers in
# <prefix>/include/suitesparse, libraries in the multiarch directory, no CMake package
# of its own).
#
#   find_package(SuiteSparse [version] [REQUIRED] [COMPONENTS cholmod umfpack klu ...])
#
# Components: cholmod umfpack klu, and the libraries they use: amd camd colamd ccolamd
# btf suitesparseconfig. Without COMPONENTS: cholmod umfpack klu. The dependencies of a
# requested component are looked for and linked along with it.
#
# Imported targets (one per found library):
#   SuiteSparse::suitesparseconfig, ::amd, ::camd, ::colamd, ::ccolamd, ::btf,
#   SuiteSparse::cholmod (amd camd colamd ccolamd suitesparseconfig),
#   SuiteSparse::umfpack (amd suitesparseconfig; its CHOLMOD ordering comes from the
#   shared library's own dependencies), SuiteSparse::klu (amd colamd btf
#   suitesparseconfig).
# Variables:
#   SuiteSparse_FOUND, SuiteSparse_VERSION (from SuiteSparse_config.h, e.g. 5.12.0),
#   SuiteSparse_INCLUDE_DIR, SuiteSparse_<comp>_FOUND, SuiteSparse_<comp>_LIBRARY.
# Hints: SuiteSparse_ROOT (CMake's <Package>_ROOT), CMAKE_PREFIX_PATH.

set(_ss_deps_suitesparseconfig "")
set(_ss_deps_amd suitesparseconfig)
set(_ss_deps_camd suitesparseconfig)
set(_ss_deps_colamd suitesparseconfig)
set(_ss_deps_ccolamd suitesparseconfig)
set(_ss_deps_btf "")
set(_ss_deps_cholmod amd camd colamd ccolamd suitesparseconfig)
set(_ss_deps_umfpack amd suitesparseconfig)
set(_ss_deps_klu amd colamd btf suitesparseconfig)
set(_ss_header_suitesparseconfig SuiteSparse_config.h)
set(_ss_known suitesparseconfig amd camd colamd ccolamd btf cholmod umfpack klu)
foreach(_ss_c IN LISTS _ss_known)
  if(NOT _ss_c STREQUAL "suitesparseconfig")
    set(_ss_header_${_ss_c} ${_ss_c}.h)
  endif()
endforeach()

if(SuiteSparse_FIND_COMPONENTS)
  set(_ss_wanted ${SuiteSparse_FIND_COMPONENTS})
else()
  set(_ss_wanted cholmod umfpack klu)
  foreach(_ss_c IN LISTS _ss_wanted)
    set(SuiteSparse_FIND_REQUIRED_${_ss_c} TRUE)
  endforeach()
endif()
foreach(_ss_c IN LISTS _ss_wanted)
  if(NOT _ss_c IN_LIST _ss_known)
    message(FATAL_ERROR "FindSuiteSparse: unknown component '${_ss_c}' "
                        "(known: ${_ss_known})")
  endif()
endforeach()

# Requested components and, transitively, what they need (deps lists are complete).
set(_ss_all ${_ss_wanted})
foreach(_ss_c IN LISTS _ss_wanted)
  list(APPEND _ss_all ${_ss_deps_${_ss_c}})
endforeach()
list(APPEND _ss_all suitesparseconfig)
list(REMOVE_DUPLICATES _ss_all)

find_path(SuiteSparse_INCLUDE_DIR NAMES SuiteSparse_config.h
          PATH_SUFFIXES suitesparse include/suitesparse
          DOC "Directory of the SuiteSparse headers")
mark_as_advanced(SuiteSparse_INCLUDE_DIR)

if(SuiteSparse_INCLUDE_DIR AND EXISTS "${SuiteSparse_INCLUDE_DIR}/SuiteSparse_config.h")
  file(STRINGS "${SuiteSparse_INCLUDE_DIR}/SuiteSparse_config.h" _ss_version_lines
       REGEX "^#define SUITESPARSE_(MAIN|SUB|SUBSUB)_VERSION[ \t]+[0-9]+")
  foreach(_ss_part MAIN SUB SUBSUB)
    set(_ss_${_ss_part} "")
    foreach(_ss_line IN LISTS _ss_version_lines)
      if(_ss_line MATCHES "^#define SUITESPARSE_${_ss_part}_VERSION[ \t]+([0-9]+)")
        set(_ss_${_ss_part} "${CMAKE_MATCH_1}")
      endif()
    endforeach()
  endforeach()
  if(NOT _ss_MAIN STREQUAL "" AND NOT _ss_SUB STREQUAL "" AND NOT _ss_SUBSUB STREQUAL "")
    set(SuiteSparse_VERSION "${_ss_MAIN}.${_ss_SUB}.${_ss_SUBSUB}")
  endif()
endif()

foreach(_ss_c IN LISTS _ss_all)
  find_library(SuiteSparse_${_ss_c}_LIBRARY NAMES ${_ss_c}
               DOC "SuiteSparse ${_ss_c} library")
  mark_as_advanced(SuiteSparse_${_ss_c}_LIBRARY)
  set(SuiteSparse_${_ss_c}_FOUND FALSE)
  if(SuiteSparse_${_ss_c}_LIBRARY AND SuiteSparse_INCLUDE_DIR
     AND EXISTS "${SuiteSparse_INCLUDE_DIR}/${_ss_header_${_ss_c}}")
    set(SuiteSparse_${_ss_c}_FOUND TRUE)
  endif()
endforeach()
# A component counts as found only with everything it links.
foreach(_ss_c IN LISTS _ss_all)
  foreach(_ss_d IN LISTS _ss_deps_${_ss_c})
    if(NOT SuiteSparse_${_ss_d}_FOUND)
      set(SuiteSparse_${_ss_c}_FOUND FALSE)
    endif()
  endforeach()
endforeach()

include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(SuiteSparse
  REQUIRED_VARS SuiteSparse_INCLUDE_DIR SuiteSparse_suitesparseconfig_LIBRARY
  VERSION_VAR SuiteSparse_VERSION
  HANDLE_COMPONENTS)

if(SuiteSparse_FOUND)
  # Dependencies first, so that INTERFACE_LINK_LIBRARIES name existing targets.
  foreach(_ss_c IN ITEMS suitesparseconfig amd camd colamd ccolamd btf cholmod umfpack klu)
    if(_ss_c IN_LIST _ss_all AND SuiteSparse_${_ss_c}_FOUND
       AND NOT TARGET SuiteSparse::${_ss_c})
      add_library(SuiteSparse::${_ss_c} UNKNOWN IMPORTED)
      set_target_properties(SuiteSparse::${_ss_c} PROPERTIES
        IMPORTED_LOCATION "${SuiteSparse_${_ss_c}_LIBRARY}"
        INTERFACE_INCLUDE_DIRECTORIES "${SuiteSparse_INCLUDE_DIR}")
      set(_ss_links "")
      foreach(_ss_d IN LISTS _ss_deps_${_ss_c})
        list(APPEND _ss_links SuiteSparse::${_ss_d})
      endforeach()
      if(_ss_links)
        set_target_properties(SuiteSparse::${_ss_c} PROPERTIES
          INTERFACE_LINK_LIBRARIES "${_ss_links}")
      endif()
    endif()
  endforeach()
endif()

foreach(_ss_v _ss_deps_suitesparseconfig _ss_deps_amd _ss_deps_camd _ss_deps_colamd
        _ss_deps_ccolamd _ss_deps_btf _ss_deps_cholmod _ss_deps_umfpack _ss_deps_klu
        _ss_known _ss_wanted _ss_all _ss_c _ss_d _ss_links _ss_version_lines _ss_line
        _ss_part _ss_MAIN _ss_SUB _ss_SUBSUB)
  unset(${_ss_v})
endforeach()
foreach(_ss_c IN ITEMS suitesparseconfig amd camd colamd ccolamd btf cholmod umfpack klu)
  unset(_ss_header_${_ss_c})
endforeach()
unset(_ss_c)
unset(_ss_v)
