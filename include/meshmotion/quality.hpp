#pragma once
/// \file
/// The quality layer: Knupp metrics of linear elements, the certified scaled Jacobian of
/// linear and curved elements, per-cell evaluation, mesh reports and SVG pictures.

#include "meshmotion/quality/cell_quality.hpp"
#include "meshmotion/quality/knupp.hpp"
#include "meshmotion/quality/quality_report.hpp"
#include "meshmotion/quality/scaled_jacobian.hpp"
#include "meshmotion/quality/svg_picture.hpp"
