// The RBF mover of the compiled library (target meshmotion::compiled) for 2D and 3D, behind the
// extern template declarations consumers see. Each mover is instantiated in one object file of the
// library alone. Both dimensions are instantiated in one translation unit: they share the headers'
// parsing and every function that does not depend on the dimension, which two objects compiled
// again (docs/compiled.md).

#include "meshmotion/movers/rbf.hpp"

namespace meshmotion {

template class detail::RbfSystem<2>;
template class RbfMover<2>;
template void RbfMover<2>::setup<Mesh<2>>(const Mesh<2>&, const ResolvedBoundary<2>&);
template DefaultSupportRadius default_support_radius<2>(const Points<2>&, const ResolvedBoundary<2>&, const RbfOptions&);

template class detail::RbfSystem<3>;
template class RbfMover<3>;
template void RbfMover<3>::setup<Mesh<3>>(const Mesh<3>&, const ResolvedBoundary<3>&);
template DefaultSupportRadius default_support_radius<3>(const Points<3>&, const ResolvedBoundary<3>&, const RbfOptions&);

}  // namespace meshmotion
