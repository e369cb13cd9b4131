#pragma once
/// \file
/// DgrbfOptions: the options of DgrbfMover (movers/dgrbf.hpp).
/// Light: the options and their one description (visit_options: key, field, doc), no mover.

#include "meshmotion/movers/delaunay_graph_options.hpp"

#include <string>

namespace meshmotion {

/// Options of DgrbfMover.
struct DgrbfOptions {
  SimplexRbfOptions rbf = {};
  OutsideGraph outside = OutsideGraph::clamp;
};

// visit_options(o, f) calls f(key, field, help) for every field of `o` that text may set.
template <class F>
void visit_options(DgrbfOptions& o, F&& f, const std::string& prefix = {}) {
  visit_options(o.rbf, f, prefix);
  f(prefix + "outside", o.outside, "nodes outside the graph's hull");
}

}  // namespace meshmotion
