// conversion_bench: P1 → P2 conversion speed (issue 22), and P1 → P3/P4 (convert_to_order, any
// shape of the catalogue; rows named -p3/-p4). The 30P30N RANS mesh's quadrilaterals
// (../shared/data; skipped when absent) and structured boxes of tetrahedra and hexahedra up to
// 5M cells, to show the time per cell staying flat. For each mesh: the first conversion in the
// process (memory fresh from the kernel, as in a program run once) and the median of repeated
// ones (memory reused, as in a loop). The table also measures the machine's limit: how fast
// fresh memory can be touched with 4 KiB pages and with 2 MiB transparent huge pages, since on
// a virtual machine page faults, not the numbering, bound a one-shot conversion.
//
//   conversion_bench [--quick] [path/to/su2_30p30n_rans_L1_coarse.su2]
//
// Runs with the programs' memory settings (core/process_memory.hpp: a huge-page heap);
// MESHMOTION_HUGE_PAGES=0 measures without.

#include "bench_memory.hpp"
#include "meshmotion/core/generators.hpp"
#include "meshmotion/curving/order_conversion.hpp"
#include "meshmotion/curving/p2_conversion.hpp"
#include "meshmotion/io.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#if defined(__linux__)
#include <sys/mman.h>
#endif

using namespace meshmotion;
using Clock = std::chrono::steady_clock;

namespace {

double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// MB/s of first touching `megabytes` of fresh anonymous memory, with or without huge pages.
double fresh_memory_rate(std::size_t megabytes, bool huge) {
#if defined(__linux__)
  const std::size_t bytes = megabytes << 20;
  void* p = mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (p == MAP_FAILED) return 0.0;
  if (huge) madvise(p, bytes, MADV_HUGEPAGE);
  const auto t = Clock::now();
  std::memset(p, 1, bytes);
  const double s = seconds_since(t);
  munmap(p, bytes);
  return static_cast<double>(megabytes) / s;
#else
  (void)megabytes;
  (void)huge;
  return 0.0;
#endif
}

// The first conversion of `mesh` to `order` in the process and the median of `repeats` more
// (order 2: convert_to_quadratic; 3 and 4: convert_to_order).
template <int Dim>
void run_case(const std::string& name, const Mesh<Dim>& mesh, int repeats, std::vector<std::string>& json, int order = 2) {
  const auto convert = [&] {
    return order == 2 ? convert_to_quadratic(mesh).mesh.num_nodes() : convert_to_order(mesh, order).mesh.num_nodes();
  };
  auto t = Clock::now();
  const Index nodes = convert();
  const double first_s = seconds_since(t);
  std::vector<double> times;
  for (int r = 0; r < repeats; ++r) {
    t = Clock::now();
    (void)convert();
    times.push_back(seconds_since(t));
  }
  std::sort(times.begin(), times.end());
  const double median_s = times[times.size() / 2];
  const double cells = static_cast<double>(mesh.num_cells());
  const std::string label = order == 2 ? name : name + "-p" + std::to_string(order);
  std::printf("%-22s %10lld %10lld %10.2f %10.2f %12.1f\n", label.c_str(), static_cast<long long>(mesh.num_cells()),
              static_cast<long long>(nodes), 1e3 * first_s, 1e3 * median_s, 1e9 * median_s / cells);
  char line[512];
  std::snprintf(line, sizeof line,
                "{\"bench\":\"conversion\",\"case\":\"%s\",\"order\":%d,\"cells\":%lld,\"%s\":%lld,\"first_s\":%.5f,"
                "\"median_s\":%.5f,\"ns_per_cell\":%.1f}",
                label.c_str(), order, static_cast<long long>(mesh.num_cells()), order == 2 ? "p2_nodes" : "nodes",
                static_cast<long long>(nodes), first_s, median_s, 1e9 * median_s / cells);
  json.emplace_back(line);
}

Mesh<3> box(Index n, BoxCells cells) {
  BoxOptions b;
  b.nx = b.ny = b.nz = n;
  b.cells = cells;
  return box_mesh(b);
}

}  // namespace

int main(int argc, char** argv) {
  const char* huge = bench::tune_memory(argc, argv);
  bool quick = false;
  std::filesystem::path file = std::filesystem::path(MESHMOTION_SHARED_DATA_DIR) / "su2_30p30n_rans_L1_coarse.su2";
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--quick") quick = true;
    else if (a == "-h" || a == "--help") {
      std::printf("usage: conversion_bench [--quick] [30p30n.su2]\n");
      return 0;
    } else file = a;
  }
  std::vector<std::string> json;
  const double small_pages = fresh_memory_rate(256, false), huge_pages = fresh_memory_rate(256, true);
  std::printf("huge-page heap: %s; first touch of fresh memory: %.0f MB/s with 4 KiB pages, %.0f MB/s with 2 MiB pages\n",
              huge, small_pages, huge_pages);
  char line[256];
  std::snprintf(line, sizeof line,
                "{\"bench\":\"conversion\",\"case\":\"fresh-memory\",\"huge_page_heap\":\"%s\",\"small_pages_mb_s\":%.0f,"
                "\"huge_pages_mb_s\":%.0f}",
                huge, small_pages, huge_pages);
  json.emplace_back(line);

  std::printf("%-22s %10s %10s %10s %10s %12s\n", "case", "cells", "nodes", "first ms", "median ms", "ns/cell");
  if (std::filesystem::exists(file)) {
    const Mesh<2> airfoil = read_mesh_as<2>(file);
    run_case("30p30n-quads", airfoil, 11, json);
    for (const int order : {3, 4}) run_case("30p30n-quads", airfoil, 5, json, order);
  } else {
    std::printf("conversion_bench: %s not found, 30P30N case skipped\n", file.string().c_str());
  }
  const std::vector<Index> tet_sides = quick ? std::vector<Index>{20, 40} : std::vector<Index>{20, 48, 96};
  for (const Index n : tet_sides) run_case("box-tet4-" + std::to_string(n), box(n, BoxCells::tet4), quick ? 3 : 5, json);
  const std::vector<Index> hex_sides = quick ? std::vector<Index>{40, 80} : std::vector<Index>{40, 100, 175};
  for (const Index n : hex_sides) run_case("box-hex8-" + std::to_string(n), box(n, BoxCells::hex8), quick ? 3 : 5, json);
  run_case("box-mixed-" + std::to_string(quick ? 30 : 90), box(quick ? 30 : 90, BoxCells::tet_pyramid_prism), 3, json);
  // Past P2: tetrahedra to P3 and P4, hexahedra and the mix to P3 (the catalogue's highest).
  const Index tets = quick ? 20 : 48, hexes = quick ? 40 : 100, mixed = quick ? 20 : 40;
  for (const int order : {3, 4}) run_case("box-tet4-" + std::to_string(tets), box(tets, BoxCells::tet4), 3, json, order);
  run_case("box-hex8-" + std::to_string(hexes), box(hexes, BoxCells::hex8), 3, json, 3);
  run_case("box-mixed-" + std::to_string(mixed), box(mixed, BoxCells::tet_pyramid_prism), 3, json, 3);
  for (const auto& j : json) std::printf("%s\n", j.c_str());
  return 0;
}
