// The Delaunay-graph movers of the compiled library (target meshmotion::compiled) for 2D and 3D,
// behind the extern template declarations consumers see. Each mover is instantiated in one object
// file of the library alone. Both dimensions are instantiated in one translation unit: they share
// the headers' parsing and every function that does not depend on the dimension, which two objects
// compiled again (docs/compiled.md).

#include "meshmotion/movers/dgm.hpp"
#include "meshmotion/movers/improved_dgm.hpp"
#include "meshmotion/movers/dgrbf.hpp"
#include "meshmotion/movers/dgrbf2.hpp"

namespace meshmotion {

template class DgmMover<2>;
template void DgmMover<2>::setup<Mesh<2>>(const Mesh<2>&, const ResolvedBoundary<2>&);
template class ImprovedDgmMover<2>;
template void ImprovedDgmMover<2>::setup<Mesh<2>>(const Mesh<2>&, const ResolvedBoundary<2>&);
template class DgrbfMover<2>;
template void DgrbfMover<2>::setup<Mesh<2>>(const Mesh<2>&, const ResolvedBoundary<2>&);
template class Dgrbf2Mover<2>;
template void Dgrbf2Mover<2>::setup<Mesh<2>>(const Mesh<2>&, const ResolvedBoundary<2>&);

template class DgmMover<3>;
template void DgmMover<3>::setup<Mesh<3>>(const Mesh<3>&, const ResolvedBoundary<3>&);
template class ImprovedDgmMover<3>;
template void ImprovedDgmMover<3>::setup<Mesh<3>>(const Mesh<3>&, const ResolvedBoundary<3>&);
template class DgrbfMover<3>;
template void DgrbfMover<3>::setup<Mesh<3>>(const Mesh<3>&, const ResolvedBoundary<3>&);
template class Dgrbf2Mover<3>;
template void Dgrbf2Mover<3>::setup<Mesh<3>>(const Mesh<3>&, const ResolvedBoundary<3>&);

}  // namespace meshmotion
