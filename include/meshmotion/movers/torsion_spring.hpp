#pragma once
/// \file
/// TorsionSpringMover: the torsional spring analogy of Farhat, Degand, Koobus and Lesoinne
/// (CMAME 163, 1998), thesis section 2.1.1: lineal springs (stiffness 1/length, eq. 2.2) plus
/// a torsional spring at every corner of every element resisting the change of the corner
/// angle θ, with stiffness C = 1/sin²θ (= l_ij² l_ik² / 4A², Farhat et al. eq. 13). The
/// torsional energy ½ C (δθ)² is linearized about the reference: δθ = gᵀ δx with g = ∂θ/∂x
/// over the corner's three nodes, contributing C g gᵀ to a coupled Dim × N system.
///
/// - Linear in the displacements; coupled (Dim dofs per node). Setup assembles and factorizes
///   once (cost: assembly O(cells) + one sparse factorization of size Dim·N); move = one solve.
/// - Cells: tri3 and quad4 (corners of the element, as in Farhat et al.), tet4: torsional
///   springs at the 12 face corners of each tetrahedron. This 3D variant is an approximation
///   of Degand & Farhat (Computers & Structures 80, 2002), who also attach springs to the
///   triangles joining each vertex to its projection on the opposite face to stop a vertex
///   crossing that face; face-corner springs alone do not see that collapse.
/// - The lineal part is Batina's (the same spring in each direction); Farhat et al. use
///   coupled (truss) lineal springs — the torsional part dominates near degeneracy either way.
/// - Robust for moderate motions; for very large ones (thesis fig. 4.2, 60° flap rotation) it
///   still inverts cells.

#include "meshmotion/core/element.hpp"
#include "meshmotion/core/error.hpp"
#include "meshmotion/core/mesh_like.hpp"
#include "meshmotion/core/types.hpp"
#include "meshmotion/movers/boundary.hpp"
#include "meshmotion/movers/detail/fem_assembly.hpp"
#include "meshmotion/movers/detail/linear_mechanics.hpp"
#include "meshmotion/movers/detail/spring_network.hpp"
#include "meshmotion/solvers/detail/stopwatch.hpp"
#include "meshmotion/solvers/solver_options.hpp"

#include <array>
#include <atomic>
#include <cmath>
#include <span>
#include <string>
#include <vector>

namespace meshmotion {

/// Options of TorsionSpringMover.
struct TorsionSpringOptions {
  /// Multiplies every torsional stiffness (0 gives plain coupled lineal springs); ≥ 0.
  double torsion_weight = 1.0;
  /// Solver of the (SPD) coupled system.
  SolverOptions solver = {};
};

namespace detail {

/// Corners (vertex, neighbour, neighbour) of a cell type carrying torsional springs.
[[nodiscard]] inline std::span<const std::array<int, 3>> torsion_corners(ElementType type) {
  static constexpr std::array<std::array<int, 3>, 3> tri{{{0, 1, 2}, {1, 2, 0}, {2, 0, 1}}};
  static constexpr std::array<std::array<int, 3>, 4> quad{{{0, 1, 3}, {1, 2, 0}, {2, 3, 1}, {3, 0, 2}}};
  static constexpr std::array<std::array<int, 3>, 12> tet{{{0, 1, 2}, {1, 2, 0}, {2, 0, 1},
                                                           {0, 1, 3}, {1, 3, 0}, {3, 0, 1},
                                                           {0, 2, 3}, {2, 3, 0}, {3, 0, 2},
                                                           {1, 2, 3}, {2, 3, 1}, {3, 1, 2}}};
  switch (type) {
    case ElementType::tri3: return tri;
    case ElementType::quad4: return quad;
    case ElementType::tet4: return tet;
    default: return {};
  }
}

}  // namespace detail

/// The torsional spring mover in Dim dimensions; models MeshMover.
template <int Dim>
class TorsionSpringMover : public detail::LinearMechanicsMover<Dim> {
 public:
  explicit TorsionSpringMover(TorsionSpringOptions options = {})
      : detail::LinearMechanicsMover<Dim>("TorsionSpringMover"), options_(options) {}

  [[nodiscard]] const TorsionSpringOptions& options() const noexcept { return options_; }

  /// Assembles and factorizes the coupled lineal + torsional system of `mesh` (any MeshLike
  /// of dimension Dim with tri3/quad4 cells in 2D, tet4 in 3D). Throws InputError for other
  /// cell types, a negative or non-finite torsion_weight, a degenerate corner (angle 0 or π)
  /// or bad boundary data; SolverError when the factorization fails.
  template <MeshLike M>
    requires(mesh_dim<M> == Dim)
  void setup(const M& mesh, const ResolvedBoundary<Dim>& boundary) {
    const detail::Stopwatch watch;
    if (!(options_.torsion_weight >= 0.0) || !std::isfinite(options_.torsion_weight))
      throw InputError("TorsionSpringMover::setup: torsion_weight must be finite and >= 0 (got " +
                       std::to_string(options_.torsion_weight) + ")");
    const Mesh<Dim> copy = this->start_setup(mesh, boundary);
    for (const auto& block : copy.cells)
      if (detail::torsion_corners(block.type).empty())
        throw InputError("TorsionSpringMover::setup: " + std::string(name(block.type)) +
                         " cells are not supported (expected tri3 or quad4 in 2D, tet4 in 3D)");
    const Index size = copy.num_nodes() * Dim;
    // Lineal springs, once per edge (Batina's, the same in each direction).
    const auto lineal = detail::lineal_spring_triplets(copy, Dim, 1.0, "TorsionSpringMover::setup");
    SparseMatrix stiffness(size, size);
    stiffness.setFromTriplets(lineal.begin(), lineal.end());
    // Torsional springs per cell corner; a degenerate corner is reported after the loop.
    std::atomic<bool> degenerate{false};
    const double weight = options_.torsion_weight;
    SparseMatrix torsion = detail::assemble(copy, size, 4 * Dim * Dim, [&](Index b, Index e, auto& out) {
      const ElementBlock& block = copy.cells[static_cast<std::size_t>(b)];
      const auto nodes = block.element(e);
      for (const auto& corner : detail::torsion_corners(block.type)) {
        std::array<Index, 3> ids{};
        for (int k = 0; k < 3; ++k) ids[static_cast<std::size_t>(k)] = nodes[static_cast<std::size_t>(corner[static_cast<std::size_t>(k)])];
        const Vec<Dim> a = copy.points.col(ids[1]) - copy.points.col(ids[0]);
        const Vec<Dim> c = copy.points.col(ids[2]) - copy.points.col(ids[0]);
        const double la = a.norm(), lc = c.norm();
        const double cosine = la > 0.0 && lc > 0.0 ? a.dot(c) / (la * lc) : 1.0;
        const double sine = std::sqrt(std::max(0.0, 1.0 - cosine * cosine));
        if (!(sine > 1e-14)) {
          degenerate.store(true, std::memory_order_relaxed);
          continue;
        }
        // ∂θ/∂a = −(ĉ − cosθ â)/(|a| sinθ), ∂θ/∂c likewise, ∂θ/∂x_vertex = −(∂θ/∂a + ∂θ/∂c).
        std::array<Vec<Dim>, 3> g;
        g[1] = -(c / lc - cosine * a / la) / (la * sine);
        g[2] = -(a / la - cosine * c / lc) / (lc * sine);
        g[0] = -(g[1] + g[2]);
        const double stiffness_c = weight / (sine * sine);
        for (int p = 0; p < 3; ++p)
          for (int q = 0; q < 3; ++q)
            for (int i = 0; i < Dim; ++i)
              for (int j = 0; j < Dim; ++j)
                out.emplace_back(static_cast<int>(ids[static_cast<std::size_t>(p)] * Dim + i),
                                 static_cast<int>(ids[static_cast<std::size_t>(q)] * Dim + j),
                                 stiffness_c * g[static_cast<std::size_t>(p)](i) * g[static_cast<std::size_t>(q)](j));
      }
    });
    if (degenerate) throw InputError("TorsionSpringMover::setup: a cell has a corner of angle 0 or 180 degrees (degenerate cell)");
    this->finish_setup(copy, boundary, SparseMatrix(stiffness + torsion), Dim, options_.solver, watch);
  }

 private:
  TorsionSpringOptions options_;
};

}  // namespace meshmotion
