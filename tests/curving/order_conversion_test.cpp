#include "meshmotion/core/generators.hpp"
#include "meshmotion/core/shape_functions.hpp"
#include "meshmotion/core/topology.hpp"
#include "meshmotion/curving/order_conversion.hpp"
#include "meshmotion/curving/p2_conversion.hpp"
#include "meshmotion/quality/cell_quality.hpp"

#include <catch2/catch.hpp>

#include "conversion_checks.hpp"

#include <algorithm>
#include <random>
#include <vector>

using namespace meshmotion;

namespace {

// The coordinates of element e of block b: Dim × num_nodes.
template <int Dim>
Eigen::Matrix<double, Dim, Eigen::Dynamic> element_coords(const Mesh<Dim>& m, const ElementBlock& b, Index e) {
  const auto el = b.element(e);
  Eigen::Matrix<double, Dim, Eigen::Dynamic> x(Dim, static_cast<Index>(el.size()));
  for (std::size_t k = 0; k < el.size(); ++k) x.col(static_cast<Index>(k)) = m.points.col(el[k]);
  return x;
}

// Every node of every converted element sits where the source element's map puts that
// node's reference point: the straight element of a linear input, or the curved one. A node
// shared in the wrong orientation would sit elsewhere from one of its elements.
template <int Dim>
void check_nodes_on_source(const Mesh<Dim>& source, const Mesh<Dim>& converted) {
  using Lists = std::pair<const std::vector<ElementBlock>*, const std::vector<ElementBlock>*>;
  for (const Lists& lists : {Lists{&source.cells, &converted.cells}, Lists{&source.facets, &converted.facets}})
    for (std::size_t b = 0; b < lists.first->size(); ++b) {
      const ElementBlock& from = (*lists.first)[b];
      const ElementBlock& to = (*lists.second)[b];
      INFO(name(from.type) << " -> " << name(to.type));
      const auto ref = reference_nodes(to.type);
      for (Index e = 0; e < from.size(); ++e) {
        const auto x = element_coords(source, from, e);
        const auto el = to.element(e);
        for (std::size_t i = 0; i < el.size(); ++i)
          CHECK((converted.points.col(el[i]) - map_to_physical(from.type, x, ref[i])).norm() < 1e-12);
      }
    }
}

template <int Dim>
void check_straight_conversion(const Mesh<Dim>& linear, int k) {
  const OrderConversion<Dim> conv = convert_to_order(linear, k);
  const Mesh<Dim>& m = conv.mesh;
  CHECK(conv.num_kept_nodes == linear.num_nodes());
  CHECK(m.points.leftCols(linear.num_nodes()) == linear.points);
  REQUIRE(m.cells.size() == linear.cells.size());
  for (std::size_t b = 0; b < m.cells.size(); ++b) CHECK(m.cells[b].type == element_type(shape(linear.cells[b].type), k));
  for (std::size_t b = 0; b < m.facets.size(); ++b) CHECK(m.facets[b].tags == linear.facets[b].tags);
  check_nodes_on_source(linear, m);
  test::check_no_duplicate_nodes(m);
  test::check_facets_match_cells(m);
  // Straight-sided cells of any order have the scaled Jacobian of their linear cell.
  for (const auto& b : m.cells)
    for (Index e = 0; e < std::min<Index>(b.size(), 8); ++e) {
      const ScaledJacobian s = scaled_jacobian(b.type, element_coords(m, b, e));
      CHECK(s.valid);
    }
}

}  // namespace

TEST_CASE("P1 -> P3 and P4 node counts on structured grids", "[curving]") {
  const Index nx = 3, ny = 2;
  const Index v2 = (nx + 1) * (ny + 1), e2 = nx * (ny + 1) + ny * (nx + 1), c2 = nx * ny;
  const Mesh<2> quads = rectangle_mesh({.nx = nx, .ny = ny});
  CHECK(to_order(quads, 3).num_nodes() == v2 + 2 * e2 + 4 * c2);
  CHECK(to_order(quads, 4).num_nodes() == v2 + 3 * e2 + 9 * c2);
  const Mesh<2> tris = rectangle_mesh({.nx = nx, .ny = ny, .cells = RectangleCells::tri3});
  CHECK(to_order(tris, 3).num_nodes() == v2 + 2 * (e2 + c2) + 2 * c2);      // a diagonal and 2 triangles per grid cell
  CHECK(to_order(tris, 4).num_nodes() == v2 + 3 * (e2 + c2) + 3 * 2 * c2);  // 3 inside nodes per tri15
  // Order 2 through either conversion: the same node count.
  CHECK(to_order(tris, 2).num_nodes() == to_quadratic(tris).num_nodes());

  const Index nz = 2;
  const Index v3 = (nx + 1) * (ny + 1) * (nz + 1);
  const Index e3 = nx * (ny + 1) * (nz + 1) + (nx + 1) * ny * (nz + 1) + (nx + 1) * (ny + 1) * nz;
  const Index f3 = nx * ny * (nz + 1) + nx * (ny + 1) * nz + (nx + 1) * ny * nz;
  const Index c3 = nx * ny * nz;
  const Mesh<3> hexes = box_mesh({.nx = nx, .ny = ny, .nz = nz});
  CHECK(to_order(hexes, 3).num_nodes() == v3 + 2 * e3 + 4 * f3 + 8 * c3);
  // Kuhn tetrahedra: one diagonal per grid face and per grid cell, 2 triangles per grid face,
  // 6 tetrahedra with 6 triangles between them per grid cell; a tet35 has one inside node.
  const Mesh<3> tets = box_mesh({.nx = nx, .ny = ny, .nz = nz, .cells = BoxCells::tet4});
  const Index edges = e3 + f3 + c3, triangles = 2 * f3 + 6 * c3;
  CHECK(to_order(tets, 3).num_nodes() == v3 + 2 * edges + triangles);
  CHECK(to_order(tets, 4).num_nodes() == v3 + 3 * edges + 3 * triangles + 6 * c3);
}

TEST_CASE("P1 -> Pk conversion of every element type and mixed meshes is conforming", "[curving]") {
  for (int k : {2, 3, 4, 5, 6, 8}) {
    INFO("order " << k);
    for (RectangleCells cells : {RectangleCells::quad4, RectangleCells::tri3, RectangleCells::tri_quad})
      check_straight_conversion(rectangle_mesh({.nx = 4, .ny = 3, .cells = cells}), k);
    for (BoxCells cells : {BoxCells::tet4, BoxCells::hex8, BoxCells::prism6, BoxCells::pyramid5, BoxCells::hex_prism,
                           BoxCells::tet_pyramid_prism}) {
      const Mesh<3> m = box_mesh({.nx = 3, .ny = 2, .nz = 2, .cells = cells});
      INFO("box cells " << static_cast<int>(cells));
      const bool held = std::all_of(m.cells.begin(), m.cells.end(), [k](const ElementBlock& b) { return max_order(shape(b.type)) >= k; });
      if (!held) {
        CHECK_THROWS_AS(convert_to_order(m, k), InputError);  // prisms and pyramids stop at 3
        continue;
      }
      check_straight_conversion(m, k);
    }
  }
}

TEST_CASE("P1 -> Pk keeps numbering, ids, tags and CAD parameters", "[curving]") {
  Mesh<2> m = o_mesh({.n_around = 24, .n_radial = 6, .first_height = 1e-3, .farfield_radius = 4.0});
  m.node_ids.resize(static_cast<std::size_t>(m.num_nodes()));
  for (std::size_t i = 0; i < m.node_ids.size(); ++i) m.node_ids[i] = 10 * static_cast<std::int64_t>(i) + 5;
  m.node_params.assign(static_cast<std::size_t>(m.num_nodes()), NodeParametrization{2, 0, 0.0, 0.0});
  for (Index i = 0; i < 24; ++i) m.node_params[static_cast<std::size_t>(i)] = {1, 7, static_cast<double>(i), 0.0};
  const Mesh<2> p3 = to_order(m, 3);
  REQUIRE(p3.node_ids.size() == static_cast<std::size_t>(p3.num_nodes()));
  CHECK(std::equal(m.node_ids.begin(), m.node_ids.end(), p3.node_ids.begin()));
  CHECK(p3.node_ids[static_cast<std::size_t>(m.num_nodes())] == m.node_ids.back() + 1);
  CHECK(p3.groups.size() == m.groups.size());
  // The wall's edge nodes of facet (i, i+1), away from the seam, carry the parameters i + 1/3
  // and i + 2/3 of the wall's curve.
  const int wall = p3.group("wall").tag;
  Index checked = 0;
  for (const auto& b : p3.facets)
    for (Index e = 0; e < b.size(); ++e) {
      if (b.tags[static_cast<std::size_t>(e)] != wall) continue;
      const auto el = b.element(e);
      const double u0 = p3.node_params[static_cast<std::size_t>(el[0])].u, u1 = p3.node_params[static_cast<std::size_t>(el[1])].u;
      if (std::abs(u1 - u0) != 1.0) continue;
      for (int j = 1; j <= 2; ++j) {
        const NodeParametrization& p = p3.node_params[static_cast<std::size_t>(el[static_cast<std::size_t>(1 + j)])];
        CHECK(p.entity_tag == 7);
        CHECK(p.u == Approx(u0 + (u1 - u0) * j / 3.0));
        ++checked;
      }
    }
  CHECK(checked >= 40);
}

TEST_CASE("raising the order of a curved mesh reproduces its map exactly", "[curving]") {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> jitter(-0.02, 0.02);
  for (BoxCells cells : {BoxCells::tet4, BoxCells::hex_prism, BoxCells::tet_pyramid_prism}) {
    const Mesh<3> linear = box_mesh({.nx = 2, .ny = 2, .nz = 2, .cells = cells});
    Mesh<3> p2 = to_quadratic(linear);
    for (Index i = linear.num_nodes(); i < p2.num_nodes(); ++i)  // bend the high-order nodes
      for (int d = 0; d < 3; ++d) p2.points(d, i) += jitter(rng);
    for (int k : {3, 4}) {
      if (k == 4 && cells != BoxCells::tet4) continue;
      INFO("cells " << static_cast<int>(cells) << ", order " << k);
      const OrderConversion<3> conv = convert_to_order(p2, k);
      CHECK(conv.num_kept_nodes == linear.num_nodes());  // the vertices, in their order
      for (Index i = 0; i < conv.num_kept_nodes; ++i) CHECK(conv.kept[static_cast<std::size_t>(i)] == i);
      check_nodes_on_source(p2, conv.mesh);
      test::check_facets_match_cells(conv.mesh);
      // Same map at points that are nodes of neither.
      const ElementBlock& from = p2.cells.front();
      const ElementBlock& to = conv.mesh.cells.front();
      const RefPoint xi = reference_centroid(from.type);
      const RefPoint off{xi[0] * 0.7 + 0.01, xi[1] * 0.9 + 0.02, xi[2] * 0.8 + 0.015};
      for (Index e = 0; e < from.size(); ++e)
        CHECK((map_to_physical(from.type, element_coords(p2, from, e), off) -
               map_to_physical(to.type, element_coords(conv.mesh, to, e), off)).norm() < 1e-12);
    }
  }
}

TEST_CASE("order conversion refuses what is not exact or not in the catalogue", "[curving]") {
  const Mesh<3> hexes = box_mesh({.nx = 1, .ny = 1, .nz = 1});
  CHECK(to_order(hexes, 8).cells.front().type == ElementType::hex729);
  const Mesh<3> prisms = box_mesh({.nx = 1, .ny = 1, .nz = 1, .cells = BoxCells::prism6});
  CHECK(to_order(prisms, 8).cells.front().type == ElementType::prism405);
  CHECK_THROWS_WITH(convert_to_order(hexes, 9), Catch::Contains("order must be 1 to 8"));
  CHECK_THROWS_WITH(convert_to_order(to_order(hexes, 3), 2), Catch::Contains("lowering the order"));
  const Mesh<3> pyramids = box_mesh({.nx = 1, .ny = 1, .nz = 1, .cells = BoxCells::pyramid5});
  CHECK(to_order(pyramids, 3).cells.front().type == ElementType::pyramid30);
  CHECK(to_order(pyramids, 8).cells.front().type == ElementType::pyramid285);
}
