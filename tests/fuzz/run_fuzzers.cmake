# The "fuzz: readers" test: a second build of the readers with clang under AddressSanitizer and
# UndefinedBehaviorSanitizer, which runs the io layer's tests and then each reader's libFuzzer
# target for SECONDS from its seed corpus (tests/fuzz/corpus/<reader>). Any crash, leak,
# undefined behaviour or allocation beyond 2 GB fails the test; libFuzzer leaves the input that
# did it in BUILD/crashes, to be added to the corpus once fixed.
#   cmake -DSOURCE=<repo> -DBUILD=<folder> -DCLANG=<clang++> -DSECONDS=20 -P run_fuzzers.cmake
foreach(var SOURCE BUILD CLANG SECONDS)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "run_fuzzers.cmake: -D${var}=... missing")
  endif()
endforeach()

function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    list(JOIN ARGN " " shown)
    message(FATAL_ERROR "fuzz: readers: '${shown}' failed (${rc})")
  endif()
endfunction()

set(sanitize "-O1 -g -fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer")
run(${CMAKE_COMMAND} -S ${SOURCE} -B ${BUILD} -DCMAKE_CXX_COMPILER=${CLANG} -DCMAKE_BUILD_TYPE=None
    "-DCMAKE_CXX_FLAGS=${sanitize}" -DMESHMOTION_BUILD_FUZZERS=ON -DMESHMOTION_WARNINGS_AS_ERRORS=OFF
    -DMESHMOTION_BUILD_EXAMPLES=OFF -DMESHMOTION_BUILD_PYTHON=OFF -DMESHMOTION_BUILD_COMPILED=OFF
    -DMESHMOTION_WITH_PARALLEL=OFF -DMESHMOTION_WITH_CAD=OFF -DMESHMOTION_USE_OPENMP=OFF -DMESHMOTION_INSTALL=OFF)
file(READ ${BUILD}/tests/fuzz/readers.txt readers)
set(targets meshmotion_io_tests)
foreach(reader ${readers})
  list(APPEND targets fuzz_${reader})
endforeach()
run(${CMAKE_COMMAND} --build ${BUILD} -j2 --target ${targets})

# The reader tests first: they hold every input that once crashed or misread. [slow] cases
# run in the main build; the sanitizers would make them several times slower.
run(${CMAKE_COMMAND} -E env ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1
    ${BUILD}/tests/meshmotion_io_tests "~[slow]")

file(MAKE_DIRECTORY ${BUILD}/crashes)
foreach(reader ${readers})
  # libFuzzer adds the inputs it finds to its first folder: a scratch one, not the tree.
  set(scratch ${BUILD}/scratch_${reader})
  file(REMOVE_RECURSE ${scratch})
  file(MAKE_DIRECTORY ${scratch})
  run(${CMAKE_COMMAND} -E env LSAN_OPTIONS=suppressions=${SOURCE}/tests/fuzz/cgns.supp
      ${BUILD}/tests/fuzz/fuzz_${reader} -max_total_time=${SECONDS} -rss_limit_mb=2048 -timeout=20
      -artifact_prefix=${BUILD}/crashes/${reader}- ${scratch} ${SOURCE}/tests/fuzz/corpus/${reader})
endforeach()
