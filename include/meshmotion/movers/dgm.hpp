#pragma once
/// \file
/// DgmMover: Delaunay graph mapping (Liu, Qin & Xia, JCP 2006; thesis section 2.2.1).
///
/// - The Delaunay graph is triangulated over the boundary nodes (prescribed, fixed and
///   sliding); every other node keeps its barycentric coordinates in its graph simplex and
///   is mapped into the moved simplex. Linear in the displacements; reproduces affine
///   motions exactly for every node inside the graph's convex hull.
/// - The map is a valid mesh motion only while no graph simplex inverts: move() checks every
///   simplex (exact orientation test) and throws InvalidMeshError naming one, with the advice
///   to use more steps; run_steps() rebuilds the graph on the moved mesh at each step.
/// - Nodes outside the graph's hull: DgmOptions::outside (clamped by default, see OutsideGraph).
/// - Sliding nodes: interpolated from a graph without them, projected onto their plane.
/// - Setup caches: the graph's simplices and, per node, its simplex and Dim+1 weights.
///   Cost: setup = one Bowyer–Watson triangulation of m boundary nodes + one walk per node,
///   O((m + n) log m) in practice; move = (Dim+1) × Dim multiply-adds per node plus the
///   inversion test over the graph's O(m) simplices; no linear system.

#include "meshmotion/movers/dgm_options.hpp"
#include "meshmotion/core/mesh_like.hpp"
#include "meshmotion/core/types.hpp"
#include "meshmotion/movers/boundary.hpp"
#include "meshmotion/movers/delaunay_graph_options.hpp"
#include "meshmotion/movers/detail/graph_mover_base.hpp"
#include "meshmotion/movers/detail/mover_support.hpp"
#include "meshmotion/movers/mover.hpp"

#include <optional>

namespace meshmotion {

/// The DGM mover in Dim dimensions; models MeshMover.
template <int Dim>
class DgmMover : public detail::MoveFromMoveInto<DgmMover<Dim>, Dim> {
 public:
  using detail::MoveFromMoveInto<DgmMover<Dim>, Dim>::move_into;  // into the caller's storage
  static constexpr int dim = Dim;

  explicit DgmMover(DgmOptions options = {}) : options_(options) {}

  [[nodiscard]] const DgmOptions& options() const noexcept { return options_; }
  [[nodiscard]] const MoverStats& stats() const noexcept { return base_.stats(); }
  /// Nodes outside the graph's convex hull at the last setup.
  [[nodiscard]] Index num_outside() const noexcept { return base_.graph().num_outside(); }

  /// Builds the graph and the barycentric coordinates (see the file comment). `boundary`:
  /// nodes and kinds (displacements unused). Throws InputError for unsorted, out-of-range or
  /// non-finite data, or boundary nodes that span no simplex (fewer than Dim+1, collinear).
  template <MeshLike M>
    requires(mesh_dim<M> == Dim)
  void setup(const M& mesh, const ResolvedBoundary<Dim>& boundary) {
    base_.setup(copy_points(mesh), boundary, {}, std::nullopt, options_.outside);
  }

  /// Displacement of every node (Dim × n_nodes) for boundary displacements `d`
  /// (Dim × boundary.size(); sliding entries ignored). Throws InputError for a wrong shape or
  /// a non-finite value, InvalidMeshError when the moved graph inverts (check_inversion).
  /// move() (inherited) returns the same; move_into writes into `out`, resized only when its
  /// shape differs.
  void move_into(PointsView<Dim> d, Points<Dim>& out) {
    base_.move_displacements(d, Points<Dim>(Dim, 0), options_.check_inversion, out);
  }

  /// Forward derivative J w (Dim × n_nodes) for a boundary displacement change w: the mover is
  /// linear, so this is the interpolation of w (no inversion check, not counted as a move).
  [[nodiscard]] Points<Dim> derivative_forward(PointsView<Dim> w) { return base_.derivative_forward(w, Points<Dim>(Dim, 0)); }
  /// Reverse derivative Jᵀ v (Dim × boundary.size()) for v (Dim × n_nodes); sliding entries zero.
  [[nodiscard]] Points<Dim> derivative_reverse(PointsView<Dim> v) const { return base_.derivative_reverse(v); }

 private:
  DgmOptions options_;
  detail::GraphMoverBase<Dim> base_{"DgmMover"};
};

}  // namespace meshmotion

// The compiled library (target meshmotion::compiled, src/) holds these for Dim 2 and 3.
#ifdef MESHMOTION_COMPILED
namespace meshmotion {
extern template class DgmMover<2>;
extern template class DgmMover<3>;
// setup is a template over the mesh type: its Mesh<Dim> form, the one make_mover() uses, too.
extern template void DgmMover<2>::setup<Mesh<2>>(const Mesh<2>&, const ResolvedBoundary<2>&);
extern template void DgmMover<3>::setup<Mesh<3>>(const Mesh<3>&, const ResolvedBoundary<3>&);
}  // namespace meshmotion
#endif
