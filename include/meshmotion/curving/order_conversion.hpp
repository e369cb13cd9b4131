#pragma once
/// \file
/// Conversion to any order of the catalogue: P1 → Pk (straight-sided, k = 2 to 8), and Pk →
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

// A shared node's place between the linear vertices: the vertices of the edge or face it lies
// on (at most 4; the nodes inside a cell are its own and have no key) and their weights,
// sorted by vertex, the weights scaled to integers. The scale is divisible by every
// denominator of the catalogue's lattices (the orders 2 to 8 and their powers), so equal
// places give equal keys, and below 2^31. Keys are kept small: the table holds one per edge
// and face node, and filling fresh memory for larger ones dominated the conversion past P2.
struct LatticeKey {
  std::array<Index, 4> vertices{};
  std::array<std::int32_t, 4> weights{};
  int size = 0;
  friend bool operator==(const LatticeKey& a, const LatticeKey& b) {
    return a.size == b.size && a.vertices == b.vertices && a.weights == b.weights;
  }
};

struct LatticeKeyHash {
  std::size_t operator()(const LatticeKey& k) const noexcept {
    std::uint64_t h = 0x9e3779b97f4a7c15ULL;
    for (std::size_t i = 0; i < static_cast<std::size_t>(k.size); ++i) {
      h ^= static_cast<std::uint64_t>(k.vertices[i]) + 0x9e3779b97f4a7c15ULL + (h << 6) + (h >> 2);
      h ^= static_cast<std::uint64_t>(k.weights[i]) + 0x9e3779b97f4a7c15ULL + (h << 6) + (h >> 2);
    }
    return static_cast<std::size_t>(h);
  }
};

inline constexpr double lattice_key_scale = 4096.0 * 729.0 * 25.0 * 7.0;

// The key of a node on an edge or face from its local vertex weights and the element's
// nodes, sorted by inserting each term in place.
inline LatticeKey lattice_key(const std::vector<std::pair<int, double>>& weights, std::span<const Index> element) {
  LatticeKey key;
  for (const auto& [v, w] : weights) {
    const Index vertex = element[static_cast<std::size_t>(v)];
    const auto scaled = static_cast<std::int32_t>(std::lround(w * lattice_key_scale));
    std::size_t at = static_cast<std::size_t>(key.size);
    for (; at > 0 && std::pair(vertex, scaled) < std::pair(key.vertices[at - 1], key.weights[at - 1]); --at) {
      key.vertices[at] = key.vertices[at - 1];
      key.weights[at] = key.weights[at - 1];
    }
    key.vertices[at] = vertex;
    key.weights[at] = scaled;
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

// A new node's parameters: the weighted mean of its vertices' when they all lie on the same
// CAD entity, otherwise unknown (inside the volume, entity dimension Dim).
template <int Dim>
NodeParametrization weighted_parameters(const std::vector<NodeParametrization>& params,
                                               const std::vector<std::pair<int, double>>& weights, std::span<const Index> element) {
  const NodeParametrization& first = params[static_cast<std::size_t>(element[static_cast<std::size_t>(weights.front().first)])];
  double u = 0.0, v = 0.0;
  for (const auto& [local, w] : weights) {
    const NodeParametrization& p = params[static_cast<std::size_t>(element[static_cast<std::size_t>(local)])];
    if (p.entity_dim != first.entity_dim || p.entity_tag != first.entity_tag) return {Dim, 0, 0.0, 0.0};
    u += w * p.u;
    v += w * p.v;
  }
  return {first.entity_dim, first.entity_tag, u, v};
}

}  // namespace detail

/// Converts `input` (any mix of element types of order ≤ `target_order`; cells, facets and
/// lower-dimensional blocks) to elements of order `target_order` (1 to 8; see max_order()
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
  const bool with_params = !input.node_params.empty();
  std::vector<Vec<Dim>> added;                       // positions of new nodes
  std::vector<NodeParametrization> added_params;     // and their parameters (when the input has them)
  std::unordered_map<detail::LatticeKey, Index, detail::LatticeKeyHash> node_of;
  // Room for every new node (the cells' nodes past their vertices bound them, edge and face
  // nodes counted once per cell): growing these copies them into fresh memory, which costs
  // more than the lookups.
  std::size_t bound = 0;
  for (const auto& b : input.cells)
    bound += static_cast<std::size_t>(b.size()) *
             static_cast<std::size_t>(num_nodes(element_type(shape(b.type), target_order)) - num_vertices(b.type));
  added.reserve(bound);
  if (with_params) added_params.reserve(bound);
  node_of.reserve(bound / 2);
  std::array<std::unique_ptr<detail::OrderTable>, num_element_types> tables{};
  for (const auto* list : {&input.cells, &input.facets, &input.lower}) {
    std::vector<ElementBlock>& out_list = list == &input.cells ? mesh.cells : list == &input.facets ? mesh.facets : mesh.lower;
    for (const auto& b : *list) {
      const ElementType t = b.type;
      const ElementType target = dimension(t) == 0 ? t : element_type(shape(t), target_order);
      auto& table = tables[static_cast<std::size_t>(t)];
      if (!table) table = std::make_unique<detail::OrderTable>(detail::make_order_table(t, target));
      const int n = num_nodes(target), nv = num_vertices(t);
      const bool own_interior = list == &input.cells;
      ElementBlock q{target, {}, b.tags, b.ids, b.entities};
      q.connectivity.reserve(static_cast<std::size_t>(b.size() * n));
      for (Index e = 0; e < b.size(); ++e) {
        const auto el = b.element(e);
        for (int i = 0; i < n; ++i) {
          if (i < nv) {
            q.connectivity.push_back(new_index[static_cast<std::size_t>(el[static_cast<std::size_t>(i)])]);
            continue;
          }
          const auto& weights = table->weights[static_cast<std::size_t>(i)];
          const auto add = [&] {
            Vec<Dim> x = Vec<Dim>::Zero();
            const auto& values = table->source_values[static_cast<std::size_t>(i)];
            for (std::size_t k = 0; k < values.size(); ++k) x += values[k] * input.points.col(el[k]);
            added.push_back(x);
            if (with_params) added_params.push_back(detail::weighted_parameters<Dim>(input.node_params, weights, el));
          };
          // A node inside a cell (weights on all its vertices) is that cell's alone.
          if (own_interior && static_cast<int>(weights.size()) == nv) {
            q.connectivity.push_back(out.num_kept_nodes + static_cast<Index>(added.size()));
            add();
            continue;
          }
          const auto [it, inserted] = node_of.try_emplace(detail::lattice_key(weights, el), out.num_kept_nodes + static_cast<Index>(added.size()));
          if (inserted) add();
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
  mesh.first_node_id = input.first_node_id;
  if (!input.node_ids.empty()) {
    for (const Index v : out.kept) mesh.node_ids.push_back(input.node_ids[static_cast<std::size_t>(v)]);
    std::int64_t next = *std::max_element(input.node_ids.begin(), input.node_ids.end()) + 1;
    for (std::size_t i = 0; i < added.size(); ++i) mesh.node_ids.push_back(next++);
  }
  if (with_params) {
    for (const Index v : out.kept) mesh.node_params.push_back(input.node_params[static_cast<std::size_t>(v)]);
    mesh.node_params.insert(mesh.node_params.end(), added_params.begin(), added_params.end());
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
