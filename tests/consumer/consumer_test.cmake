# Runs one step of the consumer tests (cmake -P). Variables:
#   STEP        install | find_package | add_subdirectory
#   SOURCE_DIR  the meshmotion source tree;  WORK_DIR  a scratch folder for this test run
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
set(common -G "${GENERATOR}" -DCMAKE_CXX_COMPILER=${CXX_COMPILER} -DCMAKE_BUILD_TYPE=Release)

if(STEP STREQUAL "install")
  file(REMOVE_RECURSE "${WORK_DIR}/meshmotion-build" "${prefix}")
  run(${CMAKE_COMMAND} -S "${SOURCE_DIR}" -B "${WORK_DIR}/meshmotion-build" ${common}
      -DMESHMOTION_BUILD_TESTS=OFF -DMESHMOTION_BUILD_EXAMPLES=OFF -DMESHMOTION_BUILD_BENCHMARKS=OFF
      -DMESHMOTION_INSTALL=ON -DMESHMOTION_BUILD_COMPILED=OFF)
  # Only the CAD component, where OpenCASCADE is installed, has anything to compile.
  run(${CMAKE_COMMAND} --build "${WORK_DIR}/meshmotion-build" --parallel 2)
  run(${CMAKE_COMMAND} --install "${WORK_DIR}/meshmotion-build" --prefix "${prefix}")
  if(NOT EXISTS "${prefix}/include/meshmotion/meshmotion.hpp")
    message(FATAL_ERROR "consumer test (install): ${prefix}/include/meshmotion/meshmotion.hpp was not installed")
  endif()
  return()
endif()

set(build "${WORK_DIR}/consumer-${STEP}")
file(REMOVE_RECURSE "${build}")
if(STEP STREQUAL "find_package")
  run(${CMAKE_COMMAND} -S "${SOURCE_DIR}/tests/consumer" -B "${build}" ${common} "-DCMAKE_PREFIX_PATH=${prefix}")
elseif(STEP STREQUAL "add_subdirectory")
  run(${CMAKE_COMMAND} -S "${SOURCE_DIR}/tests/consumer" -B "${build}" ${common} "-DMESHMOTION_SOURCE_DIR=${SOURCE_DIR}")
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
  run("${build}/consumer_cad")
else()
  message("consumer test (${STEP}): no meshmotion::cad (meshmotion built without OpenCASCADE), CAD consumer skipped")
endif()
