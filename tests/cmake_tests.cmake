# Build-system tests: every public header compiles alone, and a tiny consumer project builds
# against meshmotion through find_package (installed copy) and through add_subdirectory.

set(_meshmotion_system_dirs)
foreach(dep Eigen3::Eigen nanoflann::nanoflann)
  if(TARGET ${dep})
    get_target_property(dirs ${dep} INTERFACE_INCLUDE_DIRECTORIES)
    if(dirs)
      list(APPEND _meshmotion_system_dirs ${dirs})
    endif()
  endif()
endforeach()
set(_meshmotion_header_flags -Wall -Wextra -Wpedantic -Wshadow -Werror)
if(OpenMP_CXX_FOUND)
  separate_arguments(_omp_flags UNIX_COMMAND "${OpenMP_CXX_FLAGS}")
  list(APPEND _meshmotion_header_flags ${_omp_flags})
endif()
# ';' inside a -D value would split the ctest command: pass lists with '|' and convert back.
string(REPLACE ";" "|" _dirs_arg "${_meshmotion_system_dirs}")
string(REPLACE ";" "|" _flags_arg "${_meshmotion_header_flags}")

add_test(NAME "cmake: every public header compiles alone"
  COMMAND ${CMAKE_COMMAND}
    "-DINCLUDE_DIR=${PROJECT_SOURCE_DIR}/include"
    "-DCXX_COMPILER=${CMAKE_CXX_COMPILER}"
    "-DSYSTEM_DIRS=${_dirs_arg}"
    "-DFLAGS=${_flags_arg}"
    "-DWORK_DIR=${CMAKE_CURRENT_BINARY_DIR}/check_headers"
    -P "${CMAKE_CURRENT_SOURCE_DIR}/check_headers.cmake")

set(_consumer_args
  "-DSOURCE_DIR=${PROJECT_SOURCE_DIR}"
  "-DWORK_DIR=${CMAKE_CURRENT_BINARY_DIR}/consumer_tests"
  "-DGENERATOR=${CMAKE_GENERATOR}"
  "-DCXX_COMPILER=${CMAKE_CXX_COMPILER}")
add_test(NAME "cmake: install into a prefix"
  COMMAND ${CMAKE_COMMAND} ${_consumer_args} -DSTEP=install -P "${CMAKE_CURRENT_SOURCE_DIR}/consumer/consumer_test.cmake")
add_test(NAME "cmake: consumer through find_package"
  COMMAND ${CMAKE_COMMAND} ${_consumer_args} -DSTEP=find_package -P "${CMAKE_CURRENT_SOURCE_DIR}/consumer/consumer_test.cmake")
add_test(NAME "cmake: consumer through add_subdirectory"
  COMMAND ${CMAKE_COMMAND} ${_consumer_args} -DSTEP=add_subdirectory -P "${CMAKE_CURRENT_SOURCE_DIR}/consumer/consumer_test.cmake")
set_tests_properties("cmake: install into a prefix" PROPERTIES FIXTURES_SETUP meshmotion_installed LABELS cmake)
set_tests_properties("cmake: consumer through find_package" PROPERTIES
  FIXTURES_REQUIRED meshmotion_installed LABELS cmake PASS_REGULAR_EXPRESSION "consumer: 20 nodes")
set_tests_properties("cmake: consumer through add_subdirectory" PROPERTIES
  LABELS cmake PASS_REGULAR_EXPRESSION "consumer: 20 nodes")
set_tests_properties("cmake: every public header compiles alone" PROPERTIES LABELS cmake)
