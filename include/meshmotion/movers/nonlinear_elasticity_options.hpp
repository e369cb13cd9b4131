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
  double youngs_modulus = 1.0;
  double poisson_ratio = 0.3;
  int load_steps = 1;
  int newton_iterations = 60;
  double newton_tolerance = 1e-10;
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
  f(prefix + "newton_iterations", o.newton_iterations, OptionHelp{"Newton iterations per load step", range::at_least(1)});
  f(prefix + "newton_tolerance", o.newton_tolerance, OptionHelp{"largest update / bounding-box diagonal that stops Newton", range::positive});
  f(prefix + "min_step", o.min_step, OptionHelp{"smallest line-search step", OptionRange{0.0, 1.0, true}});
  visit_options(o.solver, f, prefix);
}

}  // namespace meshmotion
