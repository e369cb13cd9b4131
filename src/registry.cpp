// The registry of serial movers (method -> factory, movers/registered_movers.hpp) and the blending
// and boundary-only movers of the compiled library (target meshmotion::compiled) for 2D and 3D,
// behind the extern template declarations consumers see. Each mover is instantiated in one object
// file of the library alone. Both dimensions are instantiated in one translation unit: they share
// the headers' parsing and every function that does not depend on the dimension, which two objects
// compiled again (docs/compiled.md).

#include "meshmotion/movers/registered_movers.hpp"

namespace meshmotion {

template class BlendMover<2>;
template class BoundaryOnlyMover<2>;
template std::span<const MoverMethod<2>> mover_methods<2>();

template class BlendMover<3>;
template class BoundaryOnlyMover<3>;
template std::span<const MoverMethod<3>> mover_methods<3>();

}  // namespace meshmotion
