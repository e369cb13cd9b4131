# Warnings for the project's own targets only; never pushed onto consumers.
option(MESHMOTION_WARNINGS_AS_ERRORS "Treat warnings in the project's own targets as errors" ON)
add_library(meshmotion_warnings INTERFACE)
if(CMAKE_CXX_COMPILER_ID MATCHES "GNU|Clang")
  # Eigen and nanoflann are system headers (-isystem), so these flags judge our code only.
  target_compile_options(meshmotion_warnings INTERFACE -Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor)
  if(MESHMOTION_WARNINGS_AS_ERRORS)
    target_compile_options(meshmotion_warnings INTERFACE -Werror)
  endif()
endif()
if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
  # GCC 12 reports maybe-uninitialized inside inlined Eigen factorizations at -O1 (false
  # positives at the inlining site, outside Eigen's system-header shelter): keep it visible,
  # not fatal.
  target_compile_options(meshmotion_warnings INTERFACE -Wno-error=maybe-uninitialized)
endif()
# And code layout, for the same targets: loops start at 32-byte boundaries on x86-64, so that
# where the linker happens to put a function does not decide its hot loop's speed. Without it
# the RBF's stored-kernel product ran 60-80% slower in some links than in others (a compare and
# branch straddling a 64-byte line): the same code 1.13-1.21x slower in the Python module than
# in the C++ peer, and varying from one build to the next.
include(CheckCXXCompilerFlag)
check_cxx_compiler_flag(-falign-loops=32 MESHMOTION_ALIGN_LOOPS)
if(MESHMOTION_ALIGN_LOOPS AND CMAKE_SYSTEM_PROCESSOR MATCHES "x86_64|AMD64|amd64")
  target_compile_options(meshmotion_warnings INTERFACE -falign-loops=32)
endif()
