# The OpenFOAM motion solver plugin (src/openfoam/, docs/openfoam.md): libmeshmotionFoam.so,
# which an OpenFOAM solver loads from constant/dynamicMeshDict (`motionSolver meshmotion;`).
# It needs Debian's OpenFOAM libraries (libopenfoam) and their headers, which Debian ships only
# in its source package: tools/openfoam-source.sh fetches that package with apt-get into the
# build folder (MESHMOTION_OPENFOAM_SOURCE names a folder already made by it). Skipped with a
# message when either is missing; nothing else depends on it.
set(MESHMOTION_HAVE_OPENFOAM OFF)
if(NOT MESHMOTION_WITH_OPENFOAM)
  return()
endif()
set(_foam_libraries)
foreach(library OpenFOAM finiteVolume meshTools dynamicMesh fvMotionSolvers)
  find_library(MESHMOTION_FOAM_${library} ${library})
  if(NOT MESHMOTION_FOAM_${library})
    message(STATUS "meshmotion: OpenFOAM plugin skipped: lib${library}.so not found (Debian's openfoam)")
    return()
  endif()
  list(APPEND _foam_libraries ${MESHMOTION_FOAM_${library}})
endforeach()
set(MESHMOTION_OPENFOAM_SOURCE "" CACHE PATH
    "Folder made by tools/openfoam-source.sh (empty: fetched into the build folder at configure time)")
set(_foam_source "${MESHMOTION_OPENFOAM_SOURCE}")
if(NOT _foam_source)
  set(_foam_source "${PROJECT_BINARY_DIR}/openfoam-source")
  if(NOT EXISTS "${_foam_source}/src/.complete")
    message(STATUS "meshmotion: fetching Debian's OpenFOAM source package for the plugin's headers (tools/openfoam-source.sh)")
    execute_process(COMMAND "${PROJECT_SOURCE_DIR}/tools/openfoam-source.sh" "${_foam_source}"
                    RESULT_VARIABLE _fetched OUTPUT_FILE "${PROJECT_BINARY_DIR}/openfoam-source.log"
                    ERROR_FILE "${PROJECT_BINARY_DIR}/openfoam-source.log")
    if(NOT _fetched EQUAL 0)
      message(STATUS "meshmotion: OpenFOAM plugin skipped: the source package could not be fetched (${PROJECT_BINARY_DIR}/openfoam-source.log)")
      return()
    endif()
  endif()
endif()
set(_foam_includes)
foreach(library OpenFOAM OSspecific/POSIX finiteVolume meshTools dynamicMesh fvMotionSolver surfMesh fileFormats)
  if(NOT EXISTS "${_foam_source}/src/${library}/lnInclude")
    message(STATUS "meshmotion: OpenFOAM plugin skipped: ${_foam_source}/src/${library}/lnInclude missing (run tools/openfoam-source.sh)")
    return()
  endif()
  list(APPEND _foam_includes "${_foam_source}/src/${library}/lnInclude")
endforeach()
set(MESHMOTION_HAVE_OPENFOAM ON)
# OpenFOAM v1912's headers are C++17 (they do not compile as C++20): its side of the plugin is
# a translation unit of its own, with wmake's flags for Debian's double-precision, 32-bit-label
# build, talking to the C++20 side through src/openfoam/bridge.hpp.
add_library(meshmotion_foam_side OBJECT src/openfoam/meshmotion_motion_solver.cpp)
set_target_properties(meshmotion_foam_side PROPERTIES CXX_STANDARD 17 CXX_STANDARD_REQUIRED ON CXX_EXTENSIONS OFF
                                                      POSITION_INDEPENDENT_CODE ON)
target_include_directories(meshmotion_foam_side SYSTEM PRIVATE ${_foam_includes})
target_compile_definitions(meshmotion_foam_side PRIVATE WM_DP WM_LABEL_SIZE=32 NoRepository linux64 OPENFOAM=1912)
target_compile_options(meshmotion_foam_side PRIVATE -m64 -ftemplate-depth-100)
# Decomposed cases (-parallel) go through the distributed movers (Debian's OpenFOAM runs on the
# same Open MPI): bridge_parallel.cpp serves them, bridge_serial_only.cpp refuses them.
if(MESHMOTION_HAVE_PARALLEL)
  set(_foam_decomposed src/openfoam/bridge_parallel.cpp)
else()
  set(_foam_decomposed src/openfoam/bridge_serial_only.cpp)
endif()
add_library(meshmotionFoam SHARED src/openfoam/bridge.cpp ${_foam_decomposed} $<TARGET_OBJECTS:meshmotion_foam_side>)
target_link_libraries(meshmotionFoam PRIVATE ${MESHMOTION_LINK_TARGET} ${_foam_libraries})
if(MESHMOTION_HAVE_PARALLEL)
  target_link_libraries(meshmotionFoam PRIVATE meshmotion::parallel)
else()
  message(STATUS "meshmotion: OpenFOAM plugin without the parallel layer: decomposed cases are refused")
endif()
if(TARGET meshmotion_warnings)
  target_link_libraries(meshmotionFoam PRIVATE meshmotion_warnings)
endif()
if(MESHMOTION_INSTALL)
  install(TARGETS meshmotionFoam LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT openfoam)
endif()
message(STATUS "meshmotion: OpenFOAM plugin libmeshmotionFoam.so for Debian's OpenFOAM (headers from ${_foam_source})")
