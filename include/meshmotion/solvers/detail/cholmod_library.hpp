#pragma once
/// \file
/// CHOLMOD's functions, loaded on first use instead of linked (core/detail/shared_library.hpp).
/// libcholmod brings OpenBLAS, LAPACK and gfortran, whose loading and start-up cost every
/// program at start (twice with the huge-page restart of core/process_memory.hpp), while only
/// systems of supernodal_min_rows rows or more go to CHOLMOD. CMake passes the library it found
/// as MESHMOTION_CHOLMOD_LIBRARY.

#ifdef MESHMOTION_HAVE_CHOLMOD

#include "meshmotion/core/detail/shared_library.hpp"
#include "meshmotion/core/error.hpp"
#include "meshmotion/core/threads.hpp"

#include <Eigen/Core>
#include <cholmod.h>

#include <cstddef>

#ifndef MESHMOTION_CHOLMOD_LIBRARY
#define MESHMOTION_CHOLMOD_LIBRARY "libcholmod.so"
#endif

// Every function of CHOLMOD that solvers/linear_solver.hpp calls.
#define MESHMOTION_CHOLMOD_FUNCTIONS(X) \
  X(cholmod_start) X(cholmod_finish) X(cholmod_analyze) X(cholmod_factorize) X(cholmod_solve) X(cholmod_free_factor) X(cholmod_free_dense)

namespace meshmotion::detail {

struct CholmodLibrary {
  MESHMOTION_CHOLMOD_FUNCTIONS(MESHMOTION_LIBRARY_MEMBER)
  void* handle = nullptr;  ///< the library and what it loaded (its BLAS), for set_blas_threads()
};

/// The loaded library (opened once). Throws SolverError naming the library when it cannot be
/// loaded or lacks a function.
inline const CholmodLibrary& cholmod_api() {
  return loaded_api<CholmodLibrary, SolverError>(
      MESHMOTION_CHOLMOD_LIBRARY, "CHOLMOD",
      [](const LoadedLibrary<SolverError>& library, CholmodLibrary& api) {
        MESHMOTION_CHOLMOD_FUNCTIONS(MESHMOTION_LIBRARY_LOAD)
        api.handle = library.handle();
      });
}

/// CHOLMOD's supernodal LLᵀ of a symmetric matrix's lower triangle: the calls of Eigen's
/// CholmodSupernodalLLT, made through the library loaded on first use, behind the same
/// interface (analyzePattern, factorize, info, solve).
class CholmodSupernodalLLT {
 public:
  CholmodSupernodalLLT() : api_(cholmod_api()) {
    api_.cholmod_start(&common_);
    common_.final_asis = 1;
    common_.supernodal = CHOLMOD_SUPERNODAL;
  }
  CholmodSupernodalLLT(const CholmodSupernodalLLT&) = delete;
  CholmodSupernodalLLT& operator=(const CholmodSupernodalLLT&) = delete;
  ~CholmodSupernodalLLT() {
    free_factor();
    api_.cholmod_finish(&common_);
  }

  template <class Matrix>
  void analyzePattern(const Matrix& a) {
    free_factor();
    cholmod_sparse view = lower_view(a);
    factor_ = api_.cholmod_analyze(&view, &common_);
    info_ = factor_ != nullptr ? Eigen::Success : Eigen::NumericalIssue;
  }
  /// info() is NumericalIssue when the matrix is not positive definite.
  template <class Matrix>
  void factorize(const Matrix& a) {
    if (factor_ == nullptr) return;
    cholmod_sparse view = lower_view(a);
    // The BLAS's threads follow the library's (set_num_threads(): one rank's share of a node).
    set_blas_threads(api_.handle, num_threads());
    api_.cholmod_factorize(&view, factor_, &common_);
    info_ = factor_->minor == factor_->n ? Eigen::Success : Eigen::NumericalIssue;
  }
  [[nodiscard]] Eigen::ComputationInfo info() const noexcept { return info_; }
  /// A⁻¹ B (every column in one pass over the factor); info() is NumericalIssue when CHOLMOD
  /// fails.
  [[nodiscard]] Eigen::MatrixXd solve(const Eigen::Ref<const Eigen::MatrixXd>& b) {
    Eigen::MatrixXd x;
    if (factor_ == nullptr || info_ != Eigen::Success) return x;
    cholmod_dense rhs{};
    rhs.nrow = static_cast<std::size_t>(b.rows());
    rhs.ncol = static_cast<std::size_t>(b.cols());
    rhs.d = static_cast<std::size_t>(b.outerStride());
    rhs.nzmax = rhs.d * rhs.ncol;
    rhs.x = const_cast<double*>(b.data());  // read only: CHOLMOD's API is not const-correct
    rhs.xtype = CHOLMOD_REAL;
    rhs.dtype = CHOLMOD_DOUBLE;
    cholmod_dense* solution = api_.cholmod_solve(CHOLMOD_A, factor_, &rhs, &common_);
    if (solution == nullptr) {
      info_ = Eigen::NumericalIssue;
      return x;
    }
    x = Eigen::Map<const Eigen::MatrixXd>(static_cast<const double*>(solution->x), b.rows(), b.cols());
    api_.cholmod_free_dense(&solution, &common_);
    return x;
  }

 private:
  template <class Matrix>
  [[nodiscard]] static cholmod_sparse lower_view(const Matrix& a) {
    cholmod_sparse view{};
    view.nrow = static_cast<std::size_t>(a.rows());
    view.ncol = static_cast<std::size_t>(a.cols());
    view.nzmax = static_cast<std::size_t>(a.nonZeros());
    // Compressed column storage with int indices (LinearSolver's), read only.
    view.p = const_cast<int*>(a.outerIndexPtr());
    view.i = const_cast<int*>(a.innerIndexPtr());
    view.x = const_cast<double*>(a.valuePtr());
    view.stype = -1;
    view.itype = CHOLMOD_INT;
    view.xtype = CHOLMOD_REAL;
    view.dtype = CHOLMOD_DOUBLE;
    view.sorted = 1;
    view.packed = 1;
    return view;
  }
  void free_factor() {
    if (factor_ != nullptr) api_.cholmod_free_factor(&factor_, &common_);
  }

  const CholmodLibrary& api_;
  cholmod_common common_{};
  cholmod_factor* factor_ = nullptr;
  Eigen::ComputationInfo info_ = Eigen::Success;
};

}  // namespace meshmotion::detail

#undef MESHMOTION_CHOLMOD_FUNCTIONS

#endif  // MESHMOTION_HAVE_CHOLMOD
