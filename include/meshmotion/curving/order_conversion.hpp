#pragma once
/// \file
/// Conversion to any order of the catalogue: P1 → Pk (straight-sided, k = 2 to 4), and Pk →
/// Pk' for k' ≥ k (raising the order of a curved mesh, exact: the map of order k lies in the
/// space of order k').
///
/// Every new node is shared by all the cells, facets and lines that hold it, whatever their
/// local orientation. A node is identified by where it lies between the linear vertices: the
/// weights of the vertices' linear shape functions at the node, which are the same from every
/// element holding it (the lattice coordinates of an edge, face or cell node in the vertices'
/// own frame). The input's vertices keep their numbering (a linear input keeps all its nodes);
/// new nodes are appended in order of first use.

#include "meshmotion/core/element.hpp"
#include "meshmotion/core/error.hpp"
#include "meshmotion/core/mesh.hpp"
#include "meshmotion/core/shape_functions.hpp"
#include "meshmotion/core/types.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

namespace meshmotion {

/// A converted mesh and what it kept of the input.
template <int Dim>
struct OrderConversion {
  Mesh<Dim> mesh;
  /// Nodes 0 .. num_kept_nodes-1 are input nodes: all of a linear input's, in its numbering;
  /// a curved input's element vertices, in its order (its other nodes are replaced).
  Index num_kept_nodes = 0;
  std::vector<Index> kept;  ///< input index of kept node i
};

namespace detail {

// A node's place between the linear vertices: up to 8 (vertex, weight) pairs, sorted by
// vertex, the weights scaled to integers. The scale is divisible by every denominator of the
// catalogue's lattices (powers of 2, 3 and 5 up to order 4), so equal places give equal keys.
struct LatticeKey {
  std::array<std::pair<Index, std::int64_t>, 8> terms{};
  int size = 0;
  friend bool operator==(const LatticeKey& a, const LatticeKey& b) {
    if (a.size != b.size) return false;
    for (std::size_t k = 0; k < static_cast<std::size_t>(a.size); ++k)
      if (a.terms[k] != b.terms[k]) return false;
    return true;
  }
};

struct LatticeKeyHash {
  std::size_t operator()(const LatticeKey& k) const noexcept {
    std::uint64_t h = 0x9e3779b97f4a7c15ULL;
    for (int i = 0; i < k.size; ++i) {
      h ^= static_cast<std::uint64_t>(k.terms[static_cast<std::size_t>(i)].first) + 0x9e3779b97f4a7c15ULL + (h << 6) + (h >> 2);
      h ^= static_cast<std::uint64_t>(k.terms[static_cast<std::size_t>(i)].second) + 0x9e3779b97f4a7c15ULL + (h << 6) + (h >> 2);
    }
    return static_cast<std::size_t>(h);
  }
};

inline constexpr double lattice_key_scale = 4096.0 * 729.0 * 25.0;

// The key of a node from its local vertex weights and the element's nodes, sorted by
// inserting each term in place (at most 8).
inline LatticeKey lattice_key(const std::vector<std::pair<int, double>>& weights, std::span<const Index> element) {
  LatticeKey key;
  for (const auto& [v, w] : weights) {
    const std::pair<Index, std::int64_t> term{element[static_cast<std::size_t>(v)], std::llround(w * lattice_key_scale)};
    std::size_t at = static_cast<std::size_t>(key.size);
    for (; at > 0 && term < key.terms[at - 1]; --at) key.terms[at] = key.terms[at - 1];
    key.terms[at] = term;
    ++key.size;
  }
  return key;
}

// Per node of `target` (an element of the shape of `source`): the nonzero linear-vertex
// weights, and the source type's shape function values there (to place the node on a curved
// source element).
struct OrderTable {
  std::vector<std::vector<std::pair<int, double>>> weights;
  std::vector<std::vector<double>> source_values;
};

inline OrderTable make_order_table(ElementType source, ElementType target) {
  OrderTable table;
  const ElementType lin = linear_type(target);
  std::vector<double> w(static_cast<std::size_t>(num_nodes(lin)));
  for (const RefPoint& x : reference_nodes(target)) {
    shape_functions(lin, x, w);
    auto& terms = table.weights.emplace_back();
    for (int v = 0; v < num_nodes(lin); ++v)
      if (std::abs(w[static_cast<std::size_t>(v)]) > 1e-14) terms.emplace_back(v, w[static_cast<std::size_t>(v)]);
    auto& values = table.source_values.emplace_back(static_cast<std::size_t>(num_nodes(source)));
    shape_functions(source, x, values);
  }
  return table;
}

}  // namespace detail

/// Converts `input` (any mix of element types of order ≤ `target_order`; cells, facets and
/// lower-dimensional blocks) to elements of order `target_order` (1 to 4; see element_type()
/// for the orders each shape has), keeping block order, element order, tags, element ids and
/// groups. New nodes lie on the input's elements: straight-sided for a linear input. node_ids
/// of new nodes continue after the largest input id; node_params of a new node are the
/// weighted mean of its vertices' parameters when they all lie on the same CAD entity
/// (not valid across the seam of a periodic curve), otherwise "unknown".
/// Throws InputError for an order the catalogue lacks for some shape, for lowering the order
/// of an element (not exact), and when the input fails validate().
template <int Dim>
[[nodiscard]] OrderConversion<Dim> convert_to_order(const Mesh<Dim>& input, int target_order) {
  validate(input);
  if (target_order < 1 || target_order > max_element_order)
    throw InputError("convert_to_order: order must be 1 to " + std::to_string(max_element_order) + " (got " +
                     std::to_string(target_order) + ")");
  bool linear = true;
  std::vector<char> is_vertex(static_cast<std::size_t>(input.num_nodes()), 0);
  for (const auto* list : {&input.cells, &input.facets, &input.lower})
    for (const auto& b : *list) {
      if (order(b.type) > target_order)
        throw InputError("convert_to_order: the mesh has " + std::string(name(b.type)) + " elements of order " +
                         std::to_string(order(b.type)) + " (lowering the order to " + std::to_string(target_order) +
                         " is not exact)");
      (void)element_type(shape(b.type), target_order);  // names the shape the catalogue lacks at this order
      linear = linear && order(b.type) <= 1;
      const int nv = num_vertices(b.type);
      for (Index e = 0; e < b.size(); ++e)
        for (int k = 0; k < nv; ++k) is_vertex[static_cast<std::size_t>(b.element(e)[static_cast<std::size_t>(k)])] = 1;
    }

  OrderConversion<Dim> out;
  std::vector<Index> new_index(static_cast<std::size_t>(input.num_nodes()), -1);
  for (Index v = 0; v < input.num_nodes(); ++v)
    if (linear || is_vertex[static_cast<std::size_t>(v)]) {
      new_index[static_cast<std::size_t>(v)] = static_cast<Index>(out.kept.size());
      out.kept.push_back(v);
    }
  out.num_kept_nodes = static_cast<Index>(out.kept.size());

  Mesh<Dim>& mesh = out.mesh;
  mesh.groups = input.groups;
  std::vector<Vec<Dim>> added;                   // positions of new nodes
  std::vector<detail::LatticeKey> added_key;     // their keys (for node parameters)
  std::unordered_map<detail::LatticeKey, Index, detail::LatticeKeyHash> node_of;
  std::array<std::unique_ptr<detail::OrderTable>, num_element_types> tables{};
  for (const auto* list : {&input.cells, &input.facets, &input.lower}) {
    std::vector<ElementBlock>& out_list = list == &input.cells ? mesh.cells : list == &input.facets ? mesh.facets : mesh.lower;
    for (const auto& b : *list) {
      const ElementType t = b.type;
      const ElementType target = dimension(t) == 0 ? t : element_type(shape(t), target_order);
      auto& table = tables[static_cast<std::size_t>(t)];
      if (!table) table = std::make_unique<detail::OrderTable>(detail::make_order_table(t, target));
      const int n = num_nodes(target), nv = num_vertices(t);
      ElementBlock q{target, {}, b.tags, b.ids};
      q.connectivity.reserve(static_cast<std::size_t>(b.size() * n));
      for (Index e = 0; e < b.size(); ++e) {
        const auto el = b.element(e);
        for (int i = 0; i < n; ++i) {
          if (i < nv) {
            q.connectivity.push_back(new_index[static_cast<std::size_t>(el[static_cast<std::size_t>(i)])]);
            continue;
          }
          const detail::LatticeKey key = detail::lattice_key(table->weights[static_cast<std::size_t>(i)], el);
          const auto [it, inserted] = node_of.try_emplace(key, out.num_kept_nodes + static_cast<Index>(added.size()));
          if (inserted) {
            Vec<Dim> x = Vec<Dim>::Zero();
            const auto& values = table->source_values[static_cast<std::size_t>(i)];
            for (std::size_t k = 0; k < values.size(); ++k) x += values[k] * input.points.col(el[k]);
            added.push_back(x);
            added_key.push_back(key);
          }
          q.connectivity.push_back(it->second);
        }
      }
      out_list.push_back(std::move(q));
    }
  }

  const Index n_total = out.num_kept_nodes + static_cast<Index>(added.size());
  mesh.points.resize(Dim, n_total);
  for (Index i = 0; i < out.num_kept_nodes; ++i) mesh.points.col(i) = input.points.col(out.kept[static_cast<std::size_t>(i)]);
  for (std::size_t i = 0; i < added.size(); ++i) mesh.points.col(out.num_kept_nodes + static_cast<Index>(i)) = added[i];
  if (!input.node_ids.empty()) {
    for (const Index v : out.kept) mesh.node_ids.push_back(input.node_ids[static_cast<std::size_t>(v)]);
    std::int64_t next = *std::max_element(input.node_ids.begin(), input.node_ids.end()) + 1;
    for (std::size_t i = 0; i < added.size(); ++i) mesh.node_ids.push_back(next++);
  }
  if (!input.node_params.empty()) {
    for (const Index v : out.kept) mesh.node_params.push_back(input.node_params[static_cast<std::size_t>(v)]);
    for (const auto& key : added_key) {
      const NodeParametrization& first = input.node_params[static_cast<std::size_t>(key.terms[0].first)];
      NodeParametrization param{Dim, 0, 0.0, 0.0};
      bool same = true;
      double u = 0.0, v = 0.0;
      for (int k = 0; k < key.size; ++k) {
        const auto& [vertex, scaled] = key.terms[static_cast<std::size_t>(k)];
        const NodeParametrization& p = input.node_params[static_cast<std::size_t>(vertex)];
        same = same && p.entity_dim == first.entity_dim && p.entity_tag == first.entity_tag;
        const double w = static_cast<double>(scaled) / detail::lattice_key_scale;
        u += w * p.u;
        v += w * p.v;
      }
      if (same) param = {first.entity_dim, first.entity_tag, u, v};
      mesh.node_params.push_back(param);
    }
  }
  return out;
}

/// The mesh of convert_to_order() alone.
template <int Dim>
[[nodiscard]] Mesh<Dim> to_order(const Mesh<Dim>& input, int target_order) {
  return convert_to_order(input, target_order).mesh;
}

}  // namespace meshmotion

// The compiled library (target meshmotion::compiled, src/) holds these for Dim 2 and 3.
#ifdef MESHMOTION_COMPILED
namespace meshmotion {
extern template OrderConversion<2> convert_to_order<2>(const Mesh<2>&, int);
extern template OrderConversion<3> convert_to_order<3>(const Mesh<3>&, int);
}  // namespace meshmotion
#endif
