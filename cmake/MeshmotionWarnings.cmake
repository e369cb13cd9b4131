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
