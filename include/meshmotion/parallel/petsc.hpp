#pragma once
/// \file
/// PETSc plumbing of the parallel layer: one check that keeps PETSc's own message, handles
/// that destroy what they hold on every path (an exception between a create and its destroy
/// no longer leaks a matrix), and the MUMPS Cholesky that the elasticity and RBF paths share.

#include "meshmotion/core/error.hpp"

#include <petscksp.h>

#include <string>
#include <utility>

namespace meshmotion::parallel::detail {

/// Throws SolverError naming `where`, the PETSc `call` that failed and PETSc's text for `code`.
inline void petsc_check(PetscErrorCode code, const char* where, const char* call) {
  if (code == 0) return;
  std::string message = where;
  message += ": PETSc's ";
  message += call;
  message += " failed (error ";
  message += std::to_string(static_cast<int>(code));
  const char* text = nullptr;
  if (PetscErrorMessage(code, &text, nullptr) == 0 && text != nullptr) {
    message += ": ";
    message += text;
  }
  message += ")";
  throw SolverError(message);
}

/// Owns one PETSc object and destroys it with `Destroy` (MatDestroy, VecDestroy, ...).
template <class Handle, PetscErrorCode (*Destroy)(Handle*)>
class Owned {
 public:
  Owned() = default;
  Owned(const Owned&) = delete;
  Owned& operator=(const Owned&) = delete;
  Owned(Owned&& other) noexcept : handle_(std::exchange(other.handle_, nullptr)) {}
  Owned& operator=(Owned&& other) noexcept {
    if (this != &other) {
      reset();
      handle_ = std::exchange(other.handle_, nullptr);
    }
    return *this;
  }
  ~Owned() { reset(); }

  /// Destroys the object held, if any. A failure to destroy is PETSc's to report: nothing is
  /// thrown from here (destructors and error paths call it).
  void reset() noexcept {
    if (handle_ != nullptr) (void)Destroy(&handle_);
    handle_ = nullptr;
  }
  /// Where a PETSc create call writes the new object (what was held is destroyed first).
  [[nodiscard]] Handle* out() noexcept {
    reset();
    return &handle_;
  }
  [[nodiscard]] Handle get() const noexcept { return handle_; }
  [[nodiscard]] explicit operator bool() const noexcept { return handle_ != nullptr; }

 private:
  Handle handle_ = nullptr;
};

using OwnedMat = Owned<Mat, MatDestroy>;
using OwnedVec = Owned<::Vec, VecDestroy>;
using OwnedKsp = Owned<KSP, KSPDestroy>;
using OwnedIs = Owned<IS, ISDestroy>;
using OwnedScatter = Owned<VecScatter, VecScatterDestroy>;
using OwnedNullSpace = Owned<MatNullSpace, MatNullSpaceDestroy>;

/// MUMPS's ICNTL(7), the ordering of its analysis, and the value that picks METIS: on these
/// meshes MUMPS's automatic choice fills about twice as much.
inline constexpr PetscInt mumps_icntl_ordering = 7;
inline constexpr PetscInt mumps_ordering_metis = 5;

/// Makes `ksp` (operators set) one Cholesky factorization by MUMPS with METIS ordering, solved
/// without iterations.
inline void use_mumps_cholesky(KSP ksp, const char* where) {
  petsc_check(KSPSetType(ksp, KSPPREONLY), where, "KSPSetType");
  PC pc = nullptr;
  petsc_check(KSPGetPC(ksp, &pc), where, "KSPGetPC");
  petsc_check(PCSetType(pc, PCCHOLESKY), where, "PCSetType");
  petsc_check(PCFactorSetMatSolverType(pc, MATSOLVERMUMPS), where, "PCFactorSetMatSolverType");
  petsc_check(PCFactorSetUpMatSolverType(pc), where, "PCFactorSetUpMatSolverType");
  Mat factor = nullptr;
  petsc_check(PCFactorGetMatrix(pc, &factor), where, "PCFactorGetMatrix");
  petsc_check(MatMumpsSetIcntl(factor, mumps_icntl_ordering, mumps_ordering_metis), where, "MatMumpsSetIcntl");
}

}  // namespace meshmotion::parallel::detail
