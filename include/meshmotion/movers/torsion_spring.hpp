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
/// - Cells: tri3 and quad4 (corners of the element, as in Farhat et al.), tet4 following Degand
///   & Farhat (Computers & Structures 80, 2002): torsional springs at the 12 face corners, plus
///   their vertex–facet springs. Those live on the triangles joining a vertex i, its projection
///   P on the opposite face and the foot Q of P on an edge jk of that face; the triangle lies in
///   the plane normal to jk, so its angle at Q is the tetrahedron's dihedral angle φ at jk,
///   which goes to 0 (or π) when i reaches the plane of the face — the collapse face-corner
///   springs cannot see. Each edge carries two such triangles (one per opposite vertex); we
///   give the edge a spring C = 2/sin²φ on the dihedral angle itself, linearized with its exact
///   gradient (well defined even where P = Q, i.e. φ = 90°, where the triangle degenerates).
///   The springs at the triangles' other corners (the right angle at P, 90° − φ at i) are left
///   out: the right angle is not resolved by the frozen-interpolation construction and the
///   angle at i vanishes at φ = 90°, where a stiffness 1/sin² of it would be infinite.
/// - Lineal springs: Farhat et al.'s coupled (truss) form by default, k = 1/length acting along
///   the edge only (no energy in a rigid rotation); `coupled_lineal = false` gives Batina's
///   uncoupled form (the same spring in each direction).
/// - Robust for moderate motions; for very large ones (thesis fig. 4.2, 60° flap rotation) it
///   still inverts cells.

#include "meshmotion/movers/torsion_spring_options.hpp"
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

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <span>
#include <string>
#include <vector>

namespace meshmotion {

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

/// Tetrahedron edges (j, k) with their two opposite vertices (i, l): {j, k, i, l}.
inline constexpr std::array<std::array<int, 4>, 6> tet_dihedrals{
    {{0, 1, 2, 3}, {0, 2, 1, 3}, {0, 3, 1, 2}, {1, 2, 0, 3}, {1, 3, 0, 2}, {2, 3, 0, 1}}};

/// The angle θ between nonzero vectors u and w: returns sin θ (0 when degenerate) and sets
/// du = ∂θ/∂u, dw = ∂θ/∂w.
template <int Dim>
double angle_gradient(const Vec<Dim>& u, const Vec<Dim>& w, Vec<Dim>& du, Vec<Dim>& dw) {
  const double lu = u.norm(), lw = w.norm();
  if (!(lu > 0.0 && lw > 0.0)) return 0.0;
  const double cosine = std::clamp(u.dot(w) / (lu * lw), -1.0, 1.0);
  const double sine = std::sqrt(1.0 - cosine * cosine);
  if (!(sine > 1e-14)) return 0.0;
  du = -(w / lw - cosine * u / lu) / (lu * sine);
  dw = -(u / lu - cosine * w / lw) / (lw * sine);
  return sine;
}

/// Appends C g gᵀ over the Dim dofs of `nodes` (node-major) as triplets.
template <int Dim, std::size_t N, class Out>
void add_angle_spring(const std::array<Index, N>& nodes, const std::array<Vec<Dim>, N>& g, double c, Out& out) {
  for (std::size_t p = 0; p < N; ++p)
    for (std::size_t q = 0; q < N; ++q)
      for (int i = 0; i < Dim; ++i)
        for (int j = 0; j < Dim; ++j)
          out.emplace_back(static_cast<int>(nodes[p] * Dim + i), static_cast<int>(nodes[q] * Dim + j), c * g[p](i) * g[q](j));
}

/// The torsional spring at the corner (vertex, b, c) of `ids`: C = weight / sin²θ on the
/// angle θ at the vertex. Returns false for a degenerate corner (θ = 0 or π).
template <int Dim, class Out>
bool add_corner_spring(const Points<Dim>& x, const std::array<Index, 3>& ids, double weight, Out& out) {
  std::array<Vec<Dim>, 3> g;
  const double sine = angle_gradient<Dim>(x.col(ids[1]) - x.col(ids[0]), x.col(ids[2]) - x.col(ids[0]), g[1], g[2]);
  if (sine == 0.0) return false;
  g[0] = -(g[1] + g[2]);
  add_angle_spring<Dim>(ids, g, weight / (sine * sine), out);
  return true;
}

/// The vertex–facet spring of edge (j, k) of a tetrahedron with opposite vertices i and l
/// (ids = {j, k, i, l}): C = 2 weight / sin²φ on the dihedral angle φ at the edge, between
/// the components u, w of x_i − x_j and x_l − x_j normal to the edge. With s_i, s_l the edge
/// parameters of the feet of i and l, rotation and translation invariance give ∂φ/∂x_j =
/// −(1 − s_i) ∂φ/∂u − (1 − s_l) ∂φ/∂w and ∂φ/∂x_k = −s_i ∂φ/∂u − s_l ∂φ/∂w. Returns false
/// for a flat tetrahedron (φ = 0 or π).
template <class Out>
bool add_dihedral_spring(const Points<3>& x, const std::array<Index, 4>& ids, double weight, Out& out) {
  const Vec<3> e = x.col(ids[1]) - x.col(ids[0]);
  const double e2 = e.squaredNorm();
  if (!(e2 > 0.0)) return false;
  const Vec<3> ri = x.col(ids[2]) - x.col(ids[0]), rl = x.col(ids[3]) - x.col(ids[0]);
  const double si = ri.dot(e) / e2, sl = rl.dot(e) / e2;
  std::array<Vec<3>, 4> g;
  const double sine = angle_gradient<3>(Vec<3>(ri - si * e), Vec<3>(rl - sl * e), g[2], g[3]);
  if (sine == 0.0) return false;
  g[0] = -(1.0 - si) * g[2] - (1.0 - sl) * g[3];
  g[1] = -si * g[2] - sl * g[3];
  add_angle_spring<3>(ids, g, 2.0 * weight / (sine * sine), out);
  return true;
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
    // Lineal springs, once per edge.
    const auto lineal = detail::spring_triplets(copy, Dim, 1.0, options_.coupled_lineal, "TorsionSpringMover::setup");
    SparseMatrix stiffness(size, size);
    stiffness.setFromTriplets(lineal.begin(), lineal.end());
    // Torsional springs per cell corner (and tetrahedron edge); a degenerate corner is
    // reported after the loop.
    std::atomic<bool> degenerate{false};
    const double weight = options_.torsion_weight;
    const bool dihedrals = options_.vertex_facet_springs;
    SparseMatrix torsion = detail::assemble(copy, size, 4 * Dim * Dim, [&](Index b, Index e, auto& out) {
      const ElementBlock& block = copy.cells[static_cast<std::size_t>(b)];
      const auto nodes = block.element(e);
      const auto node = [&](int local) { return nodes[static_cast<std::size_t>(local)]; };
      bool ok = true;
      for (const auto& c : detail::torsion_corners(block.type))
        ok = detail::add_corner_spring<Dim>(copy.points, {node(c[0]), node(c[1]), node(c[2])}, weight, out) && ok;
      if constexpr (Dim == 3)
        if (dihedrals && block.type == ElementType::tet4)
          for (const auto& d : detail::tet_dihedrals)
            ok = detail::add_dihedral_spring(copy.points, {node(d[0]), node(d[1]), node(d[2]), node(d[3])}, weight, out) && ok;
      if (!ok) degenerate.store(true, std::memory_order_relaxed);
    });
    if (degenerate)
      throw InputError("TorsionSpringMover::setup: a cell has a corner or dihedral angle of 0 or 180 degrees (degenerate cell)");
    this->finish_setup(copy, boundary, SparseMatrix(stiffness + torsion), Dim, options_.solver, watch);
  }

 private:
  TorsionSpringOptions options_;
};

}  // namespace meshmotion

// The compiled library (target meshmotion::compiled, src/) holds these for Dim 2 and 3.
#ifdef MESHMOTION_COMPILED
namespace meshmotion {
extern template class TorsionSpringMover<2>;
extern template class TorsionSpringMover<3>;
// setup is a template over the mesh type: its Mesh<Dim> form, the one make_mover() uses, too.
extern template void TorsionSpringMover<2>::setup<Mesh<2>>(const Mesh<2>&, const ResolvedBoundary<2>&);
extern template void TorsionSpringMover<3>::setup<Mesh<3>>(const Mesh<3>&, const ResolvedBoundary<3>&);
}  // namespace meshmotion
#endif
