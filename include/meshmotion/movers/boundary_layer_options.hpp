#pragma once
/// \file
/// BoundaryLayerOptions: how estimate_boundary_layer() (movers/boundary_layer.hpp) recognizes a wall's layer.
/// Light: the options and their one description (visit_options: key, field, doc), no mover.

#include "meshmotion/core/option_text.hpp"

#include <string>

namespace meshmotion {

/// Options of estimate_boundary_layer().
struct BoundaryLayerOptions {
  double aspect_ratio_threshold = 3.0;
};

// visit_options(o, f) calls f(key, field, help) for every field of `o` that text may set.
template <class F>
void visit_options(BoundaryLayerOptions& o, F&& f, const std::string& prefix = {}) {
  f(prefix + "aspect_ratio_threshold", o.aspect_ratio_threshold,
    OptionHelp{"cells at least this anisotropic (longest/shortest edge) form a wall's boundary layer", range::at_least(1),
      "Cells with longest/shortest vertex edge at least this belong to the layer; 2–4 separates the stretched "
      "layer from the isotropic core of usual meshes."});
}

}  // namespace meshmotion
