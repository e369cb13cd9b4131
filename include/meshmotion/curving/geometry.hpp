#pragma once
/// \file
/// Analytic/CAD boundary geometry for curving: a BoundaryProjection maps a point to the
/// closest point of the true boundary of one group. The curving pipeline projects the
/// straight midpoint of each boundary edge, which places the high-order node where the true
/// boundary is nearest rather than at the midpoint of a CAD parameter that need not be arc
/// length. This header holds the callback type and the simplest ready shapes (circle/sphere,
/// plane); naca_section.hpp and function_graph.hpp hold the others.

#include "meshmotion/core/error.hpp"
#include "meshmotion/core/types.hpp"

#include <cmath>
#include <functional>
#include <span>
#include <string>

namespace meshmotion {

/// Closest-point projection onto the true boundary of a group: point -> point on it.
/// Any callable of this signature works (the ready shapes below are such callables).
template <int Dim>
using BoundaryProjection = std::function<Vec<Dim>(const Vec<Dim>&)>;

/// Where a high-order boundary node goes, from the vertices of its facet (on the geometry)
/// and its weights on them (the facet's linear shape functions at the node).
template <int Dim>
using BoundaryPlacement = std::function<Vec<Dim>(std::span<const Vec<Dim>> vertices, std::span<const double> weights)>;

/// The closest point of the true boundary to x, a point of the facet through `vertices` (on the
/// geometry) where its vertices weigh `weights`: a local search from the vertices' places,
/// much cheaper than a global projection on a CAD model.
template <int Dim>
using BoundaryNearby =
    std::function<Vec<Dim>(std::span<const Vec<Dim>> vertices, std::span<const double> weights, const Vec<Dim>& x)>;

namespace detail {

/// Throws InputError naming `where` when p has a NaN or infinite coordinate.
template <int Dim>
void require_finite_point(const Vec<Dim>& p, const char* where) {
  if (!p.allFinite())
    throw InputError(std::string(where) + ": point is not finite (expected finite coordinates)");
}

}  // namespace detail

/// Circle (Dim = 2) or sphere (Dim = 3) of a center and radius: exact radial projection.
template <int Dim>
class SphereProjection {
 public:
  /// Throws InputError for a non-finite center or a radius that is not positive.
  SphereProjection(const Vec<Dim>& center, double radius) : center_(center), radius_(radius) {
    detail::require_finite_point<Dim>(center, "SphereProjection");
    if (!(radius > 0.0) || !std::isfinite(radius))
      throw InputError("SphereProjection: invalid radius (got " + std::to_string(radius) +
                       ", expected a positive number)");
  }
  /// Throws InputError for a non-finite point or the center itself (no unique closest point).
  [[nodiscard]] Vec<Dim> operator()(const Vec<Dim>& p) const {
    detail::require_finite_point<Dim>(p, "SphereProjection");
    const Vec<Dim> offset = p - center_;
    const double distance = offset.norm();
    if (!(distance > 0.0))
      throw InputError("SphereProjection: point is the center (expected a point away from it)");
    return center_ + (radius_ / distance) * offset;
  }
  [[nodiscard]] const Vec<Dim>& center() const noexcept { return center_; }
  [[nodiscard]] double radius() const noexcept { return radius_; }

 private:
  Vec<Dim> center_;
  double radius_;
};

/// Line (Dim = 2) or plane (Dim = 3) through `origin` with normal `normal`: orthogonal
/// projection, for sliding and symmetry boundaries.
template <int Dim>
class PlaneProjection {
 public:
  /// Throws InputError for a non-finite origin or a zero or non-finite normal.
  PlaneProjection(const Vec<Dim>& origin, const Vec<Dim>& normal) : origin_(origin) {
    detail::require_finite_point<Dim>(origin, "PlaneProjection");
    const double length = normal.norm();
    if (!(length > 0.0) || !std::isfinite(length))
      throw InputError("PlaneProjection: invalid normal (expected a nonzero finite vector)");
    normal_ = normal / length;
  }
  /// Throws InputError for a non-finite point.
  [[nodiscard]] Vec<Dim> operator()(const Vec<Dim>& p) const {
    detail::require_finite_point<Dim>(p, "PlaneProjection");
    return p - (p - origin_).dot(normal_) * normal_;
  }
  [[nodiscard]] const Vec<Dim>& normal() const noexcept { return normal_; }

 private:
  Vec<Dim> origin_;
  Vec<Dim> normal_;
};

}  // namespace meshmotion
