# Finds CHOLMOD (SuiteSparse; Debian's libsuitesparse-dev ships no CMake config before
# SuiteSparse 7). Defines CHOLMOD_FOUND and the imported target CHOLMOD::CHOLMOD, located at
# the file meshmotion loads at run time (which brings SuiteSparse_config and BLAS with it).
include("${CMAKE_CURRENT_LIST_DIR}/MeshmotionFindLibrary.cmake")
meshmotion_find_library(CHOLMOD HEADER cholmod.h LIBRARY cholmod PATH_SUFFIXES suitesparse LOADED)
