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
  "-DBUILD_DIR=${PROJECT_BINARY_DIR}"
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
# The pass expression alone would ignore a failure after the first program (the CAD consumer).
set_tests_properties("cmake: consumer through find_package" PROPERTIES
  FIXTURES_REQUIRED meshmotion_installed LABELS cmake PASS_REGULAR_EXPRESSION "consumer: 20 nodes"
  FAIL_REGULAR_EXPRESSION "consumer test \\([a-z_]+\\): failed")
set_tests_properties("cmake: consumer through add_subdirectory" PROPERTIES
  LABELS cmake PASS_REGULAR_EXPRESSION "consumer: 20 nodes" FAIL_REGULAR_EXPRESSION "consumer test \\([a-z_]+\\): failed")
set_tests_properties("cmake: every public header compiles alone" PROPERTIES LABELS cmake)

# The exact predicates and certified bounds need IEEE arithmetic: -ffast-math is an #error.
set(_fast_math_includes -I "${PROJECT_SOURCE_DIR}/include")
foreach(dir ${_meshmotion_system_dirs})
  # The compiler's own folders must not be re-added (libstdc++'s #include_next breaks).
  if(NOT dir MATCHES "^/usr(/local)?/include/?$")
    list(APPEND _fast_math_includes -isystem "${dir}")
  endif()
endforeach()
add_test(NAME "cmake: -ffast-math is refused"
  COMMAND ${CMAKE_CXX_COMPILER} -std=c++20 -ffast-math -fsyntax-only ${_fast_math_includes}
          "${CMAKE_CURRENT_SOURCE_DIR}/consumer/fast_math.cpp")
set_tests_properties("cmake: -ffast-math is refused" PROPERTIES LABELS cmake
                     PASS_REGULAR_EXPRESSION "cannot be compiled with -ffast-math")
add_test(NAME "cmake: the same header compiles without -ffast-math"
  COMMAND ${CMAKE_CXX_COMPILER} -std=c++20 -fsyntax-only ${_fast_math_includes}
          "${CMAKE_CURRENT_SOURCE_DIR}/consumer/fast_math.cpp")
set_tests_properties("cmake: the same header compiles without -ffast-math" PROPERTIES LABELS cmake)

# Each mover compiled once outside the tests (the registries are compiled; front ends include
# options and registries only).
if(MESHMOTION_BUILD_COMPILED AND CMAKE_NM)
  add_test(NAME "cmake: each mover is compiled in one object"
           COMMAND ${CMAKE_COMMAND} "-DBUILD_DIR=${PROJECT_BINARY_DIR}" "-DNM=${CMAKE_NM}"
                   -P "${CMAKE_CURRENT_SOURCE_DIR}/check_instantiations.cmake")
  set_tests_properties("cmake: each mover is compiled in one object" PROPERTIES LABELS cmake
                       PASS_REGULAR_EXPRESSION "each mover's setup defined in one at most")
endif()

# The option schema's rules: each key is its field's name, each option's description its only
# doc (tests/schema/check_option_schema.py).
find_program(MESHMOTION_PYTHON3 NAMES python3)
if(MESHMOTION_PYTHON3)
  add_test(NAME "schema: keys are field names, one doc per option"
           COMMAND ${MESHMOTION_PYTHON3} "${CMAKE_CURRENT_SOURCE_DIR}/schema/check_option_schema.py" "${PROJECT_SOURCE_DIR}/include")
  set_tests_properties("schema: keys are field names, one doc per option" PROPERTIES LABELS cmake
                       PASS_REGULAR_EXPRESSION "options, 0 problems")
else()
  message(STATUS "meshmotion: no python3: the option schema's check is skipped")
endif()
