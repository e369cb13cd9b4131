// The parallel layer of the compiled library (target meshmotion::parallel) for one dimension,
// MESHMOTION_INSTANTIATE_DIM (CMake compiles this file once for 2 and once for 3): the
// distributed movers, the partitioning and the distributed registry's table
// (parallel/registered_movers.hpp), behind the extern template declarations consumers see.

#include "meshmotion/parallel/partition.hpp"
#include "meshmotion/parallel/registered_movers.hpp"

namespace meshmotion::parallel {

constexpr int D = MESHMOTION_INSTANTIATE_DIM;

template class DistributedRbfMover<D>;
template class DistributedElasticityMover<D>;
template DistributedMesh<D> partition_mesh<D>(MPI_Comm, const Mesh<D>&, std::span<const int>, int);
template std::span<const DistributedMethod<D>> distributed_methods<D>();

}  // namespace meshmotion::parallel
