#pragma once
/// \file
/// NonlinearElasticityOptions: the options of NonlinearElasticityMover (movers/nonlinear_elasticity.hpp).
/// Light: the options and their one description (visit_options: key, field, doc), no mover.

#include "meshmotion/core/option_text.hpp"
#include "meshmotion/solvers/solver_options.hpp"

#include <string>

namespace meshmotion {

/// Options of NonlinearElasticityMover.
struct NonlinearElasticityOptions {
  double youngs_modulus = 1.0;      ///< E > 0 (scales the energy only)
  double poisson_ratio = 0.3;       ///< ν in (−1, 0.5)
  int load_steps = 1;               ///< equal boundary increments, ≥ 1
  int max_newton_iterations = 60;   ///< per load step, ≥ 1
  /// Newton stops when the largest nodal update is ≤ tolerance × the mesh's bounding-box diagonal.
  double tolerance = 1e-10;
  /// Smallest line-search step before giving up.
  double min_step = 1e-8;
  /// Solver of the symmetric tangent (direct by default; it may be indefinite far from u = 0).
  SolverOptions solver = {};
};

// visit_options(o, f) calls f(key, field, help) for every field of `o` that text may set.
template <class F>
void visit_options(NonlinearElasticityOptions& o, F&& f, const std::string& prefix = {}) {
  f(prefix + "youngs_modulus", o.youngs_modulus, OptionHelp{"Young's modulus E (scales the energy only)", range::positive});
  f(prefix + "poisson_ratio", o.poisson_ratio, OptionHelp{"Poisson ratio", OptionRange{-1.0, 0.5, true, true}});
  f(prefix + "load_steps", o.load_steps, OptionHelp{"equal boundary increments", range::at_least(1)});
  f(prefix + "newton_iterations", o.max_newton_iterations, OptionHelp{"Newton iterations per load step", range::at_least(1)});
  f(prefix + "newton_tolerance", o.tolerance, OptionHelp{"largest update / bounding-box diagonal that stops Newton", range::positive});
  f(prefix + "min_step", o.min_step, OptionHelp{"smallest line-search step", OptionRange{0.0, 1.0, true}});
  visit_options(o.solver, f, prefix);
}

}  // namespace meshmotion
