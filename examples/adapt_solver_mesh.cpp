// adapt_solver_mesh: how a flow solver hands its own mesh type to meshmotion without copying
// it or changing it. The solver keeps plain arrays; a MeshTraits specialization tells the
// library how to read them, and library algorithms (topology here) then take the solver's
// mesh directly.

#include "meshmotion/core/mesh_like.hpp"
#include "meshmotion/core/topology.hpp"

#include "program.hpp"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <iostream>
#include <string>
#include <vector>

namespace solver {

/// A flow solver's own 2D triangle mesh: x, y, z per node (z unused in 2D), 3 node indices
/// per triangle, counter-clockwise.
struct FlowMesh {
  std::vector<double> xyz;
  std::vector<int> tri;
};

/// The solver's mesh of a channel [0, length] × [0, 1]: nx × ny squares split in two.
FlowMesh channel(int nx, int ny, double length) {
  FlowMesh m;
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) m.xyz.insert(m.xyz.end(), {length * i / nx, 1.0 * j / ny, 0.0});
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const int a = i + (nx + 1) * j, b = a + 1, c = b + nx + 1, d = a + nx + 1;
      m.tri.insert(m.tri.end(), {a, b, c, a, c, d});
    }
  return m;
}

}  // namespace solver

// The whole adaptation: read-only access to the solver's arrays, no copy.
template <>
struct meshmotion::MeshTraits<solver::FlowMesh> {
  static constexpr int dim = 2;
  static Index num_nodes(const solver::FlowMesh& m) { return static_cast<Index>(m.xyz.size() / 3); }
  static double coordinate(const solver::FlowMesh& m, Index node, int axis) {
    return m.xyz[static_cast<std::size_t>(3 * node + axis)];
  }
  static Index num_cell_blocks(const solver::FlowMesh&) { return 1; }
  static ElementType cell_type(const solver::FlowMesh&, Index) { return ElementType::tri3; }
  static Index num_cells(const solver::FlowMesh& m, Index) { return static_cast<Index>(m.tri.size() / 3); }
  static Index cell_node(const solver::FlowMesh& m, Index, Index cell, int local) {
    return m.tri[static_cast<std::size_t>(3 * cell + local)];
  }
};

static_assert(meshmotion::MeshLike<solver::FlowMesh>);

int main(int argc, char** argv) {
  meshmotion::tune_process_memory(argc, argv);  // may restart the program once (core/process_memory.hpp)
  CLI::App app{"Adapt a flow solver's own mesh arrays to meshmotion through MeshTraits"};
  meshmotion::examples::add_version_flag(app);
  int nx = 40, ny = 10;
  double length = 4.0;
  bool json = false;
  app.add_option("--nx", nx, "cells along the channel")->check(CLI::PositiveNumber);
  app.add_option("--ny", ny, "cells across the channel")->check(CLI::PositiveNumber);
  app.add_option("--length", length, "channel length")->check(CLI::PositiveNumber);
  app.add_flag("--json", json, "print one JSON object");
  if (const auto rc = meshmotion::examples::parse_command_line(app, argc, argv)) return *rc;

  return meshmotion::examples::guarded(json, [&] {
    const solver::FlowMesh flow = solver::channel(nx, ny, length);
    // Library algorithms read the solver's arrays in place.
    const meshmotion::EdgeTopology edges = meshmotion::unique_edges(flow);
    const auto boundary = meshmotion::boundary_facets(flow);
    const meshmotion::Adjacency neighbours = meshmotion::node_neighbours(flow);
    std::size_t max_degree = 0;
    for (meshmotion::Index i = 0; i < neighbours.num_rows(); ++i) max_degree = std::max(max_degree, neighbours.row(i).size());
    meshmotion::Index boundary_edges = 0;
    for (const auto& b : boundary) boundary_edges += b.size();
    // Where an algorithm needs the library's own container, one call copies the mesh.
    const meshmotion::Mesh<2> copy = meshmotion::to_mesh(flow);

    const auto nodes = meshmotion::MeshTraits<solver::FlowMesh>::num_nodes(flow);
    if (json) {
      std::cout << "{\"nodes\":" << nodes << ",\"triangles\":" << flow.tri.size() / 3 << ",\"edges\":" << edges.size()
                << ",\"boundary_edges\":" << boundary_edges << ",\"max_node_degree\":" << max_degree
                << ",\"copied_cells\":" << copy.num_cells() << "}\n";
    } else {
      std::cout << "solver mesh: " << nodes << " nodes, " << flow.tri.size() / 3 << " triangles\n"
                << "unique edges: " << edges.size() << " (" << boundary_edges << " on the boundary)\n"
                << "largest node degree: " << max_degree << "\n"
                << "copied into Mesh<2>: " << copy.num_cells() << " cells\n";
    }
    return meshmotion::examples::exit_ok;
  });
}
