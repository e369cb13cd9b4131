#pragma once
/// \file
/// The dimension-free intermediate that readers fill (3 coordinates per node, blocks of every
/// dimension) and its conversion to Mesh<2> or Mesh<3>.

#include "meshmotion/core/mesh.hpp"
#include "meshmotion/io/any_mesh.hpp"

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

namespace meshmotion::detail {

/// validate(mesh) for a mesh read from `file`, whose name its message then carries.
template <int Dim>
void validate_read(const Mesh<Dim>& mesh, const std::filesystem::path& file) {
  try {
    validate(mesh);
  } catch (const InputError& e) {
    throw InputError(file.string() + ": invalid mesh after reading: " + e.what());
  }
}

/// The first value listed twice among an element's `count` nodes `nodes` (its file's numbers
/// or indices), or nullopt. An element through one node twice has a collapsed edge: no mesher
/// writes one, and a reader that kept it would hand on a cell of zero volume.
template <class T>
[[nodiscard]] std::optional<T> repeated_node(const T* nodes, int count) {
  for (int a = 1; a < count; ++a)
    for (int b = 0; b < a; ++b)
      if (nodes[a] == nodes[b]) return nodes[a];
  return std::nullopt;
}

struct RawMesh {
  std::vector<double> coords;                    ///< x y z per node
  std::vector<std::int64_t> node_ids;            ///< one per node, or empty: first_node_id + i
  std::int64_t first_node_id = 1;                ///< the format's numbering (Mesh::first_node_id)
  std::vector<NodeParametrization> node_params;  ///< empty or one per node
  std::vector<ElementBlock> blocks;              ///< one per type, in order of first appearance
  std::vector<PhysicalGroup> groups;
  int dim = -1;                                  ///< forced dimension (SU2 NDIME), -1 to detect

  [[nodiscard]] Index num_nodes() const noexcept { return static_cast<Index>(coords.size() / 3); }

  ElementBlock& block(ElementType t) {
    for (auto& b : blocks)
      if (b.type == t) return b;
    blocks.push_back(ElementBlock{t, {}, {}, {}, {}});
    return blocks.back();
  }
};

/// Maps node ids of a file to 0-based indices: a dense table when ids are compact, a hash map
/// otherwise (ids are arbitrary 64-bit numbers in a hostile file).
class NodeIdMap {
 public:
  void build(const std::vector<std::int64_t>& ids, std::int64_t max_id) {
    const auto n = static_cast<std::int64_t>(ids.size());
    dense_ = max_id >= 0 && max_id <= 4 * n + 1024;
    if (dense_) {
      table_.assign(static_cast<std::size_t>(max_id + 1), -1);
      for (std::size_t i = 0; i < ids.size(); ++i)
        if (ids[i] >= 0) table_[static_cast<std::size_t>(ids[i])] = static_cast<Index>(i);
    } else {
      table_.clear();
      map_.reserve(ids.size());
      for (std::size_t i = 0; i < ids.size(); ++i) map_.emplace(ids[i], static_cast<Index>(i));
    }
  }
  /// Index of node `id`, or -1.
  [[nodiscard]] Index operator()(std::int64_t id) const {
    if (dense_) return id >= 0 && static_cast<std::size_t>(id) < table_.size() ? table_[static_cast<std::size_t>(id)] : -1;
    const auto it = map_.find(id);
    return it == map_.end() ? -1 : it->second;
  }

 private:
  bool dense_ = true;
  std::vector<Index> table_;
  std::unordered_map<std::int64_t, Index> map_;
};

/// Whether ids are exactly 1, 2, ..., n (then the mesh stores none).
[[nodiscard]] inline bool is_identity_numbering(const std::vector<std::int64_t>& ids) {
  for (std::size_t i = 0; i < ids.size(); ++i)
    if (ids[i] != static_cast<std::int64_t>(i) + 1) return false;
  return true;
}

template <int Dim>
[[nodiscard]] Mesh<Dim> to_mesh(RawMesh&& raw, const std::filesystem::path& file) {
  Mesh<Dim> mesh;
  const Index n = raw.num_nodes();
  mesh.points.resize(Dim, n);
  for (Index i = 0; i < n; ++i) {
    const double* c = raw.coords.data() + 3 * i;
    for (int d = 0; d < Dim; ++d) mesh.points(d, i) = c[d];
    if (Dim == 2 && c[2] != 0.0)
      throw InputError(file.string() + ": node " + std::to_string(raw.node_ids.empty() ? i + raw.first_node_id : raw.node_ids[static_cast<std::size_t>(i)]) +
                       " has z = " + std::to_string(c[2]) + " in a 2D mesh (expected z = 0: a mesh is 3D only if it has 3D elements)");
  }
  std::vector<double>().swap(raw.coords);
  if (!is_identity_numbering(raw.node_ids)) mesh.node_ids = std::move(raw.node_ids);
  mesh.first_node_id = raw.first_node_id;
  mesh.node_params = std::move(raw.node_params);
  for (auto& b : raw.blocks) {
    if (dimension(b.type) > Dim)
      throw InputError(file.string() + ": " + std::string(name(b.type)) + " elements in a " + std::to_string(Dim) + "D mesh");
    mesh.blocks_of_dim(dimension(b.type)).push_back(std::move(b));
  }
  mesh.groups = std::move(raw.groups);
  validate_read(mesh, file);
  return mesh;
}

/// A 3D mesh if the data holds 3D elements (or the format said so), else 2D.
[[nodiscard]] inline AnyMesh to_any_mesh(RawMesh&& raw, const std::filesystem::path& file) {
  int dim = raw.dim;
  if (dim < 0) {
    dim = 2;
    for (const auto& b : raw.blocks)
      if (dimension(b.type) == 3 && !b.empty()) dim = 3;
  }
  if (dim == 3) return to_mesh<3>(std::move(raw), file);
  return to_mesh<2>(std::move(raw), file);
}

}  // namespace meshmotion::detail
