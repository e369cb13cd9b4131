// cholmod_bench: CHOLMOD's supernodal Cholesky against Eigen's SimplicialLDLT on the systems
// the movers factorize, in the same process, alternating (simplicial, supernodal) rounds and
// reporting medians: the RBF setup of rbf_bench's 3D box (bottom face moving as a bump,
// support radius 6 spacings), the RBF setup of the 3D bump's fine level (thesis table 4.3's
// mesh, its bump moving, the top, inflow and outflow held), and the stiffened elasticity setup (χ = 2.75) of the
// 30P30N RANS mesh (../shared/data; skipped when absent). Both solve the same system; the
// moves' results are compared (relative difference, rounding only).
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
  return 0;
}
