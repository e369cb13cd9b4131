#pragma once
/// \file
/// Mesh topology: unique edges and facets with the element-to-entity maps, boundary facet
/// extraction, node adjacency in CSR form and 2D boundary chains.
///
/// Every function works on mixed meshes of any element type (vertices only: the high-order
/// nodes of quadratic elements take no part in the keys) and runs in time linear in the
/// number of element-entity occurrences (see core/detail/sub_entity_numbering.hpp).
/// "Cell order" is the order of mesh.cells blocks, elements in block order.

#include "meshmotion/core/detail/sub_entity_numbering.hpp"
#include "meshmotion/core/element.hpp"
#include "meshmotion/core/error.hpp"
#include "meshmotion/core/mesh.hpp"
#include "meshmotion/core/mesh_like.hpp"
#include "meshmotion/core/types.hpp"

#include <algorithm>
#include <array>
#include <optional>
#include <span>
#include <string>
#include <type_traits>
#include <vector>

namespace meshmotion {

/// For each element of a list of blocks, the global ids of its local sub-entities.
struct ElementEntityMap {
  std::vector<Index> ids;            ///< concatenated per element, blocks in order
  std::vector<Index> block_offsets;  ///< start of each block in `ids` (num_blocks + 1)
  std::vector<int> per_element;      ///< local sub-entities per element of each block

  /// Ids of the local entities of element e of block b (local index k → global id).
  [[nodiscard]] std::span<const Index> of(Index block, Index element) const {
    const auto ub = static_cast<std::size_t>(block);
    return {ids.data() + block_offsets[ub] + element * per_element[ub], static_cast<std::size_t>(per_element[ub])};
  }
};

/// Unique edges of a list of element blocks.
struct EdgeTopology {
  /// Per edge its two vertices, in the direction the first element using it gives them
  /// (num_edges × 2). Edges are numbered in lexicographic order of their sorted vertices.
  std::vector<std::array<Index, 2>> edges;
  /// Element → edge map; local edge k follows edges(type) (Gmsh order).
  ElementEntityMap element_edges;

  [[nodiscard]] Index size() const noexcept { return static_cast<Index>(edges.size()); }
};

/// Unique facets (codimension 1 of the elements: edges of 2D cells, faces of 3D cells), or
/// the 2D faces of a block list (see unique_faces).
struct FacetTopology {
  /// Per facet its vertices, oriented as the first element using it lists them (outward of
  /// that element); unused entries are -1 (triangles among quadrilaterals, lines in 2D).
  std::vector<std::array<Index, 4>> vertices;
  std::vector<int> num_vertices;               ///< 2, 3 or 4 per facet
  std::vector<std::array<Index, 2>> elements;  ///< the (first) two elements using it, in block order; -1 when only one
  std::vector<std::array<int, 2>> local;       ///< their local facet indices (facets(type) order)
  std::vector<Index> count;                    ///< how many elements use each facet
  ElementEntityMap element_facets;             ///< element → facet map (local f → facet id)

  [[nodiscard]] Index size() const noexcept { return static_cast<Index>(vertices.size()); }
  /// Whether facet f is used by exactly one element.
  [[nodiscard]] bool is_boundary(Index f) const { return count[static_cast<std::size_t>(f)] == 1; }
};

namespace detail {

template <class M>
struct is_mesh : std::false_type {};
template <int Dim>
struct is_mesh<Mesh<Dim>> : std::true_type {};

/// Calls f(source) with the fastest source over the cells of a MeshLike mesh.
template <MeshLike M, class F>
decltype(auto) with_cell_source(const M& mesh, F&& f) {
  if constexpr (is_mesh<M>::value) {
    const auto pointers = block_pointers(mesh.cells);
    return f(BlockListSource{pointers, mesh.num_nodes()});
  } else {
    return f(MeshLikeSource<M>{mesh});
  }
}

template <class Source>
[[nodiscard]] ElementEntityMap entity_map(const Source& source, SubEntities& numbered, SubEntity which) {
  ElementEntityMap map{std::move(numbered.element_entities), std::move(numbered.block_offsets), {}};
  for (Index b = 0; b < source.num_blocks(); ++b) map.per_element.push_back(num_local_entities(source.type(b), which));
  return map;
}

template <class Source>
[[nodiscard]] EdgeTopology edges_of_source(const Source& source) {
  SubEntities numbered = number_sub_entities<2>(source, SubEntity::edges);
  EdgeTopology out;
  out.edges.reserve(numbered.vertices.size());
  for (const auto& v : numbered.vertices) out.edges.push_back({v[0], v[1]});
  out.element_edges = entity_map(source, numbered, SubEntity::edges);
  return out;
}

template <std::size_t N, class Source>
[[nodiscard]] FacetTopology facets_of_source(const Source& source, SubEntity which) {
  SubEntities numbered = number_sub_entities<N>(source, which);
  FacetTopology out;
  out.vertices = std::move(numbered.vertices);
  out.num_vertices = std::move(numbered.num_vertices);
  out.elements = std::move(numbered.elements);
  out.local = std::move(numbered.local);
  out.count = std::move(numbered.count);
  out.element_facets = entity_map(source, numbered, which);
  return out;
}

}  // namespace detail

/// Unique edges of the cells of a mesh (Mesh<Dim> or any MeshLike type), with the
/// cell → edge map. Throws InputError for a node index out of range.
template <MeshLike M>
[[nodiscard]] EdgeTopology unique_edges(const M& mesh) {
  return detail::with_cell_source(mesh, [](const auto& source) { return detail::edges_of_source(source); });
}

/// Unique edges of any list of blocks (cells, facets and lines together, so that a facet's
/// edge gets the id of the cell edge it lies on). Element order: blocks in the given order.
[[nodiscard]] inline EdgeTopology unique_edges(std::span<const ElementBlock* const> blocks, Index num_nodes) {
  return detail::edges_of_source(detail::BlockListSource{blocks, num_nodes});
}

/// Unique facets of the cells (edges in 2D; triangles and quadrilaterals in 3D, keyed by
/// their sorted vertices) with the cell → facet map (local f follows facets(type)) and the
/// one or two cells (cell order) on each. Throws InputError when a facet is shared by more
/// than two cells (a non-manifold or duplicated element).
template <MeshLike M>
[[nodiscard]] FacetTopology unique_facets(const M& mesh) {
  constexpr std::size_t N = mesh_dim<M> == 2 ? 2 : 4;
  FacetTopology out = detail::with_cell_source(
      mesh, [](const auto& source) { return detail::facets_of_source<N>(source, detail::SubEntity::facets); });
  for (Index f = 0; f < out.size(); ++f)
    if (out.count[static_cast<std::size_t>(f)] > 2)
      throw InputError("unique_facets: facet " + std::to_string(f) + " of cell " +
                       std::to_string(out.elements[static_cast<std::size_t>(f)][0]) + " is shared by " +
                       std::to_string(out.count[static_cast<std::size_t>(f)]) + " cells (expected at most 2)");
  return out;
}

/// Unique 2D faces of any list of blocks: the facets of 3D elements and the 2D elements
/// themselves (a quad4 facet element is the face it covers); lines and points have none.
[[nodiscard]] inline FacetTopology unique_faces(std::span<const ElementBlock* const> blocks, Index num_nodes) {
  return detail::facets_of_source<4>(detail::BlockListSource{blocks, num_nodes}, detail::SubEntity::faces);
}

/// The facets used by exactly one cell, as element blocks of the facet types (line2/line3 in
/// 2D, tri3/quad4 and their quadratic kinds in 3D, as facet_type() gives), all nodes
/// included and oriented outward as facets(type) lists them. Each element is tagged `tag`.
/// Blocks appear in the order their types are first met; elements in the order of facet ids.
/// `topo` is unique_facets(mesh), for a caller that has it already.
template <MeshLike M>
[[nodiscard]] std::vector<ElementBlock> boundary_facets(const M& mesh, const FacetTopology& topo, int tag = 0) {
  return detail::with_cell_source(mesh, [&](const auto& source) {
    std::vector<Index> cell_block;  // block of each cell, by cell order
    cell_block.reserve(static_cast<std::size_t>(topo.element_facets.ids.size()));
    std::vector<Index> block_start;
    for (Index b = 0; b < source.num_blocks(); ++b) {
      block_start.push_back(static_cast<Index>(cell_block.size()));
      cell_block.insert(cell_block.end(), static_cast<std::size_t>(source.size(b)), b);
    }
    std::vector<ElementBlock> out;
    std::array<int, max_facet_nodes> local_nodes{};
    std::vector<Index> nodes;
    for (Index f = 0; f < topo.size(); ++f) {
      if (!topo.is_boundary(f)) continue;
      const Index cell = topo.elements[static_cast<std::size_t>(f)][0];
      const Index b = cell_block[static_cast<std::size_t>(cell)];
      const Index e = cell - block_start[static_cast<std::size_t>(b)];
      const ElementType t = source.type(b);
      const int lf = topo.local[static_cast<std::size_t>(f)][0];
      const ElementType ft = facet_type(t, lf);
      const int n = facet_nodes(t, lf, local_nodes);
      nodes.clear();
      for (int k = 0; k < n; ++k) nodes.push_back(source.node(b, e, local_nodes[static_cast<std::size_t>(k)]));
      auto it = std::find_if(out.begin(), out.end(), [ft](const ElementBlock& blk) { return blk.type == ft; });
      if (it == out.end()) {
        out.push_back(ElementBlock{ft, {}, {}, {}, {}});
        it = out.end() - 1;
      }
      it->add(nodes, tag);
    }
    return out;
  });
}

/// boundary_facets() of `mesh`, its facets numbered here.
template <MeshLike M>
[[nodiscard]] std::vector<ElementBlock> boundary_facets(const M& mesh, int tag = 0) {
  return boundary_facets(mesh, unique_facets(mesh), tag);
}

/// Compressed sparse rows: row i holds targets[offsets[i] .. offsets[i+1]).
struct Adjacency {
  std::vector<Index> offsets;  ///< num_rows + 1
  std::vector<Index> targets;

  [[nodiscard]] Index num_rows() const noexcept { return static_cast<Index>(offsets.size()) - 1; }
  [[nodiscard]] std::span<const Index> row(Index i) const {
    const auto ui = static_cast<std::size_t>(i);
    return {targets.data() + offsets[ui], static_cast<std::size_t>(offsets[ui + 1] - offsets[ui])};
  }
};

namespace detail {

/// CSR from (row, target) pairs that `visit(f)` enumerates by calling f(row, target); each
/// row sorted ascending. visit is called twice.
template <class Visit>
[[nodiscard]] Adjacency csr_from_pairs(Index num_rows, Visit&& visit) {
  Adjacency a;
  a.offsets.assign(static_cast<std::size_t>(num_rows) + 1, 0);
  visit([&](Index r, Index) { ++a.offsets[static_cast<std::size_t>(r) + 1]; });
  for (std::size_t i = 1; i < a.offsets.size(); ++i) a.offsets[i] += a.offsets[i - 1];
  a.targets.resize(static_cast<std::size_t>(a.offsets.back()));
  std::vector<Index> fill(a.offsets.begin(), a.offsets.end() - 1);
  visit([&](Index r, Index t) { a.targets[static_cast<std::size_t>(fill[static_cast<std::size_t>(r)]++)] = t; });
  for (Index r = 0; r < num_rows; ++r)
    std::sort(a.targets.begin() + a.offsets[static_cast<std::size_t>(r)],
              a.targets.begin() + a.offsets[static_cast<std::size_t>(r) + 1]);
  return a;
}

}  // namespace detail

/// Node → neighbouring nodes through cell edges (num_nodes rows, each sorted; vertices only:
/// the high-order nodes of quadratic cells have empty rows).
template <MeshLike M>
[[nodiscard]] Adjacency node_neighbours(const M& mesh) {
  const EdgeTopology topo = unique_edges(mesh);
  return detail::csr_from_pairs(MeshTraits<M>::num_nodes(mesh), [&](auto&& f) {
    for (const auto& e : topo.edges) {
      f(e[0], e[1]);
      f(e[1], e[0]);
    }
  });
}

/// Node → cells (cell order) that contain it, through any of their nodes (num_nodes rows).
template <MeshLike M>
[[nodiscard]] Adjacency node_cells(const M& mesh) {
  return detail::with_cell_source(mesh, [&](const auto& source) {
    return detail::csr_from_pairs(source.num_nodes(), [&](auto&& f) {
      Index cell = 0;
      for (Index b = 0; b < source.num_blocks(); ++b) {
        const int n = num_nodes(source.type(b));
        for (Index e = 0; e < source.size(b); ++e, ++cell)
          for (int k = 0; k < n; ++k) f(source.node(b, e, k), cell);
      }
    });
  });
}

/// An ordered chain of boundary vertices in 2D.
struct BoundaryChain {
  /// Vertices in order; a closed loop does not repeat its first vertex.
  std::vector<Index> nodes;
  /// Per segment (nodes[i] → nodes[i+1], and nodes.back() → nodes.front() when closed), the
  /// facet it comes from: {index of the block in mesh.facets, element in that block}.
  std::vector<std::array<Index, 2>> facets;
  bool closed = false;
  int tag = 0;  ///< the facets' tag (a chain never spans two tags)
};

/// Ordered chains of the line facets of a 2D mesh (only those tagged `tag` when given).
/// A chain breaks where the tag changes and at nodes not shared by exactly two facets;
/// chains without such a node are closed loops. Each chain runs in the direction of its
/// first facet (a mesh with consistently oriented facets gives consistent chains: outward
/// normals on the right, i.e. walls counter-clockwise). Throws InputError for a facet
/// node out of range.
[[nodiscard]] inline std::vector<BoundaryChain> boundary_chains(const Mesh<2>& mesh, std::optional<int> tag = {}) {
  struct Segment {
    Index a, b;
    int tag;
    Index block, element;
  };
  std::vector<Segment> segments;
  for (std::size_t bi = 0; bi < mesh.facets.size(); ++bi) {
    const ElementBlock& blk = mesh.facets[bi];
    if (shape(blk.type) != Shape::line) continue;
    for (Index e = 0; e < blk.size(); ++e) {
      const int t = blk.tags[static_cast<std::size_t>(e)];
      if (tag && t != *tag) continue;
      const auto el = blk.element(e);
      for (Index v : {el[0], el[1]})
        if (v < 0 || v >= mesh.num_nodes())
          throw InputError("boundary_chains: " + std::string(name(blk.type)) + " facet " + std::to_string(e) +
                           " refers to node " + std::to_string(v) + " (expected 0 to " +
                           std::to_string(mesh.num_nodes() - 1) + ")");
      segments.push_back({el[0], el[1], t, static_cast<Index>(bi), e});
    }
  }
  const Adjacency incident = detail::csr_from_pairs(mesh.num_nodes(), [&](auto&& f) {
    for (std::size_t s = 0; s < segments.size(); ++s) {
      f(segments[s].a, static_cast<Index>(s));
      f(segments[s].b, static_cast<Index>(s));
    }
  });
  // A node where a chain must stop: an end, a junction, or a change of tag.
  const auto is_break = [&](Index v) {
    const auto inc = incident.row(v);
    return inc.size() != 2 || segments[static_cast<std::size_t>(inc[0])].tag != segments[static_cast<std::size_t>(inc[1])].tag;
  };
  std::vector<char> used(segments.size(), 0);
  std::vector<BoundaryChain> chains;
  const auto walk = [&](Index start_node, Index start_segment) {
    BoundaryChain chain;
    chain.tag = segments[static_cast<std::size_t>(start_segment)].tag;
    chain.nodes.push_back(start_node);
    Index v = start_node;
    Index s = start_segment;
    while (true) {
      const Segment& seg = segments[static_cast<std::size_t>(s)];
      used[static_cast<std::size_t>(s)] = 1;
      chain.facets.push_back({seg.block, seg.element});
      v = seg.a == v ? seg.b : seg.a;
      if (v == start_node) {
        chain.closed = true;
        break;
      }
      chain.nodes.push_back(v);
      if (is_break(v)) break;
      const auto inc = incident.row(v);
      s = inc[0] == s ? inc[1] : inc[0];
    }
    const Segment& first = segments[static_cast<std::size_t>(start_segment)];
    if (first.a != start_node) {  // walked against the first facet: turn the chain round
      if (chain.closed) {
        // Keep the start vertex first: nodes s0, s_{n-1}, ..., s1; segments reversed.
        std::reverse(chain.nodes.begin() + 1, chain.nodes.end());
      } else {
        std::reverse(chain.nodes.begin(), chain.nodes.end());
      }
      std::reverse(chain.facets.begin(), chain.facets.end());
    }
    chains.push_back(std::move(chain));
  };
  for (Index v = 0; v < mesh.num_nodes(); ++v) {
    if (incident.row(v).empty() || !is_break(v)) continue;
    for (Index s : incident.row(v))
      if (!used[static_cast<std::size_t>(s)]) walk(v, s);
  }
  for (std::size_t s = 0; s < segments.size(); ++s)
    if (!used[s]) walk(segments[s].a, static_cast<Index>(s));
  return chains;
}

}  // namespace meshmotion

// The compiled library (target meshmotion::compiled, src/core.cpp) numbers the sub-entities of
// block lists, and so of every Mesh<Dim>: the numbering is the heaviest code of the core.
#ifdef MESHMOTION_COMPILED
namespace meshmotion {
extern template EdgeTopology detail::edges_of_source<detail::BlockListSource>(const detail::BlockListSource&);
extern template FacetTopology detail::facets_of_source<2, detail::BlockListSource>(const detail::BlockListSource&, detail::SubEntity);
extern template FacetTopology detail::facets_of_source<4, detail::BlockListSource>(const detail::BlockListSource&, detail::SubEntity);
extern template FacetTopology unique_facets<Mesh<2>>(const Mesh<2>&);
extern template FacetTopology unique_facets<Mesh<3>>(const Mesh<3>&);
extern template std::vector<ElementBlock> boundary_facets<Mesh<2>>(const Mesh<2>&, const FacetTopology&, int);
extern template std::vector<ElementBlock> boundary_facets<Mesh<3>>(const Mesh<3>&, const FacetTopology&, int);
}  // namespace meshmotion
#endif
