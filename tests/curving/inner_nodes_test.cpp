// Nodes inside the faces and cells of curved elements (curving/inner_nodes.hpp), and the
// regularization of walls without a boundary layer: lowest-degree extensions reproduced
// exactly, affine motions kept, cells bulging away from a layer-less wall left as snapped.
#include "meshmotion/core/generators.hpp"
#include "meshmotion/curving/curve_mesh.hpp"
#include "meshmotion/curving/inner_nodes.hpp"
#include "meshmotion/curving/order_conversion.hpp"
#include "meshmotion/curving/p2_conversion.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <tuple>
#include <vector>

using namespace meshmotion;

namespace {

// The element's nodes under an affine map of the reference element plus a displacement that
// is a polynomial of degree `degree` in the reference coordinates (what the extension must
// reproduce), in Dim = 3 (2D types lie in a tilted plane).
Eigen::Matrix<double, 3, Eigen::Dynamic> mapped_nodes(ElementType t, int degree) {
  const auto nodes = reference_nodes(t);
  Eigen::Matrix3d a;
  a << 1.3, 0.2, 0.1, -0.4, 0.9, 0.3, 0.2, 0.1, 1.1;
  Eigen::Matrix<double, 3, Eigen::Dynamic> x(3, num_nodes(t));
  for (int i = 0; i < num_nodes(t); ++i) {
    const double u = nodes[static_cast<std::size_t>(i)][0], v = nodes[static_cast<std::size_t>(i)][1],
                 w = nodes[static_cast<std::size_t>(i)][2];
    const Eigen::Vector3d polynomial(0.1 * std::pow(u, degree) + 0.05 * std::pow(v, degree), 0.07 * std::pow(u + v, degree),
                                     0.03 * std::pow(w + u, degree));
    x.col(i) = a * Eigen::Vector3d(u, v, w) + (degree > 1 ? polynomial : Eigen::Vector3d::Zero());
  }
  return x;
}

// The gap between a shaft (r = 0.5) and a housing (r = 1.5) in triangles about 0.1 wide:
// no anisotropic layer on either wall.
Mesh<2> isotropic_gap() {
  return annulus_mesh({.n_around = 32, .inner_first_height = 0.1, .inner_growth = 1.01, .outer_first_height = 0.1,
                       .outer_growth = 1.01, .core_spacing = 0.1, .triangles = true});
}

}  // namespace

TEST_CASE("inner nodes: the extension reproduces the maps of lower degree its boundary determines", "[curving]") {
  // Simplices reproduce degree p - 1, except from order 4 where a cubic bubble vanishes on the
  // boundary (degree p - 2 is what the boundary determines); tensor shapes and prisms their
  // transfinite maps (here: polynomials of degree p - 1); pyramids affine maps.
  struct Case {
    ElementType type;
    int degree;
  };
  for (const Case c : {Case{ElementType::tri10, 2}, Case{ElementType::tri15, 2}, Case{ElementType::quad9, 1},
                       Case{ElementType::quad16, 2}, Case{ElementType::quad25, 3}, Case{ElementType::tet35, 3},
                       Case{ElementType::hex27, 1}, Case{ElementType::hex64, 2}, Case{ElementType::prism40, 2},
                       Case{ElementType::pyramid30, 1}}) {
    INFO(name(c.type) << ", degree " << c.degree);
    const Eigen::Matrix<double, 3, Eigen::Dynamic> exact = mapped_nodes(c.type, c.degree);
    Eigen::Matrix<double, 3, Eigen::Dynamic> x = exact;
    std::vector<int> inside;
    for (int i = detail::first_inside_node(c.type); i < num_nodes(c.type); ++i) {
      inside.push_back(i);
      x.col(i) += Eigen::Vector3d(0.3, -0.2, 0.1);
    }
    REQUIRE(!inside.empty());
    detail::extend_inside<3>(c.type, x, inside);
    CHECK((x - exact).cwiseAbs().maxCoeff() < 1e-7);
  }
}

TEST_CASE("inner nodes: a whole mesh keeps an affine motion, and only cells touching the curved nodes change", "[curving]") {
  struct Case {
    BoxCells cells;
    int order;
  };
  for (const Case t : {Case{BoxCells::tet4, 2}, Case{BoxCells::tet4, 3}, Case{BoxCells::tet4, 4}, Case{BoxCells::hex8, 2},
                       Case{BoxCells::hex8, 3}, Case{BoxCells::tet_pyramid_prism, 2}, Case{BoxCells::tet_pyramid_prism, 3}}) {
    const int p = t.order;
    INFO("order " << p << ", cells " << static_cast<int>(t.cells));
    const Mesh<3> straight = to_order(box_mesh({.nx = 3, .ny = 2, .nz = 2, .cells = t.cells}), p);
    Eigen::Matrix3d a;
    a << 1.1, 0.3, 0.0, -0.2, 0.8, 0.1, 0.05, 0.0, 1.2;
    const Vec<3> shift(0.3, -0.1, 0.2);
    // The vertices and edge nodes moved, the nodes inside faces and cells left behind.
    Mesh<3> moved = straight;
    std::vector<char> on_edges(static_cast<std::size_t>(straight.num_nodes()), 0);
    for (const auto& b : straight.cells)
      for (Index c = 0; c < b.size(); ++c) {
        const auto el = b.element(c);
        for (int k = 0; k < num_vertices(b.type) + static_cast<int>(edges(b.type).size()) * (p - 1); ++k)
          on_edges[static_cast<std::size_t>(el[static_cast<std::size_t>(k)])] = 1;
      }
    for (Index v = 0; v < moved.num_nodes(); ++v)
      if (on_edges[static_cast<std::size_t>(v)]) moved.points.col(v) = a * straight.points.col(v) + shift;
    const std::vector<char> all(static_cast<std::size_t>(moved.num_nodes()), 1), none(all.size(), 0);
    place_inner_nodes(moved, all, none);
    double error = 0.0;
    for (Index v = 0; v < moved.num_nodes(); ++v) error = std::max(error, (moved.points.col(v) - (a * straight.points.col(v) + shift)).norm());
    CHECK(error < 1e-12);

    // Nothing touches a curved node: nothing moves; fixed faces keep their nodes.
    Mesh<3> untouched = straight;
    place_inner_nodes(untouched, none, none);
    CHECK(untouched.points == straight.points);
  }
}

TEST_CASE("inner nodes: snapping alone at order 3 and 4 follows the curved edges into the cells", "[curving]") {
  // Coarse triangles around a circle (no layer): the node inside each wall triangle, left at
  // its straight place, pinches the cell against its curved edge.
  OMeshOptions o;
  o.n_around = 12;
  o.n_radial = 6;
  o.first_height = 0.15;
  o.farfield_radius = 4.0;
  o.triangles = true;
  const Mesh<2> linear = o_mesh(o);
  for (const int p : {3, 4}) {
    INFO("order " << p);
    CurveOptions<2> options;
    options.order = p;
    options.method = "none";
    options.geometry.emplace("wall", BoundaryGeometry<2>::project(SphereProjection<2>(Vec<2>::Zero(), 0.5)));
    const CurveResult<2> placed = curve_mesh(linear, options);
    options.inner_nodes = false;
    const CurveResult<2> straight_inside = curve_mesh(linear, options);
    INFO("min " << straight_inside.quality.min << " -> " << placed.quality.min);
    CHECK(placed.invalid() == 0);
    CHECK(placed.quality.min > straight_inside.quality.min + 0.03);
    // Only nodes inside cells moved: the boundary and every edge node are the same.
    Index differ = 0;
    for (Index v = 0; v < placed.curved.num_nodes(); ++v) differ += placed.curved.points.col(v) != straight_inside.curved.points.col(v);
    CHECK(differ > 0);
    CHECK(placed.moved_nodes == differ);
  }
}

TEST_CASE("walls without a layer: the blend follows the wall where it bulges into its cells only", "[curving]") {
  // The shaft is convex (its arcs bulge into the gap), the housing concave seen from the gap
  // (its arcs bulge away).
  const Mesh<2> linear = isotropic_gap();
  CurveOptions<2> options;
  options.geometry.emplace("inner", BoundaryGeometry<2>::project(SphereProjection<2>(Vec<2>::Zero(), 0.5)));
  options.geometry.emplace("outer", BoundaryGeometry<2>::project(SphereProjection<2>(Vec<2>::Zero(), 1.5)));
  REQUIRE(options.method == "blend");
  const CurveResult<2> curved = curve_mesh(linear, options);
  for (const WallLayer& layer : curved.layers) CHECK(layer.thickness == 0.0);
  CHECK(curved.invalid() == 0);
  // Nodes off the walls: some near the shaft follow it outwards (those radially above a wall
  // vertex have nothing to follow), none near the housing moves.
  const Mesh<2> straight = convert_to_quadratic(linear).mesh;
  Index near_inner = 0, near_outer = 0;
  for (Index v = 0; v < straight.num_nodes(); ++v) {
    const double r = straight.points.col(v).norm();
    const double moved = (curved.curved.points.col(v) - straight.points.col(v)).norm();
    if (r > 0.55 && r < 0.65) near_inner += moved > 0.0;
    if (r > 1.35 && r < 1.45) {
      CHECK(moved == 0.0);
      ++near_outer;
    }
  }
  CHECK(near_inner > 0);
  CHECK(near_outer > 0);
  // The blend beats snapping alone, which leaves the shaft's cells pinched.
  CurveOptions<2> snap_only = options;
  snap_only.method = "none";
  CHECK(curved.quality.min > curve_mesh(linear, snap_only).quality.min);
}

TEST_CASE("walls without a layer: the RBF radius of a wall node is twice its facets' node spacing, half where they bulge away", "[curving]") {
  const Mesh<2> linear = isotropic_gap();
  for (const int p : {2, 3}) {
    INFO("order " << p);
    CurveOptions<2> options;
    options.order = p;
    options.method = "rbf";
    options.geometry.emplace("inner", BoundaryGeometry<2>::project(SphereProjection<2>(Vec<2>::Zero(), 0.5)));
    options.geometry.emplace("outer", BoundaryGeometry<2>::project(SphereProjection<2>(Vec<2>::Zero(), 1.5)));
    const CurveResult<2> curved = curve_mesh(linear, options);
    CHECK(curved.invalid() == 0);
    REQUIRE(curved.wall_support_radii.size() == 2);
    // 32 facets around each circle: chord 2 r sin(pi / 32), split into p node spacings. The
    // shaft's facets bulge into the gap's cells, the housing's away from them.
    for (const auto& [w, r, spacings] : {std::tuple{0, 0.5, 2.0}, std::tuple{1, 1.5, 0.5}})
      CHECK(curved.wall_support_radii[static_cast<std::size_t>(w)] == Approx(spacings * 2.0 * r * std::sin(std::numbers::pi / 32) / p));
  }
}

TEST_CASE("spline walls: each node at its fraction of the facet's arc length by default", "[curving]") {
  // An ellipse O-mesh (nodes evenly spaced in angle, so facets of varying length): the
  // spline's parameter runs at a varying speed along a facet, the arc length does not.
  OMeshOptions o;
  o.semi_axis_y = 0.2;
  o.n_around = 48;
  o.n_radial = 16;
  const Mesh<2> linear = o_mesh(o);
  const auto unevenness = [&](SplineMidpoint midpoint) {
    CurveOptions<2> options;
    options.method = "none";
    options.snap.midpoint = midpoint;
    const CurveResult<2> curved = curve_mesh(linear, options);
    double worst = 0.0;
    const int wall = curved.curved.group("wall").tag;
    for (const auto& b : curved.curved.facets)
      for (Index e = 0; e < b.size(); ++e) {
        if (b.tags[static_cast<std::size_t>(e)] != wall) continue;
        const auto el = b.element(e);
        const Vec<2> a = curved.curved.points.col(el[0]), c = curved.curved.points.col(el[1]), m = curved.curved.points.col(el[2]);
        worst = std::max(worst, std::abs((m - a).norm() - (m - c).norm()) / (a - c).norm());
      }
    return worst;
  };
  REQUIRE(CurveOptions<2>{}.snap.midpoint == SplineMidpoint::arc_length);
  const double arc = unevenness(SplineMidpoint::arc_length), parameter = unevenness(SplineMidpoint::parameter);
  INFO("arc length: " << arc << ", parameter: " << parameter);
  CHECK(arc < 1e-3);
  CHECK(parameter > 1e-2);
}
