# Finds the CGNS library (Debian's libcgns-dev ships no CMake config). Defines CGNS_FOUND and
# the imported target CGNS::CGNS. Its location is the versioned file the link resolves to
# (libcgns.so.X.Y): meshmotion loads it at run time by that name, which the run-time package
# carries without the -dev package's unversioned link.
include("${CMAKE_CURRENT_LIST_DIR}/MeshmotionFindLibrary.cmake")
meshmotion_find_library(CGNS HEADER cgnslib.h LIBRARY cgns)
if(CGNS_FOUND)
  file(REAL_PATH "${CGNS_LIBRARY}" _cgns_shared_object)
  set_target_properties(CGNS::CGNS PROPERTIES IMPORTED_LOCATION "${_cgns_shared_object}")
  unset(_cgns_shared_object)
endif()
