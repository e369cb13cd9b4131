#pragma once
/// \file
/// BoundaryOnlyMover (method "none"): the prescribed boundary nodes move, nothing else. The
/// curving pipeline's "snap only", which shows what the regularization is for; as a mover of a
/// moving body it is the reference every other mover improves on.
///
/// Linear in the displacements; setup keeps the boundary (O(boundary)), move scatters it.

#include "meshmotion/movers/boundary_only_options.hpp"
#include "meshmotion/core/mesh.hpp"
#include "meshmotion/core/types.hpp"
#include "meshmotion/movers/boundary.hpp"
#include "meshmotion/movers/detail/mover_support.hpp"
#include "meshmotion/movers/mover.hpp"
#include "meshmotion/solvers/detail/stopwatch.hpp"

#include <Eigen/Core>

namespace meshmotion {

/// Moves the prescribed boundary nodes by their displacements and nothing else (models
/// MeshMover).
template <int Dim>
class BoundaryOnlyMover : public detail::MoveFromMoveInto<BoundaryOnlyMover<Dim>, Dim> {
 public:
  static constexpr int dim = Dim;
  using detail::MoveFromMoveInto<BoundaryOnlyMover<Dim>, Dim>::move_into;

  explicit BoundaryOnlyMover(BoundaryOnlyOptions = {}) {}

  /// Keeps the boundary; throws InputError for an invalid one (check_boundary).
  void setup(const Mesh<Dim>& mesh, const ResolvedBoundary<Dim>& boundary) {
    const detail::Stopwatch clock;
    detail::check_boundary<Dim>("BoundaryOnlyMover::setup", boundary, mesh.num_nodes());
    num_nodes_ = mesh.num_nodes();
    boundary_ = boundary;
    stats_ = {};
    stats_.boundary_nodes = boundary.size();
    stats_.setup_seconds = clock.seconds();
  }
  /// Displacement of every node: d's prescribed columns at their nodes, 0 elsewhere.
  void move_into(PointsView<Dim> d, Points<Dim>& out) {
    detail::timed_move<Dim>("BoundaryOnlyMover::move", num_nodes_ > 0, d, boundary_.nodes, stats_,
                            [&] { out = scatter(d); });
  }
  [[nodiscard]] MoverStats stats() const { return stats_; }

  /// J w: w's prescribed columns at their nodes.
  [[nodiscard]] Points<Dim> derivative_forward(PointsView<Dim> w) {
    detail::check_displacements<Dim>("BoundaryOnlyMover::derivative_forward", w, boundary_.nodes);
    return scatter(w);
  }
  /// Jᵀ v: v's columns at the prescribed nodes (0 for the other boundary entries).
  [[nodiscard]] Points<Dim> derivative_reverse(PointsView<Dim> v) {
    detail::check_node_field<Dim>("BoundaryOnlyMover::derivative_reverse", v, num_nodes_);
    Points<Dim> out = Points<Dim>::Zero(Dim, boundary_.size());
    for (Index k = 0; k < boundary_.size(); ++k)
      if (boundary_.kinds[static_cast<std::size_t>(k)] == BoundaryKind::prescribed)
        out.col(k) = v.col(boundary_.nodes[static_cast<std::size_t>(k)]);
    return out;
  }

 private:
  [[nodiscard]] Points<Dim> scatter(PointsView<Dim> d) const {
    Points<Dim> out = Points<Dim>::Zero(Dim, num_nodes_);
    for (Index k = 0; k < boundary_.size(); ++k)
      if (boundary_.kinds[static_cast<std::size_t>(k)] == BoundaryKind::prescribed)
        out.col(boundary_.nodes[static_cast<std::size_t>(k)]) = d.col(k);
    return out;
  }

  Index num_nodes_ = 0;
  ResolvedBoundary<Dim> boundary_;
  MoverStats stats_;
};

}  // namespace meshmotion

// The compiled library (target meshmotion::compiled, src/) holds these for Dim 2 and 3.
#ifdef MESHMOTION_COMPILED
namespace meshmotion {
extern template class BoundaryOnlyMover<2>;
extern template class BoundaryOnlyMover<3>;
}  // namespace meshmotion
#endif
