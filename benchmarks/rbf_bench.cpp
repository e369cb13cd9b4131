// RBF mover benchmark.
// 1. Rotating ellipse in a circular farfield (boundary-layer graded quads, thesis fig. 4.11 /
//    table 4.1): 60° rotation time and Knupp skew, and the largest angle (10° resolution)
//    that keeps every cell valid in 1, 2 and 4 steps. Thesis: RBF 1.93 s, valid to ~110°.
// 2. Scaling on a 3D hex box family (bottom face moving as a bump, support radius = 6 grid
//    spacings): setup and move time against node count, peak memory, and the speed-up over
//    the direct O(N_volume × N_boundary) evaluation measured in the same run (smaller sizes).
// Prints a table and one JSON line per case. Usage: rbf_bench [max_box_cells_per_axis=126]

#include "meshmotion/core/generators.hpp"
#include "meshmotion/movers.hpp"
#include "meshmotion/quality.hpp"
#include "meshmotion/solvers/detail/stopwatch.hpp"

#include <sys/resource.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

using namespace meshmotion;

namespace {

double peak_memory_mb() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;
}

StepResult<2> rotate(const Mesh<2>& mesh, double degrees, int steps, double radius) {
  BoundarySpec<2> spec;
  spec.moving("wall", Rotation2D{Vec<2>::Zero(), radians(degrees)}).fixed("farfield");
  RbfOptions options;
  options.support_radius = radius;
  RbfMover<2> mover(options);
  return run_steps(mover, mesh, spec, StepOptions{steps, Metric::skew});
}

void rotating_object() {
  OMeshOptions o;
  o.semi_axis_x = 0.5;
  o.semi_axis_y = 0.25;
  const Mesh<2> mesh = o_mesh(o);
  const double radius = 8.0;
  const detail::Stopwatch watch;
  const StepResult<2> r = rotate(mesh, 60.0, 1, radius);
  const double seconds = watch.seconds();
  const auto& q = *r.steps.back().quality;
  std::printf("rotating ellipse: %ld nodes, support radius %.1f\n", static_cast<long>(mesh.num_nodes()), radius);
  std::printf("%-8s %10s %10s %10s %8s %12s\n", "steps", "seconds", "min_skew", "mean_skew", "invalid", "thesis_s");
  std::printf("%-8d %10.4f %10.4f %10.4f %8ld %12.2f\n", 1, seconds, q.min, q.mean, static_cast<long>(q.num_invalid), 1.93);
  std::printf("{\"case\":\"rotate60\",\"nodes\":%ld,\"seconds\":%.6f,\"min_skew\":%.6f,\"mean_skew\":%.6f,\"invalid\":%ld,"
              "\"thesis_seconds\":1.93,\"speedup_vs_thesis\":%.2f}\n",
              static_cast<long>(mesh.num_nodes()), seconds, q.min, q.mean, static_cast<long>(q.num_invalid), 1.93 / seconds);
  for (const int steps : {1, 2, 4}) {
    double largest = 0.0;
    for (double angle = 10.0; angle <= 180.0; angle += 10.0) {
      if (rotate(mesh, angle, steps, radius).steps.back().quality->num_invalid > 0) break;
      largest = angle;
    }
    std::printf("largest valid angle, %d step(s): %.0f deg (thesis RBF: ~110)\n", steps, largest);
    std::printf("{\"case\":\"largest_valid_angle\",\"steps\":%d,\"degrees\":%.0f,\"thesis_degrees\":110}\n", steps, largest);
  }
}

void scaling(int max_cells) {
  std::printf("\n%-10s %10s %10s %10s %10s %12s %12s %10s\n", "nodes", "boundary", "setup_s", "move_s", "direct_s",
              "speedup", "nonzeros", "peak_MB");
  for (int n = 20; n <= max_cells; n = n < max_cells ? std::min(max_cells, n * 5 / 2) : max_cells + 1) {
    BoxOptions b;
    b.nx = b.ny = b.nz = n;
    const Mesh<3> mesh = box_mesh(b);
    const std::vector<Index> bottom = mesh.group_nodes("bottom");
    Points<3> d = Points<3>::Zero(3, static_cast<Index>(bottom.size()));
    for (std::size_t k = 0; k < bottom.size(); ++k) {
      const double x = mesh.points(0, bottom[k]), y = mesh.points(1, bottom[k]);
      d(2, static_cast<Index>(k)) = 0.05 * std::sin(M_PI * x) * std::sin(M_PI * y);
    }
    BoundarySpec<3> spec;
    spec.moving("bottom", d);
    const ResolvedBoundary<3> boundary = spec.resolve(mesh);
    RbfOptions options;
    options.support_radius = 6.0 / n;
    RbfMover<3> mover(options);
    mover.setup(mesh, boundary);
    Points<3> u;
    const int moves = 3;
    const detail::Stopwatch move_watch;
    for (int i = 0; i < moves; ++i) mover.move_into(boundary.displacements, u);
    const double move_seconds = move_watch.seconds() / moves;
    // Baseline: the direct evaluation of every node against every boundary node.
    double direct = -1.0;
    if (mesh.num_nodes() * boundary.size() < 2e9) {
      const detail::Stopwatch direct_watch;
      Points<3> v = Points<3>::Zero(3, mesh.num_nodes());
      const Points<3>& p = mesh.points;
      const Index m = boundary.size();
#pragma omp parallel for schedule(static)
      for (Index i = 0; i < mesh.num_nodes(); ++i)
        for (Index c = 0; c < m; ++c) {
          const double phi = rbf_value(options.kernel, (p.col(i) - p.col(boundary.nodes[std::size_t(c)])).norm(), options.support_radius);
          if (phi != 0.0) v.col(i) += phi * d.col(c);
        }
      direct = direct_watch.seconds();
      if (v.norm() < 0.0) std::printf("unreachable\n");  // keeps the loop from being optimized away
    }
    const double speedup = direct > 0.0 ? direct / move_seconds : 0.0;
    std::printf("%-10ld %10ld %10.3f %10.4f %10.3f %12.1f %12ld %10.0f\n", static_cast<long>(mesh.num_nodes()),
                static_cast<long>(boundary.size()), mover.stats().setup_seconds, move_seconds, direct, speedup,
                static_cast<long>(mover.stats().nonzeros), peak_memory_mb());
    std::printf("{\"case\":\"scaling\",\"nodes\":%ld,\"boundary_nodes\":%ld,\"setup_seconds\":%.6f,\"move_seconds\":%.6f,"
                "\"direct_seconds\":%.6f,\"speedup_move_vs_direct\":%.2f,\"nonzeros\":%ld,\"peak_memory_mb\":%.1f}\n",
                static_cast<long>(mesh.num_nodes()), static_cast<long>(boundary.size()), mover.stats().setup_seconds,
                move_seconds, direct, speedup, static_cast<long>(mover.stats().nonzeros), peak_memory_mb());
    std::fflush(stdout);
  }
}

}  // namespace

int main(int argc, char** argv) {
  const int max_cells = argc > 1 ? std::atoi(argv[1]) : 126;
  rotating_object();
  scaling(max_cells);
}
