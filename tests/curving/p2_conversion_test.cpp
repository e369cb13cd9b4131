#include "meshmotion/core/generators.hpp"
#include "meshmotion/core/topology.hpp"
#include "meshmotion/curving/p2_conversion.hpp"

#include <catch2/catch.hpp>

#include "conversion_checks.hpp"

#include <algorithm>
#include <map>
#include <set>
#include <vector>

using namespace meshmotion;

namespace {

// Every high-order node sits at the mean of the vertices it belongs to: edge nodes at edge
// midpoints, face nodes at quadrilateral centres, the hex27 node at the hexahedron centre.
template <int Dim>
void check_straight_positions(const Mesh<Dim>& q) {
  for (const auto* list : {&q.cells, &q.facets})
    for (const auto& b : *list) {
      const int nv = num_vertices(b.type);
      const auto e_local = edges(b.type);
      for (Index e = 0; e < b.size(); ++e) {
        const auto el = b.element(e);
        const auto p = [&](int k) { return Vec<Dim>(q.points.col(el[static_cast<std::size_t>(k)])); };
        for (std::size_t k = 0; k < e_local.size(); ++k)
          CHECK((p(nv + static_cast<int>(k)) - 0.5 * (p(e_local[k][0]) + p(e_local[k][1]))).norm() < 1e-13);
        if (num_nodes(b.type) == nv + static_cast<int>(e_local.size())) continue;
        // Face nodes: through facet_nodes(), whose last entry is a quadrilateral's centre.
        const auto check_centre = [&](std::span<const int> corners, int centre) {
          Vec<Dim> c = Vec<Dim>::Zero();
          for (int v : corners) c += p(v);
          CHECK((p(centre) - c / static_cast<double>(corners.size())).norm() < 1e-13);
        };
        if (dimension(b.type) == 2) {
          const std::array<int, 4> corners{0, 1, 2, 3};
          check_centre(corners, 8);
        } else {
          std::array<int, max_facet_nodes> fn{};
          for (int f = 0; f < static_cast<int>(facets(b.type).size()); ++f)
            if (facet_nodes(b.type, f, fn) == 9) check_centre(std::span<const int>(fn.data(), 4), fn[8]);
          if (b.type == ElementType::hex27) {
            const std::array<int, 8> corners{0, 1, 2, 3, 4, 5, 6, 7};
            check_centre(corners, 26);
          }
        }
      }
    }
}

template <int Dim>
void check_conversion(const Mesh<Dim>& linear, bool complete) {
  const QuadraticConversion<Dim> conv = convert_to_quadratic(linear, {.complete = complete});
  const Mesh<Dim>& q = conv.mesh;
  CHECK(conv.num_linear_nodes == linear.num_nodes());
  CHECK(q.num_nodes() == linear.num_nodes() + static_cast<Index>(conv.sources.size()));
  CHECK(q.points.leftCols(linear.num_nodes()) == linear.points);
  REQUIRE(q.cells.size() == linear.cells.size());
  REQUIRE(q.facets.size() == linear.facets.size());
  for (std::size_t b = 0; b < q.cells.size(); ++b) {
    CHECK(q.cells[b].type == quadratic_type(linear.cells[b].type, complete));
    CHECK(q.cells[b].size() == linear.cells[b].size());
  }
  for (std::size_t b = 0; b < q.facets.size(); ++b) {
    CHECK(q.facets[b].type == quadratic_type(linear.facets[b].type, complete));
    CHECK(q.facets[b].tags == linear.facets[b].tags);
  }
  CHECK(q.groups.size() == linear.groups.size());
  check_straight_positions(q);
  test::check_no_duplicate_nodes(q);
  test::check_facets_match_cells(q);
  // Sources: boundary nodes know a facet holding them and lie between the listed vertices.
  for (std::size_t i = 0; i < conv.sources.size(); ++i) {
    const auto& s = conv.sources[i];
    const Index node = conv.num_linear_nodes + static_cast<Index>(i);
    if (s.facet[0] >= 0) {
      const auto el = q.facets[static_cast<std::size_t>(s.facet[0])].element(s.facet[1]);
      CHECK(std::find(el.begin(), el.end(), node) != el.end());
    }
    if (s.kind == HighOrderNodeSource::Kind::edge)
      CHECK((q.points.col(node) - 0.5 * (q.points.col(s.vertices[0]) + q.points.col(s.vertices[1]))).norm() < 1e-13);
  }
}

}  // namespace

TEST_CASE("P2 node counts on structured grids", "[curving]") {
  const Index nx = 3, ny = 2, nz = 4;
  const Index v2 = (nx + 1) * (ny + 1), e2 = nx * (ny + 1) + ny * (nx + 1);
  const Mesh<2> quads = rectangle_mesh({.nx = nx, .ny = ny});
  CHECK(to_quadratic(quads).num_nodes() == v2 + e2 + nx * ny);
  CHECK(to_quadratic(quads, {.complete = false}).num_nodes() == v2 + e2);
  const Mesh<2> tris = rectangle_mesh({.nx = nx, .ny = ny, .cells = RectangleCells::tri3});
  CHECK(to_quadratic(tris).num_nodes() == v2 + e2 + nx * ny);  // + one diagonal per grid cell

  const Index v3 = (nx + 1) * (ny + 1) * (nz + 1);
  const Index e3 = nx * (ny + 1) * (nz + 1) + (nx + 1) * ny * (nz + 1) + (nx + 1) * (ny + 1) * nz;
  const Index f3 = nx * ny * (nz + 1) + nx * (ny + 1) * nz + (nx + 1) * ny * nz;
  const Index c3 = nx * ny * nz;
  const Mesh<3> hexes = box_mesh({.nx = nx, .ny = ny, .nz = nz});
  const Mesh<3> hex27 = to_quadratic(hexes);
  CHECK(hex27.num_nodes() == v3 + e3 + f3 + c3);
  CHECK(to_quadratic(hexes, {.complete = false}).num_nodes() == v3 + e3);
  // Kuhn tetrahedra add a diagonal on every grid face and one through every grid cell.
  const Mesh<3> tets = box_mesh({.nx = nx, .ny = ny, .nz = nz, .cells = BoxCells::tet4});
  CHECK(to_quadratic(tets).num_nodes() == v3 + e3 + f3 + c3);
  CHECK(hex27.find_block(ElementType::hex27)->size() == c3);
  CHECK(hex27.find_block(ElementType::quad9)->size() == 2 * (nx * ny + ny * nz + nx * nz));
}

TEST_CASE("P2 conversion of every element type and mixed meshes is conforming", "[curving]") {
  for (bool complete : {true, false}) {
    INFO("complete " << complete);
    for (RectangleCells cells : {RectangleCells::quad4, RectangleCells::tri3, RectangleCells::tri_quad})
      check_conversion(rectangle_mesh({.nx = 4, .ny = 3, .cells = cells}), complete);
    for (BoxCells cells : {BoxCells::hex8, BoxCells::tet4, BoxCells::prism6, BoxCells::pyramid5, BoxCells::hex_prism,
                           BoxCells::tet_pyramid_prism}) {
      INFO("box cells " << static_cast<int>(cells));
      const Mesh<3> m = box_mesh({.nx = 3, .ny = 2, .nz = 2, .cells = cells});
      check_conversion(m, complete);
      // Node count from the topology: vertices + edges (+ quadrilateral faces + hexahedra).
      std::vector<const ElementBlock*> cell_blocks;
      for (const auto& b : m.cells) cell_blocks.push_back(&b);
      const FacetTopology faces = unique_faces(cell_blocks, m.num_nodes());
      const Index quad_faces = std::count(faces.num_vertices.begin(), faces.num_vertices.end(), 4);
      const Index hexes = m.find_block(ElementType::hex8) ? m.find_block(ElementType::hex8)->size() : 0;
      CHECK(to_quadratic(m, {.complete = complete}).num_nodes() ==
            m.num_nodes() + unique_edges(m).size() + (complete ? quad_faces + hexes : 0));
    }
  }
}

TEST_CASE("P2 conversion keeps numbering, tags, ids and finds the wall facets", "[curving]") {
  Mesh<2> m = o_mesh({.n_around = 24, .n_radial = 6, .first_height = 1e-3, .farfield_radius = 4.0});
  m.node_ids.resize(static_cast<std::size_t>(m.num_nodes()));
  for (std::size_t i = 0; i < m.node_ids.size(); ++i) m.node_ids[i] = 10 * static_cast<std::int64_t>(i) + 5;
  m.node_params.assign(static_cast<std::size_t>(m.num_nodes()), NodeParametrization{2, 0, 0.0, 0.0});
  for (Index i = 0; i < 24; ++i) m.node_params[static_cast<std::size_t>(i)] = {1, 7, static_cast<double>(i), 0.0};
  m.facets[0].ids.resize(static_cast<std::size_t>(m.facets[0].size()));
  for (std::size_t e = 0; e < m.facets[0].ids.size(); ++e) m.facets[0].ids[e] = 100 + static_cast<std::int64_t>(e);
  check_conversion(m, true);

  const QuadraticConversion<2> conv = convert_to_quadratic(m);
  const Mesh<2>& q = conv.mesh;
  CHECK(q.facets[0].ids == m.facets[0].ids);
  REQUIRE(q.node_ids.size() == static_cast<std::size_t>(q.num_nodes()));
  CHECK(q.node_ids[static_cast<std::size_t>(m.num_nodes())] == m.node_ids.back() + 1);
  CHECK(std::set<std::int64_t>(q.node_ids.begin(), q.node_ids.end()).size() == q.node_ids.size());
  // Every wall facet's mid node has that facet as parent, and wall mid nodes keep the wall's
  // CAD curve with the parameter midpoint (wall edges i → i+1 away from the seam).
  const int wall = q.group("wall").tag;
  Index wall_mid_nodes = 0;
  for (const auto& b : q.facets)
    for (Index e = 0; e < b.size(); ++e) {
      if (b.tags[static_cast<std::size_t>(e)] != wall) continue;
      const Index mid = b.element(e)[2];
      const auto& s = conv.sources[static_cast<std::size_t>(mid - conv.num_linear_nodes)];
      CHECK(s.facet == std::array<Index, 2>{static_cast<Index>(&b - q.facets.data()), e});
      const auto& param = q.node_params[static_cast<std::size_t>(mid)];
      CHECK(param.entity_dim == 1);
      CHECK(param.entity_tag == 7);
      CHECK(param.u == Approx(0.5 * static_cast<double>(b.element(e)[0] + b.element(e)[1])));
      ++wall_mid_nodes;
    }
  CHECK(wall_mid_nodes == 24);
  CHECK(q.num_facets() == 48);
  // Interior mid nodes are on no facet and carry the "unknown" parametrization.
  const auto& interior = conv.sources.back();
  CHECK(interior.facet == std::array<Index, 2>{-1, -1});
}

TEST_CASE("P2 conversion rejects meshes that are not linear or not valid", "[curving]") {
  const Mesh<2> q = to_quadratic(rectangle_mesh({.nx = 2, .ny = 2}));
  CHECK_THROWS_AS(to_quadratic(q), InputError);
  CHECK_THROWS_WITH(to_quadratic(q), Catch::Contains("already has quad9"));
  Mesh<2> bad = rectangle_mesh({.nx = 2, .ny = 2});
  bad.cells[0].connectivity[0] = 100;
  CHECK_THROWS_AS(to_quadratic(bad), InputError);
}
