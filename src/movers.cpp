// The movers of the compiled library (target meshmotion::compiled) for one dimension,
// MESHMOTION_INSTANTIATE_DIM (CMake compiles this file once for 2 and once for 3): the
// definitions behind the extern template declarations consumers see.

#include "meshmotion/movers/mover_options.hpp"
#include "meshmotion/movers/elasticity.hpp"
#include "meshmotion/movers/rbf.hpp"

namespace meshmotion {

constexpr int D = MESHMOTION_INSTANTIATE_DIM;

template class RbfMover<D>;
template class ElasticityMover<D>;
template class detail::LinearMechanicsMover<D>;
template AnyMover<D> make_mover<D>(const MoverConfig<D>&);

}  // namespace meshmotion
