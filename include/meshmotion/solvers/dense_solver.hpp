#pragma once
/// \file
/// DenseSolver: Eigen's dense LLT, LDLT or PartialPivLU behind one interface, for the dense
/// systems of globally supported RBF kernels. Reports like LinearSolver.

#include "meshmotion/core/error.hpp"
#include "meshmotion/core/types.hpp"
#include "meshmotion/solvers/detail/stopwatch.hpp"
#include "meshmotion/solvers/solver_options.hpp"

#include <Eigen/Cholesky>
#include <Eigen/LU>

#include <optional>
#include <array>
#include <string>
#include <string_view>

namespace meshmotion {

/// A dense linear solver over one square matrix A (n × n), factorized once. A template
/// (DenseSolver is BasicDenseSolver<>), so that its factorizations are compiled only where a
/// solve is (docs/compiled.md).
template <class Matrix = Eigen::MatrixXd>
class BasicDenseSolver {
 public:
  explicit BasicDenseSolver(DenseSolverKind kind = DenseSolverKind::partial_piv_lu) : kind_(kind) {}

  [[nodiscard]] DenseSolverKind kind() const noexcept { return kind_; }
  [[nodiscard]] const SolverReport& report() const noexcept { return report_; }
  [[nodiscard]] Index size() const noexcept { return matrix_.rows(); }

  /// Factorizes A. Throws InputError when A is not square or not finite, SolverError when the
  /// factorization fails (LLT of a matrix that is not positive definite).
  void compute(const Matrix& a) {
    const detail::Stopwatch watch;
    if (a.rows() != a.cols())
      throw InputError("DenseSolver::compute: matrix is not square (got " + std::to_string(a.rows()) + " × " +
                       std::to_string(a.cols()) + ")");
    if (!a.allFinite()) throw InputError("DenseSolver::compute: matrix holds a non-finite value");
    matrix_ = a;
    bool ok = true;
    switch (kind_) {
      case DenseSolverKind::llt: ok = llt_.emplace(matrix_).info() == Eigen::Success; break;
      case DenseSolverKind::ldlt: ok = ldlt_.emplace(matrix_).info() == Eigen::Success; break;
      case DenseSolverKind::partial_piv_lu: lu_.emplace(matrix_); break;
    }
    ++report_.factorizations;
    ++report_.analyses;
    report_.seconds += watch.seconds();
    if (!ok)
      throw SolverError(std::string(name(kind_)) + ": factorization of a " + std::to_string(a.rows()) + " × " +
                        std::to_string(a.rows()) + " matrix failed (not positive definite)");
  }

  /// Solves A X = B (B: n × m). Throws SolverError naming the solver and the residual when the
  /// result is not finite or its relative residual exceeds 1e-6 (singular matrix), unless
  /// `check` is off.
  void solve(const Eigen::Ref<const Eigen::MatrixXd>& b, Eigen::MatrixXd& x, ResidualCheck check = ResidualCheck::enforced) {
    const detail::Stopwatch watch;
    if (b.rows() != size())
      throw InputError("DenseSolver::solve: right-hand side has " + std::to_string(b.rows()) + " rows (expected " +
                       std::to_string(size()) + ")");
    if (!llt_ && !ldlt_ && !lu_) throw InputError("DenseSolver::solve: no matrix factorized (call compute first)");
    switch (kind_) {
      case DenseSolverKind::llt: x = llt_->solve(b); break;
      case DenseSolverKind::ldlt: x = ldlt_->solve(b); break;
      case DenseSolverKind::partial_piv_lu: x = lu_->solve(b); break;
    }
    const double norm_b = b.norm();
    const double residual = (matrix_ * x - b).norm() / (norm_b > 0.0 ? norm_b : 1.0);
    report_.iterations = 0;
    report_.residual = residual;
    report_.seconds += watch.seconds();
    if (check == ResidualCheck::enforced && !(residual <= 1e-6))
      throw SolverError(std::string(name(kind_)) + ": solve failed (iterations 0, relative residual " +
                        std::to_string(residual) + ", expected <= 1e-06; matrix singular?)");
  }

  [[nodiscard]] Eigen::MatrixXd solve(const Eigen::Ref<const Eigen::MatrixXd>& b) {
    Eigen::MatrixXd x;
    solve(b, x);
    return x;
  }

 private:
  DenseSolverKind kind_;
  SolverReport report_;
  Matrix matrix_;
  // Created by compute() only: Eigen leaves a default-constructed factorization's status
  // uninitialized, and moving a solver would read it.
  std::optional<Eigen::LLT<Matrix>> llt_;
  std::optional<Eigen::LDLT<Matrix>> ldlt_;
  std::optional<Eigen::PartialPivLU<Matrix>> lu_;
};
using DenseSolver = BasicDenseSolver<>;


}  // namespace meshmotion

// The compiled library (target meshmotion::compiled, src/core.cpp) holds it.
#ifdef MESHMOTION_COMPILED
namespace meshmotion {
extern template class BasicDenseSolver<>;
}  // namespace meshmotion
#endif
