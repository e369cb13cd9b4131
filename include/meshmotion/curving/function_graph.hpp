#pragma once
/// \file
/// Boundaries that are graphs of functions, y = f(x) in 2D and z = f(x, y) in 3D, as
/// boundary projections, and the NASA Turbulence Modeling Resource bump as a ready instance.

#include "meshmotion/core/error.hpp"
#include "meshmotion/core/types.hpp"
#include "meshmotion/curving/detail/closest_point.hpp"
#include "meshmotion/curving/geometry.hpp"

#include <Eigen/Core>
#include <Eigen/LU>

#include <cmath>
#include <functional>
#include <limits>
#include <numbers>
#include <string>
#include <utility>

namespace meshmotion {

/// Value, first and second derivative of f(x) at one x.
struct GraphSample1 {
  double value;
  double slope;
  double curvature;
};

/// Value, gradient and Hessian of f(x, y) at one point.
struct GraphSample2 {
  double value;
  Eigen::Vector2d gradient;
  Eigen::Matrix2d hessian;
};

/// Closest point on the curve y = f(x). `f(x)` returns GraphSample1 and must be C^2.
/// The closest point of p lies within |p_y - f(p_x)| of p, so its x is searched in that
/// window (16 samples, then bracketed Newton): the global closest point whenever f has no
/// feature narrower than the window / 16.
class GraphProjection2 {
 public:
  explicit GraphProjection2(std::function<GraphSample1(double)> f) : f_(std::move(f)) {}

  /// Throws InputError for a non-finite p, SolverError when f is not finite or the
  /// iteration fails.
  [[nodiscard]] Vec<2> operator()(const Vec<2>& p) const {
    detail::require_finite_point<2>(p, "GraphProjection2");
    const double window = std::abs(p.y() - value(p.x()));
    if (window == 0.0) return p;
    const double x = detail::closest_parameter<2>(
        [&](double s) {
          const GraphSample1 g = f_(s);
          return detail::CurveSample<2>{Vec<2>(s, g.value), Vec<2>(1.0, g.slope),
                                        Vec<2>(0.0, g.curvature)};
        },
        p, p.x() - window, p.x() + window, 16, "GraphProjection2");
    return {x, value(x)};
  }

 private:
  [[nodiscard]] double value(double x) const {
    const double v = f_(x).value;
    if (!std::isfinite(v))
      throw SolverError("GraphProjection2: f is not finite at x = " + std::to_string(x));
    return v;
  }
  std::function<GraphSample1(double)> f_;
};

/// Closest point on the surface z = f(x, y). `f(x, y)` returns GraphSample2 and must be C^2.
/// Newton on the squared distance from the foot point (p_x, p_y), with the Gauss–Newton
/// matrix where the Hessian is not positive definite and a backtracking line search: it finds
/// the closest point when the surface has no fold within |p_z - f(p_x, p_y)| of p (true of
/// gentle shapes such as the bump; a user shape with steep narrow features may need a
/// dedicated projection).
class GraphProjection3 {
 public:
  explicit GraphProjection3(std::function<GraphSample2(double, double)> f) : f_(std::move(f)) {}

  /// Throws InputError for a non-finite p, SolverError when f is not finite or the
  /// iteration does not converge in 100 steps.
  [[nodiscard]] Vec<3> operator()(const Vec<3>& p) const {
    detail::require_finite_point<3>(p, "GraphProjection3");
    Eigen::Vector2d xy = p.head<2>();
    double previous = std::numeric_limits<double>::infinity();
    for (int iteration = 0; iteration < 100; ++iteration) {
      const GraphSample2 g = sample(xy);
      const double gap = g.value - p.z();
      const Eigen::Vector2d gradient = xy - p.head<2>() + gap * g.gradient;
      const Eigen::Matrix2d gauss_newton =
          Eigen::Matrix2d::Identity() + g.gradient * g.gradient.transpose();
      Eigen::Matrix2d hessian = gauss_newton + gap * g.hessian;
      if (!(hessian.determinant() > 0.0 && hessian.trace() > 0.0)) hessian = gauss_newton;
      const Eigen::Vector2d step = -hessian.inverse() * gradient;
      // Converged when the step is at round-off, or stops shrinking near it (round-off in
      // f can make Newton cycle between neighbouring doubles a few ulps apart).
      const double size = step.norm();
      if (size <= 1e-14 * (1.0 + xy.norm()) || (size <= 1e-10 * (1.0 + xy.norm()) && size >= 0.5 * previous)) {
        xy += step;
        return {xy.x(), xy.y(), sample(xy).value};
      }
      // Backtrack while the distance grows by more than round-off.
      const double limit = squared_distance(xy, gap, p) * (1.0 + 1e-12);
      double length = 1.0;
      Eigen::Vector2d next = xy + step;
      while (length > 1e-10 && squared_distance(next, sample(next).value - p.z(), p) > limit) {
        length *= 0.5;
        next = xy + length * step;
      }
      // No decrease along a descent direction: xy is the minimum to round-off (the step
      // test above can miss it where the distance is flat to the last bits).
      if (!(length > 1e-10)) return {xy.x(), xy.y(), sample(xy).value};
      previous = size;
      xy = next;
    }
    throw SolverError("GraphProjection3: closest-point iteration did not converge in 100 steps "
                      "(point " + std::to_string(p.x()) + ", " + std::to_string(p.y()) + ", " +
                      std::to_string(p.z()) + ")");
  }

 private:
  [[nodiscard]] GraphSample2 sample(const Eigen::Vector2d& xy) const {
    GraphSample2 g = f_(xy.x(), xy.y());
    if (!std::isfinite(g.value) || !g.gradient.allFinite() || !g.hessian.allFinite())
      throw SolverError("GraphProjection3: f is not finite at (" + std::to_string(xy.x()) +
                        ", " + std::to_string(xy.y()) + ")");
    return g;
  }
  [[nodiscard]] static double squared_distance(const Eigen::Vector2d& xy, double gap,
                                               const Vec<3>& p) {
    return (xy - p.head<2>()).squaredNorm() + gap * gap;
  }
  std::function<GraphSample2(double, double)> f_;
};

/// The NASA Turbulence Modeling Resource bump-in-channel wall:
/// h(x) = 0.05 sin^4(pi x / 0.9 - pi / 3) for 0.3 <= x <= 1.2, 0 elsewhere (C^3 at the feet).
[[nodiscard]] inline GraphSample1 nasa_bump_height(double x) {
  if (x <= 0.3 || x >= 1.2) return {0.0, 0.0, 0.0};
  constexpr double amplitude = 0.05, frequency = std::numbers::pi / 0.9;
  const double s = std::sin(frequency * x - std::numbers::pi / 3.0);
  const double c = std::cos(frequency * x - std::numbers::pi / 3.0);
  return {amplitude * s * s * s * s, 4.0 * amplitude * frequency * s * s * s * c,
          amplitude * frequency * frequency * (12.0 * s * s * c * c - 4.0 * s * s * s * s)};
}

/// The 2D bump-in-channel wall y = h(x) (see nasa_bump_height).
[[nodiscard]] inline GraphProjection2 nasa_bump_2d() { return GraphProjection2(nasa_bump_height); }

/// The NASA Turbulence Modeling Resource 3D bump-in-channel wall (thesis section 4.2.2): the
/// 2D profile h (nasa_bump_height) shifted streamwise along the span,
/// z = f(x, y) = h(x - s(y)), s(y) = 0.3 sin^4(pi y) (y in [-1, 0], s = s' = 0 on both sides,
/// so the side planes are symmetry planes of the wall). The wall of bump_channel_3d().
[[nodiscard]] inline GraphSample2 nasa_bump_3d_height(double x, double y) {
  constexpr double pi = std::numbers::pi;
  const double sn = std::sin(pi * y), cs = std::cos(pi * y);
  const double shift = 0.3 * sn * sn * sn * sn;
  const double shift1 = 1.2 * pi * sn * sn * sn * cs;
  const double shift2 = 1.2 * pi * pi * (3.0 * sn * sn * cs * cs - sn * sn * sn * sn);
  const GraphSample1 h = nasa_bump_height(x - shift);
  GraphSample2 g{h.value, {h.slope, -h.slope * shift1}, Eigen::Matrix2d::Zero()};
  g.hessian << h.curvature, -h.curvature * shift1, -h.curvature * shift1,
      h.curvature * shift1 * shift1 - h.slope * shift2;
  return g;
}

/// Closest-point projection onto the 3D bump-in-channel wall (nasa_bump_3d_height), for the
/// "bump" and "symmetry_lower" groups of bump_channel_3d().
[[nodiscard]] inline GraphProjection3 nasa_bump_3d() { return GraphProjection3(nasa_bump_3d_height); }

}  // namespace meshmotion
