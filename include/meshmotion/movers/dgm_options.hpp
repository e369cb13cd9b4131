#pragma once
/// \file
/// DgmOptions: the options of DgmMover (movers/dgm.hpp).
/// Light: the options and their one description (visit_options: key, field, doc), no mover.

#include "meshmotion/movers/delaunay_graph_options.hpp"

#include <string>

namespace meshmotion {

/// Options of DgmMover.
struct DgmOptions {
  OutsideGraph outside = OutsideGraph::clamp;
  bool check_inversion = true;
};

// visit_options(o, f) calls f(key, field, help) for every field of `o` that text may set.
template <class F>
void visit_options(DgmOptions& o, F&& f, const std::string& prefix = {}) {
  f(prefix + "outside", o.outside, "nodes outside the graph's hull");
  f(prefix + "check_inversion", o.check_inversion, "refuse when the moved graph inverts");
}

}  // namespace meshmotion
