// The geometric certificate (curving/geometry_distance.hpp): each curved wall's distance to
// its geometry, bounded by sampling, checked against dense sampling for every kind of
// geometry, and a wall valid but in the wrong place reported and refused; a cell turned over
// by the snapping's vertex moves flagged.

#include <catch2/catch.hpp>

#include "test_data.hpp"

#include "meshmotion/core/generators.hpp"
#include "meshmotion/core/shape_functions.hpp"
#include "meshmotion/curving/curve_mesh.hpp"
#include "meshmotion/curving/geometry.hpp"
#include "meshmotion/curving/geometry_distance.hpp"
#include "meshmotion/curving/p2_conversion.hpp"
#include "meshmotion/io/mesh_io.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <string>
#include <vector>

using namespace meshmotion;

namespace {

const GeometryDistance& distance_of(const std::vector<GeometryDistance>& walls, const std::string& group) {
  for (const GeometryDistance& w : walls)
    if (w.group == group) return w;
  FAIL("no geometric certificate for group " << group);
  return walls.front();
}

// The largest |x - g(x)| over a lattice of order 48 on each facet of group `tag`, g being
// `reference`: what the certificate's bound must hold.
template <int Dim>
double dense_distance(const Mesh<Dim>& mesh, int tag, const GeometryReference<Dim>& reference) {
  constexpr int m = 48;
  double largest = 0.0;
  Index ordinal = 0;
  for (const auto& block : mesh.facets)
    for (Index e = 0; e < block.size(); ++e) {
      if (block.tags[static_cast<std::size_t>(e)] != tag) continue;
      const auto facet = block.element(e);
      const int nv = num_vertices(block.type);
      std::vector<double> N(facet.size()), w(static_cast<std::size_t>(nv));
      std::vector<Vec<Dim>> vertices;
      for (int k = 0; k < nv; ++k) vertices.push_back(mesh.points.col(facet[static_cast<std::size_t>(k)]));
      for (int i = 0; i <= m; ++i)
        for (int j = 0; j <= (shape(block.type) == Shape::line ? 0 : m - i); ++j) {
          const RefPoint r = shape(block.type) == Shape::line ? RefPoint{2.0 * i / m - 1.0, 0.0, 0.0}
                                                              : RefPoint{static_cast<double>(i) / m, static_cast<double>(j) / m, 0.0};
          shape_functions(block.type, r, N);
          shape_functions(linear_type(block.type), r, w);
          Vec<Dim> x = Vec<Dim>::Zero();
          for (std::size_t k = 0; k < facet.size(); ++k) x += N[k] * mesh.points.col(facet[k]);
          largest = std::max(largest, (x - reference.at(FacetPoint<Dim>{facet, vertices, ordinal, w, x})).norm());
        }
      ++ordinal;
    }
  return largest;
}

// Snaps the groups of `geometry` on the quadratic version of `linear` and measures them:
// the certificate and, per group, the dense distance.
template <int Dim>
void check_bounds_against_dense_sampling(const Mesh<Dim>& linear, const std::map<std::string, BoundaryGeometry<Dim>>& geometry) {
  Mesh<Dim> mesh = convert_to_quadratic(linear).mesh;
  name_unnamed_facet_groups(mesh);
  std::map<int, BoundaryGeometry<Dim>> by_tag;
  for (const auto& [group, geo] : geometry) by_tag.emplace(mesh.group(group).tag, geo);
  const SnappedBoundary<Dim> snapped = snap_boundary(mesh, by_tag);
  for (std::size_t k = 0; k < snapped.nodes.size(); ++k) mesh.points.col(snapped.nodes[k]) += snapped.displacements.col(static_cast<Index>(k));
  const std::vector<GeometryDistance> walls = measure_geometry_distance(mesh, snapped.references, CurveOptions<Dim>{}.geometry_tolerance);
  REQUIRE(walls.size() == geometry.size());
  for (const auto& [group, geo] : geometry) {
    const GeometryDistance& w = distance_of(walls, group);
    const double dense = dense_distance(mesh, mesh.group(group).tag, snapped.references.at(mesh.group(group).tag));
    INFO(group << " (" << w.geometry << "): bound " << w.max_distance << " (relative " << w.max_relative_distance << "), dense sampling " << dense);
    CHECK(w.facets_off == 0);
    CHECK(dense > 0.0);
    CHECK(dense <= w.max_distance);
    CHECK(w.max_distance <= 2.0 * dense);  // a bound, not a blanket
  }
}

}  // namespace

TEST_CASE("geometric certificate: a circle curved at P2 to P4 is within its bound, which dense sampling confirms", "[curving]") {
  const Mesh<2> linear = o_mesh({.n_around = 24, .n_radial = 6, .first_height = 0.02});
  std::vector<double> bounds;
  for (const int order : {2, 3, 4}) {
    CurveOptions<2> options;
    options.order = order;
    options.method = "none";
    options.geometry.emplace("wall", BoundaryGeometry<2>::project(SphereProjection<2>(Vec<2>::Zero(), 0.5)));
    const CurveResult<2> result = curve_mesh(linear, options);
    const GeometryDistance& wall = distance_of(result.geometry_distance, "wall");
    CHECK(wall.geometry == "projection");
    CHECK(wall.facets == 24);
    CHECK(wall.max_node_distance < 1e-14);
    // The distance to the circle of the facets sampled densely: | |x| - 0.5 |.
    double dense = 0.0;
    for (const auto& block : result.curved.facets)
      for (Index e = 0; e < block.size(); ++e) {
        if (block.tags[static_cast<std::size_t>(e)] != result.curved.group("wall").tag) continue;
        const auto facet = block.element(e);
        std::vector<double> N(facet.size());
        for (int i = 0; i <= 200; ++i) {
          shape_functions(block.type, RefPoint{i / 100.0 - 1.0, 0.0, 0.0}, N);
          Vec<2> x = Vec<2>::Zero();
          for (std::size_t k = 0; k < facet.size(); ++k) x += N[k] * result.curved.points.col(facet[k]);
          dense = std::max(dense, std::abs(x.norm() - 0.5));
        }
      }
    INFO("P" << order << ": bound " << wall.max_distance << ", dense " << dense);
    CHECK(dense <= wall.max_distance);
    CHECK(wall.max_distance <= 2.0 * dense);
    bounds.push_back(wall.max_distance);
    CHECK(result.off_geometry() == 0);
    // The farfield is reconstructed by a spline by default: measured too.
    CHECK(distance_of(result.geometry_distance, "farfield").geometry == "spline");
  }
  // P3's nodes are the projections of equally spaced points of the chord, not equally spaced
  // along the arc: its bound (1.3e-5) exceeds P2's (5.4e-6) on this coarse circle. P4 is 1e-8.
  CHECK(bounds[2] < 0.01 * bounds[0]);
}

TEST_CASE("geometric certificate: the bound holds for splines, projections and reconstructions", "[curving]") {
  // 2D: the O-mesh's wall as a spline of its vertices and its farfield as a circle.
  check_bounds_against_dense_sampling<2>(o_mesh({.n_around = 20, .n_radial = 4, .first_height = 0.05, .triangles = true}),
                                         {{"wall", BoundaryGeometry<2>::spline()},
                                          {"farfield", BoundaryGeometry<2>::project(SphereProjection<2>(Vec<2>::Zero(), 20.0))}});
  // 3D: the sphere's wall reconstructed from its triangles, and projected onto the sphere.
  MESHMOTION_REQUIRE_DATA(file, "meshopt_sphere_symmetry_linear_tet.msh");
  const Mesh<3> sphere = read_mesh_as<3>(file);
  check_bounds_against_dense_sampling<3>(sphere, {{"7", BoundaryGeometry<3>::spline()}});
  check_bounds_against_dense_sampling<3>(sphere, {{"7", BoundaryGeometry<3>::project(SphereProjection<3>(Vec<3>::Zero(), 0.5))}});
}

TEST_CASE("geometric certificate: a wall with its nodes on the circle but a facet the long way round is off it", "[curving]") {
  // What a closed curve's seam did: the high-order node of one facet lands on the far side of
  // the body, on the circle; the facet crosses the body. Validity need not see it.
  const Mesh<2> linear = o_mesh({.n_around = 24, .n_radial = 6, .first_height = 0.02});
  const SphereProjection<2> circle(Vec<2>::Zero(), 0.5);
  CurveOptions<2> options;
  options.method = "none";
  options.geometry.emplace("wall", BoundaryGeometry<2>::project(circle, [&](std::span<const Vec<2>> vertices, std::span<const double> w) {
    const Vec<2> x = w[0] * vertices[0] + w[1] * vertices[1];
    const bool seam = std::abs(vertices[0].y()) < 1e-12 && vertices[0].x() > 0.0;
    return seam ? Vec<2>(-circle(x)) : circle(x);
  }));
  const CurveResult<2> result = curve_mesh(linear, options);
  const GeometryDistance& wall = distance_of(result.geometry_distance, "wall");
  CHECK(wall.max_node_distance < 1e-14);  // every node is on the circle
  CHECK(wall.facets_off == 1);
  CHECK(result.off_geometry() == 1);
  CHECK(wall.max_relative_distance > 1.0);
  CHECK(wall.worst_at[0] > 0.45);  // the facet at the seam
  options.strict = true;
  CHECK_THROWS_AS(curve_mesh(linear, options), InvalidMeshError);
  CHECK_THROWS_WITH(curve_mesh(linear, options), Catch::Contains("1 curved facets are off their geometry (worst: group 'wall'"));
  options.geometry_tolerance = 0.0;
  CHECK_THROWS_WITH(curve_mesh(linear, options), Catch::Contains("curve_mesh: option 'geometry_tolerance': 0 is out of range (expected > 0)"));
}

TEST_CASE("a cell turned over by moving a vertex onto the geometry is flagged and refused when strict", "[curving]") {
  // A circle of radius 0.56 around a wall of radius 0.5 whose first ring is 0.02 away: every
  // wall vertex moves beyond it and the straight cells at the wall turn over, while the wall
  // itself lies on its geometry.
  const Mesh<2> linear = o_mesh({.n_around = 24, .n_radial = 6, .first_height = 0.02, .triangles = true});
  CurveOptions<2> options;
  options.method = "none";
  options.geometry.emplace("wall", BoundaryGeometry<2>::project(SphereProjection<2>(Vec<2>::Zero(), 0.56)));
  const CurveResult<2> moved = curve_mesh(linear, options);
  CHECK(moved.moved_vertices == 24);
  CHECK(moved.reversed_cells >= 24);
  CHECK(moved.off_geometry() == 0);
  options.strict = true;
  CHECK_THROWS_WITH(curve_mesh(linear, options), Catch::Contains("cells were turned over by moving 24 vertices onto the geometry"));
  // On the wall's own circle nothing moves and nothing turns.
  options.geometry.insert_or_assign("wall", BoundaryGeometry<2>::project(SphereProjection<2>(Vec<2>::Zero(), 0.5)));
  CHECK(curve_mesh(linear, options).reversed_cells == 0);
}
