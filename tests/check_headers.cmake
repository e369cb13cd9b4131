# Compiles every public header under include/meshmotion/<layer>/ (detail/ excluded) alone, so that each
# one includes what it uses. Run as a ctest through cmake -P; headers are globbed at test time.
# Variables: INCLUDE_DIR, CXX_COMPILER, SYSTEM_DIRS ('|'-separated, may be empty), FLAGS
# ('|'-separated extra compiler flags), WORK_DIR.
cmake_minimum_required(VERSION 3.20)

file(GLOB_RECURSE headers RELATIVE "${INCLUDE_DIR}" "${INCLUDE_DIR}/meshmotion/*.hpp")
list(FILTER headers EXCLUDE REGEX "/detail/")
# The aggregates (meshmotion.hpp and one per layer) only include the headers checked here;
# they are compiled by the consumer tests, and would double the time of this one.
list(FILTER headers EXCLUDE REGEX "^meshmotion/[^/]+[.]hpp$")
list(SORT headers)
string(REPLACE "|" ";" SYSTEM_DIRS "${SYSTEM_DIRS}")
string(REPLACE "|" ";" FLAGS "${FLAGS}")
if(NOT headers)
  message(FATAL_ERROR "check_headers: no headers found under ${INCLUDE_DIR}/meshmotion")
endif()

set(system_flags)
foreach(dir ${SYSTEM_DIRS})
  # The compiler's default folders must not be re-added: -isystem /usr/include breaks
  # libstdc++'s #include_next <stdlib.h>.
  if(dir MATCHES "^/usr(/local)?/include/?$")
    continue()
  endif()
  list(APPEND system_flags -isystem "${dir}")
endforeach()

file(MAKE_DIRECTORY "${WORK_DIR}")
# One compiler per core: execute_process runs its COMMANDs concurrently (as a pipeline whose
# pipes stay unused, since -fsyntax-only reads and writes nothing).
cmake_host_system_information(RESULT jobs QUERY NUMBER_OF_LOGICAL_CORES)
if(jobs LESS 1)
  set(jobs 1)
endif()
set(failed)
set(batch)
list(LENGTH headers n)
math(EXPR last "${n} - 1")
foreach(i RANGE ${last})
  list(GET headers ${i} header)
  list(APPEND batch "${header}")
  list(LENGTH batch size)
  if(size LESS jobs AND i LESS last)
    continue()
  endif()
  set(commands)
  foreach(h ${batch})
    # A one-line source file, so that the header is not the main file (#pragma once warns there).
    string(MAKE_C_IDENTIFIER "${h}" stem)
    file(WRITE "${WORK_DIR}/${stem}.cpp" "#include \"${h}\"\n")
    list(APPEND commands COMMAND "${CXX_COMPILER}" -std=c++20 -fsyntax-only ${FLAGS} "-I${INCLUDE_DIR}"
         ${system_flags} "${WORK_DIR}/${stem}.cpp")
  endforeach()
  execute_process(${commands} RESULTS_VARIABLE results OUTPUT_QUIET ERROR_VARIABLE err)
  foreach(h result IN ZIP_LISTS batch results)
    if(NOT result EQUAL 0)
      list(APPEND failed "${h}")
      # Compile it again alone for a readable message.
      string(MAKE_C_IDENTIFIER "${h}" stem)
      execute_process(COMMAND "${CXX_COMPILER}" -std=c++20 -fsyntax-only ${FLAGS} "-I${INCLUDE_DIR}"
                      ${system_flags} "${WORK_DIR}/${stem}.cpp" OUTPUT_QUIET ERROR_VARIABLE alone)
      message("check_headers: ${h} does not compile on its own:\n${alone}")
    endif()
  endforeach()
  set(batch)
endforeach()

if(failed)
  string(REPLACE ";" ", " failed_list "${failed}")
  message(FATAL_ERROR "check_headers: headers that do not compile alone: ${failed_list}")
endif()
message("check_headers: all ${n} public headers compile alone")
