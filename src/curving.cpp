// The curving pipeline of the compiled library for 2D and 3D (one translation unit: the two share
// the certificate, the surface reconstruction and the headers' parsing).

#include "meshmotion/curving/curve_mesh.hpp"
#include "meshmotion/curving/order_conversion.hpp"
#include "meshmotion/curving/p2_conversion.hpp"

namespace meshmotion {

template QuadraticConversion<2> convert_to_quadratic<2>(const Mesh<2>&, const P2Options&);
template OrderConversion<2> convert_to_order<2>(const Mesh<2>&, int);
template CurveResult<2> curve_mesh<2>(const Mesh<2>&, const CurveOptions<2>&);

template QuadraticConversion<3> convert_to_quadratic<3>(const Mesh<3>&, const P2Options&);
template OrderConversion<3> convert_to_order<3>(const Mesh<3>&, int);
template CurveResult<3> curve_mesh<3>(const Mesh<3>&, const CurveOptions<3>&);

}  // namespace meshmotion
