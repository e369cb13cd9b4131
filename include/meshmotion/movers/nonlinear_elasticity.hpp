#pragma once
/// \file
/// NonlinearElasticityMover: compressible neo-Hookean mesh motion (thesis eq. 2.9; Persson &
/// Peraire, AIAA 2009-949). The mesh is a hyperelastic solid with stored energy
///     W(F) = μ/2 (tr FᵀF − d) − μ ln J + λ/2 (ln J)²,   J = det F,  F = I + ∂u/∂X,
/// whose first Piola–Kirchhoff stress is P = μ(F − F⁻ᵀ) + λ ln J F⁻ᵀ (eq. 2.9). W → ∞ as
/// J → 0⁺, so an iterate that keeps J > 0 at every quadrature point keeps every element valid.
///
/// - Solver: Newton's method with the boundary displacement applied in `load_steps` equal
///   increments; each Newton step carries the remaining boundary increment, and a
///   backtracking line search halves the step (boundary increment included) until no
///   quadrature point has det F ≤ 0 and, once the boundary is in place, the energy decreases.
///   The tangent is solved by a sparse direct factorization (symmetric; LDLᵀ by default).
/// - Not linear in the displacements; for small ones it agrees with linear elasticity (the
///   tangent at u = 0 is the linear-elastic stiffness with the same λ, μ).
/// - Setup caches the reference mesh, the unknown numbering (Dirichlet elimination, sliding
///   tangent planes), the factorized reference (linear-elastic) stiffness used as a fallback
///   descent direction when the Newton direction fails the line search, and the symbolic
///   analysis of the tangent; every move starts from the
///   reference configuration and re-assembles and factorizes the tangent once per Newton
///   iteration (cost per move: iterations × (assembly + factorization)), so it is a robust
///   reference for large deformations and curving rather than a per-time-step mover.
/// - stats().iterations counts Newton iterations of the last move, factorizations the
///   tangent factorizations since setup.

#include "meshmotion/movers/nonlinear_elasticity_options.hpp"
#include "meshmotion/core/error.hpp"
#include "meshmotion/core/mesh_like.hpp"
#include "meshmotion/core/types.hpp"
#include "meshmotion/movers/boundary.hpp"
#include "meshmotion/movers/detail/constrained_system.hpp"
#include "meshmotion/movers/detail/fem_assembly.hpp"
#include "meshmotion/movers/detail/linear_mechanics.hpp"
#include "meshmotion/movers/detail/mover_support.hpp"
#include "meshmotion/movers/mover.hpp"
#include "meshmotion/solvers/detail/stopwatch.hpp"
#include "meshmotion/solvers/solver_options.hpp"

#include <atomic>
#include <cmath>
#include <string>
#include <vector>

namespace meshmotion {

/// The neo-Hookean mover in Dim dimensions; models MeshMover.
template <int Dim>
class NonlinearElasticityMover : public detail::MoveFromMoveInto<NonlinearElasticityMover<Dim>, Dim> {
 public:
  using detail::MoveFromMoveInto<NonlinearElasticityMover<Dim>, Dim>::move_into;  // into the caller's storage
  static constexpr int dim = Dim;

  explicit NonlinearElasticityMover(NonlinearElasticityOptions options = {}) : options_(options) {}

  [[nodiscard]] const NonlinearElasticityOptions& options() const noexcept { return options_; }
  [[nodiscard]] const MoverStats& stats() const noexcept { return stats_; }

  /// Copies `mesh` (any MeshLike of dimension Dim) and numbers the unknowns for `boundary`.
  /// Throws InputError for E ≤ 0, ν outside (−1, 0.5), load_steps or newton_iterations
  /// < 1, a non-positive tolerance, or bad mesh/boundary data.
  template <MeshLike M>
    requires(mesh_dim<M> == Dim)
  void setup(const M& mesh, const ResolvedBoundary<Dim>& boundary) {
    const detail::Stopwatch watch;
    ready_ = false;
    lame_ = detail::lame_parameters(options_.youngs_modulus, options_.poisson_ratio, "NonlinearElasticityMover::setup");
    if (options_.load_steps < 1 || options_.newton_iterations < 1)
      throw InputError("NonlinearElasticityMover::setup: load_steps and newton_iterations must be >= 1 (got " +
                       std::to_string(options_.load_steps) + " and " + std::to_string(options_.newton_iterations) + ")");
    if (!(options_.newton_tolerance > 0.0) || !(options_.min_step > 0.0 && options_.min_step < 1.0))
      throw InputError("NonlinearElasticityMover::setup: tolerance must be > 0 and min_step in (0, 1)");
    mesh_ = detail::checked_copy(mesh, boundary, "NonlinearElasticityMover");
    boundary_nodes_ = boundary.nodes;
    kinds_ = boundary.kinds;
    system_.build(Dim, detail::cell_nodes(mesh_), boundary, options_.solver);
    reference_.build(Dim, detail::cell_nodes(mesh_), boundary, options_.solver);
    {
      SparseMatrix stiffness;
      Eigen::MatrixXd unused(mesh_.num_nodes() * Dim, 1);
      evaluate(Points<Dim>::Zero(Dim, mesh_.num_nodes()), &unused, &stiffness);
      reference_.factorize(stiffness);
    }
    diameter_ = (mesh_.points.rowwise().maxCoeff() - mesh_.points.rowwise().minCoeff()).norm();
    stats_ = MoverStats{};
    stats_.boundary_nodes = boundary.size();
    stats_.evaluated_nodes = mesh_.num_nodes() - boundary.size();
    ready_ = true;
    stats_.setup_seconds = watch.seconds();
  }

  /// Displacement of every node (Dim × n_nodes) for boundary displacements `d` (Dim ×
  /// boundary.size()); every quadrature point keeps det F > 0. Throws InputError for a wrong
  /// shape, non-finite values or a missing setup; SolverError when Newton does not converge
  /// or the line search cannot keep the elements valid (try more load_steps).
  /// move() (inherited) returns the same; move_into writes into `out`, resized only when its
  /// shape differs.
  void move_into(PointsView<Dim> d, Points<Dim>& out) {
    detail::timed_move<Dim>("NonlinearElasticityMover::move", ready_, d, boundary_nodes_, stats_, [&] {
      detail::add_time(stats_.solve_seconds, [&] { newton(d, out); });
    });
  }

 private:
  struct Evaluation {
    bool valid = true;
    double energy = 0.0;
  };

  /// The load-stepped Newton solve of move_into (inputs checked).
  void newton(PointsView<Dim> d, Points<Dim>& out) {
    const Index n = mesh_.num_nodes();
    out.setZero(Dim, n);
    Points<Dim> applied = Points<Dim>::Zero(Dim, d.cols());
    Points<Dim> step, trial;
    Eigen::MatrixXd force(n * Dim, 1);
    Index iterations = 0;
    double energy = evaluate(out, nullptr, nullptr).energy;
    for (int s = 1; s <= options_.load_steps; ++s) {
      const Points<Dim> target = d * (static_cast<double>(s) / options_.load_steps);
      bool converged = false;
      for (int it = 0; it < options_.newton_iterations && !converged; ++it, ++iterations) {
        Points<Dim> increment = target - applied;
        for (Index k = 0; k < increment.cols(); ++k)
          if (kinds_[static_cast<std::size_t>(k)] == BoundaryKind::sliding) increment.col(k).setZero();
        const bool boundary_done = increment.cwiseAbs().maxCoeff() == 0.0;
        SparseMatrix tangent;
        evaluate(out, &force, &tangent);
        system_.factorize(tangent);
        system_.solve(increment, step, &force);
        ++stats_.factorizations;
        double alpha = line_search(out, step, boundary_done, energy, trial);
        if (alpha < options_.min_step) {
          // The tangent can be indefinite far from the reference; the reference (linear
          // elastic, SPD) stiffness always gives a descent direction for the energy.
          reference_.solve(increment, step, &force);
          alpha = line_search(out, step, boundary_done, energy, trial);
        }
        if (alpha < options_.min_step)
          throw SolverError("NonlinearElasticityMover::move: the line search found no step keeping every element valid "
                            "(load step " + std::to_string(s) + " of " + std::to_string(options_.load_steps) +
                            "; try more load_steps)");
        out = trial;
        applied += alpha * increment;
        if (alpha == 1.0) applied = target;  // exact boundary values once the increment is complete
        const double update = alpha * step.cwiseAbs().maxCoeff();
        converged = boundary_done && update <= options_.newton_tolerance * diameter_;
      }
      if (!converged)
        throw SolverError("NonlinearElasticityMover::move: Newton did not converge in " +
                          std::to_string(options_.newton_iterations) + " iterations (load step " + std::to_string(s) + ")");
    }
    // Boundary nodes get their targets exactly (sliding ones keep their computed position).
    for (Index k = 0; k < d.cols(); ++k)
      if (kinds_[static_cast<std::size_t>(k)] != BoundaryKind::sliding) out.col(boundary_nodes_[static_cast<std::size_t>(k)]) = d.col(k);
    stats_.iterations = iterations;
    stats_.residual = 0.0;
  }

  /// Backtracking from u along `step`: the largest α = 2^−k ≥ min_step with every element
  /// valid and, when the boundary is in place, no energy increase; updates `energy` and
  /// `trial` = u + α step. Returns α, or 0 when none is found.
  double line_search(const Points<Dim>& u, const Points<Dim>& step, bool boundary_done, double& energy,
                     Points<Dim>& trial) const {
    for (double alpha = 1.0; alpha >= options_.min_step; alpha *= 0.5) {
      trial = u + alpha * step;
      const Evaluation e = evaluate(trial, nullptr, nullptr);
      if (e.valid && (!boundary_done || e.energy <= energy + 1e-12 * std::abs(energy))) {
        energy = e.energy;
        return alpha;
      }
    }
    return 0.0;
  }

  /// Energy of displacement u; with `force`, also −(internal force) (n·Dim × 1) and the
  /// tangent stiffness (n·Dim square). Invalid (det F ≤ 0 somewhere) gives valid = false.
  Evaluation evaluate(const Points<Dim>& u, Eigen::MatrixXd* force, SparseMatrix* tangent) const {
    const double lambda = lame_.lambda, mu = lame_.mu;
    Evaluation result;
    if (force != nullptr) force->setZero();
    std::atomic<bool> valid{true};
    // Energy and internal force: sequential (they add into shared nodes).
    for (const auto& block : mesh_.cells) {
      const detail::QuadratureTable& table = detail::quadrature_table(block.type);
      const int nn = table.num_nodes;
      detail::FemCoords<Dim> x, ue;
      detail::ElementGradients<Dim> g;
      Eigen::Matrix<double, Dim, Dim> jacobian;
      for (Index e = 0; e < block.size(); ++e) {
        detail::gather_coords(mesh_.points, block, e, x);
        detail::gather_coords(u, block, e, ue);
        const auto nodes = block.element(e);
        for (int q = 0; q < table.size(); ++q) {
          const double c = std::abs(detail::element_geometry<Dim>(table, q, x, g, jacobian)) * table.weights[static_cast<std::size_t>(q)];
          const Eigen::Matrix<double, Dim, Dim> f = Eigen::Matrix<double, Dim, Dim>::Identity() + ue * g;
          const double j = f.determinant();
          if (!(j > 0.0)) {
            result.valid = false;
            return result;
          }
          const double log_j = std::log(j);
          result.energy += c * (0.5 * mu * ((f.transpose() * f).trace() - Dim) - mu * log_j + 0.5 * lambda * log_j * log_j);
          if (force == nullptr) continue;
          const Eigen::Matrix<double, Dim, Dim> f_inv_t = f.inverse().transpose();
          const Eigen::Matrix<double, Dim, Dim> piola = mu * (f - f_inv_t) + lambda * log_j * f_inv_t;
          for (int a = 0; a < nn; ++a) {
            const Vec<Dim> r = c * piola * g.row(a).transpose();
            for (int i = 0; i < Dim; ++i) (*force)(nodes[static_cast<std::size_t>(a)] * Dim + i, 0) -= r(i);
          }
        }
      }
    }
    if (tangent == nullptr) return result;
    *tangent = detail::assemble(mesh_, mesh_.num_nodes() * Dim, Dim * Dim, [&](Index b, Index e, auto& out) {
      const ElementBlock& block = mesh_.cells[static_cast<std::size_t>(b)];
      const detail::QuadratureTable& table = detail::quadrature_table(block.type);
      const int nn = table.num_nodes;
      thread_local detail::FemCoords<Dim> x, ue;
      thread_local detail::ElementGradients<Dim> g, m;
      Eigen::Matrix<double, Dim, Dim> jacobian;
      detail::gather_coords(mesh_.points, block, e, x);
      detail::gather_coords(u, block, e, ue);
      thread_local detail::ElementMatrix<Dim> k;
      k.setZero(nn * Dim, nn * Dim);
      for (int q = 0; q < table.size(); ++q) {
        const double c = std::abs(detail::element_geometry<Dim>(table, q, x, g, jacobian)) * table.weights[static_cast<std::size_t>(q)];
        const Eigen::Matrix<double, Dim, Dim> f = Eigen::Matrix<double, Dim, Dim>::Identity() + ue * g;
        const double j = f.determinant();
        if (!(j > 0.0)) {
          valid.store(false, std::memory_order_relaxed);
          return;
        }
        // ∂P_iJ/∂F_kL = μ δ_ik δ_JL + (μ − λ ln J) F⁻¹_Jk F⁻¹_Li + λ F⁻¹_Ji F⁻¹_Lk; with
        // m_a = F⁻ᵀ G_a the (a,i),(b,k) entry is μ δ_ik G_a·G_b + (μ − λ ln J) m_ak m_bi + λ m_ai m_bk.
        m.resize(nn, Dim);
        m.noalias() = g * f.inverse();
        const double shear = mu - lambda * std::log(j);
        for (int a = 0; a < nn; ++a)
          for (int bb = 0; bb < nn; ++bb) {
            const double dot = mu * g.row(a).dot(g.row(bb));
            for (int i = 0; i < Dim; ++i)
              for (int kk = 0; kk < Dim; ++kk)
                k(a * Dim + i, bb * Dim + kk) +=
                    c * ((i == kk ? dot : 0.0) + shear * m(a, kk) * m(bb, i) + lambda * m(a, i) * m(bb, kk));
          }
      }
      detail::scatter_element_matrix<Dim>(block.element(e), k, out);
    });
    result.valid = result.valid && valid.load();
    return result;
  }

  NonlinearElasticityOptions options_;
  MoverStats stats_;
  Mesh<Dim> mesh_;
  std::vector<Index> boundary_nodes_;
  std::vector<BoundaryKind> kinds_;
  detail::ConstrainedSystem<Dim> system_;
  detail::ConstrainedSystem<Dim> reference_;  ///< factorized linear-elastic stiffness (fallback direction)
  detail::Lame lame_{0.0, 0.0};
  double diameter_ = 0.0;
  bool ready_ = false;
};

}  // namespace meshmotion

// The compiled library (target meshmotion::compiled, src/) holds these for Dim 2 and 3.
#ifdef MESHMOTION_COMPILED
namespace meshmotion {
extern template class NonlinearElasticityMover<2>;
extern template class NonlinearElasticityMover<3>;
// setup is a template over the mesh type: its Mesh<Dim> form, the one make_mover() uses, too.
extern template void NonlinearElasticityMover<2>::setup<Mesh<2>>(const Mesh<2>&, const ResolvedBoundary<2>&);
extern template void NonlinearElasticityMover<3>::setup<Mesh<3>>(const Mesh<3>&, const ResolvedBoundary<3>&);
}  // namespace meshmotion
#endif
