#pragma once
/// \file
/// ElasticityMover: linear elasticity mesh motion (thesis section 2.1.2, eqs. 2.3–2.6),
/// optionally stiffened by the element Jacobian (eqs. 2.7–2.8; Stein, Tezduyar & Benney 2003,
/// Hartmann & Leicht) and by the distance to the moving walls (the thesis's proposal).
///
/// ∇·σ = 0 with σ = 2μ ε + λ tr(ε) I, ε = ½(∇u + ∇uᵀ), u = u_b on Dirichlet boundaries and
/// u·n = 0 with free tangential motion on sliding ones, discretized by Galerkin FEM with the
/// mesh's own Lagrange elements (P1 and P2: tri3/6, quad4/8/9, tet4/10, hex8/20/27,
/// prism6/15/18, pyramid5/13/14, mixed meshes). Stiffening multiplies the integrand at each
/// quadrature point by
///     s = (J0 / J_κ)^χ · (d̄ / d_κ)^ψ,
/// where J_κ = |det J| · |κ̂| (the element's area/volume on affine elements), J0 a reference
/// (default: the mean cell measure), d_κ the distance from the cell's vertex centroid to the
/// nearest moving-wall node (k-d tree) and d̄ its mean over the cells. Constant factors (J0,
/// d̄, Young's modulus) scale K as a whole and do not change the displacements; they only
/// change the magnitude of the numbers the solver sees. χ = ψ = 0 is plain linear elasticity.
///
/// - Linear in the displacements; coupled Dim × N system, SPD after eliminating the Dirichlet
///   dofs (sliding nodes keep their tangent-plane unknowns, so they stay on their planes).
/// - Setup caches the factorized reduced system; cost: setup = assembly O(cells · nodes² ·
///   quadrature points) (OpenMP over cells) + one sparse factorization; move = one solve.
/// - Solvers: direct Cholesky (default, simplicial_ldlt), CG with Jacobi (as in the thesis,
///   table 4.2) or incomplete Cholesky; iterations and residual land in stats().

#include "meshmotion/movers/elasticity_options.hpp"
#include "meshmotion/core/error.hpp"
#include "meshmotion/core/mesh_like.hpp"
#include "meshmotion/core/types.hpp"
#include "meshmotion/movers/boundary.hpp"
#include "meshmotion/movers/detail/fem_assembly.hpp"
#include "meshmotion/movers/detail/linear_mechanics.hpp"
#include "meshmotion/solvers/detail/stopwatch.hpp"
#include "meshmotion/solvers/solver_options.hpp"
#include "meshmotion/spatial/kd_tree.hpp"

#include <atomic>
#include <concepts>
#include <cmath>
#include <string>
#include <vector>

namespace meshmotion {

/// The (stiffened) linear elasticity mover in Dim dimensions; models MeshMover.
template <int Dim>
class ElasticityMover : public detail::LinearMechanicsMover<Dim> {
 public:
  explicit ElasticityMover(ElasticityOptions options = {})
      : detail::LinearMechanicsMover<Dim>("ElasticityMover"), options_(options) {}

  [[nodiscard]] const ElasticityOptions& options() const noexcept { return options_; }
  /// J0 used by the last setup (0 when χ = 0).
  [[nodiscard]] double reference_jacobian() const noexcept { return j0_; }

  /// Assembles and factorizes the elasticity system of `mesh` (any MeshLike of dimension Dim)
  /// with the Dirichlet and sliding nodes of `boundary` (its displacements are not used).
  /// Throws InputError for E ≤ 0, ν outside (−1, 0.5), a negative or non-finite exponent, a
  /// degenerate cell when stiffening, a non-finite active_radius, a boundary without
  /// Dirichlet nodes for distance stiffening or active_radius, or bad mesh/boundary data;
  /// SolverError when the factorization fails.
  template <MeshLike M>
    requires(mesh_dim<M> == Dim)
  void setup(const M& mesh, const ResolvedBoundary<Dim>& boundary) {
    if constexpr (std::same_as<M, Mesh<Dim>>)
      setup_mesh(mesh, boundary);
    else
      setup_mesh(to_mesh(mesh), boundary);
  }
  /// setup() on the library's own mesh type.
  void setup_mesh(const Mesh<Dim>& mesh, const ResolvedBoundary<Dim>& boundary);

  /// The stiffness matrix (n_nodes · Dim square, node-major dofs) of `mesh` before boundary
  /// conditions, with Jacobian stiffening against `j0` (used when options.stiffening_exponent
  /// ≠ 0), a factor per cell (cell order; empty: 1) and, when `unknown` is not empty, only the
  /// cells touching a flagged node. What setup() assembles; the distributed mover assembles
  /// each rank's cells with it. Throws InputError for a degenerate cell under stiffening.
  [[nodiscard]] static SparseMatrix assemble_stiffness(const Mesh<Dim>& mesh, const ElasticityOptions& options, double j0,
                                                       const std::vector<double>& cell_factor = {},
                                                       const std::vector<bool>& unknown = {});

  /// Σ over the cells of their measure Σ_q w_q |det J_q| (J0's default is its mean).
  [[nodiscard]] static double total_cell_measure(const Mesh<Dim>& mesh) {
    double total = 0.0;
    detail::FemCoords<Dim> x;
    detail::ElementGradients<Dim> g;
    Eigen::Matrix<double, Dim, Dim> jacobian;
    for (const auto& block : mesh.cells) {
      const detail::QuadratureTable& table = detail::quadrature_table(block.type);
      for (Index e = 0; e < block.size(); ++e) {
        detail::gather_coords(mesh.points, block, e, x);
        for (int q = 0; q < table.size(); ++q)
          total += table.weights[static_cast<std::size_t>(q)] * std::abs(detail::element_geometry<Dim>(table, q, x, g, jacobian));
      }
    }
    return total;
  }

 private:
  /// Mean over the cells of their measure.
  [[nodiscard]] static double mean_cell_measure(const Mesh<Dim>& mesh) {
    const double mean = total_cell_measure(mesh) / static_cast<double>(mesh.num_cells());
    if (!(mean > 0.0)) throw InputError("ElasticityMover::setup: every cell has zero measure (expected a positive mean)");
    return mean;
  }

  /// Nodes within active_radius of a prescribed node (of a fixed one when none is
  /// prescribed), as flags; empty when active_radius ≤ 0.
  [[nodiscard]] std::vector<bool> free_nodes(const Mesh<Dim>& mesh, const ResolvedBoundary<Dim>& boundary) const {
    if (!(options_.active_radius > 0.0)) return {};
    const std::vector<double> distance = wall_distances(mesh, boundary, mesh.points);
    const std::vector<bool> in_cells = detail::cell_nodes(mesh);
    std::vector<bool> unknown(distance.size(), false);
    for (std::size_t v = 0; v < distance.size(); ++v) unknown[v] = in_cells[v] && distance[v] <= options_.active_radius;
    return unknown;
  }

  /// `boundary` with its sliding nodes outside the free region turned fixed (they have no
  /// stiffness left to slide with).
  [[nodiscard]] static ResolvedBoundary<Dim> hold_far_sliding_nodes(const ResolvedBoundary<Dim>& boundary,
                                                                    const std::vector<bool>& unknown) {
    ResolvedBoundary<Dim> out = boundary;
    for (Index k = 0; k < out.size(); ++k) {
      auto& kind = out.kinds[static_cast<std::size_t>(k)];
      if (kind == BoundaryKind::sliding && !unknown[static_cast<std::size_t>(out.nodes[static_cast<std::size_t>(k)])]) {
        kind = BoundaryKind::fixed;
        out.displacements.col(k).setZero();
      }
    }
    return out;
  }

  /// Distance from each column of `queries` to the nearest wall node: the prescribed nodes,
  /// or every fixed node when none is prescribed. Throws InputError when there are neither.
  [[nodiscard]] static std::vector<double> wall_distances(const Mesh<Dim>& mesh, const ResolvedBoundary<Dim>& boundary,
                                                          const Points<Dim>& queries) {
    std::vector<Index> walls;
    for (const BoundaryKind wanted : {BoundaryKind::prescribed, BoundaryKind::fixed}) {
      for (Index k = 0; k < boundary.size(); ++k)
        if (boundary.kinds[static_cast<std::size_t>(k)] == wanted) walls.push_back(boundary.nodes[static_cast<std::size_t>(k)]);
      if (!walls.empty()) break;
    }
    if (walls.empty())
      throw InputError("ElasticityMover::setup: distance stiffening and active_radius need prescribed or fixed boundary "
                       "nodes (got none)");
    Points<Dim> wall_points(Dim, static_cast<Index>(walls.size()));
    for (std::size_t k = 0; k < walls.size(); ++k) wall_points.col(static_cast<Index>(k)) = mesh.points.col(walls[k]);
    const KdTree<Dim> tree(wall_points);
    std::vector<double> distance(static_cast<std::size_t>(queries.cols()));
    for (Index i = 0; i < queries.cols(); ++i) distance[static_cast<std::size_t>(i)] = std::sqrt(tree.nearest(Vec<Dim>(queries.col(i))).second);
    return distance;
  }

  /// (d̄/d_κ)^ψ per cell (cell order), empty when ψ = 0, with d_κ the distance from the
  /// cell's vertex centroid to the nearest wall node (see wall_distances).
  [[nodiscard]] std::vector<double> distance_factors(const Mesh<Dim>& mesh, const ResolvedBoundary<Dim>& boundary) const {
    const double psi = options_.distance_exponent;
    if (psi == 0.0) return {};
    Points<Dim> centroids(Dim, mesh.num_cells());
    Index at = 0;
    for (const auto& block : mesh.cells) {
      const int nv = num_vertices(block.type);
      for (Index e = 0; e < block.size(); ++e, ++at) {
        const auto nodes = block.element(e);
        Vec<Dim> centroid = Vec<Dim>::Zero();
        for (int v = 0; v < nv; ++v) centroid += mesh.points.col(nodes[static_cast<std::size_t>(v)]);
        centroids.col(at) = centroid / static_cast<double>(nv);
      }
    }
    std::vector<double> distance = wall_distances(mesh, boundary, centroids);
    double mean = 0.0;
    for (const double d : distance) mean += d / static_cast<double>(distance.size());
    // A cell centroid never lies on a wall node unless the cell is degenerate; the floor
    // keeps such a cell finite.
    for (double& d : distance) d = std::pow(mean / std::max(d, 1e-12 * mean), psi);
    return distance;
  }

  ElasticityOptions options_;
  double j0_ = 0.0;
};

template <int Dim>
SparseMatrix ElasticityMover<Dim>::assemble_stiffness(const Mesh<Dim>& mesh, const ElasticityOptions& options, double j0,
                                                      const std::vector<double>& cell_factor,
                                                      const std::vector<bool>& unknown) {
  std::vector<Index> block_start{0};
  for (const auto& block : mesh.cells) block_start.push_back(block_start.back() + block.size());

  std::atomic<bool> degenerate{false};
  const detail::Lame lame = detail::lame_parameters(options.youngs_modulus, options.poisson_ratio, "ElasticityMover::setup");
  const double chi = options.stiffening_exponent;
  SparseMatrix stiffness = detail::assemble(mesh, mesh.num_nodes() * Dim, Dim * Dim, [&](Index b, Index e, auto& out) {
    const ElementBlock& block = mesh.cells[static_cast<std::size_t>(b)];
    const detail::QuadratureTable& table = detail::quadrature_table(block.type);
    const double measure = detail::reference_measure(block.type);
    const double factor = cell_factor.empty() ? 1.0 : cell_factor[static_cast<std::size_t>(block_start[static_cast<std::size_t>(b)] + e)];
    thread_local detail::FemCoords<Dim> x;
    detail::gather_coords(mesh.points, block, e, x);
    const int n = table.num_nodes;
    thread_local detail::ElementMatrix<Dim> k;
    k.setZero(n * Dim, n * Dim);
    thread_local detail::ElementGradients<Dim> g;
    Eigen::Matrix<double, Dim, Dim> jacobian;
    for (int q = 0; q < table.size(); ++q) {
      const double det = std::abs(detail::element_geometry<Dim>(table, q, x, g, jacobian));
      double scale = det * table.weights[static_cast<std::size_t>(q)] * factor;
      if (chi != 0.0) {
        if (!(det > 0.0)) {
          degenerate.store(true, std::memory_order_relaxed);
          return;
        }
        scale *= std::pow(j0 / (det * measure), chi);
      }
      detail::add_elastic_stiffness<Dim>(g, lame.lambda, lame.mu, scale, k);
    }
    detail::scatter_element_matrix<Dim>(block.element(e), k, out);
  }, unknown);
  if (degenerate)
    throw InputError("ElasticityMover::setup: a cell has a zero Jacobian determinant (degenerate cell), so its "
                     "stiffening factor (J0/J)^chi is infinite");
  return stiffness;
}

template <int Dim>
void ElasticityMover<Dim>::setup_mesh(const Mesh<Dim>& mesh, const ResolvedBoundary<Dim>& boundary) {
  const detail::Stopwatch watch;
  // E and ν are refused before the mesh is copied.
  static_cast<void>(detail::lame_parameters(options_.youngs_modulus, options_.poisson_ratio, "ElasticityMover::setup"));
  for (const double exponent : {options_.stiffening_exponent, options_.distance_exponent})
    if (!(exponent >= 0.0) || !std::isfinite(exponent))
      throw InputError("ElasticityMover::setup: stiffening exponents must be finite and >= 0 (got " +
                       std::to_string(exponent) + ")");
  if (!std::isfinite(options_.reference_jacobian) || !std::isfinite(options_.active_radius))
    throw InputError("ElasticityMover::setup: reference_jacobian and active_radius must be finite");
  const Mesh<Dim> copy = this->start_setup(mesh, boundary);
  const std::vector<bool> unknown = free_nodes(copy, boundary);
  ResolvedBoundary<Dim> limited;
  if (!unknown.empty()) limited = hold_far_sliding_nodes(boundary, unknown);
  const ResolvedBoundary<Dim>& used = unknown.empty() ? boundary : limited;
  j0_ = options_.stiffening_exponent == 0.0 ? 0.0 : options_.reference_jacobian > 0.0 ? options_.reference_jacobian : mean_cell_measure(copy);
  const std::vector<double> wall_factor = distance_factors(copy, boundary);
  SparseMatrix stiffness = assemble_stiffness(copy, options_, j0_, wall_factor, unknown);
  SolverOptions solver = options_.solver;
  solver.diagonal_scaling = true;
  this->finish_setup(copy, used, std::move(stiffness), Dim, solver, watch, unknown.empty() ? nullptr : &unknown);
}

}  // namespace meshmotion

// The compiled library (target meshmotion::compiled, src/) holds these for Dim 2 and 3.
#ifdef MESHMOTION_COMPILED
namespace meshmotion {
extern template class ElasticityMover<2>;
extern template class ElasticityMover<3>;
// setup is a template over the mesh type: its Mesh<Dim> form, the one make_mover() uses, too.
extern template void ElasticityMover<2>::setup<Mesh<2>>(const Mesh<2>&, const ResolvedBoundary<2>&);
extern template void ElasticityMover<3>::setup<Mesh<3>>(const Mesh<3>&, const ResolvedBoundary<3>&);
}  // namespace meshmotion
#endif
