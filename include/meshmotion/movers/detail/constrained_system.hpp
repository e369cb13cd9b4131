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
/// coupled systems (node-major: node * Dim + axis). A coupled 3D system of at least
/// SolverOptions::coupled_cg_min_rows unknowns under a simplicial Cholesky kind is solved by
/// ComponentCg (its nodal matrix: the mean of K's same-axis blocks over the nodes with
/// unknowns), each stream of solves (moves, reverse derivatives) keeping its own history.

#include "meshmotion/core/error.hpp"
#include "meshmotion/core/types.hpp"
#include "meshmotion/movers/boundary.hpp"
#include "meshmotion/movers/detail/mover_support.hpp"
#include "meshmotion/movers/mover.hpp"
#include "meshmotion/solvers/detail/component_cg.hpp"
#include "meshmotion/solvers/linear_solver.hpp"

#include <Eigen/SparseCore>

#include <algorithm>
#include <string>
#include <vector>

namespace meshmotion::detail {

/// Qᵀ K R for maps Q, R whose rows hold few entries (a selection of dofs, or
/// a sliding node's basis): one pass over K's columns with a dense accumulator per column of
/// R, without the Qᵀ K that two sparse products build in between (on a 3D system of 256k
/// unknowns the products took 3 s, a third of the setup).
[[nodiscard]] inline SparseMatrix project(const SparseMatrix& k, const SparseMatrix& q, const SparseMatrix& r) {
  using RowMajor = Eigen::SparseMatrix<double, Eigen::RowMajor, int>;
  const RowMajor q_rows = q;
  SparseMatrix out(q.cols(), r.cols());
  Index bound = 0;  // K's entries each column of R reaches, times the most entries of a row of Q
  Index widest = 0;
  for (Index i = 0; i < q_rows.outerSize(); ++i) widest = std::max<Index>(widest, q_rows.outerIndexPtr()[i + 1] - q_rows.outerIndexPtr()[i]);
  for (Index j = 0; j < r.outerSize(); ++j)
    for (SparseMatrix::InnerIterator rj(r, j); rj; ++rj) bound += k.col(rj.row()).nonZeros();
  out.reserve(std::min(bound * widest, q.cols() * r.cols()));
  Eigen::VectorXd sum = Eigen::VectorXd::Zero(q.cols());
  std::vector<bool> touched(static_cast<std::size_t>(q.cols()), false);
  std::vector<int> rows;
  for (Index j = 0; j < r.outerSize(); ++j) {
    out.startVec(j);
    rows.clear();
    for (SparseMatrix::InnerIterator rj(r, j); rj; ++rj)
      for (SparseMatrix::InnerIterator kc(k, rj.row()); kc; ++kc) {
        const double weighted = kc.value() * rj.value();
        for (RowMajor::InnerIterator qi(q_rows, kc.row()); qi; ++qi) {
          const auto i = static_cast<std::size_t>(qi.col());
          if (!touched[i]) {
            touched[i] = true;
            rows.push_back(qi.col());
          }
          sum[qi.col()] += qi.value() * weighted;
        }
      }
    std::sort(rows.begin(), rows.end());
    for (const int i : rows) {
      out.insertBack(i, j) = sum[i];
      sum[i] = 0.0;
      touched[static_cast<std::size_t>(i)] = false;
    }
  }
  out.finalize();
  out.data().squeeze();
  return out;
}

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
    node_of_unknowns_.assign(static_cast<std::size_t>(n), -1);
    Index holding = 0;
    for (Index i = 0; i < n; ++i) {
      const Index k = boundary_index[static_cast<std::size_t>(i)];
      if (k < 0) {
        if (!active[static_cast<std::size_t>(i)]) continue;
        node_of_unknowns_[static_cast<std::size_t>(i)] = holding++;
        for (Index a = 0; a < c; ++a) p_entries.emplace_back(static_cast<int>(i * c + a), static_cast<int>(reduced++), 1.0);
      } else if (b.kinds[static_cast<std::size_t>(k)] == BoundaryKind::sliding) {
        if (c != Dim) throw InputError("ConstrainedSystem: sliding nodes need a coupled system");
        const auto t = b.sliding_basis(k);
        node_of_unknowns_[static_cast<std::size_t>(i)] = holding++;
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
    const bool cholesky = solver_options.solver == SolverKind::simplicial_ldlt || solver_options.solver == SolverKind::simplicial_llt;
    component_cg_ = c == 3 && cholesky && solver_options.coupled_cg_min_rows > 0 && reduced >= solver_options.coupled_cg_min_rows;
    direct_after_ = solver_options.coupled_direct_after_iterations;
    lift_.resize(0, 0);
    if (component_cg_) {
      std::vector<Triplet> lift_entries;
      lift_entries.reserve(p_entries.size());
      for (const Triplet& e : p_entries)
        lift_entries.emplace_back(static_cast<int>(node_of_unknowns_[static_cast<std::size_t>(e.row() / c)] * c + e.row() % c), e.col(), e.value());
      lift_.resize(holding * c, reduced);
      lift_.setFromTriplets(lift_entries.begin(), lift_entries.end());
    }
  }

  /// Forms and factorizes the reduced matrix Pᵀ K P of K (n_nodes * components square,
  /// symmetric) and the coupling Pᵀ K S. A K with the pattern of the previous call re-uses
  /// the symbolic analysis. Throws SolverError when the factorization fails.
  void factorize(const SparseMatrix& k) {
    SparseMatrix reduced_k = project(k, p_, p_);
    coupling_ = project(k, p_, s_);
    nonzeros_ = reduced_k.nonZeros() + coupling_.nonZeros();
    forward_history_.clear();
    adjoint_history_.clear();
    if (reduced_k.rows() == 0) return;
    if (component_cg_)
      cg_.compute(std::move(reduced_k), lift_, nodal_matrix(k), components_, direct_after_);
    else
      solver_.compute(reduced_k);
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
      if (component_cg_)
        cg_.solve(rhs_, x_, forward_history_);
      else
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
      if (component_cg_)
        cg_.solve(adjoint_rhs_, adjoint_x_, adjoint_history_);
      else
        solver_.solve(adjoint_rhs_, adjoint_x_);
      adjoint_values_.noalias() -= coupling_.transpose() * adjoint_x_;
    }
    gradient.setZero(Dim, m);
    for (Index k = 0; k < m; ++k) {
      if (kinds_[static_cast<std::size_t>(k)] == BoundaryKind::sliding) continue;
      for (Index a = 0; a < Dim; ++a) gradient(a, k) = c == 1 ? adjoint_values_(k, a) : adjoint_values_(k * Dim + a, 0);
    }
  }

  [[nodiscard]] const SolverReport& report() const noexcept { return component_cg_ ? cg_.report() : solver_.report(); }
  [[nodiscard]] Index nonzeros() const noexcept { return nonzeros_; }
  [[nodiscard]] Index unknowns() const noexcept { return p_.cols(); }

  /// Copies the solver's work into stats after a solve.
  void record(MoverStats& stats) const {
    const SolverReport& r = report();
    stats.iterations = r.iterations;
    stats.residual = r.residual;
    stats.fell_back = r.fell_back;
    stats.factorizations = r.factorizations;
  }

 private:
  /// The mean over the axes of K's same-axis entries between nodes that hold unknowns, in
  /// node_of_unknowns_ numbering: ComponentCg's preconditioner.
  [[nodiscard]] SparseMatrix nodal_matrix(const SparseMatrix& k) const {
    const Index c = components_;
    std::vector<Eigen::Triplet<double, int>> entries;
    entries.reserve(static_cast<std::size_t>(k.nonZeros() / (c * c)));
    for (Index column = 0; column < k.outerSize(); ++column) {
      const Index j = node_of_unknowns_[static_cast<std::size_t>(column / c)];
      if (j < 0) continue;
      for (SparseMatrix::InnerIterator it(k, column); it; ++it) {
        const Index i = node_of_unknowns_[static_cast<std::size_t>(it.row() / c)];
        if (i >= 0 && it.row() % c == column % c)
          entries.emplace_back(static_cast<int>(i), static_cast<int>(j), it.value() / static_cast<double>(c));
      }
    }
    const Index nodes = lift_.rows() / c;
    SparseMatrix nodal(nodes, nodes);
    nodal.setFromTriplets(entries.begin(), entries.end());
    return nodal;
  }

  int components_ = 1;
  std::vector<Index> boundary_nodes_;
  std::vector<BoundaryKind> kinds_;
  SparseMatrix p_, s_, coupling_;
  LinearSolver solver_;
  bool component_cg_ = false;
  Index direct_after_ = -1;
  std::vector<Index> node_of_unknowns_;  ///< per node: its index among the nodes that hold unknowns, or −1
  SparseMatrix lift_;                    ///< unknowns → those nodes' Cartesian dofs
  ComponentCg cg_;
  SolutionHistory forward_history_, adjoint_history_;
  Index nonzeros_ = 0;
  Eigen::MatrixXd values_, rhs_, x_, full_;
  // The transposed solve's own vectors, so the iterative solvers' warm start of solve() is kept.
  Eigen::MatrixXd adjoint_full_, adjoint_values_, adjoint_rhs_, adjoint_x_;
};

}  // namespace meshmotion::detail
