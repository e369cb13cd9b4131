#pragma once
/// \file
/// The quality layer: Knupp metrics of linear elements, the certified scaled Jacobian of
/// linear and curved elements, per-cell evaluation, mesh reports, SVG pictures, and checkMesh
/// measures of polyhedral cells.

#include "meshmotion/quality/cell_quality.hpp"
#include "meshmotion/quality/foam_quality.hpp"
#include "meshmotion/quality/knupp.hpp"
#include "meshmotion/quality/quality_report.hpp"
#include "meshmotion/quality/scaled_jacobian.hpp"
#include "meshmotion/quality/svg_picture.hpp"
