#pragma once
/// \file
/// The curving layer: P1 → P2 conversion, boundary reconstruction (2D splines) and analytic
/// projections, boundary snapping, and the curve_mesh pipeline (docs/curving.md). Its default
/// regularizer, the blending mover, is a mover like the others (movers/blend.hpp).

#include "meshmotion/curving/boundary_snapping.hpp"
#include "meshmotion/curving/boundary_spline.hpp"
#include "meshmotion/curving/curve_mesh.hpp"
#include "meshmotion/curving/function_graph.hpp"
#include "meshmotion/curving/geometry.hpp"
#include "meshmotion/curving/geometry_text.hpp"
#include "meshmotion/curving/inner_nodes.hpp"
#include "meshmotion/curving/naca_section.hpp"
#include "meshmotion/curving/order_conversion.hpp"
#include "meshmotion/curving/p2_conversion.hpp"
