// Boundary reconstruction and analytic projections: cubic-spline chains (thesis app. B),
// circle/sphere, plane, NACA 4-digit and function-graph projections.

#include <catch2/catch.hpp>

#include "meshmotion/core/generators.hpp"
#include "meshmotion/curving/boundary_spline.hpp"
#include "meshmotion/curving/function_graph.hpp"
#include "meshmotion/curving/geometry.hpp"
#include "meshmotion/curving/naca_section.hpp"
#include "meshmotion/curving/surface_reconstruction.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <numbers>
#include <utility>
#include <tuple>
#include <vector>

using namespace meshmotion;

namespace {

BoundaryChain chain_of(std::vector<Index> nodes, bool closed) {
  BoundaryChain chain;
  chain.nodes = std::move(nodes);
  chain.closed = closed;
  return chain;
}

constexpr double pi = std::numbers::pi;

/// Closed chain through the points of `curve(theta)` at n parameter values `theta_k`.
struct Sampled {
  Points<2> points;
  std::vector<BoundaryChain> chains;
};

Sampled closed_curve(const std::function<Vec<2>(double)>& curve,
                     const std::function<double(double)>& parameter, int n) {
  Sampled s;
  s.points.resize(2, n);
  BoundaryChain chain = chain_of({}, true);
  for (int k = 0; k < n; ++k) {
    s.points.col(k) = curve(parameter(static_cast<double>(k) / n));
    chain.nodes.push_back(k);
  }
  s.chains.push_back(chain);
  return s;
}

/// Largest distance from the facet midpoints to the curve, the distance given by `distance`.
double max_midpoint_error(const BoundarySpline& spline,
                          const std::function<double(const Vec<2>&)>& distance) {
  double error = 0.0;
  for (Index f = 0; f < spline.num_facets(); ++f)
    error = std::max(error, distance(spline.midpoint(f)));
  return error;
}

/// Observed orders between successive halvings of h.
std::vector<double> orders(const std::vector<double>& errors) {
  std::vector<double> result;
  for (std::size_t i = 1; i < errors.size(); ++i) result.push_back(std::log2(errors[i - 1] / errors[i]));
  return result;
}

double ellipse_distance(const Vec<2>& p, double a, double b) {
  // |F| / |grad F| for F = (x/a)^2 + (y/b)^2 - 1: the distance up to O(distance^2).
  const double f = p.x() * p.x() / (a * a) + p.y() * p.y() / (b * b) - 1.0;
  const Vec<2> grad(2.0 * p.x() / (a * a), 2.0 * p.y() / (b * b));
  return std::abs(f) / grad.norm();
}

}  // namespace

TEST_CASE("tridiagonal and cyclic solvers match a dense solve", "[curving]") {
  const int n = 9;
  std::vector<double> sub(n), diag(n), sup(n);
  std::vector<Vec<2>> rhs(n);
  Eigen::MatrixXd dense = Eigen::MatrixXd::Zero(n, n);
  Eigen::MatrixXd b(n, 2);
  for (int i = 0; i < n; ++i) {
    const double h0 = 0.3 + 0.1 * ((i * 7) % 5), h1 = 0.2 + 0.15 * ((i * 3) % 4);
    sub[i] = 1.0 / h0;
    sup[i] = 1.0 / h1;
    diag[i] = 2.0 * (sub[i] + sup[i]);
    rhs[i] = Vec<2>(std::sin(i + 1.0), std::cos(3.0 * i));
    b.row(i) = rhs[i].transpose();
    dense(i, i) = diag[i];
    if (i > 0) dense(i, i - 1) = sub[i];
    if (i + 1 < n) dense(i, i + 1) = sup[i];
  }
  SECTION("open") {
    std::vector<double> scratch;
    detail::solve_tridiagonal(std::span<const double>(sub), std::span<const double>(diag),
                              std::span<const double>(sup), std::span<Vec<2>>(rhs), scratch);
    const Eigen::MatrixXd x = dense.partialPivLu().solve(b);
    for (int i = 0; i < n; ++i) CHECK((rhs[i] - x.row(i).transpose()).norm() < 1e-13);
  }
  SECTION("cyclic") {
    dense(n - 1, 0) = 0.7;
    dense(0, n - 1) = 1.3;
    detail::CyclicWorkspace work;
    detail::solve_cyclic_tridiagonal(std::span<const double>(sub), std::span<const double>(diag),
                                     std::span<const double>(sup), 0.7, 1.3,
                                     std::span<Vec<2>>(rhs), work);
    const Eigen::MatrixXd x = dense.partialPivLu().solve(b);
    for (int i = 0; i < n; ++i) CHECK((rhs[i] - x.row(i).transpose()).norm() < 1e-13);
  }
}

TEST_CASE("spline tangents are exact for cubic data on uneven steps", "[curving]") {
  // r(s) = (s^3 - s, 2 s^2 - s^3): not-a-knot reproduces any cubic, natural only lines.
  const std::vector<double> knots{0.0, 0.3, 0.5, 1.1, 1.2, 1.9, 2.4};
  auto curve = [](double s) { return Vec<2>(s * s * s - s, 2.0 * s * s - s * s * s); };
  auto derivative = [](double s) { return Vec<2>(3.0 * s * s - 1.0, 4.0 * s - 3.0 * s * s); };
  std::vector<double> steps;
  std::vector<Vec<2>> values, tangents(knots.size());
  for (std::size_t j = 0; j < knots.size(); ++j) {
    values.push_back(curve(knots[j]));
    if (j + 1 < knots.size()) steps.push_back(knots[j + 1] - knots[j]);
  }
  detail::SplineWorkspace work;
  detail::spline_tangents(steps, values, false, SplineEndCondition::not_a_knot, tangents, work);
  for (std::size_t j = 0; j < knots.size(); ++j)
    CHECK((tangents[j] - derivative(knots[j])).norm() < 1e-12);

  for (std::size_t j = 0; j < knots.size(); ++j) values[j] = Vec<2>(2.0 * knots[j] + 1.0, -knots[j]);
  detail::spline_tangents(steps, values, false, SplineEndCondition::natural, tangents, work);
  for (const Vec<2>& t : tangents) CHECK((t - Vec<2>(2.0, -1.0)).norm() < 1e-12);
}

TEST_CASE("open chain reproduces a cubic curve exactly", "[curving]") {
  auto curve = [](double s) { return Vec<2>(s + 0.2 * s * s, s * s * s - 2.0 * s * s + 0.5); };
  const int n = 8;
  Points<2> points(2, n);
  BoundaryChain chain;
  // Node order differs from chain order: the spline must follow the chain.
  for (int k = 0; k < n; ++k) {
    points.col(n - 1 - k) = curve(0.25 * k);
    chain.nodes.push_back(n - 1 - k);
  }
  BoundarySplineOptions options;
  options.parametrization = SplineParametrization::uniform;
  options.corner_angle = 180.0;
  const std::vector<BoundaryChain> chains{chain};
  const BoundarySpline spline(points, chains, options);
  REQUIRE(spline.num_facets() == n - 1);
  CHECK(spline.corners().size() == 2);
  for (Index f = 0; f < spline.num_facets(); ++f)
    for (double t : {0.0, 0.17, 0.5, 0.83, 1.0})
      CHECK((spline.point(f, t) - curve(0.25 * (f + t))).norm() < 1e-12);

  SECTION("natural ends are exact only where the curve has no second derivative") {
    options.end_condition = SplineEndCondition::natural;
    const BoundarySpline natural(points, chains, options);
    CHECK((natural.midpoint(0) - curve(0.125)).norm() > 1e-4);
  }
}

TEST_CASE("square corners stay sharp: each side is reproduced as a straight segment",
          "[curving]") {
  // 4 sides, 5 facets per side with uneven spacing, counter-clockwise from (0, 0).
  const std::vector<double> along{0.0, 0.1, 0.35, 0.5, 0.8};
  const std::vector<Vec<2>> start{{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  const std::vector<Vec<2>> direction{{1, 0}, {0, 1}, {-1, 0}, {0, -1}};
  Points<2> points(2, 20);
  BoundaryChain chain = chain_of({}, true);
  for (int side = 0; side < 4; ++side)
    for (int k = 0; k < 5; ++k) {
      points.col(side * 5 + k) = start[side] + along[k] * direction[side];
      chain.nodes.push_back(side * 5 + k);
    }
  const std::vector<BoundaryChain> chains{chain};
  // Distance to the lines of the square's sides (zero on the sides and their extensions).
  auto distance_to_square = [](const Vec<2>& p) {
    return std::min({std::abs(p.x()), std::abs(p.y()), std::abs(1.0 - p.x()), std::abs(1.0 - p.y())});
  };
  auto check_sharp = [&](const BoundarySpline& spline) {
    REQUIRE(spline.corners().size() == 4);
    for (Index c : {0, 5, 10, 15}) CHECK(spline.is_corner(c));
    for (Index f = 0; f < spline.num_facets(); ++f) {
      const auto [a, b] = spline.facet_nodes(f);
      for (double t : {0.25, 0.5, 0.75}) {
        const Vec<2> p = spline.point(f, t);
        CHECK(distance_to_square(p) < 1e-14);
        // With chord length the facet is its own straight segment, linearly parametrized;
        // with the uniform parameter it stays on the side's line but the uneven spacing
        // makes it run unevenly (and overshoot the corner: 0.0118 beyond it here).
        if (spline.parametrization() == SplineParametrization::chord_length)
          CHECK((p - ((1.0 - t) * points.col(a) + t * points.col(b))).norm() < 1e-14);
      }
    }
  };
  for (auto parametrization : {SplineParametrization::uniform, SplineParametrization::chord_length,
                               SplineParametrization::centripetal}) {
    BoundarySplineOptions options;
    options.parametrization = parametrization;
    SECTION("detected by the angle threshold") {
      options.corner_angle = 45.0;
      check_sharp(BoundarySpline(points, chains, options));
    }
    SECTION("listed by the user") {
      options.corner_angle = 180.0;
      options.corner_nodes = {15, 0, 10, 5};
      check_sharp(BoundarySpline(points, chains, options));
    }
    SECTION("a threshold above 90 degrees rounds the corners off") {
      options.corner_angle = 100.0;
      const BoundarySpline spline(points, chains, options);
      CHECK(spline.corners().empty());
      CHECK(max_midpoint_error(spline, distance_to_square) > 1e-3);
    }
  }
}

TEST_CASE("corner detection follows the threshold and the user list", "[curving]") {
  // Open polyline turning by 10, 40 and 80 degrees at nodes 1, 2, 3.
  Points<2> points(2, 5);
  double heading = 0.0;
  points.col(0) = Vec<2>::Zero();
  const std::vector<double> turns{10.0, 40.0, 80.0, 0.0};
  for (int k = 1; k < 5; ++k) {
    points.col(k) = points.col(k - 1) + Vec<2>(std::cos(heading), std::sin(heading));
    heading += turns[k - 1] * pi / 180.0;
  }
  const std::vector<BoundaryChain> chains{chain_of({0, 1, 2, 3, 4}, false)};
  auto corners_for = [&](double angle, std::vector<Index> listed) {
    BoundarySplineOptions options;
    options.corner_angle = angle;
    options.corner_nodes = std::move(listed);
    const BoundarySpline spline(points, chains, options);
    return std::vector<Index>(spline.corners().begin(), spline.corners().end());
  };
  CHECK(corners_for(5.0, {}) == std::vector<Index>{0, 1, 2, 3, 4});
  CHECK(corners_for(30.0, {}) == std::vector<Index>{0, 2, 3, 4});
  CHECK(corners_for(60.0, {}) == std::vector<Index>{0, 3, 4});
  CHECK(corners_for(180.0, {}) == std::vector<Index>{0, 4});
  CHECK(corners_for(180.0, {1}) == std::vector<Index>{0, 1, 4});
}

TEST_CASE("midpoints converge at fourth order on smooth closed curves", "[curving]") {
  const double a = 2.0, b = 0.7;
  auto circle = [](double theta) { return Vec<2>(std::cos(theta), std::sin(theta)); };
  auto ellipse = [&](double theta) { return Vec<2>(a * std::cos(theta), b * std::sin(theta)); };
  auto circle_distance = [](const Vec<2>& p) { return std::abs(p.norm() - 1.0); };
  auto ellipse_error = [&](const Vec<2>& p) { return ellipse_distance(p, a, b); };
  auto even = [](double s) { return 2.0 * pi * s; };
  // A smooth but uneven sampling: nodes 4 times denser near theta = 0 than at theta = pi.
  auto graded = [](double s) { return 2.0 * pi * s - 0.6 * std::sin(2.0 * pi * s); };

  struct Case {
    const char* name;
    std::function<Vec<2>(double)> curve;
    std::function<double(double)> parameter;
    std::function<double(const Vec<2>&)> distance;
  };
  const std::vector<Case> cases{{"circle", circle, even, circle_distance},
                                {"ellipse", ellipse, even, ellipse_error},
                                {"graded ellipse", ellipse, graded, ellipse_error}};
  for (const Case& c : cases)
    for (auto parametrization : {SplineParametrization::uniform, SplineParametrization::chord_length,
                                 SplineParametrization::centripetal}) {
      std::vector<double> errors;
      for (int n : {32, 64, 128, 256}) {
        const Sampled s = closed_curve(c.curve, c.parameter, n);
        BoundarySplineOptions options;
        options.parametrization = parametrization;
        options.corner_angle = 180.0;  // the coarsest graded samples turn by more than 30 degrees
        errors.push_back(max_midpoint_error(BoundarySpline(s.points, s.chains, options), c.distance));
      }
      INFO(c.name << (parametrization == SplineParametrization::uniform ? " uniform" : " chord")
                  << ": errors " << errors[0] << " " << errors[1] << " " << errors[2] << " "
                  << errors[3]);
      for (double order : orders(errors)) CHECK(order >= 3.7);
    }
}

namespace {

/// Largest midpoint error of the spline through the unit-circle points at `angles` (one
/// open chain).
double open_arc_error(const std::vector<double>& angles, const BoundarySplineOptions& options) {
  const auto n = static_cast<Index>(angles.size());
  Points<2> points(2, n);
  BoundaryChain chain;
  for (Index k = 0; k < n; ++k) {
    points.col(k) = Vec<2>(std::cos(angles[k]), std::sin(angles[k]));
    chain.nodes.push_back(k);
  }
  const std::vector<BoundaryChain> chains{chain};
  return max_midpoint_error(BoundarySpline(points, chains, options),
                            [](const Vec<2>& p) { return std::abs(p.norm() - 1.0); });
}

}  // namespace

TEST_CASE("centripetal parametrization is the most accurate on graded boundaries",
          "[curving]") {
  // A half circle with boundary-layer-like geometric grading (growth ratio 1.3) towards both
  // ends.
  const int n = 25;
  std::vector<double> angles{0.0};
  for (int k = 1; k < n; ++k) angles.push_back(angles.back() + std::pow(1.3, std::abs(k - n / 2.0)));
  for (double& angle : angles) angle *= pi / angles.back();
  auto error = [&](SplineParametrization parametrization) {
    BoundarySplineOptions options;
    options.parametrization = parametrization;
    return open_arc_error(angles, options);
  };
  const double uniform = error(SplineParametrization::uniform);
  const double chord = error(SplineParametrization::chord_length);
  const double centripetal = error(SplineParametrization::centripetal);
  INFO("uniform " << uniform << ", chord length " << chord << ", centripetal " << centripetal);
  // Measured: 1.2e-3, 3.6e-4, 6.9e-5.
  CHECK(chord < 0.5 * uniform);
  CHECK(centripetal < 0.25 * chord);
  CHECK(BoundarySplineOptions{}.parametrization == SplineParametrization::centripetal);
}

TEST_CASE("not-a-knot ends are more accurate than natural ends on an open arc", "[curving]") {
  std::vector<double> angles;
  for (int k = 0; k <= 16; ++k) angles.push_back(0.5 * pi * k / 16.0);
  auto error = [&](SplineEndCondition end) {
    BoundarySplineOptions options;
    options.end_condition = end;
    return open_arc_error(angles, options);
  };
  const double natural = error(SplineEndCondition::natural);
  const double not_a_knot = error(SplineEndCondition::not_a_knot);
  INFO("natural " << natural << ", not-a-knot " << not_a_knot);
  CHECK(not_a_knot < 0.1 * natural);
}

TEST_CASE("spline queries: arc-length midpoint, closest point, facet lookup", "[curving]") {
  const Sampled s = closed_curve([](double t) { return Vec<2>(2.0 * std::cos(t), std::sin(t)); },
                                 [](double u) { return 2.0 * pi * u; }, 12);
  const BoundarySpline spline(s.points, s.chains);
  REQUIRE(spline.num_facets() == 12);
  CHECK(spline.num_chains() == 1);
  CHECK(spline.chain_first_facet(1) == 12);
  for (Index f = 0; f < spline.num_facets(); ++f) {
    const auto nodes = spline.facet_nodes(f);
    CHECK((spline.point(f, 0.0) - s.points.col(nodes[0])).norm() < 1e-14);
    CHECK((spline.point(f, 1.0) - s.points.col(nodes[1])).norm() < 1e-14);
    const double t = spline.arc_length_parameter(f, 0.5);
    CHECK(spline.arc_length(f, 0.0, t) == Approx(spline.arc_length(f, t, 1.0)).epsilon(1e-12));
    CHECK((spline.arc_length_midpoint(f) - spline.point(f, t)).norm() == 0.0);

    const Vec<2> foot = spline.point(f, 0.3);
    const Vec<2> tangent = spline.tangent(f, 0.3);
    const Vec<2> normal(-tangent.y(), tangent.x());
    const auto closest = spline.closest_point(f, foot + 0.01 * normal.normalized());
    CHECK(closest.t == Approx(0.3).margin(1e-10));
    CHECK(closest.distance == Approx(0.01).epsilon(1e-8));
  }
  const auto forward = spline.find_facet(3, 4);
  const auto backward = spline.find_facet(4, 3);
  REQUIRE(forward);
  REQUIRE(backward);
  CHECK(forward->facet == 3);
  CHECK_FALSE(forward->reversed);
  CHECK(backward->reversed);
  CHECK(spline.find_facet(11, 0)->facet == 11);
  CHECK_FALSE(spline.find_facet(2, 7));
}

TEST_CASE("spline rejects bad chains and points", "[curving]") {
  Points<2> points(2, 4);
  points << 0, 1, 1, 0, 0, 0, 1, 1;
  auto build = [&](std::vector<BoundaryChain> chains, BoundarySplineOptions options = {}) {
    return BoundarySpline(points, chains, std::move(options));
  };
  CHECK_THROWS_AS(build({chain_of({0, 1, 7}, false)}), InputError);
  CHECK_THROWS_AS(build({chain_of({0}, false)}), InputError);
  CHECK_THROWS_AS(build({chain_of({0, 1}, true)}), InputError);
  CHECK_THROWS_AS(build({chain_of({0, 1, 1, 2}, false)}), InputError);
  BoundarySplineOptions nan_angle;
  nan_angle.corner_angle = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_AS(build({chain_of({0, 1, 2}, false)}, nan_angle), InputError);
  const BoundarySpline spline = build({chain_of({0, 1, 2, 3}, true)});
  CHECK_THROWS_AS(spline.point(4, 0.5), InputError);
  CHECK_THROWS_AS(spline.closest_point(0, Vec<2>(std::nan(""), 0.0)), InputError);
  CHECK_THROWS_AS(spline.arc_length_parameter(0, 1.5), InputError);
  points(1, 2) = std::numeric_limits<double>::infinity();
  CHECK_THROWS_WITH(build({chain_of({0, 1, 2, 3}, true)}), Catch::Contains("non-finite"));
}

TEST_CASE("circle, sphere and plane projections are exact", "[curving]") {
  const SphereProjection<2> circle(Vec<2>(1.0, -2.0), 0.5);
  const SphereProjection<3> sphere(Vec<3>(0.0, 1.0, 2.0), 3.0);
  for (int k = 0; k < 20; ++k) {
    const double a = 0.7 * k + 0.1, r = 0.1 + 0.3 * k;
    const Vec<2> p2 = circle(Vec<2>(1.0 + r * std::cos(a), -2.0 + r * std::sin(a)));
    CHECK((p2 - Vec<2>(1.0 + 0.5 * std::cos(a), -2.0 + 0.5 * std::sin(a))).norm() < 1e-14);
    const Vec<3> direction(std::cos(a) * std::sin(2.0 * a), std::sin(a) * std::sin(2.0 * a),
                           std::cos(2.0 * a));
    const Vec<3> p3 = sphere(sphere.center() + r * direction);
    CHECK((p3 - (sphere.center() + 3.0 * direction)).norm() < 1e-14);
  }
  CHECK_THROWS_AS(circle(Vec<2>(1.0, -2.0)), InputError);
  CHECK_THROWS_AS(sphere(Vec<3>(std::nan(""), 0.0, 0.0)), InputError);
  CHECK_THROWS_AS(SphereProjection<2>(Vec<2>::Zero(), -1.0), InputError);

  const PlaneProjection<3> plane(Vec<3>(0.0, 0.0, 1.0), Vec<3>(0.0, 0.0, 2.0));
  CHECK((plane(Vec<3>(3.0, -1.0, 7.0)) - Vec<3>(3.0, -1.0, 1.0)).norm() < 1e-15);
  CHECK_THROWS_AS(PlaneProjection<2>(Vec<2>::Zero(), Vec<2>::Zero()), InputError);
  const BoundaryProjection<2> callback = circle;
  CHECK((callback(Vec<2>(3.0, -2.0)) - Vec<2>(1.5, -2.0)).norm() < 1e-15);
}

namespace {

/// Closest of `samples` dense samples of the section's two surfaces to p (chord units).
double sampled_distance(const NacaProjection& naca, const Vec<2>& p, int samples) {
  double best = std::numeric_limits<double>::infinity();
  for (int k = 0; k <= samples; ++k)
    for (bool upper : {true, false})
      best = std::min(best, (naca.surface_point(static_cast<double>(k) / samples, upper) - p).norm());
  return best;
}

}  // namespace

TEST_CASE("NACA projection lands on the section at its closest point", "[curving]") {
  SECTION("symmetric 0012: the thickness law holds to round-off") {
    const NacaProjection naca(naca4("0012"));
    for (int k = 0; k < 40; ++k) {
      const double angle = 2.0 * pi * k / 40.0;
      const Vec<2> p(0.5 + 0.6 * std::cos(angle), 0.15 * std::sin(angle));
      const Vec<2> q = naca(p);
      REQUIRE(q.x() >= 0.0);
      CHECK(std::abs(std::abs(q.y()) - naca.half_thickness(q.x())) < 1e-12);
      CHECK((q - p).norm() <= sampled_distance(naca, p, 20000) + 1e-9);
    }
  }
  SECTION("cambered 2412, scaled and moved, open trailing edge") {
    NacaParameters params = naca4("2412", false);
    params.chord = 2.0;
    params.leading_edge = Vec<2>(-1.0, 0.5);
    const NacaProjection naca(params);
    for (int k = 0; k < 40; ++k) {
      const double angle = 2.0 * pi * k / 40.0;
      const Vec<2> p = params.leading_edge + Vec<2>(1.0 + 1.3 * std::cos(angle), 0.3 * std::sin(angle));
      const Vec<2> q = naca(p);
      // The base of the open trailing edge is part of the section too.
      const Vec<2> top = naca.surface_point(1.0, true), bottom = naca.surface_point(1.0, false);
      const Vec<2> base = bottom - top;
      const double s = std::clamp((p - top).dot(base) / base.squaredNorm(), 0.0, 1.0);
      const double reference =
          std::min(sampled_distance(naca, p, 20000), (top + s * base - p).norm());
      CHECK((q - p).norm() <= reference + 1e-9);
      CHECK((q - p).norm() >= reference - 1e-6);
    }
    CHECK(naca.half_thickness(1.0) > 1e-3);
  }
  CHECK(NacaProjection(naca4("0012")).half_thickness(1.0) == Approx(0.0).margin(1e-15));
  CHECK_THROWS_AS(naca4("00x2"), InputError);
  CHECK_THROWS_AS(NacaProjection(naca4("0000")), InputError);
  CHECK_THROWS_AS(NacaProjection(naca4("0012"))(Vec<2>(std::nan(""), 0.0)), InputError);
}

TEST_CASE("3D bump-in-channel wall: derivatives match differences, profile matches the generator", "[curving]") {
  const double h = 1e-5;
  for (int k = 0; k < 40; ++k) {
    const double x = 0.25 + 1.2 * k / 39.0, y = -0.97 * std::fmod(0.37 * k, 1.0);
    const GraphSample2 g = nasa_bump_3d_height(x, y);
    const auto value = [](double a, double b) { return nasa_bump_3d_height(a, b).value; };
    const auto gradient = [](double a, double b) { return nasa_bump_3d_height(a, b).gradient; };
    INFO("x " << x << ", y " << y);
    CHECK(g.value == Approx(bump_channel_height(x - bump_channel_shift(y))).epsilon(1e-13));
    CHECK(g.gradient.x() == Approx((value(x + h, y) - value(x - h, y)) / (2 * h)).margin(1e-8));
    CHECK(g.gradient.y() == Approx((value(x, y + h) - value(x, y - h)) / (2 * h)).margin(1e-8));
    const Eigen::Matrix2d hessian = (Eigen::Matrix2d() << (gradient(x + h, y) - gradient(x - h, y)) / (2 * h),
                                     (gradient(x, y + h) - gradient(x, y - h)) / (2 * h)).finished();
    CHECK((g.hessian - hessian).norm() < 1e-6);
    CHECK(g.hessian(0, 1) == g.hessian(1, 0));
  }
}

TEST_CASE("function-graph projections find the closest point of the bump", "[curving]") {
  const GraphProjection2 bump = nasa_bump_2d();
  const GraphProjection3 bump3 = nasa_bump_3d();
  for (int k = 0; k < 30; ++k) {
    const Vec<2> p(0.1 + 1.2 * k / 29.0, 0.02 + 0.05 * std::sin(1.7 * k));
    const Vec<2> q = bump(p);
    CHECK(std::abs(q.y() - nasa_bump_height(q.x()).value) < 1e-15);
    double sampled = std::numeric_limits<double>::infinity();
    for (int j = 0; j <= 20000; ++j) {
      const double x = p.x() - 0.2 + 0.4 * j / 20000.0;
      sampled = std::min(sampled, (Vec<2>(x, nasa_bump_height(x).value) - p).norm());
    }
    CHECK((q - p).norm() <= sampled + 1e-9);
    // The side planes of the 3D bump (y = 0, -1) are unshifted symmetry planes: the 2D point.
    const double side = k % 2 == 0 ? 0.0 : -1.0;
    const Vec<3> q3 = bump3(Vec<3>(p.x(), side, p.y()));
    CHECK((Vec<2>(q3.x(), q3.z()) - q).norm() < 1e-10);
    CHECK(std::abs(q3.y() - side) < 1e-14);
    // Inside the span the profile is shifted by 0.3 sin^4(pi y): on the wall, and no sample
    // of the wall around the point is closer.
    const double y = -0.04 - 0.92 * k / 29.0;
    const Vec<3> p3(p.x() + 0.3 * std::pow(std::sin(std::numbers::pi * y), 4), y, p.y());
    const Vec<3> r = bump3(p3);
    CHECK(std::abs(r.z() - nasa_bump_3d_height(r.x(), r.y()).value) < 1e-15);
    double sampled3 = std::numeric_limits<double>::infinity();
    for (int a = 0; a <= 300; ++a)
      for (int b = 0; b <= 300; ++b) {
        const double sx = p3.x() - 0.15 + 0.3 * a / 300.0, sy = p3.y() - 0.15 + 0.3 * b / 300.0;
        sampled3 = std::min(sampled3, (Vec<3>(sx, sy, nasa_bump_3d_height(sx, sy).value) - p3).norm());
      }
    CHECK((r - p3).norm() <= sampled3 + 1e-12);
  }
  // A smooth 3D graph with curvature in both directions: the stationarity condition holds.
  const GraphProjection3 dome([](double x, double y) {
    GraphSample2 g{0.3 * x * x - 0.2 * y * y + 0.1 * x * y, {0.6 * x + 0.1 * y, -0.4 * y + 0.1 * x},
                   Eigen::Matrix2d::Zero()};
    g.hessian << 0.6, 0.1, 0.1, -0.4;
    return g;
  });
  const Vec<3> p(0.4, -0.3, 0.5);
  const Vec<3> q = dome(p);
  const Vec<3> tx(1.0, 0.0, 0.6 * q.x() + 0.1 * q.y()), ty(0.0, 1.0, -0.4 * q.y() + 0.1 * q.x());
  CHECK(std::abs((q - p).dot(tx)) < 1e-13);
  CHECK(std::abs((q - p).dot(ty)) < 1e-13);
  CHECK_THROWS_AS(bump(Vec<2>(std::nan(""), 0.0)), InputError);
  const GraphProjection2 broken([](double) { return GraphSample1{std::nan(""), 0.0, 0.0}; });
  CHECK_THROWS_AS(broken(Vec<2>(0.0, 1.0)), SolverError);
}

namespace {

struct TriangleSurface {
  Points<3> points;
  std::vector<Index> triangles;
};

TriangleSurface from_vectors(const std::vector<Vec<3>>& vertices, std::vector<Index> triangles) {
  TriangleSurface s;
  s.points.resize(3, static_cast<Index>(vertices.size()));
  for (std::size_t i = 0; i < vertices.size(); ++i) s.points.col(static_cast<Index>(i)) = vertices[i];
  s.triangles = std::move(triangles);
  return s;
}

/// Unit icosphere: the icosahedron with every triangle split in four `levels` times.
TriangleSurface icosphere(int levels) {
  const double g = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Vec<3>> v{{-1, g, 0}, {1, g, 0}, {-1, -g, 0}, {1, -g, 0}, {0, -1, g}, {0, 1, g},
                        {0, -1, -g}, {0, 1, -g}, {g, 0, -1}, {g, 0, 1}, {-g, 0, -1}, {-g, 0, 1}};
  for (Vec<3>& x : v) x.normalize();
  std::vector<Index> t{0, 11, 5, 0, 5, 1, 0, 1, 7, 0, 7, 10, 0, 10, 11, 1, 5, 9, 5, 11, 4,
                       11, 10, 2, 10, 7, 6, 7, 1, 8, 3, 9, 4, 3, 4, 2, 3, 2, 6, 3, 6, 8,
                       3, 8, 9, 4, 9, 5, 2, 4, 11, 6, 2, 10, 8, 6, 7, 9, 8, 1};
  for (int level = 0; level < levels; ++level) {
    std::map<std::pair<Index, Index>, Index> middle;
    auto mid = [&](Index a, Index b) {
      const auto key = std::minmax(a, b);
      if (const auto it = middle.find(key); it != middle.end()) return it->second;
      v.push_back((v[static_cast<std::size_t>(a)] + v[static_cast<std::size_t>(b)]).normalized());
      return middle[key] = static_cast<Index>(v.size()) - 1;
    };
    std::vector<Index> finer;
    for (std::size_t i = 0; i < t.size(); i += 3) {
      const Index a = t[i], b = t[i + 1], c = t[i + 2];
      const Index ab = mid(a, b), bc = mid(b, c), ca = mid(c, a);
      for (Index x : {a, ab, ca, ab, b, bc, ca, bc, c, ab, bc, ca}) finer.push_back(x);
    }
    t = std::move(finer);
  }
  return from_vectors(v, std::move(t));
}

/// Quads (i, j) -> (i+1, j+1) of an (nu+1) × (nv+1) grid of `point(i, j)`, two triangles each.
void add_grid(std::vector<Vec<3>>& v, std::vector<Index>& t, int nu, int nv,
              const std::function<Vec<3>(int, int)>& point, bool wrap_u) {
  const auto base = static_cast<Index>(v.size());
  const int columns = wrap_u ? nu : nu + 1;
  for (int j = 0; j <= nv; ++j)
    for (int i = 0; i < columns; ++i) v.push_back(point(i, j));
  auto id = [&](int i, int j) { return base + j * columns + (i % columns); };
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i)
      for (Index x : {id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j), id(i + 1, j + 1), id(i, j + 1)})
        t.push_back(x);
}

/// Largest |distance(p)| over the reconstructed midpoints of all edges and triangle centres.
double max_reconstruction_error(const TriangleSurface& s, const SurfaceReconstruction& r,
                                const std::function<double(const Vec<3>&)>& distance) {
  double error = 0.0;
  auto record = [&](double d) { error = std::isnan(d) || std::isnan(error) ? NAN : std::max(error, d); };
  for (Index t = 0; t < r.num_triangles(); ++t) {
    for (int k = 0; k < 3; ++k)
      record(distance(r.edge_midpoint(s.triangles[3 * t + k], s.triangles[3 * t + (k + 1) % 3])));
    record(distance(r.point(t, Vec<3>::Constant(1.0 / 3.0))));
  }
  return error;
}

}  // namespace

TEST_CASE("surface reconstruction converges at h^3 or faster on a sphere", "[curving]") {
  auto sphere_distance = [](const Vec<3>& p) { return std::abs(p.norm() - 1.0); };
  for (int degree : {2, 3}) {
    std::vector<double> errors;
    double linear = 0.0;
    for (int level = 1; level <= 4; ++level) {
      const TriangleSurface s = icosphere(level);
      SurfaceReconstructionOptions options;
      options.degree = degree;
      const SurfaceReconstruction r(s.points, s.triangles, options);
      errors.push_back(max_reconstruction_error(s, r, sphere_distance));
      linear = 0.0;
      for (std::size_t i = 0; i < s.triangles.size(); i += 3)
        linear = std::max(linear, sphere_distance(0.5 * (s.points.col(s.triangles[i]) +
                                                         s.points.col(s.triangles[i + 1]))));
    }
    INFO("degree " << degree << ": errors " << errors[0] << " " << errors[1] << " " << errors[2]
                   << " " << errors[3] << " (straight midpoints " << linear << ")");
    for (double order : orders(errors)) CHECK(order >= 3.0);
    CHECK(errors.back() < 0.01 * linear);
  }
}

TEST_CASE("surface reconstruction keeps the edges and corners of a cube sharp", "[curving]") {
  // Cube [-1, 1]^3, 3 × 3 quads per face.
  std::vector<Vec<3>> v;
  std::vector<Index> t;
  const int n = 3;
  for (int axis = 0; axis < 3; ++axis)
    for (double side : {-1.0, 1.0})
      add_grid(v, t, n, n, [&](int i, int j) {
        Vec<3> p;
        p[axis] = side;
        // Orientation does not matter to the reconstruction; the grid is uneven on purpose
        // (the same spacing in both directions, so faces meet node to node).
        auto graded = [&](int k) { return -1.0 + 2.0 * std::pow(static_cast<double>(k) / n, 1.3); };
        p[(axis + 1) % 3] = graded(i);
        p[(axis + 2) % 3] = graded(j);
        return p;
      }, false);
  // Merge the duplicated nodes along the cube's edges.
  std::vector<Index> unique_of(v.size());
  std::vector<Vec<3>> merged;
  for (std::size_t i = 0; i < v.size(); ++i) {
    unique_of[i] = static_cast<Index>(merged.size());
    for (std::size_t j = 0; j < merged.size(); ++j)
      if ((merged[j] - v[i]).norm() < 1e-12) unique_of[i] = static_cast<Index>(j);
    if (unique_of[i] == static_cast<Index>(merged.size())) merged.push_back(v[i]);
  }
  for (Index& x : t) x = unique_of[static_cast<std::size_t>(x)];
  const TriangleSurface s = from_vectors(merged, t);
  REQUIRE(s.points.cols() == 6 * 4 + 12 * 2 + 8);  // closed: the faces share their borders
  auto cube_distance = [](const Vec<3>& p) { return std::abs(p.cwiseAbs().maxCoeff() - 1.0); };

  const SurfaceReconstruction sharp(s.points, s.triangles);
  // Node 0 of the first face is the corner (-1, -1, -1); node 1 lies on the edge x = z = -1,
  // node 5 inside the face x = -1.
  CHECK(sharp.is_ridge(unique_of[0], unique_of[1]));
  CHECK_FALSE(sharp.is_ridge(unique_of[1], unique_of[5]));
  CHECK(max_reconstruction_error(s, sharp, cube_distance) < 1e-12);
  SurfaceReconstructionOptions no_ridges;
  no_ridges.ridge_angle = 180.0;
  const SurfaceReconstruction rounded(s.points, s.triangles, no_ridges);
  CHECK(max_reconstruction_error(s, rounded, cube_distance) > 1e-3);
}

TEST_CASE("surface reconstruction keeps an open surface's border corners sharp", "[curving]") {
  // A curved open patch z = 0.2 x^2 over [0, 1]^2 (a wall cut by four sides of the domain):
  // its border turns by 90 degrees at each corner, and each side of the border is a curve in
  // its own plane. Fitted as one smooth curve through a corner, the border bulged across the
  // corner (the WALF drift that left invalid cells where a curved wall met two planes).
  std::vector<Vec<3>> v;
  std::vector<Index> t;
  const int n = 4;
  add_grid(v, t, n, n, [&](int i, int j) {
    const double x = static_cast<double>(i) / n, y = static_cast<double>(j) / n;
    return Vec<3>(x, y, 0.2 * x * x);
  }, false);
  const TriangleSurface s = from_vectors(v, t);
  const SurfaceReconstruction r(s.points, s.triangles);
  const auto id = [&](int i, int j) { return static_cast<Index>(j * (n + 1) + i); };
  double off_side = 0.0, off_parabola = 0.0;
  for (int k = 0; k < n; ++k)
    for (const auto& [a, b, axis, value] : {std::tuple{id(k, 0), id(k + 1, 0), 1, 0.0}, std::tuple{id(k, n), id(k + 1, n), 1, 1.0},
                                            std::tuple{id(0, k), id(0, k + 1), 0, 0.0}, std::tuple{id(n, k), id(n, k + 1), 0, 1.0}}) {
      REQUIRE(r.is_ridge(a, b));
      for (const double f : {0.25, 0.5, 0.75}) {
        const Vec<3> p = r.edge_point(a, b, f);
        off_side = std::max(off_side, std::abs(p[axis] - value));
        off_parabola = std::max(off_parabola, std::abs(p.z() - 0.2 * p.x() * p.x()));
      }
    }
  INFO("off the side's plane " << off_side << ", off the patch " << off_parabola);
  CHECK(off_side < 1e-12);
  CHECK(off_parabola < 1e-3);
}

TEST_CASE("surface reconstruction follows a curved ridge: the rim of a cylinder", "[curving]") {
  // Unit cylinder side (0 <= z <= 1) with a flat cap at z = 1: the rim is a 90-degree ridge.
  auto rim_distance = [](const Vec<3>& p) {
    return std::abs(p.head<2>().norm() - 1.0) + std::abs(p.z() - 1.0);
  };
  std::vector<double> errors;
  for (int m : {16, 32, 64}) {
    std::vector<Vec<3>> v;
    std::vector<Index> t;
    add_grid(v, t, m, 4, [&](int i, int j) {
      const double angle = 2.0 * pi * i / m;
      return Vec<3>(std::cos(angle), std::sin(angle), 0.25 * j);
    }, true);
    // Cap: the rim (the side's top row) and an inner ring at radius 0.5, plus a centre.
    const auto rim = static_cast<Index>(4 * m);
    const auto inner = static_cast<Index>(v.size());
    for (int i = 0; i < m; ++i) {
      const double angle = 2.0 * pi * (i + 0.5) / m;
      v.push_back(Vec<3>(0.5 * std::cos(angle), 0.5 * std::sin(angle), 1.0));
    }
    const auto centre = static_cast<Index>(v.size());
    v.push_back(Vec<3>(0.0, 0.0, 1.0));
    for (Index i = 0; i < m; ++i) {
      const Index next = (i + 1) % m;
      for (Index x : {rim + i, rim + next, inner + i, inner + i, rim + next, inner + next,
                      inner + i, inner + next, centre})
        t.push_back(x);
    }
    const TriangleSurface s = from_vectors(v, t);
    const SurfaceReconstruction r(s.points, s.triangles);
    double error = 0.0;
    for (Index i = 0; i < m; ++i) {
      REQUIRE(r.is_ridge(rim + i, rim + (i + 1) % m));
      error = std::max(error, rim_distance(r.edge_midpoint(rim + i, rim + (i + 1) % m)));
    }
    errors.push_back(error);
  }
  INFO("rim errors " << errors[0] << " " << errors[1] << " " << errors[2]);
  for (double order : orders(errors)) CHECK(order >= 3.0);
}

TEST_CASE("surface reconstruction rejects bad input", "[curving]") {
  const TriangleSurface s = icosphere(1);
  SurfaceReconstructionOptions bad_degree;
  bad_degree.degree = 4;
  CHECK_THROWS_AS(SurfaceReconstruction(s.points, s.triangles, bad_degree), InputError);
  std::vector<Index> truncated(s.triangles.begin(), s.triangles.end() - 1);
  CHECK_THROWS_AS(SurfaceReconstruction(s.points, truncated), InputError);
  std::vector<Index> out_of_range = s.triangles;
  out_of_range[4] = s.points.cols();
  CHECK_THROWS_AS(SurfaceReconstruction(s.points, out_of_range), InputError);
  std::vector<Index> degenerate = s.triangles;
  degenerate[1] = degenerate[0];
  CHECK_THROWS_AS(SurfaceReconstruction(s.points, degenerate), InputError);
  const SurfaceReconstruction r(s.points, s.triangles);
  CHECK_THROWS_AS(r.edge_midpoint(s.triangles[0], s.triangles[0]), InputError);
  // A lone triangle has too few points for any fitting.
  const std::vector<Index> lone{0, 1, 2};
  CHECK_THROWS_AS(SurfaceReconstruction(s.points, lone), SolverError);
}
