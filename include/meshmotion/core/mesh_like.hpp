#pragma once
/// \file
/// The MeshLike concept: how the movers see a mesh, so that a flow solver's own mesh type
/// takes part without being copied into a Mesh<Dim> or changed. A type models MeshLike when
/// meshmotion::MeshTraits<M> is specialized with the static members listed below (the
/// library's Mesh<Dim> is adapted here; examples/adapt_solver_mesh.cpp adapts plain arrays).

#include "meshmotion/core/element.hpp"
#include "meshmotion/core/mesh.hpp"
#include "meshmotion/core/types.hpp"

#include <concepts>

namespace meshmotion {

/// Specialize for your mesh type M:
/// \code
/// template <> struct meshmotion::MeshTraits<MyMesh> {
///   static constexpr int dim = 3;
///   static Index num_nodes(const MyMesh&);
///   static double coordinate(const MyMesh&, Index node, int axis);
///   static Index num_cell_blocks(const MyMesh&);            // blocks of cells (dimension dim)
///   static ElementType cell_type(const MyMesh&, Index block);
///   static Index num_cells(const MyMesh&, Index block);
///   static Index cell_node(const MyMesh&, Index block, Index cell, int local); // our local order
/// };
/// \endcode
template <class M>
struct MeshTraits;

template <class M>
concept MeshLike = requires(const M& m, Index i, int k) {
  { MeshTraits<M>::dim } -> std::convertible_to<int>;
  { MeshTraits<M>::num_nodes(m) } -> std::convertible_to<Index>;
  { MeshTraits<M>::coordinate(m, i, k) } -> std::convertible_to<double>;
  { MeshTraits<M>::num_cell_blocks(m) } -> std::convertible_to<Index>;
  { MeshTraits<M>::cell_type(m, i) } -> std::convertible_to<ElementType>;
  { MeshTraits<M>::num_cells(m, i) } -> std::convertible_to<Index>;
  { MeshTraits<M>::cell_node(m, i, i, k) } -> std::convertible_to<Index>;
} && (MeshTraits<M>::dim == 2 || MeshTraits<M>::dim == 3);

/// Spatial dimension of a MeshLike type.
template <MeshLike M>
inline constexpr int mesh_dim = MeshTraits<M>::dim;

template <int Dim>
struct MeshTraits<Mesh<Dim>> {
  static constexpr int dim = Dim;
  static Index num_nodes(const Mesh<Dim>& m) { return m.num_nodes(); }
  static double coordinate(const Mesh<Dim>& m, Index node, int axis) { return m.points(axis, node); }
  static Index num_cell_blocks(const Mesh<Dim>& m) { return static_cast<Index>(m.cells.size()); }
  static ElementType cell_type(const Mesh<Dim>& m, Index block) { return m.cells[static_cast<std::size_t>(block)].type; }
  static Index num_cells(const Mesh<Dim>& m, Index block) { return m.cells[static_cast<std::size_t>(block)].size(); }
  static Index cell_node(const Mesh<Dim>& m, Index block, Index cell, int local) {
    return m.cells[static_cast<std::size_t>(block)].element(cell)[static_cast<std::size_t>(local)];
  }
};

/// Coordinates of every node of a MeshLike mesh: dim × num_nodes (a copy; the Mesh<Dim>
/// overload returns a reference-free copy too, so callers own the result).
template <MeshLike M>
[[nodiscard]] Points<mesh_dim<M>> copy_points(const M& mesh) {
  using T = MeshTraits<M>;
  constexpr int Dim = mesh_dim<M>;
  const Index n = T::num_nodes(mesh);
  Points<Dim> p(Dim, n);
  for (Index i = 0; i < n; ++i)
    for (int d = 0; d < Dim; ++d) p(d, i) = T::coordinate(mesh, i, d);
  return p;
}

/// A Mesh<Dim> holding the nodes and cells of any MeshLike mesh (no facets or groups).
template <MeshLike M>
[[nodiscard]] Mesh<mesh_dim<M>> to_mesh(const M& mesh) {
  using T = MeshTraits<M>;
  Mesh<mesh_dim<M>> out;
  out.points = copy_points(mesh);
  for (Index b = 0; b < T::num_cell_blocks(mesh); ++b) {
    const ElementType type = T::cell_type(mesh, b);
    ElementBlock& block = out.block(type);
    const Index n = T::num_cells(mesh, b);
    block.reserve(block.size() + n);
    for (Index e = 0; e < n; ++e) {
      for (int k = 0; k < num_nodes(type); ++k) block.connectivity.push_back(T::cell_node(mesh, b, e, k));
      block.tags.push_back(0);
    }
  }
  return out;
}

}  // namespace meshmotion
