#pragma once
// Checks shared by the tests of P1 → P2 and P1 → Pk conversion.

#include "meshmotion/core/element.hpp"
#include "meshmotion/core/mesh.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <map>
#include <vector>

namespace meshmotion::test {

// No two nodes at the same place: with straight positions, that means every edge and face
// node is shared by all elements using it (the mesh is conforming).
template <int Dim>
void check_no_duplicate_nodes(const Mesh<Dim>& q) {
  std::vector<std::array<double, Dim>> pts;
  for (Index i = 0; i < q.num_nodes(); ++i) {
    std::array<double, Dim> a{};
    for (int d = 0; d < Dim; ++d) a[static_cast<std::size_t>(d)] = q.points(d, i);
    pts.push_back(a);
  }
  std::sort(pts.begin(), pts.end());
  CHECK(std::adjacent_find(pts.begin(), pts.end()) == pts.end());
}

// Each facet element holds the same nodes as the cell facet it covers.
template <int Dim>
void check_facets_match_cells(const Mesh<Dim>& q) {
  std::map<std::vector<Index>, std::vector<Index>> cell_facets;  // sorted vertices → sorted nodes
  std::array<int, max_facet_nodes> fn{};
  for (const auto& b : q.cells)
    for (Index e = 0; e < b.size(); ++e)
      for (int f = 0; f < static_cast<int>(facets(b.type).size()); ++f) {
        const int n = facet_nodes(b.type, f, fn);
        const int nv = facets(b.type)[static_cast<std::size_t>(f)].num_vertices;
        std::vector<Index> verts, nodes;
        for (int k = 0; k < n; ++k) (k < nv ? verts : nodes).push_back(b.element(e)[static_cast<std::size_t>(fn[static_cast<std::size_t>(k)])]);
        std::sort(verts.begin(), verts.end());
        std::sort(nodes.begin(), nodes.end());
        cell_facets[verts] = nodes;
      }
  Index checked = 0;
  for (const auto& b : q.facets)
    for (Index e = 0; e < b.size(); ++e) {
      const auto el = b.element(e);
      const int nv = num_vertices(b.type);
      std::vector<Index> verts(el.begin(), el.begin() + nv), nodes(el.begin() + nv, el.end());
      std::sort(verts.begin(), verts.end());
      std::sort(nodes.begin(), nodes.end());
      const auto it = cell_facets.find(verts);
      REQUIRE(it != cell_facets.end());
      CHECK(it->second == nodes);
      ++checked;
    }
  CHECK(checked == q.num_facets());
}

}  // namespace meshmotion::test
