// Moves a mesh with the distributed RBF mover on one rank, as a solver linking
// meshmotion::parallel would: proof that the component's MPI, PETSc and METIS come along.
#include <meshmotion/core/generators.hpp>
#include <meshmotion/parallel.hpp>

#include <petscsys.h>

#include <iostream>

int main(int argc, char** argv) {
  if (PetscInitialize(&argc, &argv, nullptr, nullptr) != 0) return 1;
  int code = 1;
  {
    namespace mp = meshmotion::parallel;
    const meshmotion::Mesh<2> mesh = meshmotion::rectangle_mesh({.nx = 4, .ny = 3});
    meshmotion::BoundarySpec<2> spec;
    spec.moving("bottom", meshmotion::Translation<2>{{0.0, 0.05}}).fixed("top");
    const mp::DistributedMesh<2> part = mp::partition_mesh(MPI_COMM_WORLD, mesh);
    const meshmotion::ResolvedBoundary<2> boundary = mp::distribute_boundary(part, spec.resolve(mesh));
    mp::DistributedRbfMover<2> mover({.support_radius = 2.0});
    mover.setup(part.view(), boundary);
    const meshmotion::Points<2> u = mover.move(boundary.displacements);
    std::cout << "consumer_parallel: " << u.cols() << " nodes moved\n";
    code = u.cols() == 20 ? 0 : 1;
  }
  PetscFinalize();
  return code;
}
