# The optional CAD component (include/meshmotion/cad/, src/cad/): STEP, IGES and BREP models on
# OpenCASCADE (Debian libocct-modeling-algorithms-dev libocct-data-exchange-dev). Defines
# meshmotion::cad, a compiled library whose header holds no OpenCASCADE type, and the module it
# loads, and says what is missing otherwise; the core does not depend on it.
set(MESHMOTION_HAVE_CAD OFF)
if(NOT MESHMOTION_WITH_CAD)
  return()
endif()
find_package(OpenCASCADE CONFIG QUIET)
if(NOT OpenCASCADE_FOUND)
  message(STATUS "meshmotion: CAD component skipped: OpenCASCADE not found (libocct-modeling-algorithms-dev libocct-data-exchange-dev)")
  return()
endif()
# The toolkits the component calls: STEP and IGES readers, BRep tools, extrema, shape analysis
# (TKPrim: the tests build shapes). Linked by file, not through OpenCASCADE's imported targets:
# Debian's export names libtbb.so, which only libtbb-dev installs, while the toolkits' own
# shared objects already load the TBB they need.
set(MESHMOTION_OCCT_LIBRARIES)
foreach(toolkit TKSTEP TKIGES TKXSBase TKShHealing TKBRep TKTopAlgo TKGeomAlgo TKGeomBase TKG3d TKG2d TKMath TKernel TKPrim)
  find_library(MESHMOTION_OCCT_${toolkit} ${toolkit} HINTS ${OpenCASCADE_LIBRARY_DIR})
  if(NOT MESHMOTION_OCCT_${toolkit})
    message(STATUS "meshmotion: CAD component skipped: OpenCASCADE toolkit ${toolkit} not found (libocct-data-exchange-dev?)")
    return()
  endif()
  list(APPEND MESHMOTION_OCCT_LIBRARIES ${MESHMOTION_OCCT_${toolkit}})
endforeach()
set(MESHMOTION_HAVE_CAD ON)
# Inside another project it is built only when something links it, as meshmotion::compiled.
set(_exclude)
if(NOT MESHMOTION_TOP_LEVEL)
  set(_exclude EXCLUDE_FROM_ALL)
endif()
# The toolkits live in a module of their own that meshmotion::cad loads when a model is first
# read (src/cad/cad_shape.hpp): linked into a program, Debian's toolkits cost 0.12 s at every
# start. It installs beside the libraries; MESHMOTION_CAD_MODULE overrides where it is looked for.
add_library(meshmotion_cad_occt MODULE ${_exclude} src/cad/occt_shape.cpp)
target_include_directories(meshmotion_cad_occt SYSTEM PRIVATE ${OpenCASCADE_INCLUDE_DIR})
target_link_libraries(meshmotion_cad_occt PRIVATE meshmotion::meshmotion ${MESHMOTION_OCCT_LIBRARIES})
# The component's code compiles beside the module; the archive waits for the module, so that a
# program linking meshmotion::cad finds it built.
add_library(meshmotion_cad_objects OBJECT ${_exclude} src/cad/cad_model.cpp)
set_target_properties(meshmotion_cad_objects PROPERTIES POSITION_INDEPENDENT_CODE ON)
target_link_libraries(meshmotion_cad_objects PRIVATE meshmotion::meshmotion)
target_compile_definitions(meshmotion_cad_objects PRIVATE MESHMOTION_HAVE_CAD
  MESHMOTION_CAD_MODULE_BUILD="$<TARGET_FILE:meshmotion_cad_occt>"
  MESHMOTION_CAD_MODULE_INSTALL="${CMAKE_INSTALL_FULL_LIBDIR}/$<TARGET_FILE_NAME:meshmotion_cad_occt>")
add_library(meshmotion_cad STATIC ${_exclude} $<TARGET_OBJECTS:meshmotion_cad_objects>)
add_library(meshmotion::cad ALIAS meshmotion_cad)
set_target_properties(meshmotion_cad PROPERTIES EXPORT_NAME cad POSITION_INDEPENDENT_CODE ON)
add_dependencies(meshmotion_cad meshmotion_cad_occt)
# The header-only core, not meshmotion::compiled: linking the component must not build the
# whole compiled library (a consumer links meshmotion::compiled beside it for fast builds).
target_link_libraries(meshmotion_cad PUBLIC meshmotion::meshmotion ${CMAKE_DL_LIBS})
target_compile_definitions(meshmotion_cad PUBLIC MESHMOTION_HAVE_CAD)
if(TARGET meshmotion_warnings)
  target_link_libraries(meshmotion_cad_objects PRIVATE meshmotion_warnings)
  target_link_libraries(meshmotion_cad_occt PRIVATE meshmotion_warnings)
endif()
message(STATUS "meshmotion: CAD component on OpenCASCADE ${OpenCASCADE_VERSION}: STEP, IGES and BREP geometry for curving")
