#pragma once
/// \file
/// ImprovedDgmOptions: the options of ImprovedDgmMover (movers/improved_dgm.hpp).
/// Light: the options and their one description (visit_options: key, field, doc), no mover.

#include "meshmotion/core/option_text.hpp"
#include "meshmotion/movers/dgm_options.hpp"
#include "meshmotion/movers/rbf_options.hpp"

#include <string>

namespace meshmotion {

/// Options of ImprovedDgmMover.
struct ImprovedDgmOptions {
  DgmOptions dgm = {};
  double layer_offset = 1.0;
  double layer_spacing = 1.0;
  /// RBF moving the layer. Its support_radius is used when auto_support_radius is false.
  RbfOptions rbf = {};
  bool auto_support_radius = true;
  double relative_support_radius = 1.0;
};

// visit_options(o, f) calls f(key, field, help) for every field of `o` that text may set.
template <class F>
void visit_options(ImprovedDgmOptions& o, F&& f, const std::string& prefix = {}) {
  visit_options(o.dgm, f, prefix);
  f(prefix + "layer_offset", o.layer_offset, OptionHelp{"layer distance from the wall, in wall spacings", range::non_negative,
      "Distance of the layer from the prescribed boundary nodes, in median spacings of those nodes (> 0): "
      "about 1 makes the graph triangles between wall and layer well shaped."});
  f(prefix + "layer_spacing", o.layer_spacing, OptionHelp{"thinning of the layer, in wall spacings", range::positive});
  f(prefix + "auto_support_radius", o.auto_support_radius, OptionHelp{"the layer RBF's radius from the layer's reach", {},
      "Support radius = relative_support_radius × the larger of the largest distance from a layer node to the "
      "nearest prescribed node and the bounding-box diagonal of the prescribed nodes, so every layer node "
      "moves nearly rigidly with its body (a radius of the order of the layer offset lets the layer lag and "
      "fold the thin wall–layer triangles)."});
  f(prefix + "relative_support_radius", o.relative_support_radius, OptionHelp{"factor of the automatic radius", range::positive});
  visit_options(o.rbf, f, prefix + "rbf.");
}

}  // namespace meshmotion
