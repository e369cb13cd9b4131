#pragma once
// Memory in the benchmarks: every benchmark starts with the programs' memory settings
// (core/process_memory.hpp), so it measures what a program run measures. run_all.sh --baseline
// builds these benchmarks against an older library, which may not have those settings: then
// they run without, and say so. And the peak memory the tables print.

#include <sys/resource.h>

#if __has_include("meshmotion/core/process_memory.hpp")
#include "meshmotion/core/process_memory.hpp"
#define MESHMOTION_BENCH_HAVE_PROCESS_MEMORY 1
#endif

namespace bench {

/// What the huge-page setting came to: "enabled", "declined", "unavailable", or "not in this build".
inline const char* tune_memory([[maybe_unused]] int argc, [[maybe_unused]] char** argv) {
#ifdef MESHMOTION_BENCH_HAVE_PROCESS_MEMORY
  switch (meshmotion::tune_process_memory(argc, argv)) {
    case meshmotion::HugePages::enabled: return "enabled";
    case meshmotion::HugePages::declined: return "declined";
    case meshmotion::HugePages::unavailable: return "unavailable";
  }
#endif
  return "not in this build";
}

/// The process's peak resident memory so far, in MB (ru_maxrss only grows).
inline double peak_memory_mb() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;
}

}  // namespace bench
