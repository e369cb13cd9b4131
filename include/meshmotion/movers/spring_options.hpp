#pragma once
/// \file
/// SpringOptions: the options of SpringMover (movers/spring.hpp).
/// Light: the options and their one description (visit_options: key, field, doc), no mover.

#include "meshmotion/core/option_text.hpp"
#include "meshmotion/solvers/solver_options.hpp"

#include <string>

namespace meshmotion {

/// Options of SpringMover.
struct SpringOptions {
  double length_exponent = 1.0;
  /// Solver of the (SPD) spring system.
  SolverOptions solver = {};
};

// visit_options(o, f) calls f(key, field, help) for every field of `o` that text may set.
template <class F>
void visit_options(SpringOptions& o, F&& f, const std::string& prefix = {}) {
  f(prefix + "length_exponent", o.length_exponent, OptionHelp{"p in the spring stiffness k_ij = |r_i - r_j|^-p (Batina's, eq. 2.2: 1)", range::non_negative});
  visit_options(o.solver, f, prefix);
}

}  // namespace meshmotion
