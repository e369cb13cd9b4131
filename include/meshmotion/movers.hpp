#pragma once
/// \file
/// The movers layer: the mover contract, boundary specification, rigid motions, the step
/// driver and the movers themselves.

#include "meshmotion/movers/any_mover.hpp"
#include "meshmotion/movers/boundary.hpp"
#include "meshmotion/movers/motion.hpp"
#include "meshmotion/movers/mover.hpp"
#include "meshmotion/movers/rbf.hpp"
#include "meshmotion/movers/rbf_kernels.hpp"
#include "meshmotion/movers/step_driver.hpp"
#include "meshmotion/movers/support_radius.hpp"
