// The spring and elasticity movers of the compiled library (target meshmotion::compiled) for one dimension,
// MESHMOTION_INSTANTIATE_DIM (CMake compiles this file once for 2 and once for 3), behind the
// extern template declarations consumers see. Each mover is instantiated in one object file
// of the library alone: src/movers_*.cpp and src/registry.cpp share them out so that the two
// cores of a build compile them side by side.

#include "meshmotion/movers/spring.hpp"
#include "meshmotion/movers/torsion_spring.hpp"
#include "meshmotion/movers/elasticity.hpp"
#include "meshmotion/movers/nonlinear_elasticity.hpp"

namespace meshmotion {

constexpr int D = MESHMOTION_INSTANTIATE_DIM;

template class detail::LinearMechanicsMover<D>;
template class SpringMover<D>;
template void SpringMover<D>::setup<Mesh<D>>(const Mesh<D>&, const ResolvedBoundary<D>&);
template class TorsionSpringMover<D>;
template void TorsionSpringMover<D>::setup<Mesh<D>>(const Mesh<D>&, const ResolvedBoundary<D>&);
template class ElasticityMover<D>;
template void ElasticityMover<D>::setup<Mesh<D>>(const Mesh<D>&, const ResolvedBoundary<D>&);
template class NonlinearElasticityMover<D>;
template void NonlinearElasticityMover<D>::setup<Mesh<D>>(const Mesh<D>&, const ResolvedBoundary<D>&);

}  // namespace meshmotion
