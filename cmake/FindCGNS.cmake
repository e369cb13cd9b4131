# Finds the CGNS library (Debian's libcgns-dev ships no CMake config). Defines CGNS_FOUND and
# the imported target CGNS::CGNS, located at the file meshmotion loads at run time.
include("${CMAKE_CURRENT_LIST_DIR}/MeshmotionFindLibrary.cmake")
meshmotion_find_library(CGNS HEADER cgnslib.h LIBRARY cgns LOADED)
