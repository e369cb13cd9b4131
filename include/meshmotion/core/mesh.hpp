#pragma once
/// \file
/// Mesh<Dim>: the library's own mesh container. Coordinates are a Dim × n_nodes Eigen matrix;
/// connectivity is stored in blocks per element type, as Gmsh, VTK and CGNS do.

#include "meshmotion/core/element.hpp"
#include "meshmotion/core/error.hpp"
#include "meshmotion/core/types.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace meshmotion {

/// Elements of one type: a flat connectivity array (num_nodes(type) entries per element, in
/// the library's local order), a physical tag per element and, optionally, the element ids
/// and the model entities the file gave them.
struct ElementBlock {
  ElementType type = ElementType::tri3;
  std::vector<Index> connectivity;  ///< size() * num_nodes(type) node indices (0-based)
  std::vector<int> tags;            ///< physical tag per element, 0 when none
  std::vector<std::int64_t> ids;    ///< ids from the file; empty means 1, 2, ... in file order
  /// The model entity (Gmsh's elementary tag: the CAD face, edge or volume) of each element, 0
  /// where unknown; empty when the file gave none. Kept so that a written .msh still refers to
  /// the model's entities.
  std::vector<int> entities;

  [[nodiscard]] Index size() const noexcept {
    return static_cast<Index>(connectivity.size()) / num_nodes(type);
  }
  [[nodiscard]] bool empty() const noexcept { return connectivity.empty(); }
  [[nodiscard]] int nodes_per_element() const noexcept { return num_nodes(type); }

  /// Node indices of element e.
  [[nodiscard]] std::span<const Index> element(Index e) const {
    return {connectivity.data() + e * num_nodes(type), static_cast<std::size_t>(num_nodes(type))};
  }
  [[nodiscard]] std::span<Index> element(Index e) {
    return {connectivity.data() + e * num_nodes(type), static_cast<std::size_t>(num_nodes(type))};
  }

  /// Appends one element; `nodes` must hold num_nodes(type) indices.
  void add(std::span<const Index> nodes, int tag = 0) {
    if (static_cast<int>(nodes.size()) != num_nodes(type))
      throw InputError("ElementBlock::add: " + std::string(name(type)) + " needs " +
                       std::to_string(num_nodes(type)) + " nodes (got " + std::to_string(nodes.size()) + ")");
    connectivity.insert(connectivity.end(), nodes.begin(), nodes.end());
    tags.push_back(tag);
    if (!entities.empty()) entities.push_back(0);
  }
  void add(std::initializer_list<Index> nodes, int tag = 0) { add(std::span<const Index>(nodes.begin(), nodes.size()), tag); }

  void reserve(Index n) {
    connectivity.reserve(static_cast<std::size_t>(n * num_nodes(type)));
    tags.reserve(static_cast<std::size_t>(n));
    if (!entities.empty()) entities.reserve(static_cast<std::size_t>(n));
  }
};

/// A named physical group (Gmsh physical group, SU2 marker, OpenFOAM patch): elements carrying
/// `tag` in blocks of dimension `dim` belong to it.
struct PhysicalGroup {
  int dim = 0;
  int tag = 0;
  std::string name;
  /// Names of the sets of groups it belongs to, by which a boundary condition can name them
  /// all: an OpenFOAM patch's `inGroups` and its type when not the generic `patch` (`wall`,
  /// `empty`, `symmetryPlane`, ... as OpenFOAM adds them).
  std::vector<std::string> in_groups{};
};

/// CAD parametrization of a node, as Gmsh's $ParametricNodes gives it: the model entity the
/// node lies on and its parametric coordinates there (u only on curves, none on points or
/// volumes).
struct NodeParametrization {
  int entity_dim = 3;
  int entity_tag = 0;
  double u = 0.0;
  double v = 0.0;
};

/// An unstructured mixed-element mesh in Dim = 2 or 3 dimensions.
///
/// `cells` hold the elements of dimension Dim, `facets` those of dimension Dim - 1 (boundary
/// groups), and `lower` anything of lower dimension the file had (kept for round trips).
/// At most one block per element type in each of these lists.
template <int Dim>
struct Mesh {
  static_assert(Dim == 2 || Dim == 3, "Mesh: only 2D and 3D meshes");
  static constexpr int dim = Dim;

  Points<Dim> points;                              ///< Dim × n_nodes
  std::vector<ElementBlock> cells;                 ///< dimension Dim
  std::vector<ElementBlock> facets;                ///< dimension Dim - 1, tagged by group
  std::vector<ElementBlock> lower;                 ///< dimension < Dim - 1 (curves in 3D, points)
  std::vector<PhysicalGroup> groups;               ///< names of the tags
  std::vector<std::int64_t> node_ids;              ///< node ids from the file; empty: see first_node_id
  /// The file's id of node 0 when node_ids is empty (node i is then first_node_id + i): each
  /// format's own numbering, 1 for Gmsh and CGNS, 0 for SU2, VTU and OpenFOAM (their point
  /// indices) and for arrays given from Python.
  std::int64_t first_node_id = 1;
  std::vector<NodeParametrization> node_params;    ///< empty, or one per node
  /// The last num_auxiliary_nodes nodes are construction nodes, not the file's: the cell and
  /// face centres of a polyhedral mesh cut into tetrahedra (io/openfoam.hpp). They move with
  /// the mesh; formats that store polyhedra write the nodes before them only.
  Index num_auxiliary_nodes = 0;

  [[nodiscard]] Index num_nodes() const noexcept { return points.cols(); }
  [[nodiscard]] Index num_cells() const noexcept { return count(cells); }
  [[nodiscard]] Index num_facets() const noexcept { return count(facets); }

  /// The block list holding elements of dimension d.
  [[nodiscard]] std::vector<ElementBlock>& blocks_of_dim(int d) {
    return d == Dim ? cells : d == Dim - 1 ? facets : lower;
  }
  [[nodiscard]] const std::vector<ElementBlock>& blocks_of_dim(int d) const {
    return d == Dim ? cells : d == Dim - 1 ? facets : lower;
  }

  /// The block of type t (created empty if absent) in the list its dimension selects.
  ElementBlock& block(ElementType t) {
    auto& list = blocks_of_dim(dimension(t));
    for (auto& b : list)
      if (b.type == t) return b;
    list.push_back(ElementBlock{t, {}, {}, {}, {}});
    return list.back();
  }
  /// The block of type t, or nullptr.
  [[nodiscard]] const ElementBlock* find_block(ElementType t) const {
    for (const auto& b : blocks_of_dim(dimension(t)))
      if (b.type == t) return &b;
    return nullptr;
  }

  /// The group of that name, or nullptr. Two groups of one name (two SU2 markers, two
  /// OpenFOAM patches, a Gmsh name on two dimensions) make the name ambiguous: InputError
  /// naming both tags, rather than the first one taken in silence.
  [[nodiscard]] const PhysicalGroup* find_group(std::string_view group_name) const {
    const PhysicalGroup* found = nullptr;
    for (const auto& g : groups) {
      if (g.name != group_name) continue;
      if (found != nullptr)
        throw InputError("Mesh::group: '" + std::string(group_name) + "' names two groups (tag " + std::to_string(found->tag) +
                         " of dimension " + std::to_string(found->dim) + " and tag " + std::to_string(g.tag) + " of dimension " +
                         std::to_string(g.dim) + "): rename one in the mesh file");
      found = &g;
    }
    return found;
  }
  /// The group of that name; throws InputError listing the known names when absent.
  [[nodiscard]] const PhysicalGroup& group(std::string_view group_name) const {
    if (const auto* g = find_group(group_name)) return *g;
    std::string known;
    for (const auto& g : groups) known += (known.empty() ? "" : ", ") + g.name;
    throw InputError("Mesh::group: no group named '" + std::string(group_name) + "' (known: " +
                     (known.empty() ? std::string("none") : known) + ")");
  }

  /// Sorted unique nodes of the facets tagged `tag` (all their nodes, high-order included).
  [[nodiscard]] std::vector<Index> group_nodes(int tag, int group_dim = Dim - 1) const {
    std::vector<Index> nodes;
    for (const auto& b : blocks_of_dim(group_dim))
      for (Index e = 0; e < b.size(); ++e)
        if (b.tags[static_cast<std::size_t>(e)] == tag) {
          const auto el = b.element(e);
          nodes.insert(nodes.end(), el.begin(), el.end());
        }
    std::sort(nodes.begin(), nodes.end());
    nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
    return nodes;
  }
  /// Sorted unique nodes of the named group.
  [[nodiscard]] std::vector<Index> group_nodes(std::string_view group_name) const {
    const auto& g = group(group_name);
    return group_nodes(g.tag, g.dim);
  }

  /// The file id of node i (1-based position when the file gave none).
  [[nodiscard]] std::int64_t node_id(Index i) const {
    return node_ids.empty() ? static_cast<std::int64_t>(i) + first_node_id : node_ids[static_cast<std::size_t>(i)];
  }

  /// "node i" for messages, with the file's id beside the index when the two differ (a user
  /// looks the node up by the file's id; the index is what the library's arrays use).
  [[nodiscard]] std::string describe_node(Index i) const {
    std::string text = "node " + std::to_string(i);
    if (i < 0 || i >= num_nodes()) return text;
    const std::int64_t id = node_id(i);
    return id == i ? text : text + " (id " + std::to_string(id) + " in the file)";
  }

  /// The node indices of file node ids (node_id()'s inverse), in the order given. Throws
  /// InputError naming the first id that no node has.
  [[nodiscard]] std::vector<Index> node_indices(std::span<const std::int64_t> ids) const {
    std::vector<Index> out;
    out.reserve(ids.size());
    if (node_ids.empty()) {
      for (const std::int64_t id : ids) {
        if (id < first_node_id || id - first_node_id >= num_nodes())
          throw InputError("Mesh::node_indices: no node has id " + std::to_string(id) + " (the file numbers its nodes " +
                           std::to_string(first_node_id) + " to " + std::to_string(first_node_id + num_nodes() - 1) + ")");
        out.push_back(static_cast<Index>(id - first_node_id));
      }
      return out;
    }
    std::vector<Index> order(node_ids.size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = static_cast<Index>(i);
    std::sort(order.begin(), order.end(), [&](Index a, Index b) {
      return node_ids[static_cast<std::size_t>(a)] < node_ids[static_cast<std::size_t>(b)];
    });
    for (const std::int64_t id : ids) {
      const auto it = std::lower_bound(order.begin(), order.end(), id,
                                       [&](Index a, std::int64_t x) { return node_ids[static_cast<std::size_t>(a)] < x; });
      if (it == order.end() || node_ids[static_cast<std::size_t>(*it)] != id)
        throw InputError("Mesh::node_indices: no node has id " + std::to_string(id));
      out.push_back(*it);
    }
    return out;
  }

 private:
  static Index count(const std::vector<ElementBlock>& list) {
    Index n = 0;
    for (const auto& b : list) n += b.size();
    return n;
  }
};

using Mesh2 = Mesh<2>;
using Mesh3 = Mesh<3>;

namespace detail {

/// Element blocks in the order the .msh writer lists them: by dimension, then lower, facet
/// and cell blocks, each in its own order.
template <int Dim>
[[nodiscard]] std::vector<const ElementBlock*> blocks_in_file_order(const Mesh<Dim>& mesh) {
  std::vector<const ElementBlock*> list;
  for (int d = 0; d <= Dim; ++d)
    for (const auto* b : {&mesh.lower, &mesh.facets, &mesh.cells})
      for (const auto& block : *b)
        if (dimension(block.type) == d && !block.empty()) list.push_back(&block);
  return list;
}

/// Element id of element e of `block`: the stored one, else its 1-based position in the file.
[[nodiscard]] inline std::int64_t element_id(const ElementBlock& block, Index e, std::int64_t position) {
  return block.ids.empty() ? position + 1 : block.ids[static_cast<std::size_t>(e)];
}

}  // namespace detail

/// The id a written .msh gives node `i`: the file's id when the mesh keeps them (node_ids),
/// else i + 1, as Gmsh numbers from 1 whatever the format the mesh came from.
template <int Dim>
[[nodiscard]] std::int64_t msh_node_id(const Mesh<Dim>& mesh, Index i) {
  return mesh.node_ids.empty() ? static_cast<std::int64_t>(i) + 1 : mesh.node_ids[static_cast<std::size_t>(i)];
}

/// The id element e of `block` (a block of `mesh`) has in a .msh file written from `mesh`:
/// its stored id, else its 1-based position among all the elements the file lists (lower
/// dimensions first), which is what a user sees in Gmsh.
template <int Dim>
[[nodiscard]] std::int64_t msh_element_id(const Mesh<Dim>& mesh, const ElementBlock& block, Index e) {
  if (!block.ids.empty()) return block.ids[static_cast<std::size_t>(e)];
  std::int64_t before = 0;
  for (const auto* b : detail::blocks_in_file_order(mesh)) {
    if (b == &block) return before + e + 1;
    before += b->size();
  }
  return e + 1;
}

/// Checks what every algorithm of the library relies on: finite coordinates, node indices in
/// range, blocks whose sizes agree with their types, one tag per element, ids (when given)
/// one per node/element. Throws InputError naming the first offending node or element.
template <int Dim>
void validate(const Mesh<Dim>& mesh) {
  const Index n = mesh.num_nodes();
  for (Index i = 0; i < n; ++i)
    for (int d = 0; d < Dim; ++d)
      if (!std::isfinite(mesh.points(d, i)))
        throw InputError("validate: " + mesh.describe_node(i) + " has a non-finite coordinate (" +
                         std::to_string(mesh.points(d, i)) + ")");
  if (!mesh.node_ids.empty() && static_cast<Index>(mesh.node_ids.size()) != n)
    throw InputError("validate: " + std::to_string(mesh.node_ids.size()) + " node ids for " +
                     std::to_string(n) + " nodes");
  if (mesh.num_auxiliary_nodes < 0 || mesh.num_auxiliary_nodes > n)
    throw InputError("validate: " + std::to_string(mesh.num_auxiliary_nodes) + " auxiliary nodes for " + std::to_string(n) +
                     " nodes");
  if (!mesh.node_params.empty() && static_cast<Index>(mesh.node_params.size()) != n)
    throw InputError("validate: " + std::to_string(mesh.node_params.size()) +
                     " node parametrizations for " + std::to_string(n) + " nodes");
  for (std::size_t i = 0; i < mesh.node_params.size(); ++i)
    if (mesh.node_params[i].entity_dim < 0 || mesh.node_params[i].entity_dim > 3)
      throw InputError("validate: node " + std::to_string(i) + " lies in an entity of dimension " +
                       std::to_string(mesh.node_params[i].entity_dim) + " (expected 0 to 3)");
  const auto check_blocks = [&](const std::vector<ElementBlock>& list, int list_dim) {
    for (const auto& b : list) {
      const std::string what = std::string(name(b.type)) + " block";
      const bool right_dim = list_dim >= 0 ? dimension(b.type) == list_dim : dimension(b.type) < Dim - 1;
      if (!right_dim)
        throw InputError("validate: " + what + " of dimension " + std::to_string(dimension(b.type)) +
                         " is in the wrong block list of a " + std::to_string(Dim) + "D mesh");
      if (b.connectivity.size() % static_cast<std::size_t>(b.nodes_per_element()) != 0)
        throw InputError("validate: " + what + " connectivity of " + std::to_string(b.connectivity.size()) +
                         " entries is not a multiple of " + std::to_string(b.nodes_per_element()));
      if (static_cast<Index>(b.tags.size()) != b.size())
        throw InputError("validate: " + what + " has " + std::to_string(b.tags.size()) + " tags for " +
                         std::to_string(b.size()) + " elements");
      if (!b.ids.empty() && static_cast<Index>(b.ids.size()) != b.size())
        throw InputError("validate: " + what + " has " + std::to_string(b.ids.size()) + " ids for " +
                         std::to_string(b.size()) + " elements");
      if (!b.entities.empty() && static_cast<Index>(b.entities.size()) != b.size())
        throw InputError("validate: " + what + " has " + std::to_string(b.entities.size()) + " entity tags for " +
                         std::to_string(b.size()) + " elements");
      for (std::size_t k = 0; k < b.connectivity.size(); ++k) {
        const Index v = b.connectivity[k];
        if (v < 0 || v >= n)
          throw InputError("validate: " + what + " element " +
                           std::to_string(k / static_cast<std::size_t>(b.nodes_per_element())) +
                           " refers to node " + std::to_string(v) + " (expected 0 to " + std::to_string(n - 1) + ")");
      }
    }
  };
  check_blocks(mesh.cells, Dim);
  check_blocks(mesh.facets, Dim - 1);
  check_blocks(mesh.lower, -1);
}

/// Gives every facet tag that has no group a group named by its number ("7"), the way files
/// without physical names (Gmsh without $PhysicalNames) are addressed on command lines.
/// Returns the number of groups added.
template <int Dim>
Index name_unnamed_facet_groups(Mesh<Dim>& mesh) {
  Index added = 0;
  for (const auto& block : mesh.facets)
    for (const int tag : block.tags) {
      const bool named = std::any_of(mesh.groups.begin(), mesh.groups.end(),
                                     [&](const PhysicalGroup& g) { return g.dim == Dim - 1 && g.tag == tag; });
      if (!named && tag != 0) {
        mesh.groups.push_back({Dim - 1, tag, std::to_string(tag)});
        ++added;
      }
    }
  return added;
}

}  // namespace meshmotion

// The compiled library (target meshmotion::compiled, src/core.cpp) holds it.
#ifdef MESHMOTION_COMPILED
namespace meshmotion {
extern template void validate<2>(const Mesh<2>&);
extern template void validate<3>(const Mesh<3>&);
}  // namespace meshmotion
#endif
