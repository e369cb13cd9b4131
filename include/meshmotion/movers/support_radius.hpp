#pragma once
/// \file
/// A heuristic support radius for compactly supported RBF kernels, which the thesis asks for
/// (section 2.2.2: "big enough to accommodate the expected deformation of the boundary, but
/// small enough that the linear system is sparse"). It is the default of RbfOptions and of the
/// programs: made of the mesh's own lengths, it moves a mesh in millimetres as in metres.

#include "meshmotion/core/error.hpp"
#include "meshmotion/core/types.hpp"
#include "meshmotion/spatial/kd_tree.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

namespace meshmotion {

/// Factors of suggest_support_radius().
struct SupportRadiusOptions {
  double displacement_factor = 5.0;  ///< radius ≥ this × the largest boundary displacement
  double spacing_factor = 10.0;      ///< radius ≥ this × the median boundary node spacing
};

/// max(displacement_factor × `largest` displacement, spacing_factor × `median` spacing): the
/// last step of suggest_support_radius(), for callers that find the two figures themselves (a
/// distributed boundary). Throws InputError when no positive radius follows.
[[nodiscard]] inline double support_radius_from(double largest, double median, const SupportRadiusOptions& options = {}) {
  const double radius = std::max(options.displacement_factor * largest, options.spacing_factor * median);
  if (!(radius > 0.0) || !std::isfinite(radius))
    throw InputError("suggest_support_radius: cannot propose a radius (got " + std::to_string(radius) +
                     "; all boundary nodes coincide and do not move?)");
  return radius;
}

/// How a default radius follows a motion its mover was not set up for. A solver sets a mover
/// up once, before anything moves, where the rule above sees no displacement and gives the
/// spacing's radius; a later move whose largest prescribed displacement L has outgrown it
/// (displacement_factor × L > radius) sets the mover up again, inside the library, for
/// radius_growth_margin × L. The margin 2 makes that at most once per doubling of the motion
/// and never again for an oscillation within the largest amplitude seen; a radius the memory
/// budget holds where it was stops the growth.
inline constexpr double radius_growth_margin = 2.0;

/// Whether a move whose largest prescribed displacement is `largest` outgrew `radius`.
[[nodiscard]] inline bool radius_outgrown(double largest, double radius, const SupportRadiusOptions& options = {}) {
  return options.displacement_factor * largest > radius;
}

/// suggest_support_radius() given the largest boundary displacement instead of every one (a
/// distributed boundary reduces it over the ranks). Throws InputError when m < 2 or no
/// positive radius follows.
template <int Dim>
[[nodiscard]] double suggest_support_radius(const Points<Dim>& boundary_points, double largest,
                                            const SupportRadiusOptions& options = {}) {
  const Index m = boundary_points.cols();
  if (m < 2) throw InputError("suggest_support_radius: needs at least 2 boundary nodes (got " + std::to_string(m) + ")");
  const KdTree<Dim> tree(boundary_points);
  std::vector<double> spacing;
  spacing.reserve(static_cast<std::size_t>(m));
  for (Index i = 0; i < m; ++i) {
    const auto nn = tree.nearest(boundary_points.col(i), 2);
    if (nn.size() == 2 && nn[1].second > 0.0) spacing.push_back(std::sqrt(nn[1].second));
  }
  double median = 0.0;
  if (!spacing.empty()) {
    auto mid = spacing.begin() + static_cast<std::ptrdiff_t>(spacing.size() / 2);
    std::nth_element(spacing.begin(), mid, spacing.end());
    median = *mid;
  }
  return support_radius_from(largest, median, options);
}

/// A support radius proposed from the boundary: max(displacement_factor × largest
/// displacement, spacing_factor × median nearest-neighbour spacing of the boundary nodes).
/// A HEURISTIC, not a guarantee: a larger radius spreads the deformation over more cells
/// (better for large rotations, thesis fig. 4.11) and makes the system denser.
/// `boundary_points` and `displacements` are Dim × m; throws InputError when m < 2 or the
/// shapes differ, or when no positive radius follows (coincident nodes, no motion).
template <int Dim>
[[nodiscard]] double suggest_support_radius(const Points<Dim>& boundary_points, const Points<Dim>& displacements,
                                            const SupportRadiusOptions& options = {}) {
  const Index m = boundary_points.cols();
  if (m < 2 || displacements.cols() != m)
    throw InputError("suggest_support_radius: needs at least 2 boundary nodes and one displacement each (got " +
                     std::to_string(m) + " nodes, " + std::to_string(displacements.cols()) + " displacements)");
  return suggest_support_radius(boundary_points, displacements.colwise().norm().maxCoeff(), options);
}

}  // namespace meshmotion
