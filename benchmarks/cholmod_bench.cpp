// cholmod_bench: CHOLMOD's supernodal Cholesky against Eigen's SimplicialLDLT on the systems
// the movers factorize, in the same process, alternating (simplicial, supernodal) rounds and
// reporting medians: the RBF setup of rbf_bench's 3D box (bottom face moving as a bump,
// support radius 6 spacings), the RBF setup of the 3D bump's fine level (thesis table 4.3's
// mesh, its bump moving, the top, inflow and outflow held), and the stiffened elasticity setup (χ = 2.75) of the
// 30P30N RANS mesh (../shared/data; skipped when absent). Both solve the same system; the
// moves' results are compared (relative difference, rounding only).
//
// Then the stiffened 3D elasticity of a time loop: a hexahedral box graded towards its moving
// bottom (32³ cells, 89k unknowns, quick; 43³, 222k, full), set up once at rest and moved 20
// times, by the defaults (CG on the nodes' factorization, docs/mechanics.md) and by the coupled
// factorization (coupled_cg_min_rows = 0, the solve before), for a bottom turning about one
// axis (two fields, sin θ and 1 − cos θ) and for a bump travelling along it. Setup and moves'
// seconds, iterations, and the largest difference of the last move relative to its largest
// displacement; ratio = defaults' total / the factorization's.
//
//   cholmod_bench [box_cells_per_axis=126] [rounds=3]
//
// A table and one JSON line per case. Without CHOLMOD in the build it says so and exits 0.

#include "bench_memory.hpp"
#include "box_bump.hpp"
#include "meshmotion/core/generators.hpp"
#include "meshmotion/io.hpp"
#include "meshmotion/movers.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

using namespace meshmotion;

namespace {

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// Setup seconds (medians over rounds) of `make(options)`'s mover with and without CHOLMOD, and
// the relative difference of their moves.
template <int Dim, class Make>
void compare(const std::string& name, const Mesh<Dim>& mesh, const ResolvedBoundary<Dim>& boundary, int rounds, Make&& make) {
  std::vector<double> simplicial, supernodal;
  Points<Dim> u_simplicial, u_supernodal;
  Index rows = 0;
  for (int r = 0; r < rounds; ++r)
    for (const bool use : {false, true}) {
      SolverOptions solver;
      solver.supernodal_min_rows = use ? 1 : 0;
      auto mover = make(solver);
      mover.setup(mesh, boundary);
      (use ? supernodal : simplicial).push_back(mover.stats().setup_seconds);
      (use ? u_supernodal : u_simplicial) = mover.move(boundary.displacements);
      rows = mover.stats().boundary_nodes;
    }
  const double s = median(simplicial), c = median(supernodal);
  const double difference = (u_supernodal - u_simplicial).norm() / std::max(1e-300, u_simplicial.norm());
  std::printf("%-24s %10ld %10ld %12.3f %12.3f %8.2f %12.2e\n", name.c_str(), static_cast<long>(mesh.num_nodes()),
              static_cast<long>(rows), s, c, c / s, difference);
  std::printf("{\"case\":\"%s\",\"nodes\":%ld,\"boundary_nodes\":%ld,\"simplicial_setup_seconds\":%.6f,"
              "\"supernodal_setup_seconds\":%.6f,\"ratio\":%.3f,\"relative_difference\":%.3e,\"rounds\":%d}\n",
              name.c_str(), static_cast<long>(mesh.num_nodes()), static_cast<long>(rows), s, c, c / s, difference, rounds);
  std::fflush(stdout);
}

// The box graded towards its bottom (z → z³: cells 1:300 in height at 32³).
Mesh<3> graded_box(int cells) {
  Mesh<3> mesh = bench::box(cells);
  for (Index v = 0; v < mesh.num_nodes(); ++v) mesh.points(2, v) = std::pow(mesh.points(2, v), 3.0);
  return mesh;
}

// Displacements of `boundary` at step s of 20 for the turning (travelling = false) or the
// travelling bottom; every other node held.
Points<3> time_loop_motion(const Mesh<3>& mesh, const ResolvedBoundary<3>& boundary, int s, bool travelling) {
  Points<3> d = Points<3>::Zero(3, boundary.size());
  const double t = s / 20.0;
  for (Index k = 0; k < boundary.size(); ++k) {
    if (boundary.kinds[static_cast<std::size_t>(k)] != BoundaryKind::prescribed) continue;
    const Vec<3> x = mesh.points.col(boundary.nodes[static_cast<std::size_t>(k)]);
    const double across = std::sin(M_PI * x(1));
    if (travelling) {
      d(2, k) = 0.05 * std::exp(-std::pow((x(0) - 0.3 - 0.4 * t) / 0.1, 2)) * across;
    } else {
      const double bump = std::sin(M_PI * x(0)) * across, angle = 0.8 * t;
      d(0, k) = 0.05 * std::sin(angle) * bump;
      d(2, k) = 0.1 * (1.0 - std::cos(angle)) * bump;
    }
  }
  return d;
}

void elasticity_time_loop(int cells) {
  const Mesh<3> mesh = graded_box(cells);
  BoundarySpec<3> spec;
  spec.moving("bottom", Translation<3>{Vec<3>::Zero()});
  for (const char* held : {"top", "left", "right", "front", "back"}) spec.fixed(held);
  const ResolvedBoundary<3> rest = spec.resolve(mesh);
  std::printf("\n%-28s %10s %9s %9s %9s %10s %8s %12s\n", "sle time loop (20 moves)", "unknowns", "setup_s", "moves_s",
              "total_s", "iterations", "ratio", "difference");
  for (const bool travelling : {false, true}) {
    double direct_total = 0.0;
    Points<3> direct_last;
    for (const bool defaults : {false, true}) {
      ElasticityOptions o;
      o.stiffening_exponent = 2.75;
      if (!defaults) o.solver.coupled_cg_min_rows = 0;
      ElasticityMover<3> mover(o);
      mover.setup(mesh, rest);
      const double setup = mover.stats().setup_seconds;
      const auto start = std::chrono::steady_clock::now();
      Index iterations = 0;
      Points<3> last;
      for (int s = 1; s <= 20; ++s) {
        last = mover.move(time_loop_motion(mesh, rest, s, travelling));
        iterations += mover.stats().iterations;
      }
      const double moves = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      const std::string name = std::string(travelling ? "travelling bump" : "turning wall") + (defaults ? ", defaults" : ", factorized");
      const double total = setup + moves;
      if (!defaults) {
        direct_total = total;
        direct_last = last;
      }
      const double difference = (last - direct_last).cwiseAbs().maxCoeff() / direct_last.cwiseAbs().maxCoeff();
      const double ratio = total / direct_total;
      std::printf("%-28s %10ld %9.2f %9.2f %9.2f %10ld %8.2f %12.2e\n", name.c_str(), static_cast<long>(mover.stats().evaluated_nodes * 3),
                  setup, moves, total, static_cast<long>(iterations), ratio, difference);
      std::printf("{\"case\":\"sle time loop\",\"motion\":\"%s\",\"solver\":\"%s\",\"cells\":%d,\"setup_seconds\":%.4f,"
                  "\"moves_seconds\":%.4f,\"total_seconds\":%.4f,\"iterations\":%ld,\"ratio\":%.3f,\"relative_difference\":%.3e,"
                  "\"factorizations\":%ld}\n",
                  travelling ? "travelling bump" : "turning wall", defaults ? "defaults" : "coupled factorization", cells * cells * cells,
                  setup, moves, total, static_cast<long>(iterations), ratio, difference, static_cast<long>(mover.stats().factorizations));
      std::fflush(stdout);
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  bench::tune_memory(argc, argv);
  if (!have_cholmod()) {
    std::printf("cholmod_bench: this build has no CHOLMOD (libsuitesparse-dev): nothing to compare\n");
    return 0;
  }
  const int n = argc > 1 ? std::atoi(argv[1]) : 126;
  const int rounds = argc > 2 ? std::atoi(argv[2]) : 3;
  std::printf("%-24s %10s %10s %12s %12s %8s %12s\n", "case", "nodes", "centres", "simplicial_s", "supernodal_s", "ratio",
              "difference");
  {
    const Mesh<3> mesh = bench::box(n);
    compare("box rbf setup", mesh, bench::bottom_bump(mesh), rounds, [&](const SolverOptions& solver) {
      RbfOptions o;
      o.support_radius = 6.0 / n;
      o.solver = solver;
      return RbfMover<3>(o);
    });
  }
  {
    const Mesh<3> mesh = bump_channel_3d(2);
    // The side walls' boundary-layer nodes (2.5e-5 apart) under a 0.25 support would make the
    // system singular to working precision: the far boundaries hold the motion instead.
    BoundarySpec<3> spec;
    spec.moving("bump", Translation<3>{{0.0, 0.0, 0.01}}).fixed("top").fixed("inflow").fixed("outflow");
    compare("bump fine rbf setup", mesh, spec.resolve(mesh), rounds, [&](const SolverOptions& solver) {
      RbfOptions o;
      o.support_radius = 0.25;
      o.solver = solver;
      return RbfMover<3>(o);
    });
  }
  const std::filesystem::path file = std::filesystem::path(MESHMOTION_SHARED_DATA_DIR) / "su2_30p30n_rans_L1_coarse.su2";
  if (!std::filesystem::exists(file)) {
    std::printf("cholmod_bench: %s not found, 30P30N case skipped\n", file.string().c_str());
    elasticity_time_loop(n <= 64 ? 32 : 43);
    return 0;
  }
  const Mesh<2> mesh = std::get<Mesh<2>>(read_mesh(file.string()));
  BoundarySpec<2> spec;
  spec.moving("wall", Rotation2D{{0.25, 0.0}, radians(2.0)}).fixed("farfield");
  compare("30p30n sle setup", mesh, spec.resolve(mesh), rounds, [&](const SolverOptions& solver) {
    ElasticityOptions o;
    o.stiffening_exponent = 2.75;
    o.solver = solver;
    return ElasticityMover<2>(o);
  });
  elasticity_time_loop(n <= 64 ? 32 : 43);
  return 0;
}
