# Compiles every public header under include/meshmotion/<layer>/ (detail/ excluded) alone, so that each
# one includes what it uses. Run as a ctest through cmake -P; headers are globbed at test time.
# Variables: INCLUDE_DIR, CXX_COMPILER, SYSTEM_DIRS ('|'-separated, may be empty), FLAGS
# ('|'-separated extra compiler flags), WORK_DIR.
cmake_minimum_required(VERSION 3.20)

file(GLOB_RECURSE headers RELATIVE "${INCLUDE_DIR}" "${INCLUDE_DIR}/meshmotion/*.hpp")
list(FILTER headers EXCLUDE REGEX "/detail/")
# The optional parallel layer needs MPI's and PETSc's include folders: the parallel tests
# compile its headers. Its options header includes neither (the programs built without the
# parallel layer document its options), and is checked here.
list(FILTER headers EXCLUDE REGEX "^meshmotion/parallel/")
list(APPEND headers meshmotion/parallel/parallel_options.hpp)
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
# A header that passed before is skipped while neither it nor any project header it includes
# (its -MMD dependency list) changed, nor the flags: re-runs only check what changed.
set(stamp_content "${CXX_COMPILER} ${FLAGS} ${SYSTEM_DIRS}")
function(up_to_date stem result)
  set(ok "${WORK_DIR}/${stem}.ok")
  set(dep "${WORK_DIR}/${stem}.d")
  set(${result} FALSE PARENT_SCOPE)
  if(NOT EXISTS "${ok}" OR NOT EXISTS "${dep}")
    return()
  endif()
  file(READ "${ok}" previous)
  if(NOT previous STREQUAL stamp_content)
    return()
  endif()
  file(READ "${dep}" deps)
  string(REPLACE "\\\n" " " deps "${deps}")
  string(REGEX REPLACE "^[^:]*:" "" deps "${deps}")
  separate_arguments(deps UNIX_COMMAND "${deps}")
  foreach(d ${deps})
    if(NOT EXISTS "${d}" OR "${d}" IS_NEWER_THAN "${ok}")
      return()
    endif()
  endforeach()
  set(${result} TRUE PARENT_SCOPE)
endfunction()

set(to_check)
set(skipped 0)
foreach(header ${headers})
  string(MAKE_C_IDENTIFIER "${header}" stem)
  # A one-line source file, so that the header is not the main file (#pragma once warns there).
  # Written once: its time stamp takes part in the dependency check.
  if(NOT EXISTS "${WORK_DIR}/${stem}.cpp")
    file(WRITE "${WORK_DIR}/${stem}.cpp" "#include \"${header}\"\n")
  endif()
  up_to_date(${stem} fresh)
  if(fresh)
    math(EXPR skipped "${skipped} + 1")
  else()
    file(REMOVE "${WORK_DIR}/${stem}.ok")
    list(APPEND to_check "${header}")
  endif()
endforeach()

set(failed)
set(batch)
list(LENGTH headers n)
list(LENGTH to_check n_check)
if(n_check EQUAL 0)
  message("check_headers: all ${n} public headers compile alone (unchanged since they last did)")
  return()
endif()
math(EXPR last "${n_check} - 1")
foreach(i RANGE ${last})
  list(GET to_check ${i} header)
  list(APPEND batch "${header}")
  list(LENGTH batch size)
  if(size LESS jobs AND i LESS last)
    continue()
  endif()
  set(commands)
  foreach(h ${batch})
    string(MAKE_C_IDENTIFIER "${h}" stem)
    list(APPEND commands COMMAND "${CXX_COMPILER}" -std=c++20 -fsyntax-only ${FLAGS} "-I${INCLUDE_DIR}"
         ${system_flags} -MMD -MF "${WORK_DIR}/${stem}.d" "${WORK_DIR}/${stem}.cpp")
  endforeach()
  execute_process(${commands} RESULTS_VARIABLE results OUTPUT_QUIET ERROR_VARIABLE err)
  foreach(h result IN ZIP_LISTS batch results)
    string(MAKE_C_IDENTIFIER "${h}" stem)
    if(result EQUAL 0)
      file(WRITE "${WORK_DIR}/${stem}.ok" "${stamp_content}")
    else()
      list(APPEND failed "${h}")
      # Compile it again alone for a readable message.
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
message("check_headers: all ${n} public headers compile alone (${skipped} unchanged since they last did)")
