// The RBF mover of the compiled library (target meshmotion::compiled) for one dimension,
// MESHMOTION_INSTANTIATE_DIM (CMake compiles this file once for 2 and once for 3), behind the
// extern template declarations consumers see. Each mover is instantiated in one object file
// of the library alone: src/movers_*.cpp and src/registry.cpp share them out so that the two
// cores of a build compile them side by side.

#include "meshmotion/movers/rbf.hpp"

namespace meshmotion {

constexpr int D = MESHMOTION_INSTANTIATE_DIM;

template class detail::RbfSystem<D>;
template class RbfMover<D>;
template void RbfMover<D>::setup<Mesh<D>>(const Mesh<D>&, const ResolvedBoundary<D>&);
template DefaultSupportRadius default_support_radius<D>(const Points<D>&, const ResolvedBoundary<D>&, const RbfOptions&);

}  // namespace meshmotion
