#pragma once
/// \file
/// Numbering of the unique sub-entities (edges, faces) of element blocks, keyed by their
/// sorted vertices. Linear in the number of occurrences: the keys are bucketed by their
/// smallest vertex (a counting sort over node indices) and only each small bucket is sorted,
/// so no map or hash table is built per entity.

#include "meshmotion/core/element.hpp"
#include "meshmotion/core/error.hpp"
#include "meshmotion/core/mesh.hpp"
#include "meshmotion/core/mesh_like.hpp"
#include "meshmotion/core/types.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <vector>

namespace meshmotion::detail {

/// Key padding for entities with fewer vertices than the key length (a triangle among quads).
inline constexpr Index key_padding = std::numeric_limits<Index>::max();

/// Unique keys among numbered items.
struct KeyNumbering {
  std::vector<Index> id_of_item;   ///< unique id of every item
  std::vector<Index> first_item;   ///< per unique id, the smallest item carrying it
  std::vector<Index> second_item;  ///< per unique id, the next item carrying it, or -1
  std::vector<Index> count;        ///< per unique id, how many items carry it
};

/// number_keys() with bucket entries of integer type I (large enough for every node and item).
template <std::size_t N, class I, class Visit>
[[nodiscard]] KeyNumbering number_keys_as(Index num_items, Index num_nodes, Visit&& visit) {
  struct Entry {
    std::array<I, N - 1> rest;
    I item;
  };
  std::vector<Index> offsets(static_cast<std::size_t>(num_nodes) + 1, 0);
  visit([&](Index, const std::array<Index, N>& key) { ++offsets[static_cast<std::size_t>(key[0]) + 1]; });
  for (std::size_t i = 1; i < offsets.size(); ++i) offsets[i] += offsets[i - 1];
  std::vector<Entry> entries(static_cast<std::size_t>(num_items));
  {
    std::vector<Index> fill(offsets.begin(), offsets.end() - 1);
    visit([&](Index item, const std::array<Index, N>& key) {
      Entry& e = entries[static_cast<std::size_t>(fill[static_cast<std::size_t>(key[0])]++)];
      for (std::size_t i = 0; i + 1 < N; ++i) e.rest[i] = static_cast<I>(key[i + 1]);
      e.item = static_cast<I>(item);
    });
  }
  KeyNumbering out;
  out.id_of_item.resize(static_cast<std::size_t>(num_items));
  // At most one id per item; the reservation is address space only until ids are written,
  // and it spares the copies of growing three arrays entity by entity.
  out.first_item.reserve(static_cast<std::size_t>(num_items));
  out.second_item.reserve(static_cast<std::size_t>(num_items));
  out.count.reserve(static_cast<std::size_t>(num_items));
  for (Index v = 0; v < num_nodes; ++v) {
    const auto begin = entries.begin() + offsets[static_cast<std::size_t>(v)];
    const auto end = entries.begin() + offsets[static_cast<std::size_t>(v) + 1];
    // Element-wise comparisons: std::array's operators call memcmp, which dominated the sort.
    std::sort(begin, end, [](const Entry& a, const Entry& b) {
      for (std::size_t i = 0; i + 1 < N; ++i)
        if (a.rest[i] != b.rest[i]) return a.rest[i] < b.rest[i];
      return a.item < b.item;
    });
    const auto same_key = [](const Entry& a, const Entry& b) {
      for (std::size_t i = 0; i + 1 < N; ++i)
        if (a.rest[i] != b.rest[i]) return false;
      return true;
    };
    for (auto it = begin; it != end; ++it) {
      if (it == begin || !same_key(*it, *(it - 1))) {
        out.first_item.push_back(it->item);
        out.second_item.push_back(-1);
        out.count.push_back(0);
      } else if (out.count.back() == 1) {
        out.second_item.back() = it->item;
      }
      ++out.count.back();
      out.id_of_item[static_cast<std::size_t>(it->item)] = static_cast<Index>(out.first_item.size()) - 1;
    }
  }
  return out;
}

/// Numbers the items that `visit` enumerates: visit(f) must call f(item, key) once for every
/// item 0 .. num_items-1 (in any order), with `key` sorted ascending (padded with
/// key_padding), key[0] in [0, num_nodes). It is called twice. Unique ids follow the
/// lexicographic order of the keys.
template <std::size_t N, class Visit>
[[nodiscard]] KeyNumbering number_keys(Index num_items, Index num_nodes, Visit&& visit) {
  // The bucket entries are scattered over memory once: half their size is half the traffic.
  // Padding (key_padding) must stay the largest key value, so 32 bits only below its range.
  constexpr Index small = std::numeric_limits<std::uint32_t>::max();
  if (num_items < small && num_nodes < small) return number_keys_as<N, std::uint32_t>(num_items, num_nodes, visit);
  return number_keys_as<N, Index>(num_items, num_nodes, visit);
}

/// Blocks of elements seen through one interface, whether they are ElementBlocks or the
/// cells of a MeshLike type.
struct BlockListSource {
  std::span<const ElementBlock* const> blocks;
  Index nodes;

  [[nodiscard]] Index num_nodes() const { return nodes; }
  [[nodiscard]] Index num_blocks() const { return static_cast<Index>(blocks.size()); }
  [[nodiscard]] ElementType type(Index b) const { return blocks[static_cast<std::size_t>(b)]->type; }
  [[nodiscard]] Index size(Index b) const { return blocks[static_cast<std::size_t>(b)]->size(); }
  [[nodiscard]] Index node(Index b, Index e, int k) const {
    const ElementBlock& block = *blocks[static_cast<std::size_t>(b)];
    return block.connectivity[static_cast<std::size_t>(e * block.nodes_per_element() + k)];
  }
};

template <MeshLike M>
struct MeshLikeSource {
  const M& mesh;
  using T = MeshTraits<M>;

  [[nodiscard]] Index num_nodes() const { return T::num_nodes(mesh); }
  [[nodiscard]] Index num_blocks() const { return T::num_cell_blocks(mesh); }
  [[nodiscard]] ElementType type(Index b) const { return T::cell_type(mesh, b); }
  [[nodiscard]] Index size(Index b) const { return T::num_cells(mesh, b); }
  [[nodiscard]] Index node(Index b, Index e, int k) const { return T::cell_node(mesh, b, e, k); }
};

/// Pointers to the cell blocks of a Mesh, for BlockListSource.
[[nodiscard]] inline std::vector<const ElementBlock*> block_pointers(const std::vector<ElementBlock>& blocks) {
  std::vector<const ElementBlock*> out;
  for (const auto& b : blocks) out.push_back(&b);
  return out;
}

/// Which sub-entities of an element a numbering counts.
enum class SubEntity {
  edges,   ///< the element's edges
  facets,  ///< the element's facets (dimension dim(type) - 1)
  faces,   ///< the 2D entities: facets of a 3D element, a 2D element itself
};

[[nodiscard]] inline int num_local_entities(ElementType t, SubEntity which) {
  switch (which) {
    case SubEntity::edges: return static_cast<int>(edges(t).size());
    case SubEntity::facets: return static_cast<int>(facets(t).size());
    case SubEntity::faces: return dimension(t) == 3 ? static_cast<int>(facets(t).size()) : dimension(t) == 2 ? 1 : 0;
  }
  return 0;
}

/// Local vertices of sub-entity k of an element of type t.
[[nodiscard]] inline LocalFacet local_entity(ElementType t, SubEntity which, int k) {
  const auto uk = static_cast<std::size_t>(k);
  if (which == SubEntity::edges) return {Shape::line, 2, {edges(t)[uk][0], edges(t)[uk][1], 0, 0}};
  if (which == SubEntity::faces && dimension(t) == 2) return {shape(t), num_vertices(t), {0, 1, 2, 3}};
  return facets(t)[uk];
}

/// Sub-entities of every element of a source: unique vertex tuples, per element the local
/// sub-entity → unique id map, and the elements (in block order) using each entity.
struct SubEntities {
  std::vector<std::array<Index, 4>> vertices;  ///< per entity, as its first element lists it; -1 unused
  std::vector<int> num_vertices;               ///< per entity
  std::vector<Index> element_entities;         ///< per element in block order, its local entities' ids
  std::vector<Index> block_offsets;            ///< start of each block in element_entities (num_blocks + 1)
  std::vector<Index> element_offsets;          ///< first element (block order) of each block (num_blocks + 1)
  std::vector<std::array<Index, 2>> elements;  ///< first two elements using each entity; -1 when fewer
  std::vector<std::array<int, 2>> local;       ///< their local sub-entity indices
  std::vector<Index> count;                    ///< how many elements use each entity
};

template <std::size_t N, class Source>
[[nodiscard]] SubEntities number_sub_entities(const Source& source, SubEntity which) {
  SubEntities out;
  const Index num_blocks = source.num_blocks();
  out.block_offsets.assign(static_cast<std::size_t>(num_blocks) + 1, 0);
  out.element_offsets.assign(static_cast<std::size_t>(num_blocks) + 1, 0);
  for (Index b = 0; b < num_blocks; ++b) {
    const auto ub = static_cast<std::size_t>(b);
    out.block_offsets[ub + 1] = out.block_offsets[ub] + source.size(b) * num_local_entities(source.type(b), which);
    out.element_offsets[ub + 1] = out.element_offsets[ub] + source.size(b);
  }
  const Index num_nodes = source.num_nodes();
  const auto visit = [&](auto&& f) {
    std::array<LocalFacet, 12> local{};  // the block type's sub-entities (a hexahedron has 12 edges), looked up once per block
    for (Index b = 0; b < num_blocks; ++b) {
      const ElementType t = source.type(b);
      const int n_local = num_local_entities(t, which);
      for (int k = 0; k < n_local; ++k) local[static_cast<std::size_t>(k)] = local_entity(t, which, k);
      const Index n = source.size(b);
      Index item = out.block_offsets[static_cast<std::size_t>(b)];
      for (Index e = 0; e < n; ++e)
        for (int k = 0; k < n_local; ++k, ++item) {
          const LocalFacet& ent = local[static_cast<std::size_t>(k)];
          std::array<Index, N> key;
          key.fill(key_padding);
          for (int v = 0; v < ent.num_vertices; ++v) {
            const Index node = source.node(b, e, ent.vertices[static_cast<std::size_t>(v)]);
            if (node < 0 || node >= num_nodes)
              throw InputError("topology: " + std::string(name(t)) + " element " + std::to_string(e) +
                               " refers to node " + std::to_string(node) + " (expected 0 to " +
                               std::to_string(num_nodes - 1) + ")");
            key[static_cast<std::size_t>(v)] = node;
          }
          // Insertion sort of at most 4 entries (std::sort here trips GCC's -Warray-bounds).
          for (std::size_t i = 1; i < N; ++i)
            for (std::size_t j = i; j > 0 && key[j] < key[j - 1]; --j) std::swap(key[j], key[j - 1]);
          f(item, key);
        }
    }
  };
  KeyNumbering numbering = number_keys<N>(out.block_offsets.back(), num_nodes, visit);
  out.element_entities = std::move(numbering.id_of_item);
  out.count = std::move(numbering.count);

  // Per entity: its vertices as its first element lists them, its first two elements. The
  // items are walked in element order, so the connectivity is read in sequence; visiting the
  // entities in id order instead read it at random, which dominated at millions of cells.
  const std::size_t n_unique = numbering.first_item.size();
  out.vertices.resize(n_unique);
  out.num_vertices.resize(n_unique);
  out.elements.resize(n_unique);
  out.local.resize(n_unique);
  std::array<LocalFacet, 12> local{};
  for (Index b = 0; b < num_blocks; ++b) {
    const ElementType t = source.type(b);
    const int n_local = num_local_entities(t, which);
    for (int k = 0; k < n_local; ++k) local[static_cast<std::size_t>(k)] = local_entity(t, which, k);
    Index item = out.block_offsets[static_cast<std::size_t>(b)];
    const Index first_element = out.element_offsets[static_cast<std::size_t>(b)];
    for (Index e = 0; e < source.size(b); ++e)
      for (int k = 0; k < n_local; ++k, ++item) {
        const auto u = static_cast<std::size_t>(out.element_entities[static_cast<std::size_t>(item)]);
        if (numbering.first_item[u] == item) {
          const LocalFacet& ent = local[static_cast<std::size_t>(k)];
          std::array<Index, 4> verts{-1, -1, -1, -1};
          for (int v = 0; v < ent.num_vertices; ++v)
            verts[static_cast<std::size_t>(v)] = source.node(b, e, ent.vertices[static_cast<std::size_t>(v)]);
          out.vertices[u] = verts;
          out.num_vertices[u] = ent.num_vertices;
          out.elements[u] = {first_element + e, -1};
          out.local[u] = {k, -1};
        } else if (numbering.second_item[u] == item) {
          out.elements[u][1] = first_element + e;
          out.local[u][1] = k;
        }
      }
  }
  return out;
}

}  // namespace meshmotion::detail
