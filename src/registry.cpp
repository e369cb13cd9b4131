// The registry of serial movers (method -> factory, movers/registered_movers.hpp) and the blending and boundary-only movers of the compiled library (target meshmotion::compiled) for one dimension,
// MESHMOTION_INSTANTIATE_DIM (CMake compiles this file once for 2 and once for 3), behind the
// extern template declarations consumers see. Each mover is instantiated in one object file
// of the library alone: src/movers_*.cpp and src/registry.cpp share them out so that the two
// cores of a build compile them side by side.

#include "meshmotion/movers/registered_movers.hpp"

namespace meshmotion {

constexpr int D = MESHMOTION_INSTANTIATE_DIM;

template class BlendMover<D>;
template class BoundaryOnlyMover<D>;
template std::span<const MoverMethod<D>> mover_methods<D>();

}  // namespace meshmotion
