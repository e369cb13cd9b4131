// The C++ side of benchmarks/python_overhead.py: the same RBF job as the Python side, through
// the same run-time registry (AnyMover), on the same mesh file, writing into its own array.
//
//   python_overhead_peer write N mesh.msh     a hex box of N³ cells (binary .msh 4.1)
//   python_overhead_peer run mesh.msh RADIUS MOVES
//
// run: prescribed "bottom" (a sine bump in z), "top" fixed, the sides free; setup once, MOVES
// moves into one output array, MOVES reverse derivatives of a seed of ones. Prints one JSON
// line: seconds of setup and per move / per reverse product (median and mean), and checksums
// of the last results so the Python side can check it did the same work.

#include "bench_memory.hpp"
#include "meshmotion/core/generators.hpp"
#include "meshmotion/io/mesh_io.hpp"
#include "meshmotion/movers.hpp"
#include "meshmotion/movers/boundary.hpp"
#include "meshmotion/solvers/detail/stopwatch.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <numbers>
#include <numeric>
#include <string>
#include <vector>

using namespace meshmotion;

namespace {

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

double mean(const std::vector<double>& v) { return std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size()); }

int run(const std::string& file, double radius, int moves) {
  const Mesh<3> mesh = std::get<Mesh<3>>(read_mesh(file));
  BoundarySpec<3> spec;
  spec.prescribed("bottom").fixed("top");
  const ResolvedBoundary<3> boundary = spec.resolve(mesh);
  Points<3> d = Points<3>::Zero(3, boundary.size());
  for (const Index v : mesh.group_nodes("bottom")) {
    const Vec<3> x = mesh.points.col(v);
    d(2, boundary.column(v)) = 0.01 * std::sin(std::numbers::pi * x(0)) * std::sin(std::numbers::pi * x(1));
  }
  const detail::Stopwatch setup_watch;
  AnyMover<3> mover = make_mover<3>("rbf", {{"support_radius", format_option_value(radius)}});
  mover.setup(mesh, boundary);
  const double setup = setup_watch.seconds();

  // The solver's own array, as Python's numpy one: the mover writes into it through a Map.
  std::vector<double> storage(static_cast<std::size_t>(3 * mesh.num_nodes()));
  Eigen::Map<Points<3>> out(storage.data(), 3, mesh.num_nodes());
  std::vector<double> move_seconds, reverse_seconds;
  for (int k = 0; k < moves; ++k) {
    const detail::Stopwatch watch;
    mover.move_into(d, out);
    move_seconds.push_back(watch.seconds());
  }
  const Points<3> seed = Points<3>::Ones(3, mesh.num_nodes());
  Points<3> gradient;
  for (int k = 0; k < moves; ++k) {
    const detail::Stopwatch watch;
    gradient = mover.derivative_reverse(seed);
    reverse_seconds.push_back(watch.seconds());
  }
  std::printf("{\"side\": \"c++\", \"nodes\": %lld, \"centres\": %lld, \"setup_s\": %.6g, \"move_median_s\": %.6g, "
              "\"move_mean_s\": %.6g, \"reverse_median_s\": %.6g, \"reverse_mean_s\": %.6g, \"move_checksum\": %.17g, "
              "\"reverse_checksum\": %.17g}\n",
              static_cast<long long>(mesh.num_nodes()), static_cast<long long>(boundary.size()), setup,
              median(move_seconds), mean(move_seconds), median(reverse_seconds), mean(reverse_seconds),
              out.cwiseAbs().sum(), gradient.cwiseAbs().sum());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  bench::tune_memory(argc, argv);
  try {
    const std::string what = argc > 1 ? argv[1] : "";
    if (what == "write" && argc == 4) {
      const Index n = std::stoi(argv[2]);
      write_mesh(argv[3], box_mesh({.nx = n, .ny = n, .nz = n}), WriteOptions{.binary = true});
      return 0;
    }
    if (what == "run" && argc == 5) return run(argv[2], std::stod(argv[3]), std::stoi(argv[4]));
    std::fprintf(stderr, "usage: python_overhead_peer write N mesh.msh | run mesh.msh RADIUS MOVES\n");
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "python_overhead_peer: %s\n", e.what());
    return 1;
  }
}
