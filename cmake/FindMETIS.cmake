# Finds METIS (Debian's libmetis-dev ships no CMake config). Defines METIS_FOUND and the
# imported target METIS::METIS.
include("${CMAKE_CURRENT_LIST_DIR}/MeshmotionFindLibrary.cmake")
meshmotion_find_library(METIS HEADER metis.h LIBRARY metis)
