// RBF mover benchmark.
// 1. Rotating ellipse in a circular farfield (boundary-layer graded quads, thesis fig. 4.11 /
//    table 4.1): 60° rotation time and Knupp skew, and the largest angle (10° resolution)
//    that keeps every cell valid in 1, 2 and 4 steps. Thesis: RBF 1.93 s, valid to ~110°.
// 2. Scaling on a 3D hex box family (bottom face moving as a bump, support radius = 6 grid
//    spacings): setup and move time against node count, peak memory, and the speed-up over
//    the direct O(N_volume × N_boundary) evaluation measured in the same run (smaller sizes).
// Prints a table and one JSON line per case. Usage: rbf_bench [max_box_cells_per_axis=126]
// (sizes 20, 40, 80, 126, 160 cells per axis up to the maximum; 126 gives 2.05M nodes).

#include "bench_memory.hpp"
#include "box_bump.hpp"
#include "meshmotion/core/generators.hpp"
#include "meshmotion/movers.hpp"
#include "meshmotion/quality.hpp"
#include "meshmotion/solvers/detail/stopwatch.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

using namespace meshmotion;

namespace {

/// Seconds of the direct O(N_volume × N_boundary) evaluation Σ_c φ(|x_i − x_c|) d_c over every
/// node and every boundary node (no k-d tree): the baseline the mover's speed is a ratio to.
template <int Dim>
double direct_evaluation_seconds(const Points<Dim>& p, const ResolvedBoundary<Dim>& boundary, const RbfOptions& options) {
  const detail::Stopwatch watch;
  Points<Dim> v = Points<Dim>::Zero(Dim, p.cols());
  const Index m = boundary.size();
#pragma omp parallel for schedule(static)
  for (Index i = 0; i < p.cols(); ++i)
    for (Index c = 0; c < m; ++c) {
      const double phi = rbf_value(options.kernel, (p.col(i) - p.col(boundary.nodes[std::size_t(c)])).norm(), options.support_radius);
      if (phi != 0.0) v.col(i) += phi * boundary.displacements.col(c);
    }
  const double seconds = watch.seconds();
  if (v.norm() < 0.0) std::printf("unreachable\n");  // keeps the loop from being optimized away
  return seconds;
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
  const MoverStats& stats = r.steps.back().stats;
  BoundarySpec<2> spec;
  spec.moving("wall", Rotation2D{Vec<2>::Zero(), radians(60.0)}).fixed("farfield");
  RbfOptions options;
  options.support_radius = radius;
  const double direct = direct_evaluation_seconds(mesh.points, spec.resolve(mesh), options);
  std::printf("rotating ellipse: %ld nodes, %ld boundary nodes, support radius %.1f\n", static_cast<long>(mesh.num_nodes()),
              static_cast<long>(stats.boundary_nodes), radius);
  std::printf("%-6s %10s %10s %10s %10s %10s %10s %8s %10s\n", "steps", "total_s", "setup_s", "move_s", "direct_s",
              "direct/tot", "min_skew", "invalid", "thesis_s");
  std::printf("%-6d %10.4f %10.4f %10.4f %10.4f %10.2f %10.4f %8ld %10.2f\n", 1, seconds, stats.setup_seconds,
              stats.move_seconds, direct, direct / seconds, q.min, static_cast<long>(q.num_invalid), 1.93);
  std::printf("{\"case\":\"rotate60\",\"nodes\":%ld,\"seconds\":%.6f,\"setup_seconds\":%.6f,\"move_seconds\":%.6f,"
              "\"direct_evaluation_seconds\":%.6f,\"speedup_vs_direct\":%.2f,\"min_skew\":%.6f,\"mean_skew\":%.6f,"
              "\"invalid\":%ld,\"thesis_seconds\":1.93,\"speedup_vs_thesis\":%.2f}\n",
              static_cast<long>(mesh.num_nodes()), seconds, stats.setup_seconds, stats.move_seconds, direct,
              direct / seconds, q.min, q.mean, static_cast<long>(q.num_invalid), 1.93 / seconds);
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
  std::printf("\n%-10s %10s %10s %10s %12s %10s %12s %12s %10s\n", "nodes", "boundary", "setup_s", "move_s",
              "setup_us/node", "direct_s", "speedup", "nonzeros", "peak_MB");
  for (const int n : {20, 40, 80, 126, 160}) {
    if (n > max_cells) break;
    const Mesh<3> mesh = bench::box(n);
    const ResolvedBoundary<3> boundary = bench::bottom_bump(mesh);
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
    const double direct = mesh.num_nodes() * boundary.size() < 2e9 ? direct_evaluation_seconds(mesh.points, boundary, options) : -1.0;
    const double speedup = direct > 0.0 ? direct / move_seconds : 0.0;
    std::printf("%-10ld %10ld %10.3f %10.4f %12.3f %10.3f %12.1f %12ld %10.0f\n", static_cast<long>(mesh.num_nodes()),
                static_cast<long>(boundary.size()), mover.stats().setup_seconds, move_seconds,
                1e6 * mover.stats().setup_seconds / static_cast<double>(mesh.num_nodes()), direct, speedup,
                static_cast<long>(mover.stats().nonzeros), bench::peak_memory_mb());
    std::printf("{\"case\":\"scaling\",\"nodes\":%ld,\"boundary_nodes\":%ld,\"setup_seconds\":%.6f,\"move_seconds\":%.6f,"
                "\"direct_seconds\":%.6f,\"speedup_move_vs_direct\":%.2f,\"nonzeros\":%ld,\"peak_memory_mb\":%.1f}\n",
                static_cast<long>(mesh.num_nodes()), static_cast<long>(boundary.size()), mover.stats().setup_seconds,
                move_seconds, direct, speedup, static_cast<long>(mover.stats().nonzeros), bench::peak_memory_mb());
    std::fflush(stdout);
  }
}

}  // namespace

int main(int argc, char** argv) {
  bench::tune_memory(argc, argv);
  const int max_cells = argc > 1 ? std::atoi(argv[1]) : 126;
  rotating_object();
  scaling(max_cells);
}
