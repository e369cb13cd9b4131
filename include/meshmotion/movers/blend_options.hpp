#pragma once
/// \file
/// BlendOptions: the options of BlendMover (movers/blend.hpp).
/// Light: the options and their one description (visit_options: key, field, doc), no mover.

#include "meshmotion/core/option_text.hpp"
#include "meshmotion/movers/boundary_layer_options.hpp"

#include <memory>
#include <string>

namespace meshmotion {

struct BoundaryLayerEstimate;  // movers/boundary_layer.hpp

/// Options of BlendMover.
struct BlendOptions {
  double blending_length = 0.0;
  BoundaryLayerOptions layer{};
  double fallback_spacings = 2.0;
  double blending_factor = 1.0;
  /// An estimate_boundary_layer() made on the mesh setup() is given, for any grouping of the
  /// same wall vertices (the curving pipeline's, by group): setup takes the walls' default
  /// lengths from it instead of estimating again (a tenth of the 30P30N's curving time), when
  /// its wall vertices are exactly those of the walls. Not a keyed option: whoever sets it
  /// vouches that the mesh is the one estimated.
  std::shared_ptr<const BoundaryLayerEstimate> layer_estimate{};
};

// visit_options(o, f) calls f(key, field, help) for every field of `o` that text may set.
template <class F>
void visit_options(BlendOptions& o, F&& f, const std::string& prefix = {}) {
  f(prefix + "blending_length", o.blending_length, OptionHelp{"blending length of every wall (0: blending_factor x each wall's layer)", range::non_negative,
      "Blending length for every wall; 0 (default): `blending_factor` × each wall's boundary-layer thickness "
      "(estimate_boundary_layer), or, on a wall without an anisotropic layer, `fallback_spacings` × the size "
      "of the facet closest to each node."});
  f(prefix + "blending_factor", o.blending_factor, OptionHelp{"default blending length, in layer thicknesses of each wall", range::positive,
      "The default blending length, in layer thicknesses of each wall. φ is steepest at a quarter of the length, so at 1 the "
      "steepest gradient lies inside the layer's thin cells; at k it lies k/4 layers out, in cells that "
      "tolerate it, and the gradient within the layer falls roughly as 1/k. The registered method \"blend\" "
      "starts at 6 (docs/curving.md, \"Blending length\")."});
  f(prefix + "fallback_spacings", o.fallback_spacings, OptionHelp{"walls without a layer: blending length in facet sizes at each node", range::positive,
      "Walls without a layer: the blending length in facet sizes at each node. Such a wall has only its own spacing to size its motion by, and the spacing varies along it "
      "(on the RAE2822 the leading-edge facets are 8 times shorter than the largest): each node blends over a "
      "few of its own facets (docs/curving.md, \"Walls without a layer\")."});
  visit_options(o.layer, f, prefix);
}

}  // namespace meshmotion
