#pragma once
/// \file
/// Dgrbf2Options: the options of Dgrbf2Mover (movers/dgrbf2.hpp).
/// Light: the options and their one description (visit_options: key, field, doc), no mover.

#include "meshmotion/core/types.hpp"
#include "meshmotion/movers/delaunay_graph_options.hpp"

#include <optional>
#include <string>

namespace meshmotion {

/// Options of Dgrbf2Mover.
template <int Dim>
struct Dgrbf2Options {
  SimplexRbfOptions rbf = {};
  OutsideGraph outside = OutsideGraph::clamp;
  std::optional<Vec<Dim>> center;
  Vec<3> axis = Vec<3>::UnitZ();
};

// visit_options(o, f) calls f(key, field, help) for every field of `o` that text may set.
template <int Dim, class F>
void visit_options(Dgrbf2Options<Dim>& o, F&& f, const std::string& prefix = {}) {
  visit_options(o.rbf, f, prefix);
  f(prefix + "outside", o.outside, "nodes outside the graph's hull");
  f(prefix + "center", o.center, OptionHelp{"centre of the rigid rotation (none: centroid of the moving nodes)", {},
      "Centre of rotation (the centre of the rigid Rotation2D/Rotation3D given to the moving group; for a "
      "Composition, the rotation's centre). Empty: the centroid of the moving nodes."});
  if constexpr (Dim == 3) f(prefix + "axis", o.axis, "rotation axis");
}

}  // namespace meshmotion
