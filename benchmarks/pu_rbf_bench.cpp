// pu_rbf_bench: the partition-of-unity RBF (RbfOptions::partition_of_unity, issue 22) against
// the global system it replaces, in the same process.
// 1. Accuracy and cost: rbf_bench's 3D box (bottom face moving as a bump, support radius 6
//    spacings) at growing sizes, global and partition of unity at two patch sizes: setup and
//    move seconds, and the largest difference of the moves relative to the largest boundary
//    displacement.
// 2. Scale: a flat box whose bottom moves as the bump and whose top is fixed, sized for the
//    issue's target of 1M boundary centres and 10M volume nodes (support radius 3 spacings):
//    partition of unity, with the global system beside it at the quick size (and at full size
//    with --with-global: one factorization of the 1M-centre system, several GB).
//
//   pu_rbf_bench [--quick] [--with-global]
//
// A table and one JSON line per case; peak memory is the process's so far (ru_maxrss).

#include "bench_memory.hpp"
#include "box_bump.hpp"
#include "meshmotion/core/generators.hpp"
#include "meshmotion/movers.hpp"
#include "meshmotion/solvers/detail/stopwatch.hpp"

#include <cstdio>
#include <optional>
#include <string>
#include <vector>

using namespace meshmotion;

namespace {

struct Run {
  double setup_s = 0, move_s = 0;
  Index patches = 0;
  Points<3> u;
};

Run run(const Points<3>& points, const ResolvedBoundary<3>& boundary, const RbfOptions& options) {
  RbfMover<3> mover(options);
  Run r;
  detail::Stopwatch clock;
  mover.setup_reference(points, boundary);
  r.setup_s = clock.seconds();
  clock = detail::Stopwatch{};
  r.u = mover.move(boundary.displacements);
  r.move_s = clock.seconds();
  r.patches = mover.patches();
  return r;
}

void row(const std::string& mesh, Index nodes, Index centres, const char* method, Index patch_centres, const Run& r,
         std::optional<double> difference) {
  std::printf("%-14s %10lld %9lld %-8s %7lld %7lld %9.3f %9.3f %11s %9.0f\n", mesh.c_str(), static_cast<long long>(nodes),
              static_cast<long long>(centres), method, static_cast<long long>(patch_centres),
              static_cast<long long>(r.patches), r.setup_s, r.move_s,
              difference ? std::to_string(*difference).substr(0, 9).c_str() : "-", bench::peak_memory_mb());
  std::printf("{\"bench\":\"pu_rbf\",\"mesh\":\"%s\",\"nodes\":%lld,\"centres\":%lld,\"method\":\"%s\",\"patch_centres\":%lld,"
              "\"patches\":%lld,\"setup_s\":%.4f,\"move_s\":%.4f,\"relative_difference\":%s,\"peak_mb\":%.0f}\n",
              mesh.c_str(), static_cast<long long>(nodes), static_cast<long long>(centres), method,
              static_cast<long long>(patch_centres), static_cast<long long>(r.patches), r.setup_s, r.move_s,
              difference ? std::to_string(*difference).c_str() : "null", bench::peak_memory_mb());
  std::fflush(stdout);
}

// The flat box: n × n cells in x-y, `layers` cells high, cubic cells; bottom bump, top fixed.
struct Flat {
  Points<3> points;
  ResolvedBoundary<3> boundary;
};

Flat flat_box(Index n, Index layers) {
  Mesh<3> mesh;
  {
    BoxOptions b;
    b.nx = b.ny = n;
    b.nz = layers;
    b.z_max = static_cast<double>(layers) / static_cast<double>(n);
    mesh = box_mesh(b);
  }
  BoundarySpec<3> spec;
  spec.moving("bottom", bench::bump_displacements(mesh)).fixed("top");
  ResolvedBoundary<3> boundary = spec.resolve(mesh);
  return Flat{std::move(mesh.points), std::move(boundary)};
}

}  // namespace

int main(int argc, char** argv) {
  bench::tune_memory(argc, argv);
  bool quick = false, with_global = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--quick") quick = true;
    else if (a == "--with-global") with_global = true;
    else {
      std::printf("usage: pu_rbf_bench [--quick] [--with-global]\n");
      return a == "-h" || a == "--help" ? 0 : 2;
    }
  }
  std::printf("%-14s %10s %9s %-8s %7s %7s %9s %9s %11s %9s\n", "mesh", "nodes", "centres", "method", "patch", "patches",
              "setup s", "move s", "max diff", "peak MB");
  // 1. Accuracy against the global system.
  for (const int n : quick ? std::vector<int>{40, 64} : std::vector<int>{40, 80, 126}) {
    const Mesh<3> mesh = bench::box(n);
    const ResolvedBoundary<3> boundary = bench::bottom_bump(mesh);
    RbfOptions global;
    global.support_radius = 6.0 / n;
    const Run reference = run(mesh.points, boundary, global);
    const double scale = boundary.displacements.cwiseAbs().maxCoeff();
    const std::string name = "box-" + std::to_string(n);
    row(name, mesh.num_nodes(), boundary.size(), "global", 0, reference, std::nullopt);
    for (const Index patch : {Index{2000}, Index{4000}}) {
      RbfOptions pu = global;
      pu.partition_of_unity = true;
      pu.patch_centres = patch;
      const Run r = run(mesh.points, boundary, pu);
      row(name, mesh.num_nodes(), boundary.size(), "pu", patch, r, (r.u - reference.u).cwiseAbs().maxCoeff() / scale);
    }
  }
  // 2. Scale: 1M centres and 10M nodes in full mode (n = 707: 2 × 708² centres, 708² × 20 nodes).
  const Index n = quick ? 250 : 707, layers = 19;
  const Flat flat = flat_box(n, layers);
  RbfOptions options;
  options.support_radius = 3.0 / static_cast<double>(n);
  options.partition_of_unity = true;
  const Run r = run(flat.points, flat.boundary, options);
  const std::string name = "flat-" + std::to_string(n);
  std::optional<double> difference;
  if (quick || with_global) {
    RbfOptions global = options;
    global.partition_of_unity = false;
    const Run reference = run(flat.points, flat.boundary, global);
    difference = (r.u - reference.u).cwiseAbs().maxCoeff() / flat.boundary.displacements.cwiseAbs().maxCoeff();
    row(name, flat.points.cols(), flat.boundary.size(), "global", 0, reference, std::nullopt);
  }
  row(name, flat.points.cols(), flat.boundary.size(), "pu", options.patch_centres, r, difference);
  return 0;
}
