# Runs one step of the consumer tests (cmake -P). Variables:
#   STEP        install | find_package | add_subdirectory
#   SOURCE_DIR  the meshmotion source tree;  BUILD_DIR  its build (installed by STEP install)
#   WORK_DIR    a scratch folder for this test run
#   GENERATOR, CXX_COMPILER  as the main build uses them
cmake_minimum_required(VERSION 3.20)

function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE result OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT result EQUAL 0)
    string(REPLACE ";" " " command "${ARGN}")
    message(FATAL_ERROR "consumer test (${STEP}): failed: ${command}\n${out}\n${err}")
  endif()
  message("${out}")
endfunction()

set(prefix "${WORK_DIR}/prefix")
# No build type: the consumers are compiled unoptimized. They check that the package is found,
# compiles and links; optimizing the header-only movers they include doubled this test's time.
set(common -G "${GENERATOR}" -DCMAKE_CXX_COMPILER=${CXX_COMPILER} -DCMAKE_BUILD_TYPE=)

if(STEP STREQUAL "install")
  # The main build's own tree, installed (configuring and building meshmotion again for this
  # test cost CI minutes). Its rules without a component are the library's; the Python module
  # and the OpenFOAM plugin install where their hosts look, not under a prefix.
  file(REMOVE_RECURSE "${prefix}")
  run(${CMAKE_COMMAND} --install "${BUILD_DIR}" --prefix "${prefix}" --component Unspecified)
  if(NOT EXISTS "${prefix}/include/meshmotion/meshmotion.hpp")
    message(FATAL_ERROR "consumer test (install): ${prefix}/include/meshmotion/meshmotion.hpp was not installed")
  endif()
  # The exported targets name their dependencies by imported target, found again on the
  # consumer's machine: a path of this machine would break a relocated or repackaged install.
  file(GLOB exported "${prefix}/share/meshmotion/cmake/*Targets.cmake")
  foreach(file ${exported})
    file(STRINGS "${file}" lines REGEX "INTERFACE_(LINK_LIBRARIES|INCLUDE_DIRECTORIES)")
    foreach(line ${lines})
      if(line MATCHES "\"(/[^;\"]*)")
        message(FATAL_ERROR "consumer test (install): ${file} exports the path ${CMAKE_MATCH_1} (expected imported targets):\n${line}")
      endif()
      if(line MATCHES ";(/[^;\"]*)")
        message(FATAL_ERROR "consumer test (install): ${file} exports the path ${CMAKE_MATCH_1} (expected imported targets):\n${line}")
      endif()
    endforeach()
  endforeach()
  return()
endif()

set(build "${WORK_DIR}/consumer-${STEP}")
file(REMOVE_RECURSE "${build}")
if(STEP STREQUAL "find_package")
  run(${CMAKE_COMMAND} -S "${SOURCE_DIR}/tests/consumer" -B "${build}" ${common} "-DCMAKE_PREFIX_PATH=${prefix}")
elseif(STEP STREQUAL "add_subdirectory")
  # The optional components are the installed copy's to test (find_package): here they would
  # build the CAD component and the parallel layer a second time.
  run(${CMAKE_COMMAND} -S "${SOURCE_DIR}/tests/consumer" -B "${build}" ${common} "-DMESHMOTION_SOURCE_DIR=${SOURCE_DIR}"
      -DMESHMOTION_WITH_CAD=OFF -DMESHMOTION_WITH_PARALLEL=OFF)
else()
  message(FATAL_ERROR "consumer test: unknown STEP '${STEP}' (expected install, find_package or add_subdirectory)")
endif()
run(${CMAKE_COMMAND} --build "${build}")
run("${build}/consumer")
if(EXISTS "${build}/consumer_parallel")
  run("${build}/consumer_parallel")
else()
  message("consumer test (${STEP}): no meshmotion::parallel (meshmotion built without MPI, PETSc or METIS), parallel consumer skipped")
endif()
if(EXISTS "${build}/consumer_cad")
  # A model read through the module: the installed one for an installed meshmotion.
  set(model "${SOURCE_DIR}/../shared/data/meshopt_Sphere25CSymmetry.stp")
  if(NOT EXISTS "${model}")
    message("consumer test (${STEP}): ${model} not found, the CAD consumer reads no model")
    set(model)
  endif()
  if(STEP STREQUAL "find_package")
    file(GLOB module "${prefix}/lib*/libmeshmotion_cad_occt.so" "${prefix}/lib*/*/libmeshmotion_cad_occt.so")
    if(NOT module)
      message(FATAL_ERROR "consumer test (find_package): libmeshmotion_cad_occt.so was not installed under ${prefix}")
    endif()
    list(GET module 0 module)
    run(${CMAKE_COMMAND} -E env "MESHMOTION_CAD_MODULE=${module}" "${build}/consumer_cad" ${model})
  else()
    run("${build}/consumer_cad" ${model})
  endif()
else()
  message("consumer test (${STEP}): no meshmotion::cad (meshmotion built without OpenCASCADE), CAD consumer skipped")
endif()
