#pragma once
/// \file
/// LinearSolver: one of Eigen's sparse solvers chosen at run time by SolverOptions, with the
/// symbolic analysis kept apart from the numeric factorization (a mover re-based on a moved
/// mesh whose matrix keeps its sparsity pattern re-uses the analysis), solves for several
/// right-hand sides at once, and a SolverReport of iterations, residual, time and
/// factorizations. Failure or non-convergence raises SolverError.

#include "meshmotion/core/error.hpp"
#include "meshmotion/core/types.hpp"
#include "meshmotion/solvers/detail/cholmod_library.hpp"
#include "meshmotion/solvers/detail/stopwatch.hpp"
#include "meshmotion/solvers/solver_options.hpp"

#include <Eigen/IterativeLinearSolvers>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <Eigen/SparseLU>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>

namespace meshmotion {

/// Column-major sparse matrix used by the solvers and movers.
using SparseMatrix = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;

namespace detail {

/// Run-time choice among Eigen solver types sharing analyzePattern/factorize/solve.
class SparseBackend {
 public:
  virtual ~SparseBackend() = default;
  virtual void analyze(const SparseMatrix& a) = 0;
  /// Returns false when the factorization failed (matrix not SPD, structurally singular).
  virtual bool factorize(const SparseMatrix& a) = 0;
  /// Solves for one column; returns false when the solver reports failure.
  virtual bool solve(const Eigen::VectorXd& b, Eigen::VectorXd& x, Index& iterations) = 0;
  /// Changes the relative-residual target of an iterative solver (direct ones ignore it).
  virtual void set_tolerance(double /*tolerance*/) {}
};

template <class EigenSolver>
class DirectBackend final : public SparseBackend {
 public:
  void analyze(const SparseMatrix& a) override { solver_.analyzePattern(a); }
  bool factorize(const SparseMatrix& a) override {
    solver_.factorize(a);
    return solver_.info() == Eigen::Success;
  }
  bool solve(const Eigen::VectorXd& b, Eigen::VectorXd& x, Index& iterations) override {
    x = solver_.solve(b);
    iterations = 0;
    return solver_.info() == Eigen::Success;
  }

 private:
  EigenSolver solver_;
};

template <class EigenSolver>
class IterativeBackend final : public SparseBackend {
 public:
  IterativeBackend(double tolerance, Index max_iterations) {
    solver_.setTolerance(tolerance);
    if (max_iterations > 0) solver_.setMaxIterations(max_iterations);
  }
  void analyze(const SparseMatrix& a) override { solver_.analyzePattern(a); }
  bool factorize(const SparseMatrix& a) override {
    solver_.factorize(a);
    return solver_.info() == Eigen::Success;
  }
  bool solve(const Eigen::VectorXd& b, Eigen::VectorXd& x, Index& iterations) override {
    // Warm start from the caller's x when it has the right size (repeated moves are close).
    if (x.size() != b.size()) x.setZero(b.size());
    x = solver_.solveWithGuess(b, x);
    iterations = solver_.iterations();
    return solver_.info() == Eigen::Success;
  }
  void set_tolerance(double tolerance) override { solver_.setTolerance(tolerance); }

 private:
  EigenSolver solver_;
};

/// True when a matrix of `rows` rows goes to CHOLMOD under options `o` (see
/// SolverOptions::supernodal_min_rows).
[[nodiscard]] inline bool use_supernodal(const SolverOptions& o, Index rows) {
  if (o.solver == SolverKind::cholmod_supernodal) return true;
  return have_cholmod() && (o.solver == SolverKind::simplicial_ldlt || o.solver == SolverKind::simplicial_llt) &&
         o.supernodal_min_rows > 0 && rows >= o.supernodal_min_rows;
}

// A template, so that only a LinearSolver that is compiled instantiates the Eigen solvers.
template <int = 0>
std::unique_ptr<SparseBackend> make_backend(const SolverOptions& o) {
  constexpr int Lower = Eigen::Lower;
  constexpr int LowerUpper = Eigen::Lower | Eigen::Upper;
  switch (o.solver) {
    case SolverKind::cholmod_supernodal:
#ifdef MESHMOTION_HAVE_CHOLMOD
      return std::make_unique<DirectBackend<CholmodSupernodalLLT>>();
#else
      throw InputError("cholmod_supernodal: this build has no CHOLMOD (install libsuitesparse-dev and configure again)");
#endif
    case SolverKind::simplicial_ldlt:
      return std::make_unique<DirectBackend<Eigen::SimplicialLDLT<SparseMatrix, Lower>>>();
    case SolverKind::simplicial_llt:
      return std::make_unique<DirectBackend<Eigen::SimplicialLLT<SparseMatrix, Lower>>>();
    case SolverKind::sparse_lu:
      return std::make_unique<DirectBackend<Eigen::SparseLU<SparseMatrix, Eigen::COLAMDOrdering<int>>>>();
    case SolverKind::cg_jacobi:
      return std::make_unique<IterativeBackend<Eigen::ConjugateGradient<SparseMatrix, LowerUpper>>>(
          o.tolerance, o.max_iterations);
    case SolverKind::cg_incomplete_cholesky:
      return std::make_unique<IterativeBackend<Eigen::ConjugateGradient<
          SparseMatrix, LowerUpper, Eigen::IncompleteCholesky<double, Eigen::Lower>>>>(o.tolerance,
                                                                                           o.max_iterations);
    case SolverKind::bicgstab:
      return std::make_unique<IterativeBackend<Eigen::BiCGSTAB<SparseMatrix>>>(o.tolerance, o.max_iterations);
  }
  throw InputError("LinearSolver: unknown solver kind");
}

}  // namespace detail

/// A sparse linear solver over one square matrix A (n × n), factorized once and applied to
/// many right-hand sides.
///
/// Usage: `compute(A)` (analysis when the pattern is new, then factorization), then
/// `solve(B)` as often as needed. A later `compute(A2)` with the same sparsity pattern skips
/// the symbolic analysis. The solver keeps a copy of A (iterative solvers and residual
/// checks need it). With SolverOptions::diagonal_scaling it keeps and solves the scaled
/// matrix D^-1/2 A D^-1/2 and maps right-hand sides and solutions (callers see A's x).
///
/// A template of nothing (LinearSolver is BasicLinearSolver<>), so that its members are
/// instantiated only where a solve is compiled: a program built on meshmotion::compiled then
/// never compiles Eigen's factorizations itself (docs/compiled.md).
template <class = void>
class BasicLinearSolver {
 public:
  explicit BasicLinearSolver(SolverOptions options = {}) : options_(options) {}

  [[nodiscard]] const SolverOptions& options() const noexcept { return options_; }
  [[nodiscard]] const SolverReport& report() const noexcept { return report_; }
  /// Number of rows of the factorized matrix (0 before compute).
  [[nodiscard]] Index size() const noexcept { return matrix_.rows(); }

  /// Analyses (if the pattern differs from the last one) and factorizes A.
  /// Throws InputError when A is not square or holds a non-finite value, SolverError when the
  /// factorization fails (e.g. SimplicialLLT on a matrix that is not positive definite).
  void compute(const SparseMatrix& a) {
    const detail::Stopwatch watch;
    if (a.rows() != a.cols())
      throw InputError("LinearSolver::compute: matrix is not square (got " + std::to_string(a.rows()) + " × " +
                       std::to_string(a.cols()) + ")");
    for (Index k = 0; k < a.nonZeros(); ++k)
      if (!std::isfinite(a.valuePtr()[k]))
        throw InputError("LinearSolver::compute: matrix holds a non-finite value");
    const bool same_pattern = backend_ && same_pattern_as(a);
    matrix_ = a;
    matrix_.makeCompressed();
    if (options_.diagonal_scaling) scale_matrix();
    if (!same_pattern) {
      supernodal_ = detail::use_supernodal(options_, matrix_.rows());
      backend_ = detail::make_backend(supernodal_ ? with_kind(SolverKind::cholmod_supernodal) : options_);
      fallback_.reset();
      backend_->analyze(matrix_);
      ++report_.analyses;
    }
    bool ok = backend_->factorize(matrix_);
    ++report_.factorizations;
    // Chosen for its size, CHOLMOD may meet a matrix that is not positive definite (a
    // quasi-definite one LDLᵀ takes): the simplicial factorization asked for answers.
    if (!ok && supernodal_ && options_.solver != SolverKind::cholmod_supernodal) {
      supernodal_ = false;
      backend_ = detail::make_backend(options_);
      backend_->analyze(matrix_);
      ++report_.analyses;
      ok = backend_->factorize(matrix_);
      ++report_.factorizations;
    }
    report_.supernodal = supernodal_;
    if (fallback_) fallback_factorize();
    report_.seconds += watch.seconds();
    if (!ok)
      throw SolverError(std::string(name(supernodal_ ? SolverKind::cholmod_supernodal : options_.solver)) + ": factorization of a " + std::to_string(a.rows()) +
                        " × " + std::to_string(a.rows()) +
                        " matrix failed (matrix singular or not positive definite)");
  }

  /// Solves A X = B for every column of B (n × m); X is resized to n × m. Iterative solvers
  /// start from X when it already has that shape. Throws SolverError naming the solver, the
  /// iterations and the residual when a solve fails or does not converge (unless
  /// fallback_to_direct, which the report then records), InputError on a size mismatch or a
  /// non-finite right-hand side. With `check` off, a residual above the limit is only
  /// reported (ResidualCheck).
  void solve(const Eigen::Ref<const Eigen::MatrixXd>& b, Eigen::MatrixXd& x, ResidualCheck check = ResidualCheck::enforced) {
    const detail::Stopwatch watch;
    if (!backend_) throw InputError("LinearSolver::solve: compute() was not called");
    if (b.rows() != size())
      throw InputError("LinearSolver::solve: right-hand side has " + std::to_string(b.rows()) +
                       " rows (expected " + std::to_string(size()) + ")");
    if (!b.allFinite()) throw InputError("LinearSolver::solve: right-hand side holds a non-finite value");
    if (x.rows() != b.rows() || x.cols() != b.cols()) x.setZero(b.rows(), b.cols());
    report_.iterations = 0;
    report_.residual = 0.0;
    const bool scaled = options_.diagonal_scaling;
    for (Index c = 0; c < b.cols(); ++c) {
      rhs_ = b.col(c);
      column_ = x.col(c);
      if (scaled) {
        rhs_.array() *= scale_.array();
        column_.array() /= scale_.array();
      }
      Index iterations = 0;
      bool ok = backend_->solve(rhs_, column_, iterations);
      if (ok && scaled && is_iterative(options_.solver)) ok = tighten_scaled_solve(iterations);
      double residual = relative_residual();
      report_.iterations = std::max(report_.iterations, iterations);
      const double limit = is_iterative(options_.solver) ? 10.0 * options_.tolerance : 1e-6;
      if (check == ResidualCheck::enforced && (!ok || !(residual <= std::max(limit, 1e-13)))) {
        if (!options_.fallback_to_direct || !is_iterative(options_.solver))
          throw SolverError(std::string(name(options_.solver)) + ": solve did not converge (iterations " +
                            std::to_string(iterations) + ", relative residual " + std::to_string(residual) +
                            ", expected <= " + std::to_string(limit) + ")");
        if (!fallback_) fallback_factorize();
        ok = fallback_->solve(rhs_, column_, iterations);
        residual = relative_residual();
        report_.fell_back = true;
        if (!ok || !(residual <= 1e-6))
          throw SolverError(std::string(name(options_.solver)) + " and its sparse_lu fallback failed (relative residual " +
                            std::to_string(residual) + ")");
      }
      report_.residual = std::max(report_.residual, residual);
      if (scaled) column_.array() *= scale_.array();
      x.col(c) = column_;
    }
    report_.seconds += watch.seconds();
  }

  /// Allocating form of solve: returns X (n × m).
  [[nodiscard]] Eigen::MatrixXd solve(const Eigen::Ref<const Eigen::MatrixXd>& b) {
    Eigen::MatrixXd x;
    solve(b, x);
    return x;
  }

 private:
  [[nodiscard]] SolverOptions with_kind(SolverKind kind) const {
    SolverOptions o = options_;
    o.solver = kind;
    return o;
  }

  [[nodiscard]] bool same_pattern_as(const SparseMatrix& a) const {
    if (a.rows() != matrix_.rows() || a.nonZeros() != matrix_.nonZeros() || !a.isCompressed()) return false;
    for (Index j = 0; j <= a.cols(); ++j)
      if (a.outerIndexPtr()[j] != matrix_.outerIndexPtr()[j]) return false;
    for (Index k = 0; k < a.nonZeros(); ++k)
      if (a.innerIndexPtr()[k] != matrix_.innerIndexPtr()[k]) return false;
    return true;
  }

  /// Under diagonal_scaling the Krylov solver's own test, ||r̃|| ≤ tol ||b̃|| on the scaled
  /// system, is still dominated by the rows with the largest right-hand side (the stiffest
  /// cells); errors where the matrix is soft go unseen. In displacement units the residual is
  /// D^-1 r = S r̃ (the Jacobi correction of each unknown), so the solve is continued, with a
  /// tighter target and warm-started, until ||S r̃|| ≤ tol ||S b̃|| as well (at most 12
  /// restarts). Returns false when the iterative solver fails on the way.
  bool tighten_scaled_solve(Index& iterations) {
    const double target = options_.tolerance;
    const double norm_b = (scale_.array() * rhs_.array()).matrix().norm();
    double tolerance = target;
    bool ok = true;
    for (int round = 0; ok && round < 12 && norm_b > 0.0; ++round) {
      const double ratio = (scale_.array() * (matrix_ * column_ - rhs_).array()).matrix().norm() / norm_b;
      if (ratio <= target) break;
      tolerance = std::max(tolerance * 0.5 * target / ratio, 1e-16);
      backend_->set_tolerance(tolerance);
      Index more = 0;
      ok = backend_->solve(rhs_, column_, more);
      iterations += more;
    }
    backend_->set_tolerance(target);
    return ok;
  }

  /// Replaces matrix_ by S A S with S = diag(A)^-1/2, kept in scale_.
  void scale_matrix() {
    scale_ = matrix_.diagonal();
    for (Index i = 0; i < scale_.size(); ++i) {
      if (!(scale_[i] > 0.0))
        throw InputError("LinearSolver::compute: diagonal_scaling needs a positive diagonal (got " +
                         std::to_string(scale_[i]) + " in row " + std::to_string(i) + ")");
      scale_[i] = 1.0 / std::sqrt(scale_[i]);
    }
    for (Index j = 0; j < matrix_.outerSize(); ++j)
      for (SparseMatrix::InnerIterator it(matrix_, j); it; ++it) it.valueRef() *= scale_[it.row()] * scale_[j];
  }

  [[nodiscard]] double relative_residual() const {
    const double norm_b = rhs_.norm();
    const double r = (matrix_ * column_ - rhs_).norm();
    return norm_b > 0.0 ? r / norm_b : r;
  }

  void fallback_factorize() {
    if (!fallback_) {
      fallback_ = detail::make_backend(SolverOptions{SolverKind::sparse_lu});
      fallback_->analyze(matrix_);
    }
    if (!fallback_->factorize(matrix_))
      throw SolverError("sparse_lu fallback: factorization failed (matrix singular)");
    ++report_.factorizations;
  }

  SolverOptions options_;
  SolverReport report_;
  SparseMatrix matrix_;
  std::unique_ptr<detail::SparseBackend> backend_;
  std::unique_ptr<detail::SparseBackend> fallback_;
  bool supernodal_ = false;  ///< backend_ is CHOLMOD's
  Eigen::VectorXd scale_;  ///< diag(A)^-1/2 under diagonal_scaling
  Eigen::VectorXd rhs_;
  Eigen::VectorXd column_;
};
using LinearSolver = BasicLinearSolver<>;


}  // namespace meshmotion


// The compiled library (target meshmotion::compiled, src/core.cpp) holds the solver and its
// Eigen factorizations: consumers compile none of them.
#ifdef MESHMOTION_COMPILED
namespace meshmotion {
extern template std::unique_ptr<detail::SparseBackend> detail::make_backend<0>(const SolverOptions&);
extern template class BasicLinearSolver<>;
}  // namespace meshmotion
#endif
