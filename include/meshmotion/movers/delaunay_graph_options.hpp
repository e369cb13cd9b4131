#pragma once
/// \file
/// Options shared by the Delaunay-graph movers (DGM, DGRBF, DGRBF2, improved DGM; thesis
/// sections 2.2.1, 2.2.3, 2.2.4): what happens to nodes outside the graph's convex hull, and
/// the per-simplex RBF interpolation of DGRBF (thesis eqs. 2.15–2.16).

#include "meshmotion/core/option_text.hpp"
#include "meshmotion/movers/rbf_kernels.hpp"

#include <array>
#include <string>
#include <string_view>

namespace meshmotion {

/// Treatment of mesh nodes outside the convex hull of the graph nodes. Every node of a mesh
/// whose whole boundary is in the graph lies inside the hull; outside nodes appear when some
/// boundary group is left out of the BoundarySpec (a free outlet), or through rounding on
/// hull edges.
enum class OutsideGraph {
  /// Nearest hull simplex, barycentric coordinates clamped to [0, 1] and renormalized: the
  /// node moves by a convex combination of that simplex's displacements (bounded, never
  /// amplified). Default.
  clamp,
  /// Nearest hull simplex with extrapolating coordinates: affine motions stay exact
  /// everywhere, but far nodes amplify rotations.
  extrapolate,
};

[[nodiscard]] constexpr std::string_view name(OutsideGraph o) { return o == OutsideGraph::clamp ? "clamp" : "extrapolate"; }
/// Both treatments, for the option parser (core/option_text.hpp).
[[nodiscard]] constexpr std::array<OutsideGraph, 2> option_choices(OutsideGraph) {
  return {OutsideGraph::clamp, OutsideGraph::extrapolate};
}

/// Per-simplex RBF interpolation of DGRBF (Wang, Qin & Zhao, JCP 2015; thesis eqs. 2.15–2.16):
/// inside graph simplex T with vertices x_t1..x_t(Dim+1), s(x) = Σ_j a_j φ(|x − x_tj|) with
/// A a = s_T, A_ij = φ(|x_ti − x_tj|). The (Dim+1)² systems are factorized once per simplex.
struct SimplexRbfOptions {
  RbfKernel kernel = RbfKernel::wendland2;
  double simplex_support_radius = 0.0;
  double simplex_support = 2.0;
  bool normalize = true;
};

// visit_options(o, f) calls f(key, field, help) for every field of `o` that text may set.
template <class F>
void visit_options(SimplexRbfOptions& o, F&& f, const std::string& prefix = {}) {
  f(prefix + "kernel", o.kernel, "radial function of the per-simplex interpolation");
  f(prefix + "simplex_support_radius", o.simplex_support_radius, OptionHelp{"absolute per-simplex support radius (0: relative)", range::non_negative,
      "Absolute support radius (shape scale of global kernels) when > 0; when 0 each simplex uses "
      "simplex_support × its longest edge, so every point of the simplex lies inside the support of every "
      "vertex whatever the simplex size (graph simplices range from wall spacing to farfield size)."});
  f(prefix + "simplex_support", o.simplex_support, OptionHelp{"per-simplex support, × the simplex's longest edge (when simplex_support_radius is 0)", range::positive});
  f(prefix + "normalize", o.normalize, OptionHelp{"divide the cardinal weights by their sum", {},
      "Divide the cardinal weights A⁻¹φ(x) by their sum (rescaled RBF): the interpolant then reproduces "
      "constants exactly (rigid translations, and in DGRBF2 rigid rotations), which plain RBF with Dim+1 "
      "centres does not. false gives the thesis's eq. 2.15 as is."});
}

}  // namespace meshmotion
