// mpi_bench: the distributed movers against the serial ones in the same run.
//
//   mpiexec -n R mpi_bench [box_cells_per_axis=126] [automatic|replicated|petsc|patches] [path/to/su2_30p30n_rans_L1_coarse.su2]
//
// The second argument is where the distributed RBF solves its boundary system (BoundarySolve;
// automatic: PETSc from 50000 centres on).
// Cases: the 3D hex box of rbf_bench (bottom face moving as a bump, support radius 6 grid
// spacings; 126 cells per axis = 2.05M nodes) with the RBF mover, the same box with the
// partition-of-unity RBF (patches of at most 1000 centres, so that the quick box's 4225 make
// several; distributed: BoundarySolve::patches under automatic, each patch on one rank), and the 30P30N RANS mesh
// (../shared/data, skipped when absent) with the RBF mover (wall rotated 2°) and the
// stiffened elasticity mover (χ = 2.75; serial: direct Cholesky, distributed in 2D: MUMPS), and
// the stiffened elasticity mover on a box a third as fine (distributed in 3D: CG + GAMG).
// The serial mover runs first on rank 0 with every core's threads while the other ranks
// sleep; then every rank runs the distributed mover with its share of the node's cores
// (node_share_of_cores, what move_mesh_mpi sets). The moves are the first steps of a time loop
// (the motion times sin(2π k / 20), k = 1, 2, 3), so a
// mover that starts each solve from the last steps gets what it would in a solver. Setup and
// move are the slowest rank's; memory is the heap each rank's mover keeps after setup (largest, and
// rank 0's);
// more ranks than cores is flagged "oversubscribed". A table and one JSON line per case.

#include "../box_bump.hpp"
#include "meshmotion/core/generators.hpp"
#include "meshmotion/io.hpp"
#include "meshmotion/movers.hpp"
#include "meshmotion/parallel.hpp"
#include "meshmotion/solvers/detail/stopwatch.hpp"

#include <malloc.h>
#include <petscsys.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <filesystem>
#include <string>
#include <thread>

using namespace meshmotion;
using namespace meshmotion::parallel;

namespace {

// Heap in use now (glibc's count of live allocations), in MB: what a mover keeps after setup
// is the growth across it, unaffected by pages an earlier case freed.
double heap_mb() {
  const struct mallinfo2 m = mallinfo2();
  return static_cast<double>(m.uordblks + m.hblkhd) / (1024.0 * 1024.0);
}

// Waits for the other ranks without spinning a core (the serial run must have them all).
void sleeping_barrier(MPI_Comm comm) {
  MPI_Request request = MPI_REQUEST_NULL;
  MPI_Ibarrier(comm, &request);
  int done = 0;
  while (true) {
    MPI_Test(&request, &done, MPI_STATUS_IGNORE);
    if (done != 0) return;
    usleep(2000);
  }
}

struct Figures {
  double setup = 0.0, move = 0.0, memory = 0.0;
};

template <class Mover, class Setup>
Figures measure(Mover& mover, Setup&& setup, const Points<Mover::dim>& d, int moves) {
  Figures f;
  const double before = heap_mb();
  setup();
  f.setup = mover.stats().setup_seconds;
  f.memory = heap_mb() - before;
  Points<Mover::dim> u;
  const meshmotion::detail::Stopwatch watch;
  for (int k = 1; k <= moves; ++k) mover.move_into(std::sin(2.0 * std::numbers::pi * k / 20.0) * d, u);
  f.move = watch.seconds() / moves;
  return f;
}

enum class Method { rbf, pu, sle };

BoundarySolveOptions boundary_solve;

template <int Dim>
void run_case(const std::string& name, const Mesh<Dim>& whole, const ResolvedBoundary<Dim>& boundary, Method method,
              double radius) {
  const MPI_Comm comm = MPI_COMM_WORLD;
  const int rank = rank_of(comm), ranks = size_of(comm);
  const int cores = static_cast<int>(std::thread::hardware_concurrency());
  const int moves = 3;
  RbfOptions rbf;
  rbf.support_radius = radius;
  rbf.partition_of_unity = method == Method::pu;
  rbf.patch_centres = 1000;
  ElasticityOptions elasticity;
  elasticity.stiffening_exponent = 2.75;

  // Serial, on rank 0 with every core.
  Figures serial;
  if (rank == 0) {
    set_num_threads(cores);
    if (method != Method::sle) {
      RbfMover<Dim> mover(rbf);
      serial = measure(mover, [&] { mover.setup(whole, boundary); }, boundary.displacements, moves);
    } else {
      ElasticityMover<Dim> mover(elasticity);
      serial = measure(mover, [&] { mover.setup(whole, boundary); }, boundary.displacements, moves);
    }
  }
  sleeping_barrier(comm);

  set_num_threads(node_share_of_cores(comm));
  const DistributedMesh<Dim> part = partition_mesh(comm, whole);
  const ResolvedBoundary<Dim> local = distribute_boundary(part, boundary);
  Figures mine;
  BoundarySolve solved = BoundarySolve::petsc;
  if (method != Method::sle) {
    DistributedRbfMover<Dim> mover(rbf, boundary_solve);
    mine = measure(mover, [&] { mover.setup(part.view(), local); }, local.displacements, moves);
    solved = mover.solved_by();
  } else {
    DistributedElasticityOptions options;
    options.elasticity = elasticity;
    DistributedElasticityMover<Dim> mover(options);
    mine = measure(mover, [&] { mover.setup(part, local); }, local.displacements, moves);
  }
  // Moves are timed per rank; the slowest rank sets the pace.
  double worst[3] = {mine.setup, mine.move, mine.memory};
  MPI_Allreduce(MPI_IN_PLACE, worst, 3, MPI_DOUBLE, MPI_MAX, comm);
  if (rank != 0) return;
  const bool oversubscribed = ranks > cores;
  const double setup_ratio = worst[0] / serial.setup, move_ratio = worst[1] / serial.move;
  const char* label = method == Method::sle                 ? "sle"
                      : solved == BoundarySolve::petsc      ? "rbf/petsc"
                      : solved == BoundarySolve::patches    ? "rbf/patches"
                                                            : "rbf/repl";
  std::printf("%-16s %10s %5d %10ld %10.3f %10.3f %10.4f %10.4f %8.2f %8.2f %10.0f %10.0f %s\n", name.c_str(),
              label, ranks, static_cast<long>(whole.num_nodes()), serial.setup, worst[0],
              serial.move, worst[1], setup_ratio, move_ratio, serial.memory, worst[2], oversubscribed ? "oversubscribed" : "");
  std::printf("{\"case\":\"%s\",\"method\":\"%s\",\"boundary_solve\":\"%s\",\"ranks\":%d,\"cores\":%d,\"oversubscribed\":%s,\"nodes\":%ld,"
              "\"boundary_nodes\":%ld,\"serial_setup_seconds\":%.6f,\"setup_seconds\":%.6f,\"serial_move_seconds\":%.6f,"
              "\"move_seconds\":%.6f,\"setup_ratio\":%.3f,\"move_ratio\":%.3f,\"serial_setup_memory_mb\":%.1f,"
              "\"setup_memory_mb_per_rank_max\":%.1f,\"rank0_setup_memory_mb\":%.1f,\"threads_per_rank\":%d}\n",
              name.c_str(), method == Method::sle ? "sle" : "rbf", meshmotion::parallel::name(solved), ranks, cores, oversubscribed ? "true" : "false",
              static_cast<long>(whole.num_nodes()), static_cast<long>(boundary.size()), serial.setup, worst[0], serial.move,
              worst[1], setup_ratio, move_ratio, serial.memory, worst[2], mine.memory, num_threads());
  std::fflush(stdout);
}

void box(int n) {
  const bool root = rank_of(MPI_COMM_WORLD) == 0;
  Mesh<3> mesh;
  ResolvedBoundary<3> boundary;
  // Every rank builds the box (the serial peer needs it on rank 0 only, partition_mesh reads
  // it there): generating it is not part of either figure.
  if (root) {
    mesh = bench::box(n);
    boundary = bench::bottom_bump(mesh);
  }
  run_case("box" + std::to_string(n), mesh, boundary, Method::rbf, 6.0 / n);
  run_case("pu-box" + std::to_string(n), mesh, boundary, Method::pu, 6.0 / n);
  // Elasticity in 3D (distributed: CG + GAMG) on a box a third as fine, which the serial
  // mover's direct Cholesky still factorizes in seconds.
  const int coarse = std::max(n / 3, 8);
  if (root) {
    mesh = bench::box(coarse);
    boundary = bench::bottom_bump(mesh);
  }
  run_case("box" + std::to_string(coarse), mesh, boundary, Method::sle, 0.0);
}

void airfoil(const std::filesystem::path& file) {
  const bool root = rank_of(MPI_COMM_WORLD) == 0;
  int found = std::filesystem::exists(file) ? 1 : 0;
  MPI_Bcast(&found, 1, MPI_INT, 0, MPI_COMM_WORLD);
  if (found == 0) {
    if (root) std::printf("mpi_bench: %s not found, 30P30N cases skipped\n", file.string().c_str());
    return;
  }
  Mesh<2> mesh;
  ResolvedBoundary<2> boundary;
  double radius = 0.0;
  if (root) {
    mesh = std::get<Mesh<2>>(read_mesh(file.string()));
    BoundarySpec<2> spec;
    spec.moving("wall", Rotation2D{{0.25, 0.0}, radians(2.0)}).fixed("farfield");
    boundary = spec.resolve(mesh);
    Points<2> at(2, boundary.size());
    for (Index k = 0; k < boundary.size(); ++k) at.col(k) = mesh.points.col(boundary.nodes[static_cast<std::size_t>(k)]);
    radius = suggest_support_radius(at, boundary.displacements);
  }
  MPI_Bcast(&radius, 1, MPI_DOUBLE, 0, MPI_COMM_WORLD);
  run_case("30p30n", mesh, boundary, Method::rbf, radius);
  run_case("30p30n", mesh, boundary, Method::sle, 0.0);
}

}  // namespace

int main(int argc, char** argv) {
  int petsc_argc = 1;
  if (PetscInitialize(&petsc_argc, &argv, nullptr, nullptr) != 0) return 1;
  const int n = argc > 1 ? std::atoi(argv[1]) : 126;
  const std::string solve = argc > 2 ? argv[2] : "automatic";
  try {
    (void)set_option(boundary_solve, "boundary_solve", solve);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "mpi_bench: %s\n", e.what());
    PetscFinalize();
    return 2;
  }
  const std::filesystem::path airfoil_file =
      argc > 3 ? std::filesystem::path(argv[3]) : std::filesystem::path(MESHMOTION_SHARED_DATA_DIR) / "su2_30p30n_rans_L1_coarse.su2";
  if (rank_of(MPI_COMM_WORLD) == 0)
    std::printf("%-16s %10s %5s %10s %10s %10s %10s %10s %8s %8s %10s %10s\n", "case", "method", "ranks", "nodes",
                "ser_setup", "setup_s", "ser_move", "move_s", "setup_x", "move_x", "ser_MB", "MB/rank");
  int code = 0;
  try {
    box(n);
    airfoil(airfoil_file);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "mpi_bench: %s\n", e.what());
    code = 1;
  }
  PetscFinalize();
  return code;
}
