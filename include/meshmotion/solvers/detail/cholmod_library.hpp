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

#include <dlfcn.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <memory>

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
  /// The factor (null before a successful factorize) and the library's scope (its BLAS).
  [[nodiscard]] cholmod_factor* factor() noexcept { return info_ == Eigen::Success ? factor_ : nullptr; }
  [[nodiscard]] void* library() const noexcept { return api_.handle; }
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

/// A CholmodSupernodalLLT's factor in single precision, solved through the BLAS that CHOLMOD
/// loaded: for a preconditioner, whose solves with three right-hand sides are bound by reading
/// the factor (334 MB for a 27-point 3D matrix of 79,507 rows: 67 ms a solve in double through
/// CHOLMOD, 39 ms here). The factor is rounded in place, in the first half of CHOLMOD's own
/// array, so no second copy is ever held: a process that keeps its freed memory (under Open
/// MPI, or the programs' tuned heap) would keep both. Its answer is A⁻¹ B to about 1e-7,
/// relative: the factor is scaled by a power of two to a largest entry near 1, each column of
/// B to a largest entry of 1, before they are rounded (a stiffened system's factor spans 1e-40
/// to 1e-8 on a case at map coordinates); entries far below the largest become zero, which a
/// preconditioner does not see.
class SingleSupernodalFactor {
 public:
  /// Takes `llt`'s factor and rounds it: true, and `llt` is this object's from then on (null
  /// in the caller's hands). False, `llt` left as it was, when it has no factor, not a
  /// supernodal LLᵀ, the BLAS lacks strsm or sgemm, or a diagonal entry is too small beside
  /// the largest entry for float (1e-30 of it).
  bool take(std::unique_ptr<CholmodSupernodalLLT>& llt) {
    *this = SingleSupernodalFactor{};
    cholmod_factor* f = llt ? llt->factor() : nullptr;
    if (f == nullptr || !f->is_super || !f->is_ll || f->itype != CHOLMOD_INT || f->xtype != CHOLMOD_REAL ||
        f->dtype != CHOLMOD_DOUBLE)
      return false;
    const auto trsm = reinterpret_cast<Trsm>(dlsym(llt->library(), "strsm_"));
    const auto gemm = reinterpret_cast<Gemm>(dlsym(llt->library(), "sgemm_"));
    if (trsm == nullptr || gemm == nullptr) return false;
    const auto nsuper = static_cast<std::size_t>(f->nsuper);
    const int* super = static_cast<const int*>(f->super);
    const int* pi = static_cast<const int*>(f->pi);
    const int* px = static_cast<const int*>(f->px);
    const auto count = static_cast<std::size_t>(px[nsuper]);
    double* x = static_cast<double*>(f->x);
    double largest = 0.0;
    for (std::size_t k = 0; k < count; ++k) largest = std::max(largest, std::abs(x[k]));
    if (!(largest > 0.0) || !std::isfinite(largest)) return false;
    const double scale = std::ldexp(1.0, -std::ilogb(largest));
    for (std::size_t q = 0; q < nsuper; ++q) {
      const int rows = pi[q + 1] - pi[q];
      for (int j = 0; j < super[q + 1] - super[q]; ++j)
        if (!(scale * x[static_cast<std::size_t>(px[q]) + static_cast<std::size_t>(j) * static_cast<std::size_t>(rows + 1)] >= 1e-30))
          return false;
    }
    // Entry k's float goes to bytes 4k, below every double not yet read (bytes 8k on).
    auto* bytes = reinterpret_cast<unsigned char*>(x);
    for (std::size_t k = 0; k < count; ++k) {
      double value;
      std::memcpy(&value, bytes + 8 * k, sizeof value);
      const auto rounded = static_cast<float>(scale * value);
      std::memcpy(bytes + 4 * k, &rounded, sizeof rounded);
    }
    owner_ = std::move(llt);
    factor_ = f;
    values_ = reinterpret_cast<const float*>(bytes);
    scale_ = scale;
    trsm_ = trsm;
    gemm_ = gemm;
    return true;
  }

  /// B ← A⁻¹ B, every column in one pass over the factor.
  void solve_in_place(Eigen::MatrixXd& b) {
    const int k = static_cast<int>(b.cols()), n = static_cast<int>(factor_->n);
    const int* perm = static_cast<const int*>(factor_->Perm);
    Eigen::RowVectorXd scale = b.cwiseAbs().colwise().maxCoeff();
    for (int c = 0; c < k; ++c)
      if (!(scale(c) > 0.0)) scale(c) = 1.0;
    y_.resize(n, k);
    // One buffer for every supernode's rows below its triangle (at most maxesize of them),
    // each viewed with its own leading dimension: resizing it per supernode allocated twice
    // per supernode and solve.
    below_.resize(static_cast<Eigen::Index>(factor_->maxesize) * k);
    for (int c = 0; c < k; ++c)
      for (int r = 0; r < n; ++r) y_(r, c) = static_cast<float>(b(perm[r], c) / scale(c));
    const float one = 1.0F, zero = 0.0F, minus = -1.0F;
    const auto nsuper = static_cast<int>(factor_->nsuper);
    // L y = P b, supernode by supernode: the diagonal block's triangle, then its rows below.
    for (int q = 0; q < nsuper; ++q) {
      Block s = block(q);
      trsm_("L", "L", "N", "N", &s.columns, &k, &one, s.values, &s.rows, &y_(s.first, 0), &n);
      if (s.below == 0) continue;
      const Eigen::Map<Eigen::MatrixXf> below(below_.data(), s.below, k);
      gemm_("N", "N", &s.below, &k, &s.columns, &one, s.values + s.columns, &s.rows, &y_(s.first, 0), &n, &zero, below_.data(), &s.below);
      for (int c = 0; c < k; ++c)
        for (int i = 0; i < s.below; ++i) y_(s.below_rows[i], c) -= below(i, c);
    }
    // Lᵀ x = y, from the last supernode back.
    for (int q = nsuper - 1; q >= 0; --q) {
      Block s = block(q);
      if (s.below > 0) {
        Eigen::Map<Eigen::MatrixXf> below(below_.data(), s.below, k);
        for (int c = 0; c < k; ++c)
          for (int i = 0; i < s.below; ++i) below(i, c) = y_(s.below_rows[i], c);
        gemm_("T", "N", &s.columns, &k, &s.below, &minus, s.values + s.columns, &s.rows, below_.data(), &s.below, &one, &y_(s.first, 0), &n);
      }
      trsm_("L", "L", "T", "N", &s.columns, &k, &one, s.values, &s.rows, &y_(s.first, 0), &n);
    }
    // The factor solved was scale_ L: (scale_ L)⁻ᵀ (scale_ L)⁻¹ = A⁻¹ / scale_².
    for (int c = 0; c < k; ++c) {
      const double back = scale(c) * scale_ * scale_;
      for (int r = 0; r < n; ++r) b(perm[r], c) = static_cast<double>(y_(r, c)) * back;
    }
  }

 private:
  using Trsm = void (*)(const char*, const char*, const char*, const char*, const int*, const int*, const float*, const float*,
                        const int*, float*, const int*);
  using Gemm = void (*)(const char*, const char*, const int*, const int*, const int*, const float*, const float*, const int*,
                        const float*, const int*, const float*, float*, const int*);
  /// A supernode: its first column, its columns, its rows (the diagonal block's first), the
  /// rows below the diagonal block and their indices, its values (column-major, rows × columns).
  struct Block {
    int first, columns, rows, below;
    const int* below_rows;
    const float* values;
  };
  [[nodiscard]] Block block(int q) const {
    const auto u = static_cast<std::size_t>(q);
    const int* super = static_cast<const int*>(factor_->super);
    const int* pi = static_cast<const int*>(factor_->pi);
    const int* px = static_cast<const int*>(factor_->px);
    const int columns = super[u + 1] - super[u], rows = pi[u + 1] - pi[u];
    return {super[u], columns, rows, rows - columns, static_cast<const int*>(factor_->s) + pi[u] + columns, values_ + px[u]};
  }

  std::unique_ptr<CholmodSupernodalLLT> owner_;  ///< whose factor this is (its numbers rounded: it solves nothing)
  const cholmod_factor* factor_ = nullptr;
  const float* values_ = nullptr;                ///< the first half of the factor's array
  double scale_ = 1.0;                           ///< the rounded factor is scale_ L
  Trsm trsm_ = nullptr;
  Gemm gemm_ = nullptr;
  Eigen::MatrixXf y_;
  Eigen::VectorXf below_;
};

}  // namespace meshmotion::detail

#undef MESHMOTION_CHOLMOD_FUNCTIONS

#endif  // MESHMOTION_HAVE_CHOLMOD
