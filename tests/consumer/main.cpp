// Builds a mesh with meshmotion and prints its counts: proof that the package is usable.
#include <meshmotion/meshmotion.hpp>
#include <meshmotion/core/generators.hpp>
#include <meshmotion/core/topology.hpp>

#include <iostream>

int main() {
  const meshmotion::Mesh<2> mesh = meshmotion::rectangle_mesh({.nx = 4, .ny = 3});
  std::cout << "consumer: " << mesh.num_nodes() << " nodes, " << mesh.num_cells() << " cells, "
            << meshmotion::unique_edges(mesh).size() << " edges, " << mesh.groups.size() << " groups\n";
  return mesh.num_nodes() == 20 ? 0 : 1;
}
