#pragma once
/// \file
/// ConstrainedSystem: the symmetric stiffness system K u = 0 of the mechanics movers with
/// Dirichlet nodes (prescribed and fixed) eliminated and sliding nodes reduced to their
/// tangent unknowns (Dim − 1 on a plane, 1 on a line), factorized once; each solve maps boundary displacements to the
/// displacement of every node.
///
/// With u = P x + S d (P: free unknowns → dofs, sliding nodes through an orthonormal basis of
/// their plane or line, ResolvedBoundary::sliding_basis; S: Dirichlet values → dofs) the reduced system is (Pᵀ K P) x = −(Pᵀ K S) d,
/// so sliding nodes stay exactly on their planes (and lines). K has `components` dofs per node: 1 for
/// the uncoupled lineal-spring Laplacian (solved with Dim right-hand sides), Dim for
/// coupled systems (node-major: node * Dim + axis).

#include "meshmotion/core/error.hpp"
#include "meshmotion/core/types.hpp"
#include "meshmotion/movers/boundary.hpp"
#include "meshmotion/movers/detail/mover_support.hpp"
#include "meshmotion/movers/mover.hpp"
#include "meshmotion/solvers/linear_solver.hpp"

#include <Eigen/SparseCore>

#include <string>
#include <vector>

namespace meshmotion::detail {

template <int Dim>
class ConstrainedSystem {
 public:
  /// Numbers the unknowns: `active[i]` is false for nodes that no element touches (they do
  /// not move); Dirichlet nodes of `b` are eliminated, sliding ones (components == Dim only)
  /// keep their tangent unknowns. Creates the solver.
  void build(int components, const std::vector<bool>& active, const ResolvedBoundary<Dim>& b,
             const SolverOptions& solver_options) {
    components_ = components;
    const auto n = static_cast<Index>(active.size());
    boundary_nodes_ = b.nodes;
    kinds_ = b.kinds;
    std::vector<Index> boundary_index(static_cast<std::size_t>(n), -1);
    for (Index k = 0; k < b.size(); ++k) boundary_index[static_cast<std::size_t>(b.nodes[static_cast<std::size_t>(k)])] = k;
    using Triplet = Eigen::Triplet<double, int>;
    std::vector<Triplet> p_entries, s_entries;
    Index reduced = 0;
    const Index c = components;
    for (Index i = 0; i < n; ++i) {
      const Index k = boundary_index[static_cast<std::size_t>(i)];
      if (k < 0) {
        if (!active[static_cast<std::size_t>(i)]) continue;
        for (Index a = 0; a < c; ++a) p_entries.emplace_back(static_cast<int>(i * c + a), static_cast<int>(reduced++), 1.0);
      } else if (b.kinds[static_cast<std::size_t>(k)] == BoundaryKind::sliding) {
        if (c != Dim) throw InputError("ConstrainedSystem: sliding nodes need a coupled system");
        const auto t = b.sliding_basis(k);
        for (Index j = 0; j < t.cols(); ++j, ++reduced)
          for (Index a = 0; a < Dim; ++a)
            if (t(a, j) != 0.0) p_entries.emplace_back(static_cast<int>(i * c + a), static_cast<int>(reduced), t(a, j));
      } else {
        for (Index a = 0; a < c; ++a) s_entries.emplace_back(static_cast<int>(i * c + a), static_cast<int>(k * c + a), 1.0);
      }
    }
    p_.resize(n * c, reduced);
    p_.setFromTriplets(p_entries.begin(), p_entries.end());
    s_.resize(n * c, b.size() * c);
    s_.setFromTriplets(s_entries.begin(), s_entries.end());
    solver_ = LinearSolver(solver_options);
    x_.resize(0, 0);
  }

  /// Forms and factorizes the reduced matrix Pᵀ K P of K (n_nodes * components square,
  /// symmetric) and the coupling Pᵀ K S. A K with the pattern of the previous call re-uses
  /// the symbolic analysis. Throws SolverError when the factorization fails.
  void factorize(const SparseMatrix& k) {
    const SparseMatrix ptk = SparseMatrix(p_.transpose()) * k;
    SparseMatrix reduced_k = ptk * p_;
    coupling_ = ptk * s_;
    reduced_k.makeCompressed();
    if (reduced_k.rows() > 0) solver_.compute(reduced_k);
    nonzeros_ = reduced_k.nonZeros() + coupling_.nonZeros();
  }

  /// Displacement of every node (Dim × n_nodes) for Dirichlet values d (Dim × m, boundary
  /// order; sliding columns ignored). The iterative solvers start from the previous solution.
  /// `force` (optional, n_nodes * components × columns) adds a load: K u = force.
  void solve(PointsView<Dim> d, Points<Dim>& out, const Eigen::MatrixXd* force = nullptr) {
    const auto m = static_cast<Index>(boundary_nodes_.size());
    const Index c = components_;
    const Index columns = c == 1 ? Dim : 1;
    // Dirichlet values as (m * c) × columns.
    values_.setZero(m * c, columns);
    for (Index k = 0; k < m; ++k) {
      if (kinds_[static_cast<std::size_t>(k)] == BoundaryKind::sliding) continue;
      for (Index a = 0; a < Dim; ++a) {
        if (c == 1)
          values_(k, a) = d(a, k);
        else
          values_(k * Dim + a, 0) = d(a, k);
      }
    }
    if (p_.cols() > 0) {
      rhs_.noalias() = -(coupling_ * values_);
      if (force != nullptr) rhs_.noalias() += p_.transpose() * *force;
      solver_.solve(rhs_, x_);
      full_.noalias() = p_ * x_;
    } else {
      full_.setZero(p_.rows(), columns);
    }
    full_.noalias() += s_ * values_;
    const Index n = p_.rows() / c;
    if (out.cols() != n) out.resize(Dim, n);
    for (Index i = 0; i < n; ++i)
      for (Index a = 0; a < Dim; ++a) out(a, i) = c == 1 ? full_(i, a) : full_(i * Dim + a, 0);
  }

  /// The transpose of solve(): for v (Dim × n_nodes), the gradient (Dim × m, boundary order)
  /// of ⟨v, solve(d)⟩ with respect to d. With u = S d − P A⁻¹ C d (A = Pᵀ K P symmetric,
  /// C = Pᵀ K S) it is Sᵀ v − Cᵀ A⁻¹ Pᵀ v: one more solve with the same factorization.
  /// Sliding columns are zero (solve() ignores them).
  void solve_transpose(const PointsView<Dim>& v, Points<Dim>& gradient) {
    const auto m = static_cast<Index>(boundary_nodes_.size());
    const Index c = components_;
    const Index columns = c == 1 ? Dim : 1;
    const Index n = p_.rows() / c;
    adjoint_full_.resize(n * c, columns);
    for (Index i = 0; i < n; ++i)
      for (Index a = 0; a < Dim; ++a) (c == 1 ? adjoint_full_(i, a) : adjoint_full_(i * Dim + a, 0)) = v(a, i);
    adjoint_values_.noalias() = s_.transpose() * adjoint_full_;
    if (p_.cols() > 0) {
      adjoint_rhs_.noalias() = p_.transpose() * adjoint_full_;
      solver_.solve(adjoint_rhs_, adjoint_x_);
      adjoint_values_.noalias() -= coupling_.transpose() * adjoint_x_;
    }
    gradient.setZero(Dim, m);
    for (Index k = 0; k < m; ++k) {
      if (kinds_[static_cast<std::size_t>(k)] == BoundaryKind::sliding) continue;
      for (Index a = 0; a < Dim; ++a) gradient(a, k) = c == 1 ? adjoint_values_(k, a) : adjoint_values_(k * Dim + a, 0);
    }
  }

  [[nodiscard]] const SolverReport& report() const noexcept { return solver_.report(); }
  [[nodiscard]] Index nonzeros() const noexcept { return nonzeros_; }
  [[nodiscard]] Index unknowns() const noexcept { return p_.cols(); }

  /// Copies the solver's work into stats after a solve.
  void record(MoverStats& stats) const {
    const SolverReport& r = solver_.report();
    stats.iterations = r.iterations;
    stats.residual = r.residual;
    stats.fell_back = r.fell_back;
  }

 private:
  int components_ = 1;
  std::vector<Index> boundary_nodes_;
  std::vector<BoundaryKind> kinds_;
  SparseMatrix p_, s_, coupling_;
  LinearSolver solver_;
  Index nonzeros_ = 0;
  Eigen::MatrixXd values_, rhs_, x_, full_;
  // The transposed solve's own vectors, so the iterative solvers' warm start of solve() is kept.
  Eigen::MatrixXd adjoint_full_, adjoint_values_, adjoint_rhs_, adjoint_x_;
};

}  // namespace meshmotion::detail
