#pragma once
// Command-line options of the mechanics movers (spring, torsion, le, sle, nle) shared by
// move_mesh and curve_mesh: each given option becomes a mover registry parameter
// (movers/any_mover.hpp), so an option a method does not read is ignored by it.

#include "meshmotion/movers/any_mover.hpp"

#include <CLI/CLI.hpp>

#include <cstdio>
#include <optional>
#include <string>

namespace meshmotion::examples {

struct MechanicsArguments {
  std::optional<double> stiffening_exponent, poisson_ratio, youngs_modulus, distance_exponent, active_radius,
      active_factor, tolerance;
  std::optional<std::string> solver;
  std::optional<int> load_steps;
};

inline void add_mechanics_options(CLI::App& app, MechanicsArguments& a) {
  app.add_option("--stiffening-exponent", a.stiffening_exponent,
                 "le/sle: chi of the Jacobian stiffening (J0/J)^chi (sle default 2.75, le 0)");
  app.add_option("--poisson-ratio", a.poisson_ratio, "le/sle/nle: Poisson ratio nu in (-1, 0.5) (default 0.3)");
  app.add_option("--youngs-modulus", a.youngs_modulus, "le/sle/nle: Young's modulus E > 0 (default 1; scales K only)");
  app.add_option("--distance-exponent", a.distance_exponent, "le/sle: psi of the wall-distance stiffening (default 0)");
  app.add_option("--active-radius", a.active_radius,
                 "le/sle: solve only within this distance of the moving walls, zero displacement beyond (0: whole mesh)");
  app.add_option("--active-factor", a.active_factor,
                 "le/sle: active radius = this x the support radius (curve_mesh default for le/sle: 4, i.e. 4 x the "
                 "wall layer)");
  app.add_option("--solver", a.solver,
                 "spring/torsion/le/sle/nle: simplicial_ldlt (default) | simplicial_llt | sparse_lu | cg_jacobi | "
                 "cg_incomplete_cholesky | bicgstab");
  app.add_option("--tolerance", a.tolerance, "iterative solvers: relative residual (of the diagonally scaled system for le/sle)");
  app.add_option("--load-steps", a.load_steps, "nle: load increments (default 1)");
}

/// Adds the given options to `p` as registry parameters.
inline void add_mechanics_parameters(const MechanicsArguments& a, MoverParameters& p) {
  const auto number = [&](const char* key, const std::optional<double>& v) {
    if (!v) return;
    char text[32];
    std::snprintf(text, sizeof text, "%.17g", *v);
    p.values[key] = text;
  };
  number("stiffening_exponent", a.stiffening_exponent);
  number("poisson_ratio", a.poisson_ratio);
  number("youngs_modulus", a.youngs_modulus);
  number("distance_exponent", a.distance_exponent);
  number("active_radius", a.active_radius);
  number("active_radius_factor", a.active_factor);
  number("tolerance", a.tolerance);
  if (a.load_steps) number("load_steps", static_cast<double>(*a.load_steps));
  if (a.solver) p.values["solver"] = *a.solver;
}

}  // namespace meshmotion::examples
