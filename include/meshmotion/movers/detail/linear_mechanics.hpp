#pragma once
/// \file
/// LinearMechanicsMover: what the linear mechanics movers (lineal and torsional springs,
/// linear and stiffened elasticity) share — the copied reference mesh, the checks, the
/// constrained system factorized in setup, and move/move_into/stats. A mover derives from it,
/// assembles its stiffness matrix in setup and hands it to finish_setup().

#include "meshmotion/core/error.hpp"
#include "meshmotion/core/mesh.hpp"
#include "meshmotion/core/mesh_like.hpp"
#include "meshmotion/core/types.hpp"
#include "meshmotion/movers/boundary.hpp"
#include "meshmotion/movers/detail/constrained_system.hpp"
#include "meshmotion/movers/detail/mover_support.hpp"
#include "meshmotion/movers/mover.hpp"
#include "meshmotion/solvers/detail/stopwatch.hpp"
#include "meshmotion/solvers/linear_solver.hpp"

#include <string>
#include <vector>

namespace meshmotion::detail {

/// A Mesh<Dim> copy of any MeshLike `mesh`, checked: finite coordinates, at least one cell,
/// node indices in range, a valid `boundary`. Throws InputError prefixed by `where`.
template <MeshLike M, int Dim = mesh_dim<M>>
[[nodiscard]] Mesh<Dim> checked_copy(const M& mesh, const ResolvedBoundary<Dim>& boundary, const std::string& where) {
  Mesh<Dim> copy = to_mesh(mesh);
  if (!copy.points.allFinite()) throw InputError(where + "::setup: mesh has a non-finite coordinate");
  if (copy.num_cells() == 0) throw InputError(where + "::setup: mesh has no cells (expected at least one)");
  for (const auto& block : copy.cells)
    for (const Index v : block.connectivity)
      if (v < 0 || v >= copy.num_nodes())
        throw InputError(where + "::setup: a " + std::string(name(block.type)) + " cell refers to node " +
                         std::to_string(v) + " (expected 0 to " + std::to_string(copy.num_nodes() - 1) + ")");
  check_boundary(where + "::setup", boundary, copy.num_nodes());
  return copy;
}

/// Nodes used by some cell (the others have no stiffness and stay put).
template <int Dim>
[[nodiscard]] std::vector<bool> cell_nodes(const Mesh<Dim>& mesh) {
  std::vector<bool> active(static_cast<std::size_t>(mesh.num_nodes()), false);
  for (const auto& block : mesh.cells)
    for (const Index v : block.connectivity) active[static_cast<std::size_t>(v)] = true;
  return active;
}

template <int Dim>
class LinearMechanicsMover {
 public:
  static constexpr int dim = Dim;

  [[nodiscard]] const MoverStats& stats() const noexcept { return stats_; }

  /// The assembled stiffness matrix before boundary conditions: (n_nodes · c) square with
  /// c = 1 (uncoupled springs without sliding nodes) or Dim (node-major dofs, node · Dim + axis).
  [[nodiscard]] const SparseMatrix& stiffness() const noexcept { return stiffness_; }

  /// Displacement of every node (Dim × n_nodes) for boundary displacements `d` (Dim ×
  /// boundary.size(), boundary.nodes order; sliding entries ignored). Prescribed and fixed
  /// nodes get their targets exactly, sliding nodes stay on their planes. Throws InputError
  /// for a wrong shape, a non-finite value or a missing setup; SolverError when an
  /// iterative solve does not converge.
  [[nodiscard]] Points<Dim> move(PointsView<Dim> d) {
    Points<Dim> out;
    move_into(d, out);
    return out;
  }

  /// move() into `out` (resized only when its shape differs).
  void move_into(PointsView<Dim> d, Points<Dim>& out);
  /// move() into an Eigen::Map (or any Eigen::Ref) of the caller's Dim × n_nodes array.
  void move_into(PointsView<Dim> d, Eigen::Ref<Points<Dim>> out) {
    move_into(d, scratch_);
    copy_to_caller<Dim>((name_ + "::move_into").c_str(), scratch_, out);
  }

  /// Forward derivative J w (Dim × n_nodes) for a boundary displacement change w (Dim ×
  /// boundary.size()): the mover is linear in the displacements, so this is move(w), without
  /// counting as a move. Throws as move().
  [[nodiscard]] Points<Dim> derivative_forward(PointsView<Dim> w);

  /// Reverse derivative Jᵀ v: for v (Dim × n_nodes), the gradient of ⟨v, move(d)⟩ with respect
  /// to d (Dim × boundary.size()); one solve with the factorization of setup (the reduced
  /// matrix is symmetric). Sliding nodes' entries are zero (move() ignores their input).
  /// Throws InputError for a missing setup, a wrong shape or a non-finite value.
  [[nodiscard]] Points<Dim> derivative_reverse(PointsView<Dim> v);

 protected:
  explicit LinearMechanicsMover(std::string name) : name_(std::move(name)) {}

  /// Copies the mesh (any MeshLike) and checks it and the boundary; returns the copy.
  template <MeshLike M>
  [[nodiscard]] Mesh<Dim> start_setup(const M& mesh, const ResolvedBoundary<Dim>& boundary) {
    ready_ = false;
    return checked_copy(mesh, boundary, name_);
  }

  /// Factorizes the constrained system of K (components dofs per node) and records stats.
  /// `free_nodes` (optional, one flag per node) limits the unknowns to the flagged nodes that
  /// are not Dirichlet nodes: the others keep zero displacement (by default every node of a
  /// cell is free).
  void finish_setup(const Mesh<Dim>& mesh, const ResolvedBoundary<Dim>& boundary, SparseMatrix k, int components,
                    const SolverOptions& solver, const Stopwatch& watch, const std::vector<bool>* free_nodes = nullptr) {
    stiffness_ = std::move(k);
    boundary_nodes_ = boundary.nodes;
    num_nodes_ = mesh.num_nodes();
    system_.build(components, free_nodes != nullptr ? *free_nodes : cell_nodes(mesh), boundary, solver);
    system_.factorize(stiffness_);
    stats_ = MoverStats{};
    stats_.boundary_nodes = boundary.size();
    stats_.evaluated_nodes = system_.unknowns() / (components == 1 ? 1 : Dim);
    stats_.nonzeros = system_.nonzeros();
    stats_.factorizations = system_.report().factorizations;
    ready_ = true;
    stats_.setup_seconds = watch.seconds();
  }

  std::string name_;
  MoverStats stats_;

 private:
  SparseMatrix stiffness_;
  std::vector<Index> boundary_nodes_;
  Index num_nodes_ = 0;
  ConstrainedSystem<Dim> system_;
  bool ready_ = false;
  Points<Dim> scratch_;  // a move into the caller's storage
};

template <int Dim>
void LinearMechanicsMover<Dim>::move_into(PointsView<Dim> d, Points<Dim>& out) {
  timed_move<Dim>(name_ + "::move", ready_, d, boundary_nodes_, stats_, [&] {
    add_time(stats_.solve_seconds, [&] { system_.solve(d, out); });
    system_.record(stats_);
  });
}

template <int Dim>
Points<Dim> LinearMechanicsMover<Dim>::derivative_forward(PointsView<Dim> w) {
  if (!ready_) throw InputError(name_ + "::derivative_forward: setup() was not called");
  check_displacements<Dim>(name_ + "::derivative_forward", w, boundary_nodes_);
  Points<Dim> out;
  system_.solve(w, out);
  return out;
}

template <int Dim>
Points<Dim> LinearMechanicsMover<Dim>::derivative_reverse(PointsView<Dim> v) {
  if (!ready_) throw InputError(name_ + "::derivative_reverse: setup() was not called");
  check_node_field<Dim>(name_ + "::derivative_reverse", v, num_nodes_);
  Points<Dim> gradient;
  system_.solve_transpose(v, gradient);
  return gradient;
}

}  // namespace meshmotion::detail

// The compiled library (target meshmotion::compiled, src/) holds these for Dim 2 and 3.
#ifdef MESHMOTION_COMPILED
namespace meshmotion {
extern template class detail::LinearMechanicsMover<2>;
extern template class detail::LinearMechanicsMover<3>;
}  // namespace meshmotion
#endif
