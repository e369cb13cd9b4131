// The C++ side of benchmarks/python_overhead.py's MPI rows, run under mpiexec: the job of
// python_overhead_peer on the parallel layer. Rank 0 reads the box and resolves "bottom"
// (a sine bump in z) and "top" (fixed); METIS splits it; the distributed RBF mover is set up
// once, then MOVES moves into one array and MOVES reverse derivatives of a seed of ones.
//
//   mpiexec -n R python_mpi_overhead_peer mesh.msh RADIUS MOVES
//
// Rank 0 prints one JSON line: the slowest rank's setup and per-operation medians and means,
// and checksums over the owned nodes (the Python side checks it did the same work).

#include "meshmotion/io/mesh_io.hpp"
#include "meshmotion/movers/boundary.hpp"
#include "meshmotion/parallel.hpp"
#include "meshmotion/solvers/detail/stopwatch.hpp"

#include <petscsys.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <numbers>
#include <numeric>
#include <string>
#include <vector>

using namespace meshmotion;
using namespace meshmotion::parallel;

namespace {

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

double mean(const std::vector<double>& v) { return std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size()); }

double slowest(MPI_Comm comm, double seconds) {
  MPI_Allreduce(MPI_IN_PLACE, &seconds, 1, MPI_DOUBLE, MPI_MAX, comm);
  return seconds;
}

double owned_abs_sum(MPI_Comm comm, const DistributedMesh<3>& part, const Points<3>& field) {
  double sum = 0.0;
  for (Index i = 0; i < part.num_owned; ++i) sum += field.col(i).cwiseAbs().sum();
  MPI_Allreduce(MPI_IN_PLACE, &sum, 1, MPI_DOUBLE, MPI_SUM, comm);
  return sum;
}

int run(const std::string& file, double radius, int moves) {
  const MPI_Comm comm = MPI_COMM_WORLD;
  const bool root = rank_of(comm) == 0;
  Mesh<3> whole;
  ResolvedBoundary<3> boundary;
  if (root) {
    whole = std::get<Mesh<3>>(read_mesh(file));
    BoundarySpec<3> spec;
    spec.prescribed("bottom").fixed("top");
    boundary = spec.resolve(whole);
    for (const Index v : whole.group_nodes("bottom")) {
      const meshmotion::Vec<3> x = whole.points.col(v);
      boundary.displacements(2, boundary.column(v)) =
          0.01 * std::sin(std::numbers::pi * x(0)) * std::sin(std::numbers::pi * x(1));
    }
  }
  const DistributedMesh<3> part = partition_mesh(comm, whole);
  const ResolvedBoundary<3> local = distribute_boundary(part, boundary);
  MPI_Barrier(comm);
  const meshmotion::detail::Stopwatch setup_watch;
  RbfOptions options;
  options.support_radius = radius;
  DistributedRbfMover<3> mover(options);
  mover.setup(part.view(), part.local, local);  // with the cells, as Python's DistributedMover3.setup(part, ...)
  const double setup = slowest(comm, setup_watch.seconds());

  Points<3> out;
  std::vector<double> move_seconds, reverse_seconds;
  for (int k = 0; k < moves; ++k) {
    const meshmotion::detail::Stopwatch watch;
    mover.move_into(local.displacements, out);
    move_seconds.push_back(slowest(comm, watch.seconds()));
  }
  const Points<3> seed = Points<3>::Ones(3, part.view().size());
  Points<3> gradient;
  for (int k = 0; k < moves; ++k) {
    const meshmotion::detail::Stopwatch watch;
    gradient = mover.derivative_reverse(seed);
    reverse_seconds.push_back(slowest(comm, watch.seconds()));
  }
  const double move_sum = owned_abs_sum(comm, part, out);
  double reverse_sum = gradient.cwiseAbs().sum();  // ghost and sliding entries are zero
  MPI_Allreduce(MPI_IN_PLACE, &reverse_sum, 1, MPI_DOUBLE, MPI_SUM, comm);
  if (root)
    std::printf("{\"side\": \"c++\", \"ranks\": %d, \"nodes\": %lld, \"setup_s\": %.6g, \"move_median_s\": %.6g, "
                "\"move_mean_s\": %.6g, \"reverse_median_s\": %.6g, \"reverse_mean_s\": %.6g, \"move_checksum\": %.17g, "
                "\"reverse_checksum\": %.17g}\n",
                size_of(comm), static_cast<long long>(part.num_global_nodes), setup, median(move_seconds),
                mean(move_seconds), median(reverse_seconds), mean(reverse_seconds), move_sum, reverse_sum);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  int code = 2;
  try {
    // PETSc only where the boundary solve chooses it; started like the Python side does.
    if (PetscInitializeNoArguments() != 0) throw std::runtime_error("PetscInitializeNoArguments failed");
    if (argc == 4) {
      code = run(argv[1], std::stod(argv[2]), std::stoi(argv[3]));
    } else if (rank_of(MPI_COMM_WORLD) == 0) {
      std::fprintf(stderr, "usage: mpiexec -n R python_mpi_overhead_peer mesh.msh RADIUS MOVES\n");
    }
    PetscFinalize();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "python_mpi_overhead_peer: %s\n", e.what());
    code = 1;
  }
  MPI_Finalize();
  return code;
}
