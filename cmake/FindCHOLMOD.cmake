# Finds CHOLMOD (SuiteSparse; Debian's libsuitesparse-dev ships no CMake config before
# SuiteSparse 7). Defines CHOLMOD_FOUND and the imported target CHOLMOD::CHOLMOD, which
# carries the include folder and links SuiteSparse_config with it.
if(TARGET CHOLMOD::CHOLMOD)
  set(CHOLMOD_FOUND TRUE)
  return()
endif()

# SuiteSparse 7 and later install a config with SuiteSparse::CHOLMOD.
find_package(CHOLMOD CONFIG QUIET NO_MODULE)
if(TARGET SuiteSparse::CHOLMOD)
  add_library(CHOLMOD::CHOLMOD INTERFACE IMPORTED)
  set_target_properties(CHOLMOD::CHOLMOD PROPERTIES INTERFACE_LINK_LIBRARIES SuiteSparse::CHOLMOD)
  set(CHOLMOD_FOUND TRUE)
  return()
endif()

# CHOLMOD's own library needs SuiteSparse_config's.
find_library(SUITESPARSECONFIG_LIBRARY suitesparseconfig)
mark_as_advanced(SUITESPARSECONFIG_LIBRARY)
if(NOT SUITESPARSECONFIG_LIBRARY)
  set(CHOLMOD_FOUND FALSE)
  return()
endif()
include("${CMAKE_CURRENT_LIST_DIR}/MeshmotionFindLibrary.cmake")
meshmotion_find_library(CHOLMOD HEADER cholmod.h LIBRARY cholmod PATH_SUFFIXES suitesparse)
if(CHOLMOD_FOUND)
  set_target_properties(CHOLMOD::CHOLMOD PROPERTIES INTERFACE_LINK_LIBRARIES "${SUITESPARSECONFIG_LIBRARY}")
endif()
