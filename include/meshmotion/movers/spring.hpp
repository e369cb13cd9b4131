#pragma once
/// \file
/// SpringMover: Batina's lineal spring analogy (thesis section 2.1.1, eqs. 2.1–2.2; J. T.
/// Batina, AIAA paper 89-0115, 1989). Every edge is a spring of stiffness k_ij = 1/‖r_i − r_j‖
/// (more generally ‖r_i − r_j‖^−p); node displacements solve Σ_j k_ij (Δr_i − Δr_j) = 0 at
/// every free node with the boundary displacements imposed.
///
/// - Linear in the displacements.
/// - Uncoupled: one scalar Laplacian-like matrix shared by the Dim coordinate directions
///   (Dim right-hand sides). Sliding boundaries couple the directions, so with sliding nodes
///   the matrix is expanded to Dim dofs per node and the sliding nodes keep only their
///   tangent-plane unknowns (they end exactly on their planes).
/// - Any element type, 2D and 3D: springs along the cell edges (half edges on quadratic
///   cells, see detail/spring_network.hpp), each counted once.
/// - Setup caches the factorized reduced matrix; cost: setup = assembly O(edges) + one sparse
///   factorization, move = one solve (forward/back substitution, or CG from the last solution).
/// - Known weakness (thesis): inverts cells for moderate rotations; use it for small motions.

#include "meshmotion/movers/spring_options.hpp"
#include "meshmotion/core/error.hpp"
#include "meshmotion/core/mesh_like.hpp"
#include "meshmotion/core/types.hpp"
#include "meshmotion/movers/boundary.hpp"
#include "meshmotion/movers/detail/linear_mechanics.hpp"
#include "meshmotion/movers/detail/spring_network.hpp"
#include "meshmotion/solvers/detail/stopwatch.hpp"
#include "meshmotion/solvers/solver_options.hpp"

#include <cmath>
#include <string>
#include <vector>

namespace meshmotion {

/// Batina's lineal spring mover in Dim dimensions; models MeshMover.
template <int Dim>
class SpringMover : public detail::LinearMechanicsMover<Dim> {
 public:
  explicit SpringMover(SpringOptions options = {})
      : detail::LinearMechanicsMover<Dim>("SpringMover"), options_(options) {}

  [[nodiscard]] const SpringOptions& options() const noexcept { return options_; }

  /// Assembles and factorizes the spring system of `mesh` (any MeshLike of dimension Dim)
  /// with the Dirichlet and sliding nodes of `boundary` (its displacements are not used).
  /// Throws InputError for a non-finite exponent, bad mesh or boundary data, or two distinct
  /// nodes of one edge at the same position; SolverError when the factorization fails.
  template <MeshLike M>
    requires(mesh_dim<M> == Dim)
  void setup(const M& mesh, const ResolvedBoundary<Dim>& boundary) {
    const detail::Stopwatch watch;
    if (!std::isfinite(options_.length_exponent))
      throw InputError("SpringMover::setup: length_exponent must be finite (got " +
                       std::to_string(options_.length_exponent) + ")");
    const Mesh<Dim> copy = this->start_setup(mesh, boundary);
    const int c = boundary.has_sliding() ? Dim : 1;
    const auto triplets = detail::lineal_spring_triplets(copy, c, options_.length_exponent, "SpringMover::setup");
    SparseMatrix stiffness(copy.num_nodes() * c, copy.num_nodes() * c);
    stiffness.setFromTriplets(triplets.begin(), triplets.end());
    this->finish_setup(copy, boundary, std::move(stiffness), c, options_.solver, watch);
  }

 private:
  SpringOptions options_;
};

}  // namespace meshmotion

// The compiled library (target meshmotion::compiled, src/) holds these for Dim 2 and 3.
#ifdef MESHMOTION_COMPILED
namespace meshmotion {
extern template class SpringMover<2>;
extern template class SpringMover<3>;
// setup is a template over the mesh type: its Mesh<Dim> form, the one make_mover() uses, too.
extern template void SpringMover<2>::setup<Mesh<2>>(const Mesh<2>&, const ResolvedBoundary<2>&);
extern template void SpringMover<3>::setup<Mesh<3>>(const Mesh<3>&, const ResolvedBoundary<3>&);
}  // namespace meshmotion
#endif
