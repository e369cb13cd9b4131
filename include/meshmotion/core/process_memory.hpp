#pragma once
/// \file
/// Process-wide memory settings for programs that handle large meshes.
///
/// On virtual machines a page fault can cost tens of microseconds: first touching fresh memory
/// then runs at ~160 MB/s with 4 KiB pages, against several GB/s with 2 MiB transparent huge
/// pages (measured in docs/benchmarks.md). The library's stages allocate their arrays once, so
/// on such machines most of a P1 → P2 conversion or a file read is the kernel handing out
/// pages. glibc backs its heap with huge pages only when the process starts with the tunable
/// glibc.malloc.hugetlb=1 (glibc ≥ 2.35), and returns freed blocks to the kernel eagerly, so a
/// program that converts, moves and writes a mesh faults the same memory in again and again.
///
/// tune_process_memory() is meant for the first line of a program's main(): it restarts the
/// program once with the tunable set (when the kernel offers huge pages on request and nothing
/// chose otherwise) and keeps freed memory in the heap for reuse. A library linked into a
/// solver cannot do this for its host; docs/benchmarks.md says what to set instead.

#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>

#if defined(__linux__) && defined(__GLIBC__)
#include <malloc.h>
#endif
#if defined(__unix__)
#include <unistd.h>
#endif

namespace meshmotion {

/// What tune_process_memory() found and did.
enum class HugePages {
  enabled,      ///< the process runs with glibc's huge-page heap (restarted into it, or the kernel gives them always)
  declined,     ///< MESHMOTION_HUGE_PAGES=0, or GLIBC_TUNABLES sets glibc.malloc.hugetlb=0
  unavailable,  ///< not Linux/glibc ≥ 2.35, the kernel offers no transparent huge pages, or the restart failed
};

namespace detail {

/// The kernel's transparent-huge-page mode: "always", "madvise", "never", or "" when unknown.
[[nodiscard]] inline std::string transparent_huge_page_mode() {
  std::ifstream in("/sys/kernel/mm/transparent_hugepage/enabled");
  std::string line;
  if (!std::getline(in, line)) return {};
  const auto open = line.find('[');
  const auto close = line.find(']', open);
  if (open == std::string::npos || close == std::string::npos) return {};
  return line.substr(open + 1, close - open - 1);
}

}  // namespace detail

/// The machine's physical memory in bytes; 0 when unknown.
[[nodiscard]] inline double physical_memory_bytes() {
#if defined(__unix__) && defined(_SC_PHYS_PAGES) && defined(_SC_PAGE_SIZE)
  const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
  if (pages > 0 && page > 0) return static_cast<double>(pages) * static_cast<double>(page);
#endif
  return 0.0;
}

/// Call first in main(). On Linux with glibc ≥ 2.35 and transparent huge pages in "madvise"
/// mode, re-executes the program (same pid, arguments and environment, plus
/// GLIBC_TUNABLES=glibc.malloc.hugetlb=1) unless MESHMOTION_HUGE_PAGES=0 or GLIBC_TUNABLES
/// already sets glibc.malloc.hugetlb (then its value decides); if the exec fails the program goes on unchanged. Then,
/// on glibc, every allocation comes from the heap and freed memory stays there for reuse
/// instead of going back to the kernel (the process keeps its peak until it exits).
/// Do not call it where a restart is unsafe (after threads, MPI or open resources exist).
inline HugePages tune_process_memory([[maybe_unused]] int argc, [[maybe_unused]] char** argv) {
#if defined(__linux__) && defined(__GLIBC__)
  // Freed blocks are reused instead of being unmapped and faulted in again by the next stage:
  // every block comes from the heap (no block of its own mapped and unmapped, however large),
  // and the heap never shrinks. With a 1 GiB trim threshold and 32 MiB blocks mapped one by
  // one, a 5M-cell P1 → P2 conversion gave back its 1.2 GB on return, and the next one faulted
  // it in again: 0.7–2.1 s a call instead of 0.63 s.
  mallopt(M_MMAP_MAX, 0);
  mallopt(M_TRIM_THRESHOLD, -1);
#if __GLIBC__ > 2 || (__GLIBC__ == 2 && __GLIBC_MINOR__ >= 35)
  const char* choice = std::getenv("MESHMOTION_HUGE_PAGES");
  const char* tunables = std::getenv("GLIBC_TUNABLES");
  if (tunables != nullptr && std::strstr(tunables, "glibc.malloc.hugetlb=") != nullptr)
    return std::strstr(tunables, "glibc.malloc.hugetlb=0") != nullptr ? HugePages::declined : HugePages::enabled;
  if (choice != nullptr && std::strcmp(choice, "0") == 0) return HugePages::declined;
  const std::string mode = detail::transparent_huge_page_mode();
  if (mode == "always") return HugePages::enabled;
  if (mode != "madvise" || argc < 1 || argv == nullptr) return HugePages::unavailable;
  const std::string previous = tunables != nullptr ? tunables : "";
  const std::string value = previous.empty() ? "glibc.malloc.hugetlb=1" : previous + ":glibc.malloc.hugetlb=1";
  if (setenv("GLIBC_TUNABLES", value.c_str(), 1) != 0) return HugePages::unavailable;
  execv("/proc/self/exe", argv);
  // Still here: the exec failed; leave the environment as it was.
  if (tunables != nullptr) setenv("GLIBC_TUNABLES", previous.c_str(), 1);
  else unsetenv("GLIBC_TUNABLES");
#endif
#endif
  return HugePages::unavailable;
}

}  // namespace meshmotion
