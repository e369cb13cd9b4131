# meshmotion_find_library(<Name> HEADER <file> LIBRARY <name> [PATH_SUFFIXES <dir>...] [LOADED])
# The part the find modules of libraries without a CMake config share (Debian's SuiteSparse
# 5, CGNS, METIS): finds the header and the library, sets <Name>_FOUND, <Name>_INCLUDE_DIR
# and <Name>_LIBRARY, and defines the imported target <Name>::<Name> when found. LOADED: the
# target's location is the versioned file the link resolves to (libcgns.so.X.Y), the name
# meshmotion loads at run time, which the run-time package carries without the -dev
# package's unversioned link.
include(FindPackageHandleStandardArgs)

macro(meshmotion_find_library name)
  cmake_parse_arguments(_mfl "LOADED" "HEADER;LIBRARY" "PATH_SUFFIXES" ${ARGN})
  find_path(${name}_INCLUDE_DIR ${_mfl_HEADER} PATH_SUFFIXES ${_mfl_PATH_SUFFIXES})
  find_library(${name}_LIBRARY ${_mfl_LIBRARY})
  find_package_handle_standard_args(${name} REQUIRED_VARS ${name}_LIBRARY ${name}_INCLUDE_DIR)
  if(${name}_FOUND AND NOT TARGET ${name}::${name})
    set(_mfl_location "${${name}_LIBRARY}")
    if(_mfl_LOADED)
      file(REAL_PATH "${_mfl_location}" _mfl_location)
    endif()
    add_library(${name}::${name} UNKNOWN IMPORTED)
    set_target_properties(${name}::${name} PROPERTIES
      IMPORTED_LOCATION "${_mfl_location}"
      INTERFACE_INCLUDE_DIRECTORIES "${${name}_INCLUDE_DIR}")
  endif()
  mark_as_advanced(${name}_INCLUDE_DIR ${name}_LIBRARY)
endmacro()
