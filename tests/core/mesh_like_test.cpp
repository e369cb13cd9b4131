// A foreign mesh type (plain arrays, as a flow solver keeps them) adapted through
// MeshTraits gives the same results as the library's own Mesh<Dim>.

#include "meshmotion/core/generators.hpp"
#include "meshmotion/core/mesh_like.hpp"
#include "meshmotion/core/topology.hpp"

#include <catch2/catch.hpp>

#include <vector>

namespace foreign {

// 3D solver mesh: x, y, z per node; hexahedra and prisms in separate int arrays (Gmsh order).
struct SolverMesh {
  std::vector<double> xyz;
  std::vector<int> hexes;
  std::vector<int> prisms;
};

}  // namespace foreign

template <>
struct meshmotion::MeshTraits<foreign::SolverMesh> {
  using M = foreign::SolverMesh;
  static constexpr int dim = 3;
  static Index num_nodes(const M& m) { return static_cast<Index>(m.xyz.size() / 3); }
  static double coordinate(const M& m, Index node, int axis) { return m.xyz[static_cast<std::size_t>(3 * node + axis)]; }
  static Index num_cell_blocks(const M&) { return 2; }
  static ElementType cell_type(const M&, Index block) { return block == 0 ? ElementType::hex8 : ElementType::prism6; }
  static Index num_cells(const M& m, Index block) {
    return block == 0 ? static_cast<Index>(m.hexes.size() / 8) : static_cast<Index>(m.prisms.size() / 6);
  }
  static Index cell_node(const M& m, Index block, Index cell, int local) {
    return block == 0 ? m.hexes[static_cast<std::size_t>(8 * cell + local)] : m.prisms[static_cast<std::size_t>(6 * cell + local)];
  }
};

using namespace meshmotion;

static_assert(MeshLike<foreign::SolverMesh>);
static_assert(MeshLike<Mesh<2>> && MeshLike<Mesh<3>>);
static_assert(!MeshLike<std::vector<double>>);

namespace {

foreign::SolverMesh from_mesh(const Mesh<3>& m) {
  foreign::SolverMesh s;
  s.xyz.assign(m.points.data(), m.points.data() + m.points.size());
  for (Index v : m.find_block(ElementType::hex8)->connectivity) s.hexes.push_back(static_cast<int>(v));
  for (Index v : m.find_block(ElementType::prism6)->connectivity) s.prisms.push_back(static_cast<int>(v));
  return s;
}

}  // namespace

TEST_CASE("a foreign mesh type gives the same topology as Mesh<3>", "[core]") {
  Mesh<3> mesh = box_mesh({.nx = 4, .ny = 3, .nz = 2, .cells = BoxCells::hex_prism});
  // Put the hexahedra first, as the foreign type lists them.
  if (mesh.cells[0].type != ElementType::hex8) std::swap(mesh.cells[0], mesh.cells[1]);
  const foreign::SolverMesh solver = from_mesh(mesh);

  CHECK(copy_points(solver) == mesh.points);
  const Mesh<3> copy = to_mesh(solver);
  REQUIRE(copy.cells.size() == 2);
  CHECK(copy.cells[0].connectivity == mesh.cells[0].connectivity);
  CHECK(copy.cells[1].connectivity == mesh.cells[1].connectivity);

  const EdgeTopology e1 = unique_edges(mesh), e2 = unique_edges(solver);
  CHECK(e1.edges == e2.edges);
  CHECK(e1.element_edges.ids == e2.element_edges.ids);
  const FacetTopology f1 = unique_facets(mesh), f2 = unique_facets(solver);
  CHECK(f1.vertices == f2.vertices);
  CHECK(f1.elements == f2.elements);
  CHECK(f1.element_facets.ids == f2.element_facets.ids);
  const auto b1 = boundary_facets(mesh), b2 = boundary_facets(solver);
  REQUIRE(b1.size() == b2.size());
  for (std::size_t b = 0; b < b1.size(); ++b) {
    CHECK(b1[b].type == b2[b].type);
    CHECK(b1[b].connectivity == b2[b].connectivity);
  }
  CHECK(node_neighbours(mesh).targets == node_neighbours(solver).targets);
  CHECK(node_cells(mesh).targets == node_cells(solver).targets);
  CHECK(node_cells(mesh).offsets == node_cells(solver).offsets);
}

TEST_CASE("a foreign mesh with a bad node index raises InputError", "[core]") {
  foreign::SolverMesh solver = from_mesh(box_mesh({.nx = 2, .ny = 1, .nz = 1, .cells = BoxCells::hex_prism}));
  solver.prisms[3] = 1000;
  CHECK_THROWS_AS(unique_edges(solver), InputError);
  CHECK_THROWS_WITH(boundary_facets(solver), Catch::Contains("refers to node 1000"));
}
