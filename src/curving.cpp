// The curving pipeline of the compiled library for one dimension, MESHMOTION_INSTANTIATE_DIM
// (compiled once for 2 and once for 3).

#include "meshmotion/curving/curve_mesh.hpp"
#include "meshmotion/curving/order_conversion.hpp"
#include "meshmotion/curving/p2_conversion.hpp"

namespace meshmotion {

constexpr int D = MESHMOTION_INSTANTIATE_DIM;

template QuadraticConversion<D> convert_to_quadratic<D>(const Mesh<D>&, const P2Options&);
template OrderConversion<D> convert_to_order<D>(const Mesh<D>&, int);
template CurveResult<D> curve_mesh<D>(const Mesh<D>&, const CurveOptions<D>&);

}  // namespace meshmotion
