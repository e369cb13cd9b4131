// The spring and elasticity movers of the compiled library (target meshmotion::compiled) for 2D and
// 3D, behind the extern template declarations consumers see. Each mover is instantiated in one
// object file of the library alone. Both dimensions are instantiated in one translation unit: they
// share the headers' parsing and every function that does not depend on the dimension, which two
// objects compiled again (docs/compiled.md).

#include "meshmotion/movers/spring.hpp"
#include "meshmotion/movers/torsion_spring.hpp"
#include "meshmotion/movers/elasticity.hpp"
#include "meshmotion/movers/nonlinear_elasticity.hpp"

namespace meshmotion {

template class detail::LinearMechanicsMover<2>;
template class SpringMover<2>;
template void SpringMover<2>::setup<Mesh<2>>(const Mesh<2>&, const ResolvedBoundary<2>&);
template class TorsionSpringMover<2>;
template void TorsionSpringMover<2>::setup<Mesh<2>>(const Mesh<2>&, const ResolvedBoundary<2>&);
template class ElasticityMover<2>;
template void ElasticityMover<2>::setup<Mesh<2>>(const Mesh<2>&, const ResolvedBoundary<2>&);
template class NonlinearElasticityMover<2>;
template void NonlinearElasticityMover<2>::setup<Mesh<2>>(const Mesh<2>&, const ResolvedBoundary<2>&);

template class detail::LinearMechanicsMover<3>;
template class SpringMover<3>;
template void SpringMover<3>::setup<Mesh<3>>(const Mesh<3>&, const ResolvedBoundary<3>&);
template class TorsionSpringMover<3>;
template void TorsionSpringMover<3>::setup<Mesh<3>>(const Mesh<3>&, const ResolvedBoundary<3>&);
template class ElasticityMover<3>;
template void ElasticityMover<3>::setup<Mesh<3>>(const Mesh<3>&, const ResolvedBoundary<3>&);
template class NonlinearElasticityMover<3>;
template void NonlinearElasticityMover<3>::setup<Mesh<3>>(const Mesh<3>&, const ResolvedBoundary<3>&);

}  // namespace meshmotion
