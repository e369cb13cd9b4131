#pragma once
/// \file
/// O(n) solvers for the tridiagonal and cyclic tridiagonal systems of cubic-spline
/// reconstruction (thesis eqs. B.13 and B.14): the Thomas algorithm and, for the cyclic
/// case, a Sherman–Morrison correction of two Thomas solves. No dense matrix is formed.

#include "meshmotion/core/error.hpp"

#include <cmath>
#include <cstddef>
#include <span>
#include <string>
#include <vector>

namespace meshmotion::detail {

/// Solves T x = rhs in place, T tridiagonal (Thomas algorithm, no pivoting: meant for the
/// diagonally dominant spline systems).
/// `sub[i]` is T(i, i-1) (sub[0] unused), `diag[i]` is T(i, i), `sup[i]` is T(i, i+1)
/// (sup[n-1] unused); all spans have the same length n >= 1. `rhs` holds n values of T
/// (double or a fixed-size Eigen vector: each component is an independent right-hand side)
/// and is overwritten by the solution. `scratch` is resized to n (reuse it to avoid
/// allocations). Throws SolverError on a zero or non-finite pivot.
template <class Value>
void solve_tridiagonal(std::span<const double> sub, std::span<const double> diag,
                       std::span<const double> sup, std::span<Value> rhs,
                       std::vector<double>& scratch) {
  const std::size_t n = diag.size();
  scratch.resize(n);
  auto pivot_check = [](double pivot, std::size_t row) {
    if (!(std::abs(pivot) > 0.0) || !std::isfinite(pivot))
      throw SolverError("solve_tridiagonal: zero or non-finite pivot in row " +
                        std::to_string(row) + " (got " + std::to_string(pivot) +
                        ", expected a nonzero number)");
  };
  pivot_check(diag[0], 0);
  scratch[0] = n > 1 ? sup[0] / diag[0] : 0.0;
  rhs[0] = rhs[0] / diag[0];
  for (std::size_t i = 1; i < n; ++i) {
    const double pivot = diag[i] - sub[i] * scratch[i - 1];
    pivot_check(pivot, i);
    scratch[i] = i + 1 < n ? sup[i] / pivot : 0.0;
    rhs[i] = (rhs[i] - sub[i] * rhs[i - 1]) / pivot;
  }
  for (std::size_t i = n - 1; i-- > 0;) rhs[i] = rhs[i] - scratch[i] * rhs[i + 1];
}

/// Work arrays of solve_cyclic_tridiagonal, kept by the caller so that repeated solves do
/// not allocate.
struct CyclicWorkspace {
  std::vector<double> diag;
  std::vector<double> correction;
  std::vector<double> scratch;
};

/// Solves C x = rhs in place, C the cyclic tridiagonal matrix of `sub`, `diag`, `sup` (as in
/// solve_tridiagonal) plus the corner entries C(n-1, 0) = `lower_corner` and
/// C(0, n-1) = `upper_corner`; n >= 3. Sherman–Morrison (C = T + u v^T with T tridiagonal):
/// two O(n) Thomas solves. Throws SolverError when the system is singular.
template <class Value>
void solve_cyclic_tridiagonal(std::span<const double> sub, std::span<const double> diag,
                              std::span<const double> sup, double lower_corner,
                              double upper_corner, std::span<Value> rhs,
                              CyclicWorkspace& work) {
  const std::size_t n = diag.size();
  if (n < 3)
    throw SolverError("solve_cyclic_tridiagonal: system too small (got " + std::to_string(n) +
                      " rows, expected at least 3)");
  // gamma = -diag[0] keeps the modified first pivot away from zero (Numerical Recipes 2.7).
  const double gamma = -diag[0];
  work.diag.assign(diag.begin(), diag.end());
  work.diag[0] -= gamma;
  work.diag[n - 1] -= lower_corner * upper_corner / gamma;
  const std::span<const double> modified(work.diag);
  solve_tridiagonal(sub, modified, sup, rhs, work.scratch);

  work.correction.assign(n, 0.0);
  work.correction[0] = gamma;
  work.correction[n - 1] = lower_corner;
  solve_tridiagonal(sub, modified, sup, std::span<double>(work.correction), work.scratch);

  const double ratio = upper_corner / gamma;
  const double denominator = 1.0 + work.correction[0] + ratio * work.correction[n - 1];
  if (!(std::abs(denominator) > 0.0))
    throw SolverError("solve_cyclic_tridiagonal: singular cyclic system");
  const Value factor = (rhs[0] + ratio * rhs[n - 1]) / denominator;
  for (std::size_t i = 0; i < n; ++i) rhs[i] = rhs[i] - work.correction[i] * factor;
}

}  // namespace meshmotion::detail
