#pragma once
/// \file
/// The number of threads the library's parallel loops use (OpenMP), set by the program rather
/// than by the environment: a solver running MPI ranks with a few threads each sets it once.
///
/// \code
/// meshmotion::set_num_threads(2);   // every later setup, move and quality report
/// \endcode

#include "meshmotion/core/error.hpp"

#include <atomic>
#include <string>

#ifdef _OPENMP
#include <omp.h>
#endif

#include <Eigen/Core>

namespace meshmotion {

namespace detail {
// One setting per program: an inline function's static is shared by every translation unit.
inline std::atomic<int>& thread_setting() {
  static std::atomic<int> n{0};
  return n;
}
}  // namespace detail

/// Threads of the library's parallel loops (and of Eigen's dense products) from now on;
/// 0 gives back OpenMP's own default (OMP_NUM_THREADS, else the cores). Throws InputError for
/// a negative count. Without OpenMP the library runs on one thread whatever is set.
inline void set_num_threads(int n) {
  if (n < 0) throw InputError("set_num_threads: expected 0 (OpenMP's default) or more threads (got " + std::to_string(n) + ")");
  detail::thread_setting().store(n);
  Eigen::setNbThreads(n);
}

/// Threads the library's parallel loops use now (1 without OpenMP).
[[nodiscard]] inline int num_threads() {
#ifdef _OPENMP
  const int n = detail::thread_setting().load();
  return n > 0 ? n : omp_get_max_threads();
#else
  return 1;
#endif
}

}  // namespace meshmotion
