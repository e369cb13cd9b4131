#pragma once
/// \file
/// DgrbfMover: RBF interpolation inside each Delaunay graph simplex (Wang, Qin & Zhao,
/// JCP 2015; thesis section 2.2.3, eqs. 2.15–2.16).
///
/// - Graph as in DGM (boundary nodes); a node in simplex T moves by Σ_j w_j(x) d_tj with the
///   cardinal weights w(x) = A_T⁻¹ φ_T(x) of T's (Dim+1)² RBF system, divided by their sum
///   when SimplexRbfOptions::normalize (default: reproduces rigid translations exactly).
///   Linear in the displacements.
/// - No inversion refusal: the weights are not positional, so a folded graph does not
///   imply a folded mesh (check the result with quality_report()).
/// - Setup caches: the graph, one factorized (Dim+1)² system per simplex, and per node its
///   simplex and weights. Cost: setup = DGM's + O(m) small factorizations + one kernel
///   evaluation per node; move = (Dim+1) × Dim multiply-adds per node.
/// - Nodes outside the hull and sliding nodes as in DgmMover.

#include "meshmotion/movers/dgrbf_options.hpp"
#include "meshmotion/core/mesh_like.hpp"
#include "meshmotion/core/types.hpp"
#include "meshmotion/movers/boundary.hpp"
#include "meshmotion/movers/delaunay_graph_options.hpp"
#include "meshmotion/movers/detail/graph_mover_base.hpp"
#include "meshmotion/movers/detail/mover_support.hpp"
#include "meshmotion/movers/mover.hpp"

namespace meshmotion {

/// The DGRBF mover in Dim dimensions; models MeshMover.
template <int Dim>
class DgrbfMover : public detail::MoveFromMoveInto<DgrbfMover<Dim>, Dim> {
 public:
  using detail::MoveFromMoveInto<DgrbfMover<Dim>, Dim>::move_into;  // into the caller's storage
  static constexpr int dim = Dim;

  explicit DgrbfMover(DgrbfOptions options = {}) : options_(options) {}

  [[nodiscard]] const DgrbfOptions& options() const noexcept { return options_; }
  [[nodiscard]] const MoverStats& stats() const noexcept { return base_.stats(); }
  /// Nodes that kept barycentric weights at the last setup (singular simplex system, or an
  /// absolute support radius reaching no vertex).
  [[nodiscard]] Index num_fallback() const noexcept { return base_.graph().num_fallback(); }

  /// Builds the graph, factorizes each simplex's system and computes every node's weights.
  /// Throws InputError as DgmMover::setup and for a non-positive support.
  template <MeshLike M>
    requires(mesh_dim<M> == Dim)
  void setup(const M& mesh, const ResolvedBoundary<Dim>& boundary) {
    base_.setup(copy_points(mesh), boundary, {}, options_.rbf, options_.outside);
  }

  /// Displacement of every node (Dim × n_nodes) for `d` (Dim × boundary.size()). Throws
  /// InputError for a wrong shape or a non-finite value.
  /// move() (inherited) returns the same; move_into writes into `out`, resized only when its
  /// shape differs.
  void move_into(PointsView<Dim> d, Points<Dim>& out) {
    base_.move_displacements(d, Points<Dim>(Dim, 0), false, out);
  }

  /// Forward derivative J w (Dim × n_nodes) for a boundary displacement change w: the mover is
  /// linear, so this is the interpolation of w (no inversion check, not counted as a move).
  [[nodiscard]] Points<Dim> derivative_forward(PointsView<Dim> w) { return base_.derivative_forward(w, Points<Dim>(Dim, 0)); }
  /// Reverse derivative Jᵀ v (Dim × boundary.size()) for v (Dim × n_nodes); sliding entries zero.
  [[nodiscard]] Points<Dim> derivative_reverse(PointsView<Dim> v) const { return base_.derivative_reverse(v); }

 private:
  DgrbfOptions options_;
  detail::GraphMoverBase<Dim> base_{"DgrbfMover"};
};

}  // namespace meshmotion

// The compiled library (target meshmotion::compiled, src/) holds these for Dim 2 and 3.
#ifdef MESHMOTION_COMPILED
namespace meshmotion {
extern template class DgrbfMover<2>;
extern template class DgrbfMover<3>;
// setup is a template over the mesh type: its Mesh<Dim> form, the one make_mover() uses, too.
extern template void DgrbfMover<2>::setup<Mesh<2>>(const Mesh<2>&, const ResolvedBoundary<2>&);
extern template void DgrbfMover<3>::setup<Mesh<3>>(const Mesh<3>&, const ResolvedBoundary<3>&);
}  // namespace meshmotion
#endif
