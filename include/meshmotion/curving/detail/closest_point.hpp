#pragma once
/// \file
/// Closest point of a smooth parametric curve to a point: coarse sampling to find the basin
/// of the global minimum, then Newton on the stationarity condition (r(t) - p) . r'(t) = 0
/// kept inside a shrinking bracket (bisection when a Newton step would leave it).

#include "meshmotion/core/error.hpp"
#include "meshmotion/core/types.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace meshmotion::detail {

/// Position and first two derivatives of a curve at one parameter value.
template <int Dim>
struct CurveSample {
  Vec<Dim> r;
  Vec<Dim> dr;
  Vec<Dim> ddr;
};

/// Parameter in [lo, hi] of the point of the curve closest to `p`.
/// `eval(t)` returns CurveSample<Dim>; the curve must be C^2 on [lo, hi]. The interval is
/// sampled at `samples` + 1 evenly spaced values (more samples for curves that wind).
/// Throws SolverError naming `where` when the curve evaluates to a non-finite value or the
/// iteration does not settle.
template <int Dim, class Eval>
[[nodiscard]] double closest_parameter(const Eval& eval, const Vec<Dim>& p, double lo,
                                       double hi, int samples, const char* where) {
  auto squared_distance = [&](double t) {
    const CurveSample<Dim> s = eval(t);
    if (!s.r.allFinite())
      throw SolverError(std::string(where) + ": curve evaluation is not finite at parameter " +
                        std::to_string(t));
    return (s.r - p).squaredNorm();
  };
  const double step = (hi - lo) / samples;
  int best = 0;
  double best_value = std::numeric_limits<double>::infinity();
  for (int k = 0; k <= samples; ++k) {
    const double value = squared_distance(k == samples ? hi : lo + k * step);
    if (value < best_value) {
      best_value = value;
      best = k;
    }
  }
  double left = std::max(lo, lo + (best - 1) * step);
  double right = std::min(hi, lo + (best + 1) * step);
  double t = best == samples ? hi : lo + best * step;
  const double tolerance = 4.0 * std::numeric_limits<double>::epsilon() * (hi - lo);
  for (int iteration = 0; iteration < 200; ++iteration) {
    const CurveSample<Dim> s = eval(t);
    const Vec<Dim> offset = s.r - p;
    const double gradient = offset.dot(s.dr);
    const double curvature = s.dr.squaredNorm() + offset.dot(s.ddr);
    if (!std::isfinite(gradient) || !std::isfinite(curvature))
      throw SolverError(std::string(where) + ": curve evaluation is not finite at parameter " +
                        std::to_string(t));
    if (gradient > 0.0)
      right = t;
    else if (gradient < 0.0)
      left = t;
    else
      return t;
    double next = curvature > 0.0 ? t - gradient / curvature : 0.5 * (left + right);
    if (!(next > left && next < right)) next = 0.5 * (left + right);
    if (std::abs(next - t) <= tolerance || right - left <= tolerance) {
      // The minimum may sit on an end of the interval, where the gradient keeps its sign.
      return std::clamp(next, lo, hi);
    }
    t = next;
  }
  throw SolverError(std::string(where) + ": closest-point iteration did not converge (got " +
                    "bracket width " + std::to_string(right - left) + ", expected below " +
                    std::to_string(tolerance) + ")");
}

}  // namespace meshmotion::detail
