// The parallel layer of the compiled library (target meshmotion::parallel) for 2D and 3D: the
// distributed movers, the partitioning and the distributed registry's table
// (parallel/registered_movers.hpp), behind the extern template declarations consumers see.

#include "meshmotion/parallel/partition.hpp"
#include "meshmotion/parallel/registered_movers.hpp"

namespace meshmotion::parallel {

template class DistributedRbfMover<2>;
template class DistributedElasticityMover<2>;
template DistributedMesh<2> partition_mesh<2>(MPI_Comm, const Mesh<2>&, std::span<const int>, int);
template std::span<const DistributedMethod<2>> distributed_methods<2>();

template class DistributedRbfMover<3>;
template class DistributedElasticityMover<3>;
template DistributedMesh<3> partition_mesh<3>(MPI_Comm, const Mesh<3>&, std::span<const int>, int);
template std::span<const DistributedMethod<3>> distributed_methods<3>();

}  // namespace meshmotion::parallel
