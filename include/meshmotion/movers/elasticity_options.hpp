#pragma once
/// \file
/// ElasticityOptions: the options of ElasticityMover (movers/elasticity.hpp).
/// Light: the options and their one description (visit_options: key, field, doc), no mover.

#include "meshmotion/core/option_text.hpp"
#include "meshmotion/solvers/solver_options.hpp"

#include <string>

namespace meshmotion {

/// Options of ElasticityMover.
struct ElasticityOptions {
  double youngs_modulus = 1.0;
  double poisson_ratio = 0.3;
  double stiffening_exponent = 0.0;
  double reference_jacobian = 0.0;
  double distance_exponent = 0.0;
  /// Solver of the SPD system. ElasticityMover always solves the diagonally scaled system
  /// (solver.diagonal_scaling is switched on): stiffening spreads the rows of K over many
  /// orders of magnitude, and an iterative solver's relative residual only means something
  /// on the balanced system.
  SolverOptions solver = {};
  double active_radius = 0.0;
};

// visit_options(o, f) calls f(key, field, help) for every field of `o` that text may set.
template <class F>
void visit_options(ElasticityOptions& o, F&& f, const std::string& prefix = {}) {
  f(prefix + "youngs_modulus", o.youngs_modulus, OptionHelp{"Young's modulus E (scales K only)", range::positive});
  f(prefix + "poisson_ratio", o.poisson_ratio, OptionHelp{"Poisson ratio (the thesis uses 0.4)", OptionRange{-1.0, 0.5, true, true}});
  f(prefix + "stiffening_exponent", o.stiffening_exponent, OptionHelp{"chi of the Jacobian stiffening (J0/J)^chi", range::non_negative,
      "χ of the Jacobian stiffening (J0/J)^χ, eq. 2.8 (thesis table 4.2: 2.75 and 2.9); 0 disables it."});
  f(prefix + "reference_jacobian", o.reference_jacobian, "J0 (<= 0: the mean cell measure)");
  f(prefix + "distance_exponent", o.distance_exponent, OptionHelp{"psi of the wall-distance stiffening", range::non_negative});
  visit_options(o.solver, f, prefix);
  f(prefix + "active_radius", o.active_radius, OptionHelp{"solve only within this distance of the moving walls (0: whole mesh)", range::non_negative,
      "Solve only near the moving walls: nodes farther than this from every prescribed boundary node keep "
      "zero displacement (a homogeneous Dirichlet condition there, like the compact support of an RBF); cells "
      "without a free node are not assembled, and sliding nodes beyond the radius are held fixed. ≤ 0 "
      "(default): the whole mesh."});
}

}  // namespace meshmotion
