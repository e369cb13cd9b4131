// The curving pipeline: boundary-layer estimate, blending regularizer, snapping, and the
// whole linear -> certified P2 pipeline on circles, boundary layers, every element type
// and a 3D sphere.

#include <catch2/catch.hpp>

#include "test_data.hpp"

#include "meshmotion/core/generators.hpp"
#include "meshmotion/core/shape_functions.hpp"
#include "meshmotion/core/topology.hpp"
#include "meshmotion/movers/blend.hpp"
#include "meshmotion/movers/boundary_layer.hpp"
#include "meshmotion/curving/curve_mesh.hpp"
#include "meshmotion/curving/function_graph.hpp"
#include "meshmotion/curving/geometry.hpp"
#include "meshmotion/curving/p2_conversion.hpp"
#include "meshmotion/io/mesh_io.hpp"
#include "meshmotion/spatial/kd_tree.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

using namespace meshmotion;

namespace {

// The O-mesh layer by construction: ring j at wall distance s_j = h1 (g^j - 1)/(g - 1); the
// cell of layer j is w_j (inner chord) by h1 g^j with outer chord w_{j+1}. Returns the
// distance where the first cell with aspect ratio below `threshold` starts.
double o_mesh_layer_thickness(const OMeshOptions& o, double threshold) {
  const double h1 = o.first_height, g = o.growth;
  const auto s = [&](Index j) { return h1 * (std::pow(g, static_cast<double>(j)) - 1.0) / (g - 1.0); };
  const auto chord = [&](Index j) {
    return 2.0 * (o.semi_axis_x + s(j)) * std::sin(std::numbers::pi / static_cast<double>(o.n_around));
  };
  for (Index j = 0; j < o.n_radial; ++j) {
    const double h = h1 * std::pow(g, static_cast<double>(j));
    const double ratio = std::max(chord(j + 1), h) / std::min(chord(j), h);
    if (ratio < threshold) return s(j);
  }
  return s(o.n_radial);
}

const std::vector<std::string> wall_group{"wall"};

// The graph z = a sin(πx) sin(πy) over the unit square, with its derivatives.
auto sine_bump(double a) {
  return [a](double x, double y) {
    const double p = std::numbers::pi;
    GraphSample2 g;
    g.value = a * std::sin(p * x) * std::sin(p * y);
    g.gradient << a * p * std::cos(p * x) * std::sin(p * y), a * p * std::sin(p * x) * std::cos(p * y);
    g.hessian << -p * p * g.value, a * p * p * std::cos(p * x) * std::cos(p * y), a * p * p * std::cos(p * x) * std::cos(p * y),
        -p * p * g.value;
    return g;
  };
}

}  // namespace

TEST_CASE("boundary layer: thickness of a generated O-mesh layer is the one built", "[curving]") {
  OMeshOptions o;
  o.n_around = 64;
  o.n_radial = 40;
  o.first_height = 1e-4;
  o.growth = 1.2;
  for (const double threshold : {2.0, 3.0, 4.0}) {
    const Mesh<2> mesh = o_mesh(o);
    const auto estimate = estimate_boundary_layer(mesh, wall_group, {threshold});
    const double expected = o_mesh_layer_thickness(o, threshold);
    INFO("threshold " << threshold << ", expected " << expected);
    REQUIRE(expected > 10 * o.first_height);
    CHECK(estimate.wall("wall").thickness == Approx(expected).epsilon(1e-9));
    CHECK(estimate.wall("wall").max_thickness == Approx(expected).epsilon(1e-9));
    CHECK(estimate.wall_nodes.size() == 64);
  }
  SECTION("triangles: the same layer to within one cell") {
    o.triangles = true;
    const Mesh<2> mesh = o_mesh(o);
    const double expected = o_mesh_layer_thickness(o, 3.0);
    const double estimate = estimate_boundary_layer(mesh, wall_group).wall("wall").thickness;
    CHECK(estimate >= expected / o.growth);
    CHECK(estimate <= expected * o.growth * o.growth);
  }
  SECTION("an isotropic mesh has no layer") {
    const Mesh<2> grid = rectangle_mesh({});
    const std::vector<std::string> bottom{"bottom"};
    CHECK(estimate_boundary_layer(grid, bottom).wall("bottom").thickness == 0.0);
  }
  SECTION("bad input") {
    const Mesh<2> mesh = o_mesh(o);
    CHECK_THROWS_AS(estimate_boundary_layer(mesh, std::vector<std::string>{}), InputError);
    CHECK_THROWS_AS(estimate_boundary_layer(mesh, std::vector<std::string>{"nope"}), InputError);
    CHECK_THROWS_AS(estimate_boundary_layer(mesh, wall_group, {0.5}), InputError);
  }
}

TEST_CASE("wall distance: the closest point within a reach is the closest point, found by one pruned search", "[curving]") {
  // A wall of 64 segments on the unit circle; queries inside, on and outside it.
  constexpr Index n = 64;
  Points<2> points(2, n);
  std::vector<detail::WallFacet> facets;
  for (Index i = 0; i < n; ++i) {
    const double a = 2.0 * std::numbers::pi * static_cast<double>(i) / static_cast<double>(n);
    points.col(i) = Vec<2>(std::cos(a), std::sin(a));
    facets.push_back({ElementType::line2, {i, (i + 1) % n}});
  }
  const detail::WallDistance<2> wall(points, facets);
  const double reach = 0.3;
  for (int k = 0; k < 200; ++k) {
    const double r = 0.5 + 0.005 * k, a = 0.37 * k;
    const Vec<2> x(r * std::cos(a), r * std::sin(a));
    // Brute force: the nearest vertex decides "within", every facet the closest point.
    double vertex = std::numeric_limits<double>::infinity(), facet = vertex;
    for (Index i = 0; i < n; ++i) {
      vertex = std::min(vertex, (points.col(i) - x).norm());
      const Vec<2> a0 = points.col(i), a1 = points.col((i + 1) % n);
      const double t = std::clamp((x - a0).dot(a1 - a0) / (a1 - a0).squaredNorm(), 0.0, 1.0);
      facet = std::min(facet, (a0 + t * (a1 - a0) - x).norm());
    }
    const auto within = wall.closest_within(x, reach);
    REQUIRE(within.has_value() == (vertex < reach));
    CHECK(wall.closest(x).distance == Approx(facet).margin(1e-14));
    if (within) {
      CHECK(within->distance == Approx(facet).margin(1e-14));
      CHECK(within->facet == wall.closest(x).facet);
    }
  }
  CHECK_THROWS_AS(detail::WallDistance<2>(points, facets, 0), InputError);
  CHECK_THROWS_AS(detail::WallDistance<2>(points, facets, 17), InputError);
}

TEST_CASE("blend mover: a wall translation is blended by the C2 weight of the wall distance", "[curving]") {
  OMeshOptions o;
  o.n_around = 32;
  o.n_radial = 30;
  o.first_height = 1e-3;
  o.growth = 1.15;
  const Mesh<2> mesh = o_mesh(o);
  BoundarySpec<2> spec;
  spec.moving("wall", Translation<2>{Vec<2>(1e-3, -2e-3)});
  spec.fixed("farfield");
  const ResolvedBoundary<2> boundary = spec.resolve(mesh);
  const double length = 0.05;
  BlendMover<2> mover(BlendOptions{length, {}, 3.0});
  mover.setup(mesh, boundary);
  const Points<2> u = mover.move(boundary.displacements);
  const auto s = [&](Index j) { return o.first_height * (std::pow(o.growth, static_cast<double>(j)) - 1.0) / (o.growth - 1.0); };
  for (Index j = 0; j <= o.n_radial; ++j)
    for (Index i = 0; i < o.n_around; i += 7) {
      const Index v = j * o.n_around + i;
      const double weight = j == o.n_radial ? 0.0 : rbf_value(RbfKernel::wendland2, s(j), length);
      INFO("ring " << j << " node " << i);
      CHECK((u.col(v) - weight * Vec<2>(1e-3, -2e-3)).norm() < 1e-15);
    }
  CHECK(mover.stats().evaluated_nodes > 0);
  CHECK(mover.stats().evaluated_nodes < mesh.num_nodes() - 2 * o.n_around);
  CHECK(mover.move(Points<2>::Zero(2, boundary.size())).isZero(0.0));
  CHECK_THROWS_AS(mover.move(Points<2>::Zero(2, 3)), InputError);
}

TEST_CASE("blend mover: one wall's field vanishes on the other wall", "[curving]") {
  // Two walls: the bottom moves, the top moves too; each one's share dies on the other.
  Mesh<2> mesh = rectangle_mesh({8, 8, 0.0, 1.0, 0.0, 0.1, RectangleCells::tri3});
  BoundarySpec<2> spec;
  spec.moving("bottom", Translation<2>{Vec<2>(0.0, 1e-3)});
  spec.moving("top", Translation<2>{Vec<2>(0.0, 0.0)});
  spec.fixed("left").fixed("right");
  const ResolvedBoundary<2> boundary = spec.resolve(mesh);
  BlendMover<2> mover(BlendOptions{1.0, {}, 3.0});  // longer than the gap: only damping stops it
  mover.setup(mesh, boundary);
  const Points<2> u = mover.move(boundary.displacements);
  CHECK(mover.blending_lengths().size() == 2);
  for (Index i = 1; i < 8; ++i) {
    CHECK(u(1, i) == Approx(1e-3));            // bottom row: its target
    CHECK(u.col(8 * 9 + i).norm() == 0.0);     // top row: untouched by the bottom's field
    CHECK(u(1, 4 * 9 + i) > 0.0);              // middle row: in between
    CHECK(u(1, 4 * 9 + i) < 1e-3);
  }
  // The gap (0.1) is narrower than L (1): the damping runs over the gap, not over L, so the
  // bottom's first row keeps nearly all of its wall's displacement (over L it kept 6%).
  for (Index j = 1; j < 8; ++j) {
    const double y = 0.1 * static_cast<double>(j) / 8.0;
    const double expected = rbf_value(RbfKernel::wendland2, y, 1.0) * (1.0 - rbf_value(RbfKernel::wendland2, 0.1 - y, 0.1)) * 1e-3;
    for (Index i = 1; i < 8; ++i) CHECK(u(1, 9 * j + i) == Approx(expected).epsilon(1e-12));
  }
  CHECK(u(1, 9 + 4) > 0.98e-3);
}

TEST_CASE("blend mover: a moving node on no wall facet is refused at setup, and at the move when set up at rest", "[curving]") {
  const Mesh<2> mesh = rectangle_mesh({4, 4, 0.0, 1.0, 0.0, 1.0, RectangleCells::tri3});
  // The bottom row's nodes prescribed and an interior node (2,2) prescribed with them: it
  // lies on no facet, so no wall carries its motion into the volume.
  const Index lone = 2 * 5 + 2;
  const auto boundary = [&](double dy) {
    BoundaryCollector<2> c(mesh.num_nodes());
    BoundaryEntry<2> e;
    e.kind = BoundaryKind::prescribed;
    e.displacement = Vec<2>(0.0, dy);
    for (Index i = 0; i < 5; ++i) c.add(i, e);
    c.add(lone, e);
    return c.resolve();
  };
  BlendMover<2> moving(BlendOptions{0.5, {}, 3.0});
  CHECK_THROWS_WITH(moving.setup(mesh, boundary(0.01)), Catch::Contains("moving boundary node 12 lies on no facet"));
  BlendMover<2> at_rest(BlendOptions{0.5, {}, 3.0});
  const ResolvedBoundary<2> rest = boundary(0.0);
  at_rest.setup(mesh, rest);
  Points<2> d = boundary(0.01).displacements;
  CHECK_THROWS_WITH(at_rest.move(d), Catch::Contains("BlendMover::move: moving boundary node 12 lies on no facet"));
  d.col(rest.column(lone)).setZero();  // the lone node held: the wall's motion alone is blended
  const Points<2> u = at_rest.move(d);
  CHECK(u(1, 2) == Approx(0.01));
  CHECK(u.col(lone).norm() == 0.0);
}

TEST_CASE("blend mover: the default length is blending_factor wall layers, and longer is better on a thin layer", "[curving]") {
  // The O-mesh triangles of docs/curving.md "Blending length" at 64 wall facets: a bow of
  // h^2/(8 rho) that a blend over one layer bends most inside the layer's thin cells.
  OMeshOptions o;
  o.n_around = 64;
  o.triangles = true;
  const Mesh<2> linear = o_mesh(o);
  const BoundaryLayerEstimate layer = estimate_boundary_layer(linear, std::vector<std::string>{"wall"});
  const double thickness = layer.wall("wall").thickness;
  REQUIRE(thickness > 100 * o.first_height);
  BoundarySpec<2> spec;
  spec.moving("wall", Translation<2>{Vec<2>(1e-4, 0.0)});
  spec.fixed("farfield");
  const ResolvedBoundary<2> boundary = spec.resolve(linear);
  for (const double factor : {1.0, 6.0}) {
    BlendOptions options;
    options.blending_factor = factor;
    BlendMover<2> mover(options);
    mover.setup(linear, boundary);
    REQUIRE(mover.blending_lengths().size() == 1);
    CHECK(mover.blending_lengths()[0] == Approx(factor * thickness).epsilon(1e-12));
  }
  BlendOptions zero;
  zero.blending_factor = 0.0;
  CHECK_THROWS_WITH(BlendMover<2>(zero).setup(linear, boundary), Catch::Contains("blending factor 0"));

  CurveOptions<2> curve;
  curve.method = "blend";
  curve.geometry.emplace("wall", BoundaryGeometry<2>::project(SphereProjection<2>(Vec<2>::Zero(), 0.5)));
  REQUIRE(std::get<BlendOptions>(mover_config<2>("blend").options).blending_factor == 6.0);
  const CurveResult<2> six = curve_mesh(linear, curve);
  set_curve_options(curve, {{"blending_factor", "1"}});
  const CurveResult<2> one = curve_mesh(linear, curve);
  INFO("blend over 1 layer: " << one.quality.min << ", over 6: " << six.quality.min);
  CHECK(one.invalid() == 0);
  CHECK(six.invalid() == 0);
  CHECK(1.0 - six.quality.min < 0.5 * (1.0 - one.quality.min));
}

TEST_CASE("blend mover: a layer estimate of the same wall vertices is reused, one of other walls is not", "[curving]") {
  OMeshOptions o;
  o.n_around = 64;
  o.triangles = true;
  const Mesh<2> mesh = o_mesh(o);
  BoundarySpec<2> spec;
  spec.moving("wall", Translation<2>{Vec<2>(1e-4, 0.0)});
  spec.fixed("farfield");
  const ResolvedBoundary<2> boundary = spec.resolve(mesh);
  const auto lengths = [&](std::shared_ptr<const BoundaryLayerEstimate> estimate) {
    BlendOptions options;
    options.layer_estimate = std::move(estimate);
    BlendMover<2> mover(options);
    mover.setup(mesh, boundary);
    return mover.blending_lengths();
  };
  const std::vector<double> own = lengths(nullptr);
  REQUIRE(own.size() == 1);
  REQUIRE(own[0] > 0.0);
  // The same estimate handed in gives the same length, bit for bit.
  const BoundaryLayerEstimate wall = estimate_boundary_layer(mesh, std::vector<std::string>{"wall"});
  CHECK(lengths(std::make_shared<const BoundaryLayerEstimate>(wall)) == own);
  // It is what the mover uses: doubled thicknesses double the length.
  BoundaryLayerEstimate doubled = wall;
  for (double& t : doubled.node_thickness) t *= 2.0;
  CHECK(lengths(std::make_shared<const BoundaryLayerEstimate>(doubled))[0] == 2.0 * own[0]);
  // An estimate over other wall vertices (the far field too) is not this setup's: ignored.
  BoundaryLayerEstimate other = estimate_boundary_layer(mesh, std::vector<std::string>{"wall", "farfield"});
  for (double& t : other.node_thickness) t *= 2.0;
  CHECK(lengths(std::make_shared<const BoundaryLayerEstimate>(other)) == own);
}

namespace {

// Largest distance from the wall facets (line3 in P2, line2 linear) to the circle |x| = r,
// sampled at 21 points per facet.
double distance_to_circle(const Mesh<2>& mesh, const std::string& group, double r) {
  const int tag = mesh.group(group).tag;
  double worst = 0.0;
  for (const auto& block : mesh.facets)
    for (Index e = 0; e < block.size(); ++e) {
      if (block.tags[static_cast<std::size_t>(e)] != tag) continue;
      const auto el = block.element(e);
      Eigen::Matrix<double, 2, Eigen::Dynamic> coords(2, block.nodes_per_element());
      for (int k = 0; k < block.nodes_per_element(); ++k) coords.col(k) = mesh.points.col(el[static_cast<std::size_t>(k)]);
      for (int k = 0; k <= 20; ++k) {
        const Vec<2> x = map_to_physical(block.type, coords, {-1.0 + k / 10.0, 0.0, 0.0});
        worst = std::max(worst, std::abs(x.norm() - r));
      }
    }
  return worst;
}

OMeshOptions circle_mesh(Index n_around) {
  OMeshOptions o;
  o.n_around = n_around;
  o.n_radial = 6;
  o.first_height = 0.02;
  o.farfield_radius = 3.0;
  return o;
}

}  // namespace

TEST_CASE("pipeline: P2 boundary converges to a circle as h^3 or faster, linear as h^2", "[curving][slow]") {
  const double radius = 0.5;
  std::vector<double> linear_error, circle_error, spline_error;
  for (const Index n : {12, 24, 48, 96}) {
    const Mesh<2> linear = o_mesh(circle_mesh(n));
    linear_error.push_back(distance_to_circle(linear, "wall", radius));
    CurveOptions<2> options;
    options.geometry.emplace("wall", BoundaryGeometry<2>::project(SphereProjection<2>(Vec<2>::Zero(), radius)));
    const CurveResult<2> curved = curve_mesh(linear, options);
    CHECK(curved.invalid() == 0);
    CHECK(curved.moved_vertices == 0);  // the generator puts the vertices on the circle
    circle_error.push_back(distance_to_circle(curved.curved, "wall", radius));
    // Every wall node, high-order ones included, on the circle to round-off.
    for (const Index v : curved.curved.group_nodes("wall")) CHECK(std::abs(curved.curved.points.col(v).norm() - radius) < 1e-15);
    // Linear nodes keep their numbers and, off the support, their places.
    CHECK(curved.num_linear_nodes == linear.num_nodes());
    CHECK(curved.curved.points.leftCols(n) == linear.points.leftCols(n));
    spline_error.push_back(distance_to_circle(curve_mesh(linear, CurveOptions<2>{}).curved, "wall", radius));
  }
  for (std::size_t k = 1; k < linear_error.size(); ++k) {
    const double linear_order = std::log2(linear_error[k - 1] / linear_error[k]);
    const double circle_order = std::log2(circle_error[k - 1] / circle_error[k]);
    const double spline_order = std::log2(spline_error[k - 1] / spline_error[k]);
    INFO("refinement " << k << ": linear " << linear_order << ", projected P2 " << circle_order << ", spline P2 "
                       << spline_order);
    CHECK(linear_order == Approx(2.0).margin(0.1));
    CHECK(circle_order >= 2.9);
    CHECK(spline_order >= 2.9);
    CHECK(circle_error[k] < linear_error[k]);
  }
}

TEST_CASE("pipeline: P3 and P4 boundaries converge to a circle as h^(p+1), the spline's as h^4", "[curving][slow]") {
  const double radius = 0.5;
  for (const int p : {3, 4}) {
    std::vector<double> circle_error, spline_error;
    for (const Index n : {12, 24, 48}) {
      const Mesh<2> linear = o_mesh(circle_mesh(n));
      CurveOptions<2> options;
      options.order = p;
      options.geometry.emplace("wall", BoundaryGeometry<2>::project(SphereProjection<2>(Vec<2>::Zero(), radius)));
      const CurveResult<2> curved = curve_mesh(linear, options);
      CHECK(curved.invalid() == 0);
      CHECK(order(curved.curved.cells.front().type) == p);
      CHECK(curved.curved.points.leftCols(n) == linear.points.leftCols(n));
      for (const Index v : curved.curved.group_nodes("wall")) CHECK(std::abs(curved.curved.points.col(v).norm() - radius) < 1e-15);
      circle_error.push_back(distance_to_circle(curved.curved, "wall", radius));
      CurveOptions<2> spline;
      spline.order = p;
      const CurveResult<2> splined = curve_mesh(linear, spline);
      CHECK(splined.invalid() == 0);
      spline_error.push_back(distance_to_circle(splined.curved, "wall", radius));
    }
    for (std::size_t k = 1; k < circle_error.size(); ++k) {
      const double circle_order = std::log2(circle_error[k - 1] / circle_error[k]);
      const double spline_order = std::log2(spline_error[k - 1] / spline_error[k]);
      INFO("P" << p << ", refinement " << k << ": projected " << circle_order << " (" << circle_error[k] << "), spline "
               << spline_order << " (" << spline_error[k] << ")");
      CHECK(circle_order >= p + 0.8);
      CHECK(spline_order >= 3.8);  // the cubic spline's own accuracy
    }
  }
}

TEST_CASE("pipeline: boundary-layer mesh (aspect ratio >= 1000) needs the regularization", "[curving]") {
  OMeshOptions o;  // 128 x 64 cells, first cell 1e-5 for a wall spacing of 0.025
  o.triangles = GENERATE(false, true);
  const Mesh<2> linear = o_mesh(o);
  CurveOptions<2> options;
  options.geometry.emplace("wall", BoundaryGeometry<2>::project(SphereProjection<2>(Vec<2>::Zero(), 0.5)));
  options.method = "none";
  const CurveResult<2> snapped = curve_mesh(linear, options);
  CHECK(snapped.invalid() > 0);
  // "none" leaves the interior to the snapping: the untangling does not repair it either.
  CHECK(snapped.untangle.cells_below == 0);
  CHECK(snapped.untangle.evaluations == 0);
  // Snapping alone moves no vertex and no edge node off the boundary: only the centres of the
  // quadrilaterals on the wall and on the (spline-curved) farfield follow their curved edges
  // (inner_nodes.hpp); the triangles have none at P2.
  CHECK(snapped.moved_nodes == (o.triangles ? 0 : 2 * o.n_around));
  options.strict = true;
  try {
    (void)curve_mesh(linear, options);
    FAIL("strict mode accepted invalid cells");
  } catch (const InvalidMeshError& e) {
    CHECK_THAT(e.what(), Catch::Contains(std::to_string(snapped.invalid()) + " of ") && Catch::Contains("worst"));
  }
  for (const std::string method : {"rbf", "blend"}) {
    options.method = method;
    const CurveResult<2> curved = curve_mesh(linear, options);
    INFO(method << ": min " << curved.quality.min << ", radius " << curved.support_radius);
    CHECK(curved.invalid() == 0);
    CHECK(curved.quality.min > 0.3);
    // The per-cell values behind the report, in cell order (what the program writes to its .vtu).
    REQUIRE(curved.cell_quality.size() == static_cast<std::size_t>(curved.curved.num_cells()));
    CHECK(*std::min_element(curved.cell_quality.begin(), curved.cell_quality.end()) == curved.quality.min);
    CHECK(curved.cell_quality[static_cast<std::size_t>(curved.quality.worst.front().id)] == curved.quality.min);
    CHECK(curved.moved_nodes > 0);
    REQUIRE(curved.layers.size() == 2);  // the farfield is spline-curved too, and has no layer
    CHECK(curved.layers[0].group == "wall");
    CHECK(curved.layers[0].thickness > 100 * o.first_height);
    CHECK(curved.layers[1].thickness == 0.0);
    if (method != "rbf") continue;
    // The wall's radius follows its layer; the farfield, without one and snapped away from its
    // cells, gets half its node spacing (half the chord of 128 facets on R = 20 at P2).
    REQUIRE(curved.wall_support_radii.size() == 2);
    CHECK(curved.wall_support_radii[0] == options.support_radius_factor * curved.layers[0].thickness);
    CHECK(curved.wall_support_radii[1] == Approx(0.5 * 20.0 * std::sin(std::numbers::pi / 128.0)));
    REQUIRE(curved.wall_support_radii[1] > curved.wall_support_radii[0]);
    CHECK(curved.support_radius == curved.wall_support_radii[1]);
  }
}

TEST_CASE("pipeline: each wall's RBF support follows its own boundary layer", "[curving]") {
  // The gap of a journal bearing: a shaft (r = 0.5) with a thin layer, a housing (r = 1.5)
  // with a thick one.
  const Mesh<2> linear = annulus_mesh({});
  CurveOptions<2> options;
  options.method = "rbf";
  options.geometry.emplace("inner", BoundaryGeometry<2>::project(SphereProjection<2>(Vec<2>::Zero(), 0.5)));
  options.geometry.emplace("outer", BoundaryGeometry<2>::project(SphereProjection<2>(Vec<2>::Zero(), 1.5)));
  const CurveResult<2> curved = curve_mesh(linear, options);
  REQUIRE(curved.layers.size() == 2);
  const double inner = curved.layers[0].thickness, outer = curved.layers[1].thickness;
  INFO("layers " << inner << ", " << outer << "; min " << curved.quality.min);
  CHECK(inner > 0.0);
  CHECK(outer > 3.0 * inner);
  REQUIRE(curved.wall_support_radii.size() == 2);
  const double r_inner = curved.wall_support_radii[0], r_outer = curved.wall_support_radii[1];
  CHECK(r_inner == options.support_radius_factor * inner);
  CHECK(r_outer == options.support_radius_factor * outer);
  REQUIRE(r_inner + r_outer < 1.0);  // a band of the core is beyond both walls' supports
  CHECK(curved.invalid() == 0);
  const auto on_circles = [](const Mesh<2>& mesh) {
    double worst = 0.0;
    for (const auto& block : mesh.facets)
      for (Index e = 0; e < block.size(); ++e)
        for (const Index v : block.element(e))
          worst = std::max(worst, std::abs(mesh.points.col(v).norm() - (block.tags[std::size_t(e)] == 1 ? 0.5 : 1.5)));
    return worst;
  };
  CHECK(on_circles(curved.curved) < 1e-14);

  // A vertex moves iff a wall's support reaches it: with each wall's radius, the core from
  // r_inner off the shaft to r_outer off the housing stays; with the housing's radius for both
  // (options.per_wall_radius = false) the shaft's motion reaches r_outer into the gap.
  options.per_wall_radius = false;
  const CurveResult<2> single = curve_mesh(linear, options);
  CHECK(single.wall_support_radii.empty());
  CHECK(single.support_radius == r_outer);
  CHECK(single.invalid() == 0);
  Index between = 0;
  for (Index v = 0; v < linear.num_nodes(); ++v) {
    const double from_shaft = linear.points.col(v).norm() - 0.5, from_housing = 1.5 - linear.points.col(v).norm();
    if (from_shaft < 1e-12 || from_housing < 1e-12) continue;
    const bool moved = curved.curved.points.col(v) != linear.points.col(v);
    const bool moved_single = single.curved.points.col(v) != linear.points.col(v);
    CHECK(moved == (from_shaft < r_inner || from_housing < r_outer));
    CHECK(moved_single == (from_shaft < r_outer || from_housing < r_outer));
    between += from_shaft > r_inner && from_shaft < r_outer ? 1 : 0;
  }
  CHECK(between > 0);
}

TEST_CASE("pipeline: under the RBF a farfield snapped outward moves only its own nodes", "[curving]") {
  // An O-mesh: a wall with a layer, and a farfield circle (R = 20, no layer) whose facets bulge
  // away from their cells when snapped. Its centres get half a node spacing, which reaches no
  // other node; at 2 spacings the 30P30N's farfield made the RBF system 0.91M nonzeros.
  const Mesh<2> linear = o_mesh({.n_around = 64, .n_radial = 24});
  CurveOptions<2> options;
  options.method = "rbf";
  options.geometry.emplace("wall", BoundaryGeometry<2>::project(SphereProjection<2>(Vec<2>::Zero(), 0.5)));
  options.geometry.emplace("farfield", BoundaryGeometry<2>::project(SphereProjection<2>(Vec<2>::Zero(), 20.0)));
  options.untangle.untangle = false;  // its rounds raise the worst cells anywhere
  const CurveResult<2> curved = curve_mesh(linear, options);
  REQUIRE(curved.layers.size() == 2);
  REQUIRE(curved.layers[1].thickness == 0.0);
  REQUIRE(curved.wall_support_radii.size() == 2);
  const double chord = 2.0 * 20.0 * std::sin(std::numbers::pi / 64.0);
  CHECK(curved.wall_support_radii[1] == Approx(0.5 * chord / 2.0));
  CHECK(curved.invalid() == 0);
  Index stayed = 0;
  for (Index v = 0; v < linear.num_nodes(); ++v) {
    const double r = linear.points.col(v).norm();
    if (r <= 0.5 + curved.wall_support_radii[0] || r > 20.0 - 1e-9) continue;
    CHECK(curved.curved.points.col(v) == linear.points.col(v));
    ++stayed;
  }
  CHECK(stayed > 64 * 4);
}

TEST_CASE("pipeline: each wall's RBF support follows its own layer in 3D (two cylinders)", "[curving]") {
  // The journal-bearing gap extruded along its axis: a shaft cylinder (r = 0.5) with a thin
  // layer, a housing cylinder (r = 1.5) with a thick one, end planes sliding.
  const AnnulusOptions gap{.n_around = 48, .inner_first_height = 1e-3, .inner_growth = 1.5,
                           .outer_first_height = 5e-3, .outer_growth = 1.3, .core_spacing = 0.08};
  const ExtrudeOptions slab{.layers = 2, .height = 0.1};
  const Mesh<3> linear = extrude_mesh(annulus_mesh(gap), slab);
  const auto cylinder = [](double radius) {
    return BoundaryGeometry<3>::project([radius](const Vec<3>& p) {
      Vec<3> q = p;
      q.head<2>() *= radius / p.head<2>().norm();
      return q;
    });
  };
  CurveOptions<3> options;
  options.method = "rbf";
  options.geometry.emplace("inner", cylinder(0.5));
  options.geometry.emplace("outer", cylinder(1.5));
  options.sliding = {"z_min", "z_max"};
  const CurveResult<3> curved = curve_mesh(linear, options);
  REQUIRE(curved.layers.size() == 2);
  const double inner = curved.layers[0].thickness, outer = curved.layers[1].thickness;
  INFO("layers " << inner << ", " << outer << "; min " << curved.quality.min);
  CHECK(inner > 0.0);
  CHECK(outer > 3.0 * inner);
  REQUIRE(curved.wall_support_radii.size() == 2);
  const double r_inner = curved.wall_support_radii[0], r_outer = curved.wall_support_radii[1];
  CHECK(r_inner == options.support_radius_factor * inner);
  // The housing's radius is limited to max_support_nodes boundary nodes per support (3D).
  CHECK(r_outer <= options.support_radius_factor * outer);
  REQUIRE(2.0 * r_inner < 0.8 * r_outer);
  CHECK(curved.invalid() == 0);
  double off_wall = 0.0, off_plane = 0.0;
  for (const auto& block : curved.curved.facets)
    for (Index e = 0; e < block.size(); ++e)
      for (const Index v : block.element(e)) {
        const Vec<3> p = curved.curved.points.col(v);
        const int tag = block.tags[static_cast<std::size_t>(e)];
        if (tag <= 2) off_wall = std::max(off_wall, std::abs(p.head<2>().norm() - (tag == 1 ? 0.5 : 1.5)));
        else off_plane = std::max(off_plane, std::min(std::abs(p.z()), std::abs(p.z() - slab.height)));
      }
  CHECK(off_wall < 1e-14);
  CHECK(off_plane < 1e-14);

  // With the housing's radius for both walls the shaft's motion reaches r_outer into the gap;
  // with each wall's own it stays within a couple of r_inner (the sliding end planes' centres
  // reach a radius beyond the walls' own).
  options.per_wall_radius = false;
  const CurveResult<3> single = curve_mesh(linear, options);
  CHECK(single.support_radius == r_outer);
  CHECK(single.invalid() == 0);
  const double wall_motion = curved.max_boundary_displacement;
  double band_own = 0.0, band_single = 0.0, reached_own = std::numeric_limits<double>::infinity();
  Index band = 0;
  for (Index v = 0; v < linear.num_nodes(); ++v) {
    const Vec<3> p = linear.points.col(v);
    const double from_shaft = p.head<2>().norm() - 0.5;
    const double own = (curved.curved.points.col(v) - p).norm(), one = (single.curved.points.col(v) - p).norm();
    if (from_shaft > 1e-12 && from_shaft < 0.5 * r_inner) reached_own = std::min(reached_own, own);
    if (from_shaft < 2.0 * r_inner || from_shaft > 0.8 * r_outer) continue;
    ++band;
    band_own = std::max(band_own, own);
    band_single = std::max(band_single, one);
  }
  INFO("wall motion " << wall_motion << ", band " << band << ": own " << band_own << ", single " << band_single
                      << "; near the shaft at least " << reached_own);
  CHECK(band > 0);
  CHECK(reached_own > 0.0);
  CHECK(band_own < 1e-4 * wall_motion);
  CHECK(band_single > 1e-3 * wall_motion);
}

TEST_CASE("pipeline: every element type and mixed meshes curve onto a graph", "[curving][slow]") {
  const auto wave = [](double x) {
    const double k = 2.0 * std::numbers::pi;
    return GraphSample1{0.02 * std::sin(k * x), 0.02 * k * std::cos(k * x), -0.02 * k * k * std::sin(k * x)};
  };
  for (const auto cells : {RectangleCells::tri3, RectangleCells::quad4, RectangleCells::tri_quad}) {
    const Mesh<2> linear = rectangle_mesh({6, 4, 0.0, 1.0, 0.0, 0.5, cells});
    CurveOptions<2> options;
    options.geometry.emplace("bottom", BoundaryGeometry<2>::project(GraphProjection2(wave)));
    const CurveResult<2> curved = curve_mesh(linear, options);
    INFO("2D cells " << static_cast<int>(cells));
    CHECK(curved.invalid() == 0);
    for (const Index v : curved.curved.group_nodes("bottom"))
      CHECK(std::abs(curved.curved.points(1, v) - wave(curved.curved.points(0, v)).value) < 1e-12);
  }
  const auto bump = sine_bump(0.02);
  for (const auto cells : {BoxCells::hex8, BoxCells::tet4, BoxCells::prism6, BoxCells::pyramid5, BoxCells::hex_prism,
                           BoxCells::tet_pyramid_prism}) {
    const Mesh<3> linear = box_mesh({3, 3, 3, 0.0, 1.0, 0.0, 1.0, 0.0, 1.0, cells});
    CurveOptions<3> options;
    options.geometry.emplace("bottom", BoundaryGeometry<3>::project(GraphProjection3(bump)));
    const CurveResult<3> curved = curve_mesh(linear, options);
    INFO("3D cells " << static_cast<int>(cells));
    CHECK(curved.invalid() == 0);
    CHECK(curved.moved_vertices == 4);  // the interior vertices of the bottom face
    for (const Index v : curved.curved.group_nodes("bottom")) {
      const Vec<3> x = curved.curved.points.col(v);
      CHECK(std::abs(x.z() - bump(x.x(), x.y()).value) < 1e-10);
    }
  }
}

TEST_CASE("pipeline: tetrahedra curve onto a graph at orders 7 and 8, hexahedra, prisms and pyramids at orders 4 to 8, certified",
          "[curving]") {
  // The orders whose det J the certificate subdivides without tables (tetrahedra) and whose
  // det J the untangling's rounds hold on the heap (a tet165's 2,024 points, a hex216's 3,375,
  // a hex729's 13,824: the untangling stopped at hexahedra of order 4 when it held them in
  // place).
  const auto bump = sine_bump(0.03);
  // One cube of tetrahedra (a second of cells at order 8, with 3 s for the tables' first use),
  // eight hexahedra, one at order 8; two prisms, six pyramids (certified on their collapsed
  // cube) and the mixed box of tetrahedra, pyramids and prisms.
  struct Case {
    BoxCells cells;
    Index n;
    int order;
    ElementType type;
  };
  for (const Case c : {Case{BoxCells::tet4, 1, 7, ElementType::tet120}, Case{BoxCells::tet4, 1, 8, ElementType::tet165},
                       Case{BoxCells::hex8, 2, 4, ElementType::hex125}, Case{BoxCells::hex8, 2, 5, ElementType::hex216},
                       Case{BoxCells::hex8, 2, 6, ElementType::hex343}, Case{BoxCells::hex8, 1, 8, ElementType::hex729},
                       Case{BoxCells::prism6, 1, 4, ElementType::prism75}, Case{BoxCells::prism6, 1, 6, ElementType::prism196},
                       Case{BoxCells::prism6, 1, 8, ElementType::prism405}, Case{BoxCells::pyramid5, 1, 5, ElementType::pyramid91},
                       Case{BoxCells::pyramid5, 1, 8, ElementType::pyramid285},
                       Case{BoxCells::tet_pyramid_prism, 3, 5, ElementType::pyramid91}}) {
    INFO(name(c.type));
    const Mesh<3> linear = box_mesh({c.n, c.n, c.n, 0.0, 1.0, 0.0, 1.0, 0.0, 1.0, c.cells});
    CurveOptions<3> options;
    options.order = c.order;
    options.geometry.emplace("bottom", BoundaryGeometry<3>::project(GraphProjection3(bump)));
    const CurveResult<3> curved = curve_mesh(linear, options);
    REQUIRE(curved.curved.find_block(c.type));
    INFO("min " << curved.quality.min);
    CHECK(curved.invalid() == 0);
    CHECK(curved.quality.min > 0.5);
    for (const Index v : curved.curved.group_nodes("bottom")) {
      const Vec<3> x = curved.curved.points.col(v);
      CHECK(std::abs(x.z() - bump(x.x(), x.y()).value) < 1e-10);
    }
    // The report's verdicts are the certificate's, cell by cell.
    const auto certified = scaled_jacobians(curved.curved);
    for (std::size_t e = 0; e < certified.size(); ++e) CHECK(certified[e].valid);
  }
}

TEST_CASE("pipeline: bad options", "[curving]") {
  const Mesh<2> linear = o_mesh(circle_mesh(12));
  CurveOptions<2> options;
  options.method = "magic";
  CHECK_THROWS_AS(curve_mesh(linear, options), InputError);
  options.method = "rbf";
  options.steps = 0;
  CHECK_THROWS_AS(curve_mesh(linear, options), InputError);
  options.steps = 1;
  options.geometry.emplace("nope", BoundaryGeometry<2>::spline());
  CHECK_THROWS_AS(curve_mesh(linear, options), InputError);
  const Mesh<3> box = box_mesh({});
  CHECK_THROWS_AS(curve_mesh(box, CurveOptions<3>{}), InputError);  // nothing to curve in 3D
  CurveOptions<3> spline3;
  spline3.geometry.emplace("bottom", BoundaryGeometry<3>::spline());
  CHECK_THROWS_AS(curve_mesh(box, spline3), InputError);  // reconstruction needs triangles
}

TEST_CASE("pipeline: in 3D the groups named like walls are reconstructed by default, and said so", "[curving]") {
  // Which groups: named like a wall and made of triangles (the reconstruction takes no quads).
  Mesh<3> box = box_mesh({.nx = 3, .ny = 3, .nz = 3, .cells = BoxCells::tet4});
  for (auto& g : box.groups)
    if (g.name == "bottom") g.name = "Wall_bottom";
  CurveOptions<3> snap;
  snap.method = "none";
  CHECK(curve_mesh(box, snap).curved_groups == std::vector<std::string>{"Wall_bottom"});
  CurveOptions<3> off = snap;
  off.reconstruct_walls_by_default = false;
  CHECK_THROWS_WITH(curve_mesh(box, off), Catch::Contains("no group to curve in 3D"));
  Mesh<3> hexes = box_mesh({.nx = 2, .ny = 2, .nz = 2});
  for (auto& g : hexes.groups)
    if (g.name == "bottom") g.name = "wall";
  CHECK_THROWS_WITH(curve_mesh(hexes, snap), Catch::Contains("no group to curve in 3D"));  // quadrilaterals
  // The sphere: its wall, renamed, is reconstructed without being asked.
  MESHMOTION_REQUIRE_DATA(file, "meshopt_sphere_symmetry_linear_tet.msh");
  Mesh<3> linear = read_mesh_as<3>(file);
  name_unnamed_facet_groups(linear);
  for (auto& g : linear.groups)
    if (g.name == "7") g.name = "sphere_wall";
  CurveOptions<3> options;
  options.sliding.push_back("20");
  const CurveResult<3> curved = curve_mesh(linear, options);
  CHECK(curved.curved_groups == std::vector<std::string>{"sphere_wall"});
  CHECK(curved.invalid() == 0);
  double error = 0.0;
  for (const Index v : curved.curved.group_nodes("sphere_wall")) error = std::max(error, std::abs(curved.curved.points.col(v).norm() - 0.5));
  CHECK(error < 0.01);
}

TEST_CASE("pipeline: planar groups meeting a curved wall slide in their planes by default", "[curving]") {
  // A box whose bottom is a bowl z = h(x, y): each side meets it along a curve in its plane; the
  // top meets no curved group.
  Mesh<3> box = box_mesh({.nx = 4, .ny = 4, .nz = 4, .cells = BoxCells::tet4});
  const auto bowl = [](double x, double y) { return 0.3 * ((x - 0.3) * (x - 0.3) + (y - 0.4) * (y - 0.4)); };
  for (Index v = 0; v < box.num_nodes(); ++v) {
    auto p = box.points.col(v);
    p.z() += bowl(p.x(), p.y()) * (1.0 - p.z());
  }
  CurveOptions<3> options;
  options.geometry.emplace("bottom", BoundaryGeometry<3>::project([&](const Vec<3>& x) {
    return Vec<3>(x.x(), x.y(), bowl(x.x(), x.y()));
  }));
  // The top, given a geometry it already lies on: snapping moves nothing, so it is a fixed
  // boundary and no wall to estimate a layer for.
  options.geometry.emplace("top", BoundaryGeometry<3>::project([](const Vec<3>& x) { return x; }));
  const CurveResult<3> curved = curve_mesh(box, options);
  CHECK(curved.invalid() == 0);
  CHECK(curved.curved_groups == std::vector<std::string>{"bottom", "top"});
  CHECK(curved.sliding_groups == std::vector<std::string>{"left", "right", "front", "back"});
  REQUIRE(curved.layers.size() == 1);
  CHECK(curved.layers.front().group == "bottom");
  const Mesh<3> straight = convert_to_quadratic(box).mesh;
  const std::array<std::pair<const char*, int>, 4> sides{{{"left", 0}, {"right", 0}, {"front", 1}, {"back", 1}}};
  double slid = 0.0;
  for (const auto& [side, axis] : sides)
    for (const Index v : curved.curved.group_nodes(std::string_view(side))) {
      CHECK(curved.curved.points(axis, v) == straight.points(axis, v));
      slid = std::max(slid, (curved.curved.points.col(v) - straight.points.col(v)).norm());
    }
  CHECK(slid > 1e-3);  // the sides' nodes by the wall followed it
  for (const Index v : curved.curved.group_nodes("top")) CHECK(curved.curved.points.col(v) == straight.points.col(v));

  CurveOptions<3> fixed_sides = options;
  fixed_sides.slide_planar_groups = false;
  const CurveResult<3> fixed = curve_mesh(box, fixed_sides);
  CHECK(fixed.sliding_groups.empty());
  const std::vector<Index> wall = fixed.curved.group_nodes("bottom");  // sorted
  for (const auto& [side, axis] : sides)
    for (const Index v : fixed.curved.group_nodes(std::string_view(side)))
      if (!std::binary_search(wall.begin(), wall.end(), v)) CHECK(fixed.curved.points.col(v) == straight.points.col(v));
}

TEST_CASE("pipeline: a reconstructed wall meeting the inlet and the symmetry plane curves valid by default", "[curving]") {
  // A tetrahedral channel whose bottom wall has a bump reaching the inlet (x = 0) and the
  // symmetry plane (y = 0), curved with the defaults (the wall reconstructed from the mesh
  // alone). The wall's border turns at the domain's corners: fitted as one smooth curve there
  // it left 5 invalid cells at P2 and 6 at P3 (minimum -0.16 / -0.77).
  Mesh<3> channel = box_mesh({.nx = 8, .ny = 4, .nz = 4, .x_max = 2.0, .cells = BoxCells::tet4});
  const auto bump = [](double x, double y) { return 0.2 * std::exp(-((x - 0.3) * (x - 0.3) + (y - 0.2) * (y - 0.2)) / 0.3); };
  for (Index v = 0; v < channel.num_nodes(); ++v) {
    auto p = channel.points.col(v);
    p.z() += bump(p.x(), p.y()) * (1.0 - p.z());
  }
  for (auto& g : channel.groups)
    g.name = g.name == "bottom" ? "wall" : g.name == "left" ? "inlet" : g.name == "front" ? "symmetry" : g.name;
  for (const int order : {2, 3}) {
    INFO("order " << order);
    CurveOptions<3> options;
    options.order = order;
    const CurveResult<3> curved = curve_mesh(channel, options);
    CHECK(curved.curved_groups == std::vector<std::string>{"wall"});
    CHECK(curved.invalid() == 0);
    CHECK(curved.quality.min > 0.8);
    // On their planes to round-off: the raise rounds slide nodes along the fitted plane's
    // tangents, whose components off the plane are round-off (1e-17), not zero.
    for (const Index v : curved.curved.group_nodes("inlet")) CHECK(std::abs(curved.curved.points(0, v)) <= 1e-15);
    for (const Index v : curved.curved.group_nodes("symmetry")) CHECK(std::abs(curved.curved.points(1, v)) <= 1e-15);
  }
}

TEST_CASE("pipeline: 3D sphere with a symmetry plane curves onto the sphere", "[curving]") {
  MESHMOTION_REQUIRE_DATA(file, "meshopt_sphere_symmetry_linear_tet.msh");
  const Mesh<3> linear = read_mesh_as<3>(file);
  CurveOptions<3> options;
  options.geometry.emplace("7", BoundaryGeometry<3>::project(SphereProjection<3>(Vec<3>::Zero(), 0.5)));
  options.sliding.push_back("20");
  const CurveResult<3> curved = curve_mesh(linear, options);
  INFO("min " << curved.quality.min << ", radius " << curved.support_radius);
  CHECK(curved.invalid() == 0);
  for (const Index v : curved.curved.group_nodes("7")) CHECK(std::abs(curved.curved.points.col(v).norm() - 0.5) < 1e-12);
  for (const Index v : curved.curved.group_nodes("20")) CHECK(std::abs(curved.curved.points(1, v)) < 1e-12);
  // Without a boundary layer the default radius is a few wall spacings: the regularization must
  // improve on snapping alone (a radius spanning the body made it worse: 0.22 against 0.30).
  CurveOptions<3> snap_only = options;
  snap_only.method = "none";
  CHECK(curved.quality.min > curve_mesh(linear, snap_only).quality.min + 0.2);
  CHECK(curved.support_radius < 0.5);
}

TEST_CASE("pipeline: 3D sphere at order 3 puts every wall node on the sphere", "[curving][slow]") {
  MESHMOTION_REQUIRE_DATA(file, "meshopt_sphere_symmetry_linear_tet.msh");
  const Mesh<3> linear = read_mesh_as<3>(file);
  CurveOptions<3> options;
  options.order = 3;
  options.geometry.emplace("7", BoundaryGeometry<3>::project(SphereProjection<3>(Vec<3>::Zero(), 0.5)));
  options.sliding.push_back("20");
  const CurveResult<3> curved = curve_mesh(linear, options);
  INFO("min " << curved.quality.min);
  CHECK(curved.curved.cells.front().type == ElementType::tet20);
  CHECK(curved.invalid() == 0);
  for (const Index v : curved.curved.group_nodes("7")) CHECK(std::abs(curved.curved.points.col(v).norm() - 0.5) < 1e-12);
  for (const Index v : curved.curved.group_nodes("20")) CHECK(std::abs(curved.curved.points(1, v)) < 1e-12);
  // The surface reconstruction places the P3 wall nodes too (edge and face nodes).
  CurveOptions<3> reconstructed = options;
  reconstructed.geometry.clear();
  reconstructed.geometry.emplace("7", BoundaryGeometry<3>::spline());
  const CurveResult<3> rebuilt = curve_mesh(linear, reconstructed);
  CHECK(rebuilt.invalid() == 0);
  double error = 0.0;
  for (const Index v : rebuilt.curved.group_nodes("7")) error = std::max(error, std::abs(rebuilt.curved.points.col(v).norm() - 0.5));
  CHECK(error < 0.01);
}

TEST_CASE("pipeline: 3D sphere reconstructed from the linear mesh alone", "[curving]") {
  MESHMOTION_REQUIRE_DATA(file, "meshopt_sphere_symmetry_linear_tet.msh");
  const Mesh<3> linear = read_mesh_as<3>(file);
  CurveOptions<3> options;
  options.geometry.emplace("7", BoundaryGeometry<3>::spline());
  options.sliding.push_back("20");
  const CurveResult<3> curved = curve_mesh(linear, options);
  CHECK(curved.invalid() == 0);
  CHECK(curved.moved_vertices == 0);
  // Edge nodes: closer to the sphere than the straight midpoints were (measured on this
  // 106-triangle hemisphere: 0.0061 against 0.0217, the worst at the symmetry-plane border).
  const CurveResult<3> straight = curve_mesh(linear, [&] {
    CurveOptions<3> o;
    o.geometry.emplace("7", BoundaryGeometry<3>::project([](const Vec<3>& x) { return x; }));
    o.method = "none";
    return o;
  }());
  double reconstructed_error = 0.0, straight_error = 0.0;
  for (const Index v : curved.curved.group_nodes("7")) {
    reconstructed_error = std::max(reconstructed_error, std::abs(curved.curved.points.col(v).norm() - 0.5));
    straight_error = std::max(straight_error, std::abs(straight.curved.points.col(v).norm() - 0.5));
  }
  INFO("straight midpoints " << straight_error << ", reconstructed " << reconstructed_error);
  CHECK(straight_error > 1e-3);
  CHECK(reconstructed_error < 0.5 * straight_error);
}

TEST_CASE("bump_channel_3d: the TMR 3D bump-in-channel grid family", "[curving]") {
  const Mesh<3> coarse = bump_channel_3d(0);
  const Mesh<3> medium = bump_channel_3d(1);
  // (spanwise × streamwise × normal) 5×45×21 and 9×89×41; the coarse P2 mesh has the medium
  // grid's 32,841 points (thesis table 4.3).
  CHECK(coarse.num_nodes() == 5 * 45 * 21);
  CHECK(coarse.num_cells() == 4 * 44 * 20);
  CHECK(medium.num_nodes() == 9 * 89 * 41);
  CHECK(convert_to_quadratic(coarse).mesh.num_nodes() == 32841);
  // Nested: the coarse grid is every other line of the medium one.
  for (Index k = 0; k <= 20; ++k)
    for (Index j = 0; j <= 4; ++j)
      for (Index i = 0; i <= 44; ++i)
        REQUIRE((coarse.points.col(i + 45 * (j + 5 * k)) - medium.points.col(2 * i + 89 * (2 * j + 9 * 2 * k))).norm() < 1e-14);
  // Groups and their facet counts (spanwise 4, streamwise 12 + 20 + 12, normal 20 cells).
  const std::vector<std::pair<std::string, Index>> groups{{"bump", 4 * 20}, {"symmetry_lower", 4 * 24}, {"inflow", 4 * 20},
                                                          {"outflow", 4 * 20}, {"top", 4 * 44},       {"side_y0", 44 * 20},
                                                          {"side_y1", 44 * 20}};
  for (const auto& [name, count] : groups) {
    const int tag = coarse.group(name).tag;
    Index found = 0;
    for (const auto& block : coarse.facets)
      found += static_cast<Index>(std::count(block.tags.begin(), block.tags.end(), tag));
    INFO(name);
    CHECK(found == count);
  }
  // Every hexahedron valid, wall cells stretched as in RANS grids.
  const QualityReport q = quality_report(coarse, Metric::scaled_jacobian);
  CHECK(q.num_invalid == 0);
  CHECK(q.min > 0.0);
  double first_height = 1.0;
  for (const Index v : coarse.group_nodes("side_y0"))
    if (coarse.points(0, v) < -20.0 && coarse.points(2, v) > 0.0) first_height = std::min(first_height, coarse.points(2, v));
  CHECK(first_height == Approx(2.5e-5).epsilon(0.05));
  // Wall nodes on the shifted bump z = h(x - 0.3 sin^4(pi y)), the viscous wall over 0 <= x0 <= 1.5.
  double highest = 0.0;
  for (const Index v : coarse.group_nodes("bump")) {
    const Vec<3> x = coarse.points.col(v);
    CHECK(std::abs(x.z() - nasa_bump_3d_height(x.x(), x.y()).value) < 1e-15);
    CHECK(x.x() - bump_channel_shift(x.y()) >= -1e-15);
    CHECK(x.x() - bump_channel_shift(x.y()) <= 1.5 + 1e-15);
    highest = std::max(highest, x.z());
  }
  CHECK(highest > 0.04);
  for (const Index v : coarse.group_nodes("symmetry_lower")) CHECK(coarse.points(2, v) == 0.0);
  for (const Index v : coarse.group_nodes("inflow")) CHECK(coarse.points(0, v) == -25.0);
  for (const Index v : coarse.group_nodes("side_y1")) CHECK(coarse.points(1, v) == 0.0);
  CHECK_THROWS_AS(bump_channel_3d(-1), InputError);
  CHECK_THROWS_AS(bump_channel_3d(5), InputError);
}

TEST_CASE("nasa_bump_3d projects every wall edge midpoint and face centre of the fine grid", "[curving]") {
  // The fine level's wall: 16 × 80 quadrilaterals (the projection once stalled on one).
  const Mesh<3> fine = bump_channel_3d(2);
  const GraphProjection3 bump = nasa_bump_3d();
  const int tag = fine.group("bump").tag;
  Index projected = 0;
  for (const auto& block : fine.facets)
    for (Index e = 0; e < block.size(); ++e) {
      if (block.tags[static_cast<std::size_t>(e)] != tag) continue;
      const auto q = block.element(e);
      Vec<3> centre = Vec<3>::Zero();
      for (int k = 0; k < 4; ++k) {
        const Vec<3> a = fine.points.col(q[static_cast<std::size_t>(k)]), b = fine.points.col(q[static_cast<std::size_t>((k + 1) % 4)]);
        centre += a / 4.0;
        const Vec<3> x = bump(0.5 * (a + b));
        CHECK(std::abs(x.z() - nasa_bump_3d_height(x.x(), x.y()).value) < 1e-15);
        ++projected;
      }
      const Vec<3> x = bump(centre);
      CHECK(std::abs(x.z() - nasa_bump_3d_height(x.x(), x.y()).value) < 1e-15);
    }
  CHECK(projected == 4 * 16 * 80);
}

TEST_CASE("pipeline: the coarse 3D bump-in-channel curves onto the analytic bump", "[curving][slow]") {
  const Mesh<3> linear = bump_channel_3d(0);
  CurveOptions<3> options;
  options.method = "rbf";
  options.geometry.emplace("bump", BoundaryGeometry<3>::project(nasa_bump_3d()));
  options.sliding = {"side_y0", "side_y1"};
  options.support_radius = 0.06;  // thesis table 4.3
  const CurveResult<3> curved = curve_mesh(linear, options);
  INFO("min " << curved.quality.min << ", mean " << curved.quality.mean);
  CHECK(curved.curved.num_nodes() == 32841);
  CHECK(curved.invalid() == 0);
  CHECK(curved.moved_vertices == 0);  // the generator's wall vertices are on the bump
  CHECK(curved.moved_nodes > 0);
  CHECK(curved.max_boundary_displacement > 1e-3);  // the straight hex faces were off the bump
  const std::vector<Index> wall = curved.curved.group_nodes("bump");
  CHECK(wall.size() == 9 * 41);
  for (const Index v : wall) {
    const Vec<3> x = curved.curved.points.col(v);
    CHECK(std::abs(x.z() - nasa_bump_3d_height(x.x(), x.y()).value) < 1e-15);
  }
  for (const Index v : curved.curved.group_nodes("side_y0")) CHECK(std::abs(curved.curved.points(1, v) + 1.0) < 1e-14);
  for (const Index v : curved.curved.group_nodes("side_y1")) CHECK(std::abs(curved.curved.points(1, v)) < 1e-14);
  // Snapping alone leaves the thin wall cells invalid: the regularization is what saves them.
  CurveOptions<3> snap_only = options;
  snap_only.method = "none";
  CHECK(curve_mesh(linear, snap_only).invalid() > 0);

  // Every boundary node a centre (the thesis) against centres within 2 radii of the motion:
  // far fewer centres, the same mesh up to a small fraction of the wall displacement, and the
  // boundary nodes without a centre stay where they were.
  CurveOptions<3> all_centres = options;
  all_centres.centre_reach = 0.0;
  const CurveResult<3> thesis = curve_mesh(linear, all_centres);
  CHECK(curved.mover_steps.back().boundary_nodes < thesis.mover_steps.back().boundary_nodes / 3);
  CHECK(curved.quality.min == Approx(thesis.quality.min).margin(1e-3));
  CHECK((curved.curved.points - thesis.curved.points).cwiseAbs().maxCoeff() < 0.02 * curved.max_boundary_displacement);
  const Mesh<3> straight = convert_to_quadratic(linear).mesh;
  for (const char* group : {"top", "inflow", "outflow"})
    for (const Index v : curved.curved.group_nodes(group)) CHECK(curved.curved.points.col(v) == straight.points.col(v));
  // The flat wall around the bump meets it: it slides in its plane (z = 0).
  CHECK(curved.sliding_groups == std::vector<std::string>{"side_y0", "side_y1", "symmetry_lower"});
  for (const Index v : curved.curved.group_nodes("symmetry_lower")) CHECK(curved.curved.points(2, v) == 0.0);
}

TEST_CASE("pipeline: the default support radius is limited to a budget of boundary nodes", "[curving][slow]") {
  const Mesh<3> linear = bump_channel_3d(0);
  CurveOptions<3> options;
  options.method = "rbf";
  options.geometry.emplace("bump", BoundaryGeometry<3>::project(nasa_bump_3d()));
  options.sliding = {"side_y0", "side_y1"};
  options.max_support_nodes = 0.0;
  const CurveResult<3> free = curve_mesh(linear, options);
  CHECK_FALSE(free.support_radius_limited);
  CHECK(free.support_radius == Approx(options.support_radius_factor * free.layers.front().thickness));
  options.max_support_nodes = 20.0;
  const CurveResult<3> limited = curve_mesh(linear, options);
  CHECK(limited.support_radius_limited);
  CHECK(limited.support_radius < free.support_radius);
  CHECK(limited.invalid() == 0);
  // Around the wall nodes the snapping moved, a support holds 20 boundary nodes or fewer on average.
  const Mesh<3> straight = convert_to_quadratic(linear).mesh;
  std::vector<Index> boundary;
  for (const auto& block : boundary_facets(straight)) boundary.insert(boundary.end(), block.connectivity.begin(), block.connectivity.end());
  std::sort(boundary.begin(), boundary.end());
  boundary.erase(std::unique(boundary.begin(), boundary.end()), boundary.end());
  Points<3> at(3, static_cast<Index>(boundary.size()));
  for (std::size_t k = 0; k < boundary.size(); ++k) at.col(static_cast<Index>(k)) = straight.points.col(boundary[k]);
  const KdTree<3> tree(at);
  double inside = 0.0, moving = 0.0;
  for (const Index v : straight.group_nodes("bump"))
    if (limited.curved.points.col(v) != straight.points.col(v)) {
      inside += static_cast<double>(tree.radius_search(Vec<3>(straight.points.col(v)), limited.support_radius).size());
      moving += 1.0;
    }
  REQUIRE(moving > 0.0);
  CHECK(inside / moving <= 20.0);
  CHECK(inside / moving > 10.0);  // not shrunk far below the budget
  options.max_support_nodes = -1.0;
  CHECK_THROWS_AS(curve_mesh(linear, options), InputError);
  options.max_support_nodes = 100.0;
  options.centre_reach = -1.0;
  CHECK_THROWS_AS(curve_mesh(linear, options), InputError);
}
