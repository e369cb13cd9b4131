// Tutorial 1: embedding meshmotion in a CFD time loop.
//
// A flow solver owns its mesh as plain arrays and advances in time; at every time step the
// body (here a thin airfoil-like ellipse pitching about its quarter chord,
// angle(t) = A sin(2π t / T)) has moved and the volume mesh must follow it before the flow
// step. The pattern shown:
//
//   1. adapt the solver's mesh type through MeshTraits (no copy, no change to the solver);
//   2. set the mover up ONCE on the reference configuration (the expensive part: k-d tree,
//      factorization, evaluation operator);
//   3. each step: compute the wall displacement, `move_into` preallocated storage and write
//      the positions back into the solver's arrays (the cheap part: one solve with the cached
//      factorization and one sparse product; the loop itself allocates nothing);
//   4. watch the quality every step with an allocation-free per-cell check;
//   5. set up again on the CURRENT mesh when the quality drops below a threshold, so that
//      later displacements are measured from a mesh closer to the body's position.
//
//   tutorial_1_time_loop --steps 400 --amplitude 20 --print-every 20
//   tutorial_1_time_loop --json

#include "meshmotion/core/json.hpp"
#include "meshmotion/core/generators.hpp"
#include "meshmotion/core/mesh_like.hpp"
#include "meshmotion/movers/boundary.hpp"
#include "meshmotion/movers/rbf.hpp"
#include "meshmotion/quality/knupp.hpp"
#include "meshmotion/quality/quality_report.hpp"

#include "program.hpp"

#include <CLI/CLI.hpp>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <iostream>
#include <numbers>
#include <vector>

namespace solver {

/// The flow solver's own mesh: coordinates in two arrays, four node indices per quadrilateral
/// (counter-clockwise), and the node lists of its boundary markers.
struct AirfoilGrid {
  std::vector<double> x, y;
  std::vector<std::int32_t> quads;
  std::vector<std::int32_t> wall, farfield;

  [[nodiscard]] std::size_t num_nodes() const { return x.size(); }
  [[nodiscard]] std::size_t num_quads() const { return quads.size() / 4; }
};

/// The solver's grid around an ellipse of chord 1 and the given thickness. A real solver reads
/// its grid from a file; here the library's O-mesh generator stands in for that file.
AirfoilGrid make_grid(double thickness, meshmotion::Index n_around, meshmotion::Index n_radial) {
  meshmotion::OMeshOptions o;
  o.semi_axis_x = 0.5;
  o.semi_axis_y = 0.5 * thickness;
  o.n_around = n_around;
  o.n_radial = n_radial;
  o.first_height = 2e-3;
  o.farfield_radius = 10.0;
  const meshmotion::Mesh<2> mesh = meshmotion::o_mesh(o);
  AirfoilGrid g;
  for (meshmotion::Index i = 0; i < mesh.num_nodes(); ++i) {
    g.x.push_back(mesh.points(0, i));
    g.y.push_back(mesh.points(1, i));
  }
  for (const auto v : mesh.cells.front().connectivity) g.quads.push_back(static_cast<std::int32_t>(v));
  for (const auto v : mesh.group_nodes("wall")) g.wall.push_back(static_cast<std::int32_t>(v));
  for (const auto v : mesh.group_nodes("farfield")) g.farfield.push_back(static_cast<std::int32_t>(v));
  return g;
}

}  // namespace solver

// The whole adaptation: the movers read the solver's arrays through these functions.
template <>
struct meshmotion::MeshTraits<solver::AirfoilGrid> {
  static constexpr int dim = 2;
  static Index num_nodes(const solver::AirfoilGrid& g) { return static_cast<Index>(g.num_nodes()); }
  static double coordinate(const solver::AirfoilGrid& g, Index node, int axis) {
    return (axis == 0 ? g.x : g.y)[static_cast<std::size_t>(node)];
  }
  static Index num_cell_blocks(const solver::AirfoilGrid&) { return 1; }
  static ElementType cell_type(const solver::AirfoilGrid&, Index) { return ElementType::quad4; }
  static Index num_cells(const solver::AirfoilGrid& g, Index) { return static_cast<Index>(g.num_quads()); }
  static Index cell_node(const solver::AirfoilGrid& g, Index, Index cell, int local) {
    return g.quads[static_cast<std::size_t>(4 * cell + local)];
  }
};

static_assert(meshmotion::MeshLike<solver::AirfoilGrid>);

namespace {

using namespace meshmotion;

struct Settings {
  int steps = 400;
  int period_steps = 100;       // time steps per pitch period
  double amplitude = 20.0;      // degrees
  double thickness = 0.12;      // of the chord
  Index n_around = 128, n_radial = 48;
  double support_radius = 3.0;  // chords
  double min_ratio = 0.8;       // re-setup when a cell keeps less than this of its skew
  int print_every = 20;
  bool json = false;
};

/// Knupp skew of quad c of the solver's grid (0 for a folded cell). Knupp's per-element
/// function takes a fixed-size coordinate block, so this allocates nothing and can run on
/// every cell at every step.
double skew(const solver::AirfoilGrid& g, std::size_t c) {
  Eigen::Matrix<double, 2, 4> corners;
  for (std::size_t k = 0; k < 4; ++k) {
    const auto v = static_cast<std::size_t>(g.quads[4 * c + k]);
    corners.col(static_cast<Index>(k)) << g.x[v], g.y[v];
  }
  return knupp_quality(ElementType::quad4, corners, 0.0).skew;
}

/// What the quality watch sees after a step.
struct Watch {
  double min_skew = 1.0;   ///< smallest skew over the cells
  double min_ratio = 1.0;  ///< smallest skew / skew on the mesh of the last setup
};

/// Skew of every cell against `at_setup` (the skews of the mesh the mover was set up on).
/// The ratio, not the absolute skew, tells how much the mover's deformation has cost: a
/// thin body's O-grid starts with skewed cells at its edges that the motion barely changes.
Watch watch_quality(const solver::AirfoilGrid& g, const std::vector<double>& at_setup) {
  Watch w;
  for (std::size_t c = 0; c < g.num_quads(); ++c) {
    const double q = skew(g, c);
    w.min_skew = std::min(w.min_skew, q);
    w.min_ratio = std::min(w.min_ratio, q / at_setup[c]);
  }
  return w;
}

/// Overwrites `out` (already num_quads long, so nothing is allocated) with every cell's skew.
void record_skews(const solver::AirfoilGrid& g, std::vector<double>& out) {
  for (std::size_t c = 0; c < g.num_quads(); ++c) out[c] = skew(g, c);
}

int run(const Settings& s) {
  solver::AirfoilGrid grid = solver::make_grid(s.thickness, s.n_around, s.n_radial);
  const Index n = static_cast<Index>(grid.num_nodes());

  // The wall moves, the farfield stays. The solver knows its markers as node lists, so the
  // spec is resolved against those lists rather than named groups of a Mesh<2>. The rigid
  // motion given here is a placeholder: the loop computes the wall displacement itself.
  BoundarySpec<2> spec;
  spec.moving("wall", Translation<2>{}).fixed("farfield");
  const GroupNodes markers{{"wall", {grid.wall.begin(), grid.wall.end()}},
                           {"farfield", {grid.farfield.begin(), grid.farfield.end()}}};
  const Points<2> reference = copy_points(grid);
  const ResolvedBoundary<2> boundary = spec.resolve(reference, markers);
  const Index m = boundary.size();

  // A support radius of a few chords spreads the rotation over many cells: the near-wall
  // cells then turn almost rigidly with the body and keep their shape.
  RbfOptions options;
  options.support_radius = s.support_radius;
  RbfMover<2> mover(options);
  mover.setup(grid, boundary);
  Index setups = 1;
  double setup_seconds = mover.stats().setup_seconds;

  // Storage the loop reuses: `base` is the mesh the mover was last set up on (its moves are
  // displacements from there), `d` the boundary displacements, `u` every node's displacement.
  Points<2> base = reference;
  Points<2> d = Points<2>::Zero(2, m);
  Points<2> u = Points<2>::Zero(2, n);
  const Vec<2> pivot(-0.25, 0.0);  // quarter chord

  std::vector<double> skew_at_setup(grid.num_quads());
  record_skews(grid, skew_at_setup);
  const Watch initial = watch_quality(grid, skew_at_setup);
  double lowest_skew = initial.min_skew;
  double move_seconds = 0.0;
  Index moves = 0, invalid_steps = 0;
  if (!s.json)
    std::printf("%6s %7s %8s %9s %10s %7s %10s\n", "step", "t/T", "angle", "min skew", "skew ratio", "setups", "move [ms]");

  for (int step = 1; step <= s.steps; ++step) {
    const double t = static_cast<double>(step) / s.period_steps;
    const double angle = radians(s.amplitude) * std::sin(2.0 * std::numbers::pi * t);
    const Eigen::Matrix2d rotation = Eigen::Rotation2Dd(angle).toRotationMatrix();

    // Targets come from the REFERENCE wall, so the body stays rigid however many re-setups
    // happened; the displacement handed to the mover is measured from `base`.
    for (Index k = 0; k < m; ++k) {
      const auto node = boundary.nodes[static_cast<std::size_t>(k)];
      d.col(k) = boundary.kinds[static_cast<std::size_t>(k)] == BoundaryKind::prescribed
                     ? Vec<2>(pivot + rotation * (reference.col(node) - pivot) - base.col(node))
                     : Vec<2>::Zero();
    }
    const auto start = std::chrono::steady_clock::now();
    mover.move_into(d, u);
    for (Index i = 0; i < n; ++i) {
      grid.x[static_cast<std::size_t>(i)] = base(0, i) + u(0, i);
      grid.y[static_cast<std::size_t>(i)] = base(1, i) + u(1, i);
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    move_seconds += seconds;
    ++moves;

    const Watch now = watch_quality(grid, skew_at_setup);
    lowest_skew = std::min(lowest_skew, now.min_skew);
    if (now.min_skew <= 0.0) ++invalid_steps;
    // ... the flow solver's step would run here, on grid.x / grid.y ...

    // Re-setup is the one expensive, allocating call, so it runs only when the deformation
    // since the last setup has cost too much quality. It also makes the mesh depend on the
    // path: with a single setup, a periodic motion gives a periodic mesh.
    const bool resetup = now.min_ratio < s.min_ratio;
    if (resetup) {
      mover.setup(grid, boundary);
      base = copy_points(grid);
      record_skews(grid, skew_at_setup);
      ++setups;
      setup_seconds += mover.stats().setup_seconds;
    }
    if (!s.json && (step % s.print_every == 0 || resetup))
      std::printf("%6d %7.3f %8.3f %9.4f %10.4f %7lld %10.3f%s\n", step, t, angle * 180.0 / std::numbers::pi,
                  now.min_skew, now.min_ratio, static_cast<long long>(setups), 1e3 * seconds, resetup ? "  re-setup" : "");
  }

  // The full report (quality layer on a Mesh<2> copy) is worth its allocation once, at the end.
  const Mesh<2> final_mesh = to_mesh(grid);
  const QualityReport skew_report = quality_report(final_mesh, Metric::skew);
  const QualityReport jacobian_report = quality_report(final_mesh, Metric::scaled_jacobian);
  const double per_move = moves > 0 ? move_seconds / static_cast<double>(moves) : 0.0;
  if (s.json) {
    JsonWriter w(std::cout);
    w.begin_object();
    w.key("nodes").value(n).key("cells").value(static_cast<Index>(grid.num_quads())).key("boundary_nodes").value(m);
    w.key("steps").value(s.steps).key("amplitude_degrees").value(s.amplitude).key("support_radius").value(s.support_radius);
    w.key("min_ratio_threshold").value(s.min_ratio);
    w.key("setups").value(setups).key("moves").value(moves);
    w.key("setup_seconds").value(setup_seconds).key("seconds_per_move").value(per_move);
    w.key("initial_min_skew").value(initial.min_skew).key("lowest_min_skew").value(lowest_skew);
    w.key("final_min_skew").value(skew_report.min).key("final_min_scaled_jacobian").value(jacobian_report.min);
    w.key("invalid_steps").value(invalid_steps).key("final_invalid").value(jacobian_report.num_invalid);
    w.end_object();
    std::cout << "\n";
  } else {
    std::printf("\n%lld nodes, %lld quads, %lld boundary nodes\n", static_cast<long long>(n),
                static_cast<long long>(grid.num_quads()), static_cast<long long>(m));
    std::printf("setups: %lld (%.4f s in total), moves: %lld (%.3f ms per move)\n", static_cast<long long>(setups),
                setup_seconds, static_cast<long long>(moves), 1e3 * per_move);
    std::printf("min skew: initial %.4f, lowest %.4f, final %.4f; final min scaled Jacobian %.4f\n", initial.min_skew,
                lowest_skew, skew_report.min, jacobian_report.min);
    std::printf("steps with folded cells: %lld\n", static_cast<long long>(invalid_steps));
  }
  return invalid_steps == 0 && jacobian_report.num_invalid == 0 ? 0 : 2;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Tutorial 1: a pitching airfoil-like body in a solver's time loop (setup once, move_into each step, "
               "re-setup when the quality drops)"};
  meshmotion::examples::add_version_flag(app);
  Settings s;
  app.add_option("--steps", s.steps, "time steps")->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--period-steps", s.period_steps, "time steps per pitch period")->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--amplitude", s.amplitude, "pitch amplitude A in degrees")->capture_default_str();
  app.add_option("--thickness", s.thickness, "ellipse thickness / chord")->check(CLI::Range(0.01, 1.0))->capture_default_str();
  app.add_option("--n-around", s.n_around, "nodes around the body")->check(CLI::Range(8, 100000))->capture_default_str();
  app.add_option("--n-radial", s.n_radial, "cell layers to the farfield")->check(CLI::Range(2, 100000))->capture_default_str();
  app.add_option("--support-radius", s.support_radius, "RBF support radius in chords")->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--min-ratio", s.min_ratio,
                 "set up again when some cell's skew falls below this fraction of its skew at the last setup")->check(CLI::Range(0.0, 1.0))->capture_default_str();
  app.add_option("--print-every", s.print_every, "print a table line every N steps")->check(CLI::PositiveNumber)->capture_default_str();
  app.add_flag("--json", s.json, "print one JSON object instead of the table");
  if (const auto rc = meshmotion::examples::parse_command_line(app, argc, argv)) return *rc;
  return meshmotion::examples::guarded(s.json, [&] { return run(s); });
}
