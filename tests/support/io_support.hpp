#pragma once
// Meshes and comparisons shared by the io tests.

#include "meshmotion/core/mesh.hpp"
#include "meshmotion/core/shape_functions.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace meshmotion::test {

// Number of elements in the group of that name.
template <int Dim>
Index group_size(const Mesh<Dim>& mesh, const std::string& group_name) {
  const auto& g = mesh.group(group_name);
  Index n = 0;
  for (const auto& b : mesh.blocks_of_dim(g.dim)) n += std::count(b.tags.begin(), b.tags.end(), g.tag);
  return n;
}

// Element ids as written: the stored ones or positions over the blocks in file order.
template <int Dim>
void require_same_mesh(const Mesh<Dim>& a, const Mesh<Dim>& b, bool exact_ids = true) {
  REQUIRE(a.num_nodes() == b.num_nodes());
  CHECK(a.points == b.points);  // bitwise
  // The ids a .msh file gives the nodes (the read mesh's own numbering may start elsewhere).
  if (exact_ids)
    for (Index i = 0; i < a.num_nodes(); ++i) REQUIRE(msh_node_id(a, i) == msh_node_id(b, i));
  for (const auto& lists : {std::pair{&a.cells, &b.cells}, std::pair{&a.facets, &b.facets}, std::pair{&a.lower, &b.lower}}) {
    REQUIRE(lists.first->size() == lists.second->size());
    for (std::size_t k = 0; k < lists.first->size(); ++k) {
      const auto& x = (*lists.first)[k];
      const auto& y = (*lists.second)[k];
      CHECK(x.type == y.type);
      CHECK(x.connectivity == y.connectivity);
      CHECK(x.tags == y.tags);
      if (exact_ids && !x.ids.empty()) CHECK(x.ids == y.ids);
      // The model entities the elements came with (Gmsh's elementary tags) are kept.
      if (exact_ids && !x.entities.empty() && std::find(x.entities.begin(), x.entities.end(), 0) == x.entities.end())
        CHECK(x.entities == y.entities);
    }
  }
  REQUIRE(a.groups.size() == b.groups.size());
  for (std::size_t k = 0; k < a.groups.size(); ++k) {
    CHECK(a.groups[k].name == b.groups[k].name);
    CHECK(a.groups[k].tag == b.groups[k].tag);
    CHECK(a.groups[k].dim == b.groups[k].dim);
  }
}

// One element of each type of dimension <= Dim, each at its reference nodes shifted apart, with
// non-contiguous node ids and element ids.
template <int Dim>
Mesh<Dim> all_types_mesh(int order_wanted) {
  Mesh<Dim> mesh;
  std::vector<Vec<Dim>> points;
  int shift = 0;
  for (int t = 0; t < num_element_types; ++t) {
    const auto type = static_cast<ElementType>(t);
    if (dimension(type) > Dim || (order(type) != order_wanted && order(type) != 0)) continue;
    auto& block = mesh.block(type);
    std::vector<Index> nodes;
    for (const auto& x : reference_nodes(type)) {
      Vec<Dim> p;
      for (int d = 0; d < Dim; ++d) p[d] = x[static_cast<std::size_t>(d)] + (d == 0 ? 3.0 * shift : 0.1 * d);
      nodes.push_back(static_cast<Index>(points.size()));
      points.push_back(p);
    }
    block.add(nodes, dimension(type) == Dim ? 0 : 10 + t);
    block.ids.push_back(1000 + 7 * t);
    ++shift;
  }
  mesh.points.resize(Dim, static_cast<Index>(points.size()));
  for (std::size_t i = 0; i < points.size(); ++i) {
    mesh.points.col(static_cast<Index>(i)) = points[i];
    mesh.node_ids.push_back(static_cast<std::int64_t>(5 + 3 * i));
  }
  mesh.groups.push_back({Dim - 1, 10 + static_cast<int>(mesh.facets.front().type), "first facets"});
  return mesh;
}

}  // namespace meshmotion::test
