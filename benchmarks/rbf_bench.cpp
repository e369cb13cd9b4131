// RBF mover benchmark.
// 1. Rotating ellipse in a circular farfield (boundary-layer graded quads, thesis fig. 4.11 /
//    table 4.1): 60° rotation time and Knupp skew, and the largest angle (10° resolution)
//    that keeps every cell valid in 1, 2 and 4 steps. Thesis: RBF 1.93 s, valid to ~110°.
// 2. Scaling on a 3D hex box family (bottom face moving as a bump, support radius = 6 grid
//    spacings): setup and move time against node count, peak memory, and the speed-up over
//    the direct O(N_volume × N_boundary) evaluation measured in the same run (smaller sizes).
// 3. One setup, many moves: a ring whose whole boundary turns 56° (with a ±0.15 rad swirl),
//    stretches by 1.16 and translates by 0.31 of its radius, in 10 moves from one setup made
//    before anything moved, as solvers run it. The defaults (radius growing with the motion)
//    beside the radius held at the setup's; how often the mover set up again; a move without a
//    set-up again against a mover given that radius (no growth rule), timed in the same run.
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
  // The thesis's RBF: the whole rotation interpolated. The defaults blend a rigid body's turn
  // from one setup at rest (run_steps), valid at any angle: plate_turn_bench.py measures them.
  options.rigid_part = RigidPart::none;
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

/// Boundary displacements of step s ∈ [0, 1] of the ring's whole-boundary motion.
Points<2> ring_step(const Mesh<2>& ring, const ResolvedBoundary<2>& boundary, double s) {
  Points<2> d(2, boundary.size());
  for (Index k = 0; k < d.cols(); ++k) {
    const Vec<2> x = ring.points.col(boundary.nodes[static_cast<std::size_t>(k)]);
    const double turn = s * (radians(56.0) + 0.15 * std::cos(2.0 * std::atan2(x.y(), x.x())));
    d.col(k) = Eigen::Rotation2Dd(turn) * Vec<2>(std::pow(1.16, s) * x.x(), std::pow(1.16, -s) * x.y()) +
               Vec<2>(s * 0.31 * 1.5, 0.0) - x;
  }
  return d;
}

struct OneSetupRun {
  int invalid = 0;           // cells invalid over every step
  double min_quality = 1.0;  // smallest scaled Jacobian over every step
  Index growths = 0;
  double radius = 0.0;
};

OneSetupRun ten_moves(RbfMover<2>& mover, const Mesh<2>& ring, const ResolvedBoundary<2>& boundary) {
  OneSetupRun run;
  mover.setup(ring, boundary);
  Mesh<2> moved = ring;
  for (int step = 1; step <= 10; ++step) {
    moved.points = ring.points + mover.move(ring_step(ring, boundary, 0.1 * step));
    const QualityReport q = quality_report(moved, Metric::scaled_jacobian);
    run.invalid += static_cast<int>(q.num_invalid);
    run.min_quality = std::min(run.min_quality, q.min);
  }
  run.growths = mover.stats().radius_growths;
  run.radius = mover.support_radius();
  return run;
}

void one_setup_many_moves() {
  const Mesh<2> ring = annulus_mesh({.n_around = 512});
  BoundarySpec<2> spec;
  spec.moving("inner", Translation<2>{Vec<2>::Zero()}).moving("outer", Translation<2>{Vec<2>::Zero()});
  const ResolvedBoundary<2> boundary = spec.resolve(ring);
  RbfMover<2> defaults;
  const OneSetupRun grown = ten_moves(defaults, ring, boundary);
  RbfOptions held_options;
  {
    RbfMover<2> first;
    first.setup(ring, boundary);
    held_options.support_radius = first.support_radius();
  }
  RbfMover<2> held(held_options);
  const OneSetupRun kept = ten_moves(held, ring, boundary);
  // A move the growth rule lets through, against the same radius given (no rule), alternately.
  RbfOptions given_options;
  given_options.support_radius = grown.radius;
  RbfMover<2> given(given_options);
  given.setup(ring, boundary);
  const Points<2> last = ring_step(ring, boundary, 1.0);
  Points<2> out;
  double with_rule = 1e300, without = 1e300;
  for (int round = 0; round < 5; ++round) {
    detail::Stopwatch a;
    defaults.move_into(last, out);
    with_rule = std::min(with_rule, a.seconds());
    detail::Stopwatch b;
    given.move_into(last, out);
    without = std::min(without, b.seconds());
  }
  std::printf("\none setup, many moves: a ring of %ld nodes (%ld on its boundary), its whole boundary turned 56 deg, "
              "stretched and translated in 10 moves\n",
              static_cast<long>(ring.num_nodes()), static_cast<long>(boundary.size()));
  std::printf("%-34s %8s %10s %8s %10s\n", "options", "invalid", "min_sj", "setups", "radius");
  for (const auto& [name, run] : {std::pair{"(defaults)", grown}, std::pair{"support_radius held at the setup's", kept}}) {
    std::printf("%-34s %8d %10.4f %8ld %10.4f\n", name, run.invalid, run.min_quality, static_cast<long>(1 + run.growths), run.radius);
    std::printf("{\"case\":\"one_setup_many_moves\",\"options\":\"%s\",\"nodes\":%ld,\"steps\":10,\"invalid\":%d,"
                "\"min_scaled_jacobian\":%.6f,\"setups_again\":%ld,\"support_radius\":%.6f}\n",
                name, static_cast<long>(ring.num_nodes()), run.invalid, run.min_quality, static_cast<long>(run.growths), run.radius);
  }
  // doublings: how often the motion doubled past what the setup's radius covers (5 × the
  // largest displacement against it), the set-ups again it allows.
  const double largest = last.colwise().norm().maxCoeff();
  std::printf("a move without a set-up again: %.6f s, with the radius given: %.6f s (ratio %.3f)\n", with_rule, without,
              with_rule / without);
  std::printf("{\"case\":\"one_setup_move_cost\",\"nodes\":%ld,\"move_seconds\":%.6f,\"given_radius_move_seconds\":%.6f,"
              "\"ratio\":%.4f,\"largest_displacement\":%.6f,\"setup_radius\":%.6f,\"setups_again\":%ld,"
              "\"doublings\":%.3f}\n",
              static_cast<long>(ring.num_nodes()), with_rule, without, with_rule / without, largest, held_options.support_radius,
              static_cast<long>(grown.growths), std::log2(5.0 * largest / held_options.support_radius));
}

}  // namespace

int main(int argc, char** argv) {
  bench::tune_memory(argc, argv);
  const int max_cells = argc > 1 ? std::atoi(argv[1]) : 126;
  rotating_object();
  scaling(max_cells);
  one_setup_many_moves();
}
