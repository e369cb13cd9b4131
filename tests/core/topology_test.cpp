#include "meshmotion/core/generators.hpp"
#include "meshmotion/core/topology.hpp"

#include <Eigen/Geometry>
#include <catch2/catch.hpp>

#include <algorithm>
#include <set>

using namespace meshmotion;

namespace {

// Area vector of a planar facet (half the cross product of its diagonals for quads).
Vec<3> area_vector(const Mesh<3>& m, std::span<const Index> v, int nv) {
  const auto p = [&](int k) { return Vec<3>(m.points.col(v[static_cast<std::size_t>(k)])); };
  if (nv == 3) return 0.5 * (p(1) - p(0)).cross(p(2) - p(0));
  return 0.5 * (p(2) - p(0)).cross(p(3) - p(1));
}

const std::vector<BoxCells> all_box_cells{BoxCells::hex8,     BoxCells::tet4,      BoxCells::prism6,
                                          BoxCells::pyramid5, BoxCells::hex_prism, BoxCells::tet_pyramid_prism};

}  // namespace

TEST_CASE("unique edges of a quad grid and the cell-to-edge map", "[core]") {
  const Index nx = 3, ny = 2;
  const Mesh<2> m = rectangle_mesh({.nx = nx, .ny = ny});
  const EdgeTopology topo = unique_edges(m);
  CHECK(topo.size() == nx * (ny + 1) + ny * (nx + 1));
  const ElementBlock& quads = m.cells[0];
  for (Index c = 0; c < quads.size(); ++c) {
    const auto ids = topo.element_edges.of(0, c);
    REQUIRE(ids.size() == 4);
    for (std::size_t k = 0; k < 4; ++k) {
      const auto& local = edges(ElementType::quad4)[k];
      const auto& e = topo.edges[static_cast<std::size_t>(ids[k])];
      const std::set<Index> expected{quads.element(c)[static_cast<std::size_t>(local[0])],
                                     quads.element(c)[static_cast<std::size_t>(local[1])]};
      CHECK(std::set<Index>{e[0], e[1]} == expected);
    }
  }
  // Sorted vertex pairs are unique.
  std::set<std::pair<Index, Index>> keys;
  for (const auto& e : topo.edges) keys.insert({std::min(e[0], e[1]), std::max(e[0], e[1])});
  CHECK(static_cast<Index>(keys.size()) == topo.size());
}

TEST_CASE("Euler characteristic of every box and rectangle mesh is that of a ball", "[core]") {
  for (BoxCells cells : all_box_cells) {
    INFO("box cells " << static_cast<int>(cells));
    const Mesh<3> m = box_mesh({.nx = 3, .ny = 2, .nz = 2, .cells = cells});
    const Index v = m.num_nodes(), e = unique_edges(m).size(), f = unique_facets(m).size(), c = m.num_cells();
    CHECK(v - e + f - c == 1);
  }
  for (RectangleCells cells : {RectangleCells::quad4, RectangleCells::tri3, RectangleCells::tri_quad}) {
    const Mesh<2> m = rectangle_mesh({.nx = 4, .ny = 3, .cells = cells});
    CHECK(m.num_nodes() - unique_edges(m).size() + m.num_cells() == 1);
  }
}

TEST_CASE("facets know their cells and extracted boundary facets point outward", "[core]") {
  for (BoxCells cells : all_box_cells) {
    INFO("box cells " << static_cast<int>(cells));
    const Mesh<3> m = box_mesh({.nx = 3, .ny = 2, .nz = 2, .x_max = 2.0, .cells = cells});
    const FacetTopology topo = unique_facets(m);
    Index n_boundary = 0;
    for (Index f = 0; f < topo.size(); ++f) {
      const auto uf = static_cast<std::size_t>(f);
      if (topo.is_boundary(f)) {
        ++n_boundary;
        CHECK(topo.elements[uf][1] == -1);
      } else {
        CHECK(topo.count[uf] == 2);
        CHECK(topo.elements[uf][1] > topo.elements[uf][0]);
      }
    }
    const auto boundary = boundary_facets(m, 7);
    Index extracted = 0;
    double area = 0.0, volume = 0.0;
    for (const auto& b : boundary) {
      extracted += b.size();
      for (Index e = 0; e < b.size(); ++e) {
        CHECK(b.tags[static_cast<std::size_t>(e)] == 7);
        const Vec<3> a = area_vector(m, b.element(e), num_vertices(b.type));
        Vec<3> centroid = Vec<3>::Zero();
        for (int k = 0; k < num_vertices(b.type); ++k) centroid += m.points.col(b.element(e)[static_cast<std::size_t>(k)]);
        centroid /= num_vertices(b.type);
        area += a.norm();
        volume += a.dot(centroid) / 3.0;  // divergence theorem: only outward normals give +volume
      }
    }
    CHECK(extracted == n_boundary);
    CHECK(area == Approx(2.0 * (2.0 + 2.0 + 1.0)));
    CHECK(volume == Approx(2.0));
  }
}

TEST_CASE("node adjacency in CSR form", "[core]") {
  const Mesh<2> m = rectangle_mesh({.nx = 2, .ny = 2});
  const Adjacency nb = node_neighbours(m);
  REQUIRE(nb.num_rows() == 9);
  const auto centre = nb.row(4);
  CHECK(std::vector<Index>(centre.begin(), centre.end()) == std::vector<Index>{1, 3, 5, 7});
  const auto corner = nb.row(0);
  CHECK(std::vector<Index>(corner.begin(), corner.end()) == std::vector<Index>{1, 3});
  for (Index i = 0; i < nb.num_rows(); ++i)
    for (Index j : nb.row(i)) {
      const auto r = nb.row(j);
      CHECK(std::binary_search(r.begin(), r.end(), i));
    }
  const Adjacency cells = node_cells(m);
  CHECK(cells.row(4).size() == 4);
  CHECK(cells.row(0).size() == 1);
  CHECK(cells.row(1).size() == 2);
}

TEST_CASE("2D boundary chains break at group changes and close around walls", "[core]") {
  const Index nx = 3, ny = 2;
  Mesh<2> m = rectangle_mesh({.nx = nx, .ny = ny});
  const auto chains = boundary_chains(m);
  REQUIRE(chains.size() == 4);
  for (const auto& c : chains) {
    CHECK_FALSE(c.closed);
    CHECK(c.facets.size() + 1 == c.nodes.size());
  }
  const auto bottom = boundary_chains(m, m.group("bottom").tag);
  REQUIRE(bottom.size() == 1);
  // Facets point outward, so the bottom side runs in +x.
  CHECK(bottom[0].nodes == std::vector<Index>{0, 1, 2, 3});
  const auto left = boundary_chains(m, m.group("left").tag);
  REQUIRE(left.size() == 1);
  CHECK(left[0].nodes.size() == static_cast<std::size_t>(ny + 1));

  for (auto& b : m.facets) std::fill(b.tags.begin(), b.tags.end(), 1);
  const auto loop = boundary_chains(m);
  REQUIRE(loop.size() == 1);
  CHECK(loop[0].closed);
  CHECK(loop[0].nodes.size() == static_cast<std::size_t>(2 * (nx + ny)));
  CHECK(loop[0].facets.size() == loop[0].nodes.size());

  // Around a body the outward (fluid) normal points into it: the wall runs clockwise.
  const Mesh<2> o = o_mesh({.n_around = 16, .n_radial = 4, .first_height = 0.01, .farfield_radius = 3.0});
  const auto shoelace = [&](const BoundaryChain& c) {
    double a = 0;
    for (std::size_t k = 0; k < c.nodes.size(); ++k) {
      const auto p = o.points.col(c.nodes[k]);
      const auto q = o.points.col(c.nodes[(k + 1) % c.nodes.size()]);
      a += 0.5 * (p.x() * q.y() - q.x() * p.y());
    }
    return a;
  };
  const auto wall = boundary_chains(o, o.group("wall").tag);
  REQUIRE(wall.size() == 1);
  CHECK(wall[0].closed);
  CHECK(wall[0].nodes.size() == 16);
  CHECK(shoelace(wall[0]) < 0);
  const auto far = boundary_chains(o, o.group("farfield").tag);
  REQUIRE(far.size() == 1);
  CHECK(shoelace(far[0]) > 0);
}

TEST_CASE("topology rejects bad connectivity", "[core]") {
  Mesh<2> m = rectangle_mesh({.nx = 1, .ny = 1, .cells = RectangleCells::tri3});
  m.cells[0].add({0, 1, 3});  // a duplicate triangle: its diagonal is shared by three cells
  CHECK_THROWS_AS(unique_facets(m), InputError);
  CHECK_THROWS_WITH(unique_facets(m), Catch::Contains("shared by 3 cells"));
  Mesh<2> bad = rectangle_mesh({.nx = 1, .ny = 1});
  bad.cells[0].connectivity[2] = 99;
  CHECK_THROWS_WITH(unique_edges(bad), Catch::Contains("refers to node 99"));
  bad.facets[0].connectivity[0] = -1;
  CHECK_THROWS_AS(boundary_chains(bad), InputError);
}
