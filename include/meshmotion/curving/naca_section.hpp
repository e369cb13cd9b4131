#pragma once
/// \file
/// NACA 4-digit airfoil section as a boundary projection (closest point on its surface).
/// Abbott & von Doenhoff, "Theory of Wing Sections", ch. 6: thickness
/// y_t = 5 t (0.2969 sqrt(x) - 0.1260 x - 0.3516 x^2 + 0.2843 x^3 - 0.1015 x^4), the last
/// coefficient -0.1036 for a closed trailing edge; mean line y_c of maximum camber m at
/// chord fraction p; surface points offset from the mean line along its normal.

#include "meshmotion/core/error.hpp"
#include "meshmotion/core/types.hpp"
#include "meshmotion/curving/detail/closest_point.hpp"
#include "meshmotion/curving/geometry.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <string_view>

namespace meshmotion {

/// Shape and placement of a NACA 4-digit section.
struct NacaParameters {
  double max_camber = 0.0;       ///< m, fraction of chord (first digit / 100)
  double camber_position = 0.0;  ///< p, fraction of chord (second digit / 10)
  double thickness = 0.12;       ///< t, fraction of chord (last two digits / 100)
  double chord = 1.0;
  Vec<2> leading_edge = Vec<2>::Zero();
  bool closed_trailing_edge = true;  ///< -0.1036 instead of -0.1015 in the thickness law
};

/// Parameters of the section "MPTT" (e.g. "0012", "2412"), unit chord at the origin.
/// Throws InputError unless `digits` is four decimal digits.
[[nodiscard]] inline NacaParameters naca4(std::string_view digits, bool closed_trailing_edge = true) {
  if (digits.size() != 4 || !std::all_of(digits.begin(), digits.end(),
                                         [](char ch) { return ch >= '0' && ch <= '9'; }))
    throw InputError("naca4: invalid designation (got \"" + std::string(digits) +
                     "\", expected four digits such as \"0012\")");
  NacaParameters params;
  params.max_camber = (digits[0] - '0') / 100.0;
  params.camber_position = (digits[1] - '0') / 10.0;
  params.thickness = ((digits[2] - '0') * 10 + (digits[3] - '0')) / 100.0;
  params.closed_trailing_edge = closed_trailing_edge;
  return params;
}

/// Closest-point projection onto a NACA 4-digit section (upper and lower surfaces, and the
/// base of an open trailing edge). Each surface is parametrized by u = sqrt(x/c), which
/// removes the square-root singularity of the thickness law at the leading edge, and
/// projected by a bracketed Newton iteration from the best of 32 samples.
class NacaProjection {
 public:
  /// Throws InputError for a thickness outside (0, 0.4], a camber outside [0, 0.1), a
  /// camber position outside (0, 1) for a cambered section, or a non-positive chord.
  explicit NacaProjection(const NacaParameters& params) : params_(params) {
    const auto fail = [](const std::string& what) {
      throw InputError("NacaProjection: " + what);
    };
    if (!(params.thickness > 0.0 && params.thickness <= 0.4))
      fail("invalid thickness (got " + std::to_string(params.thickness) + ", expected (0, 0.4])");
    if (!(params.max_camber >= 0.0 && params.max_camber < 0.1))
      fail("invalid camber (got " + std::to_string(params.max_camber) + ", expected [0, 0.1))");
    if (params.max_camber > 0.0 && !(params.camber_position > 0.0 && params.camber_position < 1.0))
      fail("invalid camber position (got " + std::to_string(params.camber_position) +
           ", expected (0, 1))");
    if (!(params.chord > 0.0) || !std::isfinite(params.chord))
      fail("invalid chord (got " + std::to_string(params.chord) + ", expected > 0)");
    detail::require_finite_point<2>(params.leading_edge, "NacaProjection");
    coefficients_ = {0.2969, -0.1260, -0.3516, 0.2843,
                     params.closed_trailing_edge ? -0.1036 : -0.1015};
  }

  /// Half thickness y_t at chord fraction x in [0, 1], in chord units.
  [[nodiscard]] double half_thickness(double x) const {
    return 5.0 * params_.thickness * thickness_polynomial(std::sqrt(x))[0];
  }
  /// Mean-line height y_c at chord fraction x in [0, 1], in chord units.
  [[nodiscard]] double camber(double x) const { return camber_line(x)[0]; }

  /// Point of the upper (`upper`) or lower surface at u = sqrt(x/c), u in [0, 1].
  [[nodiscard]] Vec<2> surface_point(double u, bool upper) const {
    return params_.leading_edge + params_.chord * sample(u, upper ? 1.0 : -1.0).r;
  }

  /// Closest point of the section to p. Throws InputError for a non-finite p and
  /// SolverError when the iteration fails.
  [[nodiscard]] Vec<2> operator()(const Vec<2>& p) const {
    detail::require_finite_point<2>(p, "NacaProjection");
    // Scaling and translation preserve closest points: work in chord units.
    const Vec<2> q = (p - params_.leading_edge) / params_.chord;
    Vec<2> best = Vec<2>::Zero();
    double best_distance = std::numeric_limits<double>::infinity();
    for (const double side : {1.0, -1.0}) {
      const double u = detail::closest_parameter<2>(
          [&](double s) { return sample(s, side); }, q, 0.0, 1.0, 32, "NacaProjection");
      const Vec<2> candidate = sample(u, side).r;
      const double distance = (candidate - q).norm();
      if (distance < best_distance) {
        best_distance = distance;
        best = candidate;
      }
    }
    if (!params_.closed_trailing_edge) {
      const Vec<2> top = sample(1.0, 1.0).r, bottom = sample(1.0, -1.0).r;
      const Vec<2> base = bottom - top;
      const double s = std::clamp((q - top).dot(base) / base.squaredNorm(), 0.0, 1.0);
      const Vec<2> candidate = top + s * base;
      if ((candidate - q).norm() < best_distance) best = candidate;
    }
    return params_.leading_edge + params_.chord * best;
  }

  [[nodiscard]] const NacaParameters& parameters() const noexcept { return params_; }

 private:
  /// Thickness polynomial in u = sqrt(x) and its first two u-derivatives (without 5 t).
  [[nodiscard]] std::array<double, 3> thickness_polynomial(double u) const {
    const auto& a = coefficients_;
    const double u2 = u * u, u4 = u2 * u2, u6 = u4 * u2;
    return {a[0] * u + a[1] * u2 + a[2] * u4 + a[3] * u6 + a[4] * u4 * u4,
            a[0] + 2.0 * a[1] * u + 4.0 * a[2] * u2 * u + 6.0 * a[3] * u4 * u + 8.0 * a[4] * u6 * u,
            2.0 * a[1] + 12.0 * a[2] * u2 + 30.0 * a[3] * u4 + 56.0 * a[4] * u6};
  }

  /// Mean line y_c and its first two x-derivatives.
  [[nodiscard]] std::array<double, 3> camber_line(double x) const {
    const double m = params_.max_camber, p = params_.camber_position;
    if (m == 0.0) return {0.0, 0.0, 0.0};
    const double scale = x < p ? m / (p * p) : m / ((1.0 - p) * (1.0 - p));
    const double offset = x < p ? 0.0 : 1.0 - 2.0 * p;
    return {scale * (offset + 2.0 * p * x - x * x), 2.0 * scale * (p - x), -2.0 * scale};
  }

  /// Surface point and u-derivatives in chord units; side = +1 upper, -1 lower.
  [[nodiscard]] detail::CurveSample<2> sample(double u, double side) const {
    const double x = u * u, x_u = 2.0 * u, x_uu = 2.0;
    const auto poly = thickness_polynomial(u);
    const double scale = side * 5.0 * params_.thickness;
    const double yt = scale * poly[0], yt_u = scale * poly[1], yt_uu = scale * poly[2];
    const auto [yc, k, kk] = camber_line(x);
    // theta = atan(dy_c/dx), the mean-line slope angle, and its u-derivatives.
    const double w = 1.0 + k * k;
    const double sin_t = k / std::sqrt(w), cos_t = 1.0 / std::sqrt(w);
    const double theta_x = kk / w, theta_xx = -2.0 * k * kk * kk / (w * w);
    const double th_u = theta_x * x_u, th_uu = theta_xx * x_u * x_u + theta_x * x_uu;
    detail::CurveSample<2> s;
    s.r = {x - yt * sin_t, yc + yt * cos_t};
    s.dr = {x_u - yt_u * sin_t - yt * cos_t * th_u, k * x_u + yt_u * cos_t - yt * sin_t * th_u};
    s.ddr = {x_uu - yt_uu * sin_t - 2.0 * yt_u * cos_t * th_u + yt * sin_t * th_u * th_u -
                 yt * cos_t * th_uu,
             kk * x_u * x_u + k * x_uu + yt_uu * cos_t - 2.0 * yt_u * sin_t * th_u -
                 yt * cos_t * th_u * th_u - yt * sin_t * th_uu};
    return s;
  }

  NacaParameters params_;
  std::array<double, 5> coefficients_{};
};

}  // namespace meshmotion
