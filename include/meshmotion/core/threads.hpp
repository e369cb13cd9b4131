#pragma once
/// \file
/// The number of threads the library's parallel loops use (OpenMP), set by the program rather
/// than by the environment: a solver running MPI ranks with a few threads each sets it once.
///
/// \code
/// meshmotion::set_num_threads(2);   // every later setup, move and quality report
/// \endcode

#include "meshmotion/core/error.hpp"

#include <algorithm>
#include <atomic>
#include <charconv>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <string>
#include <string_view>
#include <system_error>

#ifdef _OPENMP
#include <omp.h>
#endif

#include <Eigen/Core>

#include <dlfcn.h>

namespace meshmotion {

/// Most threads set_num_threads takes: the OpenMP runtime fails outright on tens of
/// thousands, and no node has this many cores.
inline constexpr int max_threads = 1024;

namespace detail {
// One setting per program: an inline function's static is shared by every translation unit.
inline std::atomic<int>& thread_setting() {
  static std::atomic<int> n{0};
  return n;
}

#ifdef _OPENMP
// OpenMP's default before the first set_num_threads, to give back on set_num_threads(0);
// capped, as an OMP_NUM_THREADS of 100000 would crash the runtime.
inline int openmp_default_threads() {
  static const int n = std::min(omp_get_max_threads(), max_threads);
  return n;
}
#endif

/// An exception cannot leave an OpenMP region: the runtime ends the program (a bad_alloc in a
/// worker thread ended a move with "terminate called", rc 134 and no JSON error). Each
/// iteration of a region runs through run(), which keeps the first exception and skips the
/// iterations after it; the caller rethrows it once the region has ended. A region's
/// worksharing loop must still be reached by every thread (its barrier waits for all), so
/// run() wraps iterations and per-thread set-up, never a whole region.
class RegionErrors {
 public:
  template <class F>
  void run(F&& body) noexcept {
    if (failed_.load(std::memory_order_relaxed)) return;
    try {
      body();
    } catch (...) {
      failed_.store(true, std::memory_order_relaxed);
#ifdef _OPENMP
#pragma omp critical(meshmotion_region_errors)
#endif
      if (!first_) first_ = std::current_exception();
    }
  }
  /// Rethrows the first exception an iteration raised, if any. Call after the region.
  void rethrow() const {
    if (first_) std::rethrow_exception(first_);
  }

 private:
  std::atomic<bool> failed_{false};
  std::exception_ptr first_;
};
/// OpenBLAS's thread count, where `scope` (a dlopen handle, or RTLD_DEFAULT: what the process
/// linked) holds OpenBLAS: its pthreads build (Debian's libopenblas0-pthread) keeps a pool of
/// its own, sized by the machine rather than by OpenMP. Nothing where there is no OpenBLAS.
inline void set_blas_threads(void* scope, int n) noexcept {
  using SetThreads = void (*)(int);
  if (const auto set = reinterpret_cast<SetThreads>(dlsym(scope, "openblas_set_num_threads"))) set(n);
}
}  // namespace detail

[[nodiscard]] inline int num_threads();

/// Threads of the library's parallel loops, of Eigen's dense products and of the libraries
/// it calls that use OpenMP (CHOLMOD's supernodal factorization) from now on; 0 gives back
/// OpenMP's own default (OMP_NUM_THREADS, else the cores). Throws InputError for a negative
/// count or one above max_threads. Without OpenMP the library runs on one thread whatever is set.
///
/// OpenMP's default is set too, on the calling thread: CHOLMOD opens its parallel regions
/// with it, and 16 MPI ranks each opening 16 threads there made the replicated RBF setup 17×
/// slower on a 16-core node (docs/parallel.md). So is OpenBLAS's pool where the process has
/// linked it (PETSc's MUMPS); CHOLMOD's, loaded later, is set at each factorization.
inline void set_num_threads(int n) {
  if (n < 0 || n > max_threads)
    throw InputError("set_num_threads: expected 0 (OpenMP's default) to " + std::to_string(max_threads) + " threads (got " +
                     std::to_string(n) + ")");
#ifdef _OPENMP
  // Read before the first change, so that 0 gives back the default as the program started.
  const int fallback = detail::openmp_default_threads();
  omp_set_num_threads(n > 0 ? n : fallback);
#endif
  detail::thread_setting().store(n);
  Eigen::setNbThreads(n);
  detail::set_blas_threads(RTLD_DEFAULT, num_threads());
}

/// Threads the library's parallel loops use now (1 without OpenMP; at most max_threads).
[[nodiscard]] inline int num_threads() {
#ifdef _OPENMP
  const int n = detail::thread_setting().load();
  return n > 0 ? n : std::min(omp_get_max_threads(), max_threads);
#else
  return 1;
#endif
}

/// Refuses an OMP_NUM_THREADS beyond max_threads (InputError naming it): the OpenMP runtime
/// opens that many threads in the first parallel region of a library that takes its default
/// (CHOLMOD, OpenBLAS), which crashes at tens of thousands. The programs call it first.
inline void check_thread_environment() {
  const char* text = std::getenv("OMP_NUM_THREADS");
  if (text == nullptr) return;
  // OpenMP reads the first number of a list ("8,2" nests).
  const std::string_view first(text, std::strcspn(text, ","));
  long long n = 0;
  const auto [ptr, ec] = std::from_chars(first.data(), first.data() + first.size(), n);
  if (ec == std::errc::result_out_of_range || (ec == std::errc() && n > max_threads))
    throw InputError("OMP_NUM_THREADS=" + std::string(text).substr(0, 32) + ": more than " + std::to_string(max_threads) +
                     " threads (the OpenMP runtime fails on that many; set it to the cores to use)");
}

}  // namespace meshmotion
