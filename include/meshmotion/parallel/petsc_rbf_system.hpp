#pragma once
/// \file
/// PetscRbfSystem: the RBF interpolation system of a compact kernel, A α + P β = d, Pᵀ α = 0,
/// factorized once by MUMPS across the ranks instead of on every rank.
///
/// The centres are known to every rank (the distributed RBF mover gathers them); rank r
/// assembles the rows of A of its block of centres [m r / P, m (r + 1) / P) with k-d tree radius
/// queries, and MUMPS's Cholesky (METIS ordering) holds the factor distributed. A solve takes
/// right-hand sides every rank holds and gives every rank the whole solution (α is needed by
/// every rank's evaluation). The polynomial is eliminated as the serial RbfSystem does
/// (detail::RbfPolynomial), with A⁻¹ P kept on every rank.
///
/// For a single radius only (A symmetric positive definite) and distinct centres: the
/// distributed mover chooses it under those conditions.

#include "meshmotion/core/error.hpp"
#include "meshmotion/core/types.hpp"
#include "meshmotion/movers/detail/rbf_system.hpp"
#include "meshmotion/movers/rbf_kernels.hpp"
#include "meshmotion/parallel/communicator.hpp"
#include "meshmotion/parallel/petsc.hpp"
#include "meshmotion/spatial/kd_tree.hpp"

#include <Eigen/LU>

#include <span>
#include <string>
#include <vector>

namespace meshmotion::parallel::detail {

template <int Dim>
class PetscRbfSystem {
 public:
  using PolyCoefficients = typename meshmotion::detail::RbfPolynomial<Dim>::Coefficients;

  PetscRbfSystem() = default;
  PetscRbfSystem(const PetscRbfSystem&) = delete;
  PetscRbfSystem& operator=(const PetscRbfSystem&) = delete;

  /// Collective. `centres` (Dim × m, the same on every rank, distinct), a compact kernel with
  /// one radius. Throws SolverError when MUMPS fails (on every rank).
  void setup(MPI_Comm comm, const Points<Dim>& centres, const meshmotion::detail::RbfKernelSettings& kernel) {
    constexpr const char* where = "DistributedRbfMover::setup";
    ksp_.reset();
    a_.reset();
    comm_ = comm;
    centres_ = centres;
    kernel_ = kernel;
    const Index m = centres_.cols();
    const int r = rank_of(comm), p = size_of(comm);
    lo_ = m * r / p;
    hi_ = m * (r + 1) / p;
    tree_.build(centres_);
    std::vector<Index> rows;
    for (Index i = lo_; i < hi_; ++i) rows.push_back(i);
    // Sorted columns per row: the storage-order round trip sorts them.
    const Eigen::SparseMatrix<double, Eigen::RowMajor, int> block(Eigen::SparseMatrix<double, Eigen::ColMajor, int>(
        meshmotion::detail::compact_kernel_rows(centres_, rows, within(), m, kernel_)));
    nonzeros_ = block.nonZeros();
    const auto local = static_cast<PetscInt>(hi_ - lo_);
    std::vector<PetscInt> outer(block.outerIndexPtr(), block.outerIndexPtr() + local + 1);
    std::vector<PetscInt> inner(block.innerIndexPtr(), block.innerIndexPtr() + block.nonZeros());
    std::vector<PetscScalar> values(block.valuePtr(), block.valuePtr() + block.nonZeros());
    collective(comm_, [&] {
      petsc_check(MatCreateMPIAIJWithArrays(comm_, local, local, static_cast<PetscInt>(m), static_cast<PetscInt>(m),
                                            outer.data(), inner.data(), values.data(), a_.out()),
                  where, "MatCreateMPIAIJWithArrays");
      petsc_check(MatSetOption(a_.get(), MAT_SPD, PETSC_TRUE), where, "MatSetOption");
      petsc_check(KSPCreate(comm_, ksp_.out()), where, "KSPCreate");
      petsc_check(KSPSetOperators(ksp_.get(), a_.get(), a_.get()), where, "KSPSetOperators");
      use_mumps_cholesky(ksp_.get(), where);
      petsc_check(KSPSetOptionsPrefix(ksp_.get(), "meshmotion_rbf_"), where, "KSPSetOptionsPrefix");
      petsc_check(KSPSetFromOptions(ksp_.get()), where, "KSPSetFromOptions");
      petsc_check(KSPSetUp(ksp_.get()), where, "KSPSetUp");
    });
    PC pc = nullptr;
    KSPGetPC(ksp_.get(), &pc);
    PCFailedReason failed = PC_NOERROR;
    PCGetFailedReason(pc, &failed);
    if (failed != PC_NOERROR)
      throw SolverError("DistributedRbfMover::setup: MUMPS could not factorize the boundary system (PETSc reason " +
                        std::to_string(static_cast<int>(failed)) + ")");
    polynomial_.setup(centres_, kernel_.polynomial, [this](const Eigen::MatrixXd& b, Eigen::MatrixXd& x) { solve_a(b, x); },
                      where);
  }

  [[nodiscard]] Index size() const noexcept { return centres_.cols(); }
  [[nodiscard]] Index nonzeros() const noexcept { return nonzeros_; }
  [[nodiscard]] auto within() const {
    return [this](const Vec<Dim>& x, std::vector<Neighbor>& out) { tree_.radius_search(x, kernel_.radius, out); };
  }
  /// The polynomial basis, the serial RbfSystem's.
  [[nodiscard]] Vec<Dim + 1> polynomial(const Vec<Dim>& x) const { return polynomial_(x); }

  /// Collective. Coefficients (m × Dim, on every rank) interpolating `values` (m × Dim, the
  /// same on every rank).
  void solve(const Eigen::MatrixXd& values, Eigen::MatrixXd& alpha, PolyCoefficients& beta) {
    solve_a(values, alpha);
    polynomial_.eliminate(alpha, beta);
  }
  /// Collective. The transpose of solve() (A is symmetric): A⁻¹ (ᾱ + P S⁻ᵀ (β̄ − Gᵀ ᾱ)).
  void solve_transpose(const Eigen::MatrixXd& alpha_bar, const PolyCoefficients& beta_bar, Eigen::MatrixXd& values_bar) {
    solve_a(polynomial_.transpose_rhs(alpha_bar, beta_bar), values_bar);
  }

 private:

  // b: m rows on every rank. This rank's rows go in as one dense block, all columns solved in
  // one MUMPS call (one pass of communication for the Dim right-hand sides, not one each);
  // every rank gets the whole solution.
  void solve_a(const Eigen::MatrixXd& b, Eigen::MatrixXd& x) {
    constexpr const char* where = "DistributedRbfMover::move";
    const auto local = static_cast<PetscInt>(hi_ - lo_);
    const auto columns = static_cast<PetscInt>(b.cols());
    OwnedMat rhs, solution;
    petsc_check(MatCreateDense(comm_, local, PETSC_DECIDE, static_cast<PetscInt>(b.rows()), columns, nullptr, rhs.out()), where,
                "MatCreateDense");
    petsc_check(MatDuplicate(rhs.get(), MAT_DO_NOT_COPY_VALUES, solution.out()), where, "MatDuplicate");
    PetscScalar* block = nullptr;
    petsc_check(MatDenseGetArrayWrite(rhs.get(), &block), where, "MatDenseGetArrayWrite");
    Eigen::Map<Eigen::MatrixXd>(block, local, columns) = b.middleRows(lo_, local);
    petsc_check(MatDenseRestoreArrayWrite(rhs.get(), &block), where, "MatDenseRestoreArrayWrite");
    petsc_check(KSPMatSolve(ksp_.get(), rhs.get(), solution.get()), where, "KSPMatSolve");
    const PetscScalar* solved = nullptr;
    petsc_check(MatDenseGetArrayRead(solution.get(), &solved), where, "MatDenseGetArrayRead");
    // Row-major pieces, so that each rank's rows land contiguously in x's transpose.
    Eigen::MatrixXd mine = Eigen::Map<const Eigen::MatrixXd>(solved, local, columns).transpose();
    petsc_check(MatDenseRestoreArrayRead(solution.get(), &solved), where, "MatDenseRestoreArrayRead");
    const std::vector<double> all = all_gather(comm_, std::span<const double>(mine.data(), static_cast<std::size_t>(mine.size())));
    x = Eigen::Map<const Eigen::MatrixXd>(all.data(), columns, b.rows()).transpose();
  }

  MPI_Comm comm_ = MPI_COMM_NULL;
  Points<Dim> centres_;
  meshmotion::detail::RbfKernelSettings kernel_;
  KdTree<Dim> tree_;
  Index lo_ = 0, hi_ = 0, nonzeros_ = 0;
  OwnedMat a_;
  OwnedKsp ksp_;
  meshmotion::detail::RbfPolynomial<Dim> polynomial_;
};

}  // namespace meshmotion::parallel::detail
