#pragma once
/// \file
/// The mover contract (DESIGN.md "The mover contract"): every mover is constructed from its
/// options struct, does all reference-configuration work in `setup(mesh, boundary)` and then
/// maps boundary displacements to the displacement of every node in `move`, many times.

#include "meshmotion/core/mesh.hpp"
#include "meshmotion/core/types.hpp"
#include "meshmotion/movers/boundary.hpp"

#include <concepts>

namespace meshmotion {

/// What a mover did: setup and move costs, solver work.
struct MoverStats {
  double setup_seconds = 0.0;  ///< the last setup
  double move_seconds = 0.0;   ///< the last move
  /// Of move_seconds: the last move's solves (the interpolation's coefficients, the system's
  /// displacements, a factorization deferred to them included). What is left of move_seconds
  /// after these and rebuild_seconds is evaluation: the operators applied, the rigid part blended.
  double solve_seconds = 0.0;
  /// Of move_seconds: what the last move set up again or built first (RBF: a radius the motion
  /// outgrew, the interpolation a mover set up at rest builds when it first has a rest to carry).
  double rebuild_seconds = 0.0;
  Index moves = 0;             ///< moves since the last setup
  Index factorizations = 0;    ///< numeric factorizations since the last setup (1 for linear movers)
  Index iterations = 0;        ///< solver iterations of the last move (0 for direct solvers)
  double residual = 0.0;       ///< largest relative solver residual of the last move
  bool fell_back = false;      ///< an iterative solver failed and a direct one answered
  Index boundary_nodes = 0;    ///< constrained nodes after merging coincident ones
  Index evaluated_nodes = 0;   ///< nodes whose displacement the mover computes (others stay put)
  Index nonzeros = 0;          ///< stored nonzeros of the system and evaluation operators
  /// A lower bound of the interpolation system's 2-norm condition number (RBF: the largest
  /// over its systems or patches); 0 where the mover has none or does not estimate it.
  double condition = 0.0;
  /// RBF: the rigid part of the boundary's motion was blended into the volume and the
  /// interpolation carried the rest (RbfOptions::rigid_part).
  bool rigid_part = false;
  /// RBF: centres thinned because the system's condition exceeded RbfOptions::condition_limit.
  Index thinned_centres = 0;
  /// RBF: the support radius of the last setup, given or the mover's default (0 where the
  /// method has none). Front ends report it from here: the mover alone chooses it.
  double support_radius = 0.0;
  /// RBF: the default radius was reduced to fit the memory budget (RbfOptions::max_memory_bytes).
  bool radius_reduced = false;
  /// RBF: times a move outgrew the default radius and set the mover up again since the setup
  /// the caller made (radius_outgrown()); `moves` counts on through them.
  Index radius_growths = 0;
  /// RBF: centres of the coarse level of a two-level interpolation (RbfOptions::levels; 0: one level).
  Index coarse_centres = 0;
  /// RBF set up with a mesh of linear cells: cells the last move folded (RbfOptions::repair),
  /// nodes the repair then moved, and cells it left folded.
  Index folded_cells = 0;
  Index repaired_nodes = 0;
  Index left_folded = 0;
};

template <class F>
void visit_fields(const MoverStats& s, F&& f) {
  f("setup_seconds", s.setup_seconds, "the last setup");
  f("move_seconds", s.move_seconds, "the last move");
  f("solve_seconds", s.solve_seconds, "of the last move: its solves");
  f("rebuild_seconds", s.rebuild_seconds, "of the last move: what it set up again or built first");
  f("moves", s.moves, "moves since the last setup");
  f("factorizations", s.factorizations, "numeric factorizations since the last setup");
  f("iterations", s.iterations, "solver iterations of the last move (0 for direct solvers)");
  f("residual", s.residual, "largest relative solver residual of the last move");
  f("fell_back", s.fell_back, "an iterative solver failed and a direct one answered");
  f("boundary_nodes", s.boundary_nodes, "constrained nodes after merging coincident ones");
  f("evaluated_nodes", s.evaluated_nodes, "nodes whose displacement the mover computes");
  f("nonzeros", s.nonzeros, "stored nonzeros of the system and evaluation operators");
  f("condition", s.condition, "lower bound of the RBF system's condition number (0: not estimated)");
  f("rigid_part", s.rigid_part, "RBF: the rigid part of the boundary's motion was blended in first");
  f("thinned_centres", s.thinned_centres, "RBF: centres thinned because the system's condition exceeded condition_limit");
  f("support_radius", s.support_radius, "RBF: the support radius of the last setup, given or the default (0: none)");
  f("radius_reduced", s.radius_reduced, "RBF: the default radius was reduced to fit the memory budget");
  f("radius_growths", s.radius_growths, "RBF: moves that outgrew the default radius and set the mover up again");
  f("coarse_centres", s.coarse_centres, "RBF: centres of the coarse level of a two-level interpolation (0: one level)");
  f("folded_cells", s.folded_cells, "RBF: linear cells the last move folded (before the repair)");
  f("repaired_nodes", s.repaired_nodes, "RBF: nodes the repair of the folded cells moved");
  f("left_folded", s.left_folded, "RBF: cells still folded after the repair");
}

/// A mesh mover in Dim = M::dim dimensions.
///
/// - `setup(mesh, boundary)`: `mesh` any MeshLike (Mesh<Dim> is checked here), `boundary` a
///   ResolvedBoundary<Dim>; copies what it needs, so the mesh may change afterwards.
/// - `move(d)`: d is Dim × boundary.size() (columns in boundary.nodes order; entries of
///   sliding nodes are ignored); returns the displacement of every node, Dim × n_nodes,
///   with boundary nodes at their targets. The library's movers take d as a PointsView, so a
///   solver's or numpy's array (an Eigen::Map) is read in place.
/// - `move_into(d, out)`: the same into caller storage (resized only when its shape differs).
/// - `stats()`: MoverStats.
template <class M>
concept MeshMover = requires(M mover, const Mesh<M::dim>& mesh, const ResolvedBoundary<M::dim>& boundary,
                             const Points<M::dim>& d, Points<M::dim>& out) {
  { M::dim } -> std::convertible_to<int>;
  mover.setup(mesh, boundary);
  { mover.move(d) } -> std::same_as<Points<M::dim>>;
  mover.move_into(d, out);
  { mover.stats() } -> std::convertible_to<MoverStats>;
};

}  // namespace meshmotion
