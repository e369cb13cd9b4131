# Finds the header-only nanoflann library (Debian's libnanoflann-dev ships no CMake config).
# Defines nanoflann_FOUND, nanoflann_INCLUDE_DIR, nanoflann_VERSION and the nanoflann::nanoflann target.
find_package(nanoflann CONFIG QUIET NO_MODULE)
if(TARGET nanoflann::nanoflann)
  set(nanoflann_FOUND TRUE)
  return()
endif()

find_path(nanoflann_INCLUDE_DIR NAMES nanoflann.hpp)
if(nanoflann_INCLUDE_DIR AND EXISTS "${nanoflann_INCLUDE_DIR}/nanoflann.hpp")
  file(STRINGS "${nanoflann_INCLUDE_DIR}/nanoflann.hpp" _nanoflann_version_line
       REGEX "#define NANOFLANN_VERSION")
  if(_nanoflann_version_line MATCHES "0x([0-9A-Fa-f])([0-9A-Fa-f])([0-9A-Fa-f])")
    math(EXPR _major "0x${CMAKE_MATCH_1}")
    math(EXPR _minor "0x${CMAKE_MATCH_2}")
    math(EXPR _patch "0x${CMAKE_MATCH_3}")
    set(nanoflann_VERSION "${_major}.${_minor}.${_patch}")
  endif()
endif()

include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(nanoflann
  REQUIRED_VARS nanoflann_INCLUDE_DIR
  VERSION_VAR nanoflann_VERSION)

if(nanoflann_FOUND AND NOT TARGET nanoflann::nanoflann)
  add_library(nanoflann::nanoflann INTERFACE IMPORTED)
  set_target_properties(nanoflann::nanoflann PROPERTIES
    INTERFACE_INCLUDE_DIRECTORIES "${nanoflann_INCLUDE_DIR}")
endif()
mark_as_advanced(nanoflann_INCLUDE_DIR)
