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
  Index moves = 0;             ///< moves since the last setup
  Index factorizations = 0;    ///< numeric factorizations since the last setup (1 for linear movers)
  Index iterations = 0;        ///< solver iterations of the last move (0 for direct solvers)
  double residual = 0.0;       ///< largest relative solver residual of the last move
  bool fell_back = false;      ///< an iterative solver failed and a direct one answered
  Index boundary_nodes = 0;    ///< constrained nodes after merging coincident ones
  Index evaluated_nodes = 0;   ///< nodes whose displacement the mover computes (others stay put)
  Index nonzeros = 0;          ///< stored nonzeros of the system and evaluation operators
};

/// A mesh mover in Dim = M::dim dimensions.
///
/// - `setup(mesh, boundary)`: `mesh` any MeshLike (Mesh<Dim> is checked here), `boundary` a
///   ResolvedBoundary<Dim>; copies what it needs, so the mesh may change afterwards.
/// - `move(d)`: d is Dim × boundary.size() (columns in boundary.nodes order; entries of
///   sliding nodes are ignored); returns the displacement of every node, Dim × n_nodes,
///   with boundary nodes at their targets.
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
