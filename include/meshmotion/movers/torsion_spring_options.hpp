#pragma once
/// \file
/// TorsionSpringOptions: the options of TorsionSpringMover (movers/torsion_spring.hpp).
/// Light: the options and their one description (visit_options: key, field, doc), no mover.

#include "meshmotion/core/option_text.hpp"
#include "meshmotion/solvers/solver_options.hpp"

#include <string>

namespace meshmotion {

/// Options of TorsionSpringMover.
struct TorsionSpringOptions {
  double torsion_weight = 1.0;
  bool coupled_lineal = true;
  bool vertex_facet_springs = true;
  /// Solver of the (SPD) coupled system.
  SolverOptions solver = {};
};

// visit_options(o, f) calls f(key, field, help) for every field of `o` that text may set.
template <class F>
void visit_options(TorsionSpringOptions& o, F&& f, const std::string& prefix = {}) {
  f(prefix + "torsion_weight", o.torsion_weight, OptionHelp{"factor of every torsional stiffness", range::non_negative});
  f(prefix + "coupled_lineal", o.coupled_lineal, "lineal springs in the coupled truss form");
  f(prefix + "vertex_facet_springs", o.vertex_facet_springs, "3D: vertex-facet springs too");
  visit_options(o.solver, f, prefix);
}

}  // namespace meshmotion
