#pragma once
/// \file
/// SolverOptions: which of Eigen's sparse solvers a LinearSolver uses, with its tolerances,
/// and SolverReport: what the solver did.

#include "meshmotion/core/option_text.hpp"
#include "meshmotion/core/types.hpp"

#include <array>
#include <string>
#include <string_view>

namespace meshmotion {

/// Eigen sparse solvers the library chooses among.
enum class SolverKind {
  simplicial_ldlt,         ///< Eigen::SimplicialLDLT: sparse symmetric (SPD or quasi-definite), direct
  simplicial_llt,          ///< Eigen::SimplicialLLT: sparse SPD Cholesky, direct
  sparse_lu,               ///< Eigen::SparseLU (SuperLU's algorithm): any square matrix, direct
  cg_jacobi,               ///< Eigen::ConjugateGradient with a diagonal preconditioner: SPD, iterative
  cg_incomplete_cholesky,  ///< Eigen::ConjugateGradient with IncompleteCholesky: SPD, iterative
  bicgstab,                ///< Eigen::BiCGSTAB with a diagonal preconditioner: any square, iterative
  /// CHOLMOD's supernodal Cholesky (loaded on first use): SPD, direct; only in builds
  /// with SuiteSparse (MESHMOTION_HAVE_CHOLMOD, set by CMake when libsuitesparse-dev is found).
  cholmod_supernodal,
};

/// Name of a solver kind as used in messages and on command lines ("simplicial_ldlt", ...).
[[nodiscard]] constexpr std::string_view name(SolverKind kind) {
  switch (kind) {
    case SolverKind::simplicial_ldlt: return "simplicial_ldlt";
    case SolverKind::simplicial_llt: return "simplicial_llt";
    case SolverKind::sparse_lu: return "sparse_lu";
    case SolverKind::cg_jacobi: return "cg_jacobi";
    case SolverKind::cg_incomplete_cholesky: return "cg_incomplete_cholesky";
    case SolverKind::bicgstab: return "bicgstab";
    case SolverKind::cholmod_supernodal: return "cholmod_supernodal";
  }
  return "unknown";
}

/// Every solver kind, for the option parser (core/option_text.hpp).
[[nodiscard]] constexpr std::array<SolverKind, 7> option_choices(SolverKind) {
  return {SolverKind::simplicial_ldlt, SolverKind::simplicial_llt, SolverKind::sparse_lu,
          SolverKind::cg_jacobi,       SolverKind::cg_incomplete_cholesky, SolverKind::bicgstab,
          SolverKind::cholmod_supernodal};
}

/// True when this build has CHOLMOD (SolverKind::cholmod_supernodal and the automatic choice).
[[nodiscard]] constexpr bool have_cholmod() {
#ifdef MESHMOTION_HAVE_CHOLMOD
  return true;
#else
  return false;
#endif
}

/// True for the Krylov solvers (tolerance and max_iterations apply to them only).
[[nodiscard]] constexpr bool is_iterative(SolverKind kind) {
  return kind == SolverKind::cg_jacobi || kind == SolverKind::cg_incomplete_cholesky ||
         kind == SolverKind::bicgstab;
}

/// Options of a LinearSolver.
struct SolverOptions {
  SolverKind solver = SolverKind::simplicial_ldlt;
  double tolerance = 1e-12;
  Index max_iterations = 0;
  bool fallback_to_direct = false;
  bool diagonal_scaling = false;
  /// The simplicial Cholesky kinds hand matrices of at least this many rows to CHOLMOD's
  /// supernodal factorization in builds that have it (its dense kernels win on the large
  /// systems; the simplicial factorization answers if CHOLMOD finds the matrix not positive
  /// definite). 0 never does.
  Index supernodal_min_rows = 10000;
  /// The simplicial Cholesky kinds solve a coupled 3D mechanics system (three unknowns per
  /// node: elasticity) of at least this many rows by conjugate gradients preconditioned with
  /// one factorization of the nodes' scalar matrix, started from the earlier solutions
  /// (solvers/detail/component_cg.hpp): its factor holds a ninth of the coupled one's entries
  /// and costs about a twentieth of its time, and a time loop's moves take a few iterations
  /// each. 0 never does. Coupled 2D systems, whose factorization is cheap, stay direct.
  Index coupled_cg_min_rows = 60000;
  /// That CG factorizes the coupled system after all once its iterations since setup add up
  /// to this many, and solves directly from then on (a long run of motions that keep changing
  /// shape then pays at most about twice the cheaper of the two). −1: the factorization's
  /// estimated cost in iterations (ComponentCg::direct_after: 270 at 222k unknowns); 0: never
  /// (the memory stays the nodal factor's).
  Index coupled_direct_after_iterations = -1;
};

/// What a solver did, accumulated since it was created (seconds, factorizations) or for the
/// latest solve (iterations, residual).
/// Whether a solve refuses a result whose relative residual exceeds the solver's limit. Off
/// only for solves whose right-hand side is chosen to be hard (a condition estimate's), where
/// the residual measures the matrix rather than the solve.
enum class ResidualCheck { enforced, off };

struct SolverReport {
  Index iterations = 0;      ///< largest iteration count over the right-hand sides of the last solve
  double residual = 0.0;     ///< largest relative residual ||A x - b|| / ||b|| of the last solve (of the scaled system under diagonal_scaling)
  double seconds = 0.0;      ///< total time in analysis, factorization and solves
  Index analyses = 0;        ///< symbolic analyses (sparsity pattern) performed
  Index factorizations = 0;  ///< numeric factorizations (or preconditioner builds) performed
  bool fell_back = false;    ///< an iterative solve failed and the direct fallback answered
  bool supernodal = false;   ///< the last factorization was CHOLMOD's supernodal one
  bool component_cg = false; ///< solved by CG preconditioned with the nodes' scalar factorization (coupled_cg_min_rows)
};

/// Dense factorizations.
enum class DenseSolverKind {
  llt,              ///< Cholesky: symmetric positive definite
  ldlt,             ///< robust Cholesky with pivoting: symmetric semi-definite or indefinite
  partial_piv_lu,   ///< LU with partial pivoting: any invertible matrix
};

[[nodiscard]] constexpr std::string_view name(DenseSolverKind kind) {
  switch (kind) {
    case DenseSolverKind::llt: return "dense_llt";
    case DenseSolverKind::ldlt: return "dense_ldlt";
    case DenseSolverKind::partial_piv_lu: return "dense_partial_piv_lu";
  }
  return "unknown";
}

/// Every dense factorization, for the option parser (core/option_text.hpp).
[[nodiscard]] constexpr std::array<DenseSolverKind, 3> option_choices(DenseSolverKind) {
  return {DenseSolverKind::llt, DenseSolverKind::ldlt, DenseSolverKind::partial_piv_lu};
}

// visit_options(o, f) calls f(key, field, help) for every field of `o` that text may set.
template <class F>
void visit_options(SolverOptions& o, F&& f, const std::string& prefix = {}) {
  f(prefix + "solver", o.solver, "sparse solver of the system");
  f(prefix + "tolerance", o.tolerance, OptionHelp{"relative residual an iterative solver must reach", range::positive});
  f(prefix + "max_iterations", o.max_iterations, OptionHelp{"iteration cap of an iterative solver (0: twice the size)", range::non_negative});
  f(prefix + "fallback_to_direct", o.fallback_to_direct, "solve with sparse LU when an iterative solver fails");
  f(prefix + "diagonal_scaling", o.diagonal_scaling, OptionHelp{"solve the diagonally scaled system", {},
      "Solve the symmetrically scaled system (D^-1/2 A D^-1/2) y = D^-1/2 b, x = D^-1/2 y, D = diag(A) (needs "
      "a positive diagonal). The tolerance and the reported residual then refer to the scaled system, whose "
      "rows are balanced: when the rows of A span many orders of magnitude (stiffened elasticity), ||A x − "
      "b|| / ||b|| is dominated by the stiffest rows and says nothing about the others. CG with the Jacobi "
      "preconditioner makes the same iterates either way; only its stopping test changes. Iterative solvers "
      "then also meet the tolerance in D^-1-scaled (displacement) units, ||D^-1 r|| ≤ tol ||D^-1 b||, "
      "restarting warm with a tighter target when their own test stops short."});
}

}  // namespace meshmotion
