#pragma once
/// \file
/// The movers layer: the mover contract, boundary specification, rigid motions, the step
/// driver and the movers themselves (interpolation: RBF, DGM, DGRBF, DGRBF2, improved DGM;
/// mechanics: lineal and torsional springs, linear, stiffened and neo-Hookean elasticity;
/// wall-distance blending; the boundary alone) and their registry by method name.

#include "meshmotion/movers/any_mover.hpp"
#include "meshmotion/movers/blend.hpp"
#include "meshmotion/movers/boundary.hpp"
#include "meshmotion/movers/boundary_layer.hpp"
#include "meshmotion/movers/boundary_only.hpp"
#include "meshmotion/movers/delaunay_graph_options.hpp"
#include "meshmotion/movers/dgm.hpp"
#include "meshmotion/movers/dgrbf.hpp"
#include "meshmotion/movers/dgrbf2.hpp"
#include "meshmotion/movers/elasticity.hpp"
#include "meshmotion/movers/improved_dgm.hpp"
#include "meshmotion/movers/motion.hpp"
#include "meshmotion/movers/mover.hpp"
#include "meshmotion/movers/mover_options.hpp"
#include "meshmotion/movers/nonlinear_elasticity.hpp"
#include "meshmotion/movers/rbf.hpp"
#include "meshmotion/movers/rbf_kernels.hpp"
#include "meshmotion/movers/section_mover.hpp"
#include "meshmotion/movers/spring.hpp"
#include "meshmotion/movers/step_driver.hpp"
#include "meshmotion/movers/support_radius.hpp"
#include "meshmotion/movers/torsion_spring.hpp"
