// The Delaunay-graph movers of the compiled library (target meshmotion::compiled) for one dimension,
// MESHMOTION_INSTANTIATE_DIM (CMake compiles this file once for 2 and once for 3), behind the
// extern template declarations consumers see. Each mover is instantiated in one object file
// of the library alone: src/movers_*.cpp and src/registry.cpp share them out so that the two
// cores of a build compile them side by side.

#include "meshmotion/movers/dgm.hpp"
#include "meshmotion/movers/improved_dgm.hpp"
#include "meshmotion/movers/dgrbf.hpp"
#include "meshmotion/movers/dgrbf2.hpp"

namespace meshmotion {

constexpr int D = MESHMOTION_INSTANTIATE_DIM;

template class DgmMover<D>;
template void DgmMover<D>::setup<Mesh<D>>(const Mesh<D>&, const ResolvedBoundary<D>&);
template class ImprovedDgmMover<D>;
template void ImprovedDgmMover<D>::setup<Mesh<D>>(const Mesh<D>&, const ResolvedBoundary<D>&);
template class DgrbfMover<D>;
template void DgrbfMover<D>::setup<Mesh<D>>(const Mesh<D>&, const ResolvedBoundary<D>&);
template class Dgrbf2Mover<D>;
template void Dgrbf2Mover<D>::setup<Mesh<D>>(const Mesh<D>&, const ResolvedBoundary<D>&);

}  // namespace meshmotion
