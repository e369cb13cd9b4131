#pragma once
/// \file
/// The interpolation system of the RBF mover over a set of centres (thesis eqs. 2.10–2.13):
/// A α + P β = d, Pᵀ α = 0, with A_ij = φ(|c_i - c_j|) and P the optional linear polynomial
/// [1, x]. Compact kernels give a sparse A (assembled with k-d tree radius queries), global
/// kernels a dense one. The saddle-point system is never factorized: A is factorized once and
/// the polynomial part eliminated through the small Schur complement S = Pᵀ A⁻¹ P, which keeps
/// SimplicialLDLT applicable (A is SPD for Wendland kernels) and costs Dim + 1 extra solves in
/// setup.

#include "meshmotion/core/error.hpp"
#include "meshmotion/core/types.hpp"
#include "meshmotion/movers/rbf_kernels.hpp"
#include "meshmotion/solvers/dense_solver.hpp"
#include "meshmotion/solvers/linear_solver.hpp"
#include "meshmotion/spatial/kd_tree.hpp"

#include <Eigen/LU>


#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

namespace meshmotion::detail {

/// Kernel settings shared by the system and the evaluation operators.
struct RbfKernelSettings {
  RbfKernel kernel = RbfKernel::wendland2;
  double radius = 1.0;
  bool polynomial = false;
};

/// Rows of φ(|x_i - c_j|) for the points x_i (columns of `points` listed in `rows`) against
/// the centres in `tree`, compact kernels only: a row-major sparse matrix (rows.size() ×
/// n_centres; with `kept`, only the rows with some centre inside the support, their positions
/// in `rows` written to *kept). With `sorted` false the column indices of a row are in k-d
/// tree order: enough for products and for a storage-order conversion (which sorts), not for
/// coefficient access. Parallel over ranges of rows, each queried into one buffer that is
/// copied once into the matrix.
template <int Dim>
[[nodiscard]] Eigen::SparseMatrix<double, Eigen::RowMajor, int> compact_kernel_rows(
    const Points<Dim>& points, const std::vector<Index>& rows, const KdTree<Dim>& tree, Index n_centres,
    const RbfKernelSettings& k, bool sorted = true, std::vector<Index>* kept = nullptr) {
  const auto n = static_cast<Index>(rows.size());
  std::vector<int> count(static_cast<std::size_t>(n));
  // Contiguous row ranges, more of them than threads so that dynamic scheduling balances
  // rows with many and with no neighbours; each range's pairs go to one buffer, in row order.
  const Index chunks = std::clamp<Index>(n / 256, 1, 64);
  std::vector<std::vector<Neighbor>> found(static_cast<std::size_t>(chunks));
#pragma omp parallel
  {
    std::vector<Neighbor> buffer;
#pragma omp for schedule(dynamic, 1)
    for (Index c = 0; c < chunks; ++c) {
      std::vector<Neighbor>& pairs = found[static_cast<std::size_t>(c)];
      for (Index r = n * c / chunks; r < n * (c + 1) / chunks; ++r) {
        tree.radius_search(points.col(rows[static_cast<std::size_t>(r)]), k.radius, buffer);
        if (sorted) std::sort(buffer.begin(), buffer.end());
        count[static_cast<std::size_t>(r)] = static_cast<int>(buffer.size());
        pairs.insert(pairs.end(), buffer.begin(), buffer.end());
      }
    }
  }
  // Row offsets (skipping empty rows when asked) and where each range's pairs start.
  std::vector<int> outer;
  outer.reserve(static_cast<std::size_t>(n) + 1);
  outer.push_back(0);
  if (kept != nullptr) kept->clear();
  for (Index r = 0; r < n; ++r) {
    const int c = count[static_cast<std::size_t>(r)];
    if (kept != nullptr) {
      if (c == 0) continue;
      kept->push_back(r);
    }
    outer.push_back(outer.back() + c);
  }
  const auto n_out = static_cast<Index>(outer.size()) - 1;
  Eigen::SparseMatrix<double, Eigen::RowMajor, int> m(n_out, n_centres);
  m.resizeNonZeros(outer.back());
  std::copy(outer.begin(), outer.end(), m.outerIndexPtr());
  std::vector<Index> start(found.size() + 1, 0);
  for (std::size_t c = 0; c < found.size(); ++c) start[c + 1] = start[c] + static_cast<Index>(found[c].size());
#pragma omp parallel for schedule(dynamic, 1)
  for (Index c = 0; c < chunks; ++c) {
    const auto& pairs = found[static_cast<std::size_t>(c)];
    int* inner = m.innerIndexPtr() + start[static_cast<std::size_t>(c)];
    double* value = m.valuePtr() + start[static_cast<std::size_t>(c)];
    for (std::size_t i = 0; i < pairs.size(); ++i) {
      inner[i] = static_cast<int>(pairs[i].first);
      value[i] = rbf_value(k.kernel, std::sqrt(pairs[i].second), k.radius);
    }
  }
  return m;
}

template <int Dim>
class RbfSystem {
 public:
  using Coefficients = Eigen::Matrix<double, Eigen::Dynamic, Dim>;       ///< n_centres × Dim
  using PolyCoefficients = Eigen::Matrix<double, Dim + 1, Dim>;        ///< (Dim + 1) × Dim

  /// Assembles and factorizes the system over `centres` (Dim × k, distinct points).
  /// Throws InputError when a global kernel has more than `max_dense` centres, SolverError
  /// when the factorization fails.
  void setup(const Points<Dim>& centres, const RbfKernelSettings& kernel, const SolverOptions& sparse_options,
             DenseSolverKind dense_kind, Index max_dense) {
    centres_ = centres;
    kernel_ = kernel;
    const Index k = centres_.cols();
    tree_.build(centres_);
    if (k > 0) {
      shift_ = centres_.rowwise().mean();
      scale_ = std::max((centres_.colwise() - shift_).colwise().norm().maxCoeff(), 1e-300);
    }
    compact_ = is_compact(kernel.kernel);
    if (compact_) {
      std::vector<Index> all(static_cast<std::size_t>(k));
      for (Index i = 0; i < k; ++i) all[static_cast<std::size_t>(i)] = i;
      // The pattern is symmetric, so the row-major rows are the columns of a column-major A.
      const auto rows = compact_kernel_rows(centres_, all, tree_, k, kernel);
      const SparseMatrix a = rows.transpose();
      nonzeros_ = a.nonZeros();
      sparse_ = LinearSolver(sparse_options);
      sparse_.compute(a);
    } else {
      if (k > max_dense)
        throw InputError("RbfMover::setup: " + std::to_string(k) + " boundary nodes give a dense " +
                         std::string(name(kernel.kernel)) + " system beyond the limit (expected at most " +
                         std::to_string(max_dense) + "); use a compact kernel such as wendland2 or raise max_dense_centres");
      Eigen::MatrixXd a(k, k);
      for (Index j = 0; j < k; ++j)
        for (Index i = 0; i < k; ++i) a(i, j) = rbf_value(kernel.kernel, (centres_.col(i) - centres_.col(j)).norm(), kernel.radius);
      nonzeros_ = k * k;
      dense_ = DenseSolver(dense_kind);
      dense_.compute(a);
    }
    if (kernel.polynomial && k > 0) {
      Eigen::MatrixXd p(k, Dim + 1);
      for (Index i = 0; i < k; ++i) p.row(i) = polynomial(centres_.col(i)).transpose();
      solve_a(p, g_);
      const Eigen::Matrix<double, Dim + 1, Dim + 1> s = p.transpose() * g_;
      schur_.compute(s);
      if (!(std::abs(schur_.determinant()) > 1e-14 * std::max(1.0, s.norm())))
        throw InputError("RbfMover::setup: linear polynomial augmentation needs boundary nodes that span the space "
                         "(got them all on a line or plane)");
    }
  }

  [[nodiscard]] Index size() const noexcept { return centres_.cols(); }
  [[nodiscard]] const Points<Dim>& centres() const noexcept { return centres_; }
  [[nodiscard]] const KdTree<Dim>& tree() const noexcept { return tree_; }
  [[nodiscard]] const RbfKernelSettings& kernel() const noexcept { return kernel_; }
  [[nodiscard]] Index nonzeros() const noexcept { return nonzeros_; }
  [[nodiscard]] const SolverReport& report() const noexcept { return compact_ ? sparse_.report() : dense_.report(); }

  /// The polynomial basis [1, (x - shift)/scale] (scaled for conditioning).
  [[nodiscard]] Vec<Dim + 1> polynomial(const Vec<Dim>& x) const {
    Vec<Dim + 1> q;
    q[0] = 1.0;
    q.template tail<Dim>() = (x - shift_) / scale_;
    return q;
  }

  /// Coefficients interpolating `values` (k × Dim) at the centres. β is zero without
  /// augmentation.
  void solve(const Eigen::MatrixXd& values, Eigen::MatrixXd& alpha, PolyCoefficients& beta) {
    solve_a(values, alpha);
    beta.setZero();
    if (!kernel_.polynomial || size() == 0) return;
    // β = S⁻¹ Gᵀ d, α = A⁻¹ d - G β  (Gᵀ d = Pᵀ A⁻¹ d since A is symmetric).
    beta = schur_.solve(g_.transpose() * values);
    alpha.noalias() -= g_ * beta;
  }

  /// Transpose of solve(): the gradient with respect to `values` of ⟨ᾱ, α⟩ + ⟨β̄, β⟩.
  void solve_transpose(const Eigen::MatrixXd& alpha_bar, const PolyCoefficients& beta_bar, Eigen::MatrixXd& values_bar) {
    solve_a(alpha_bar, values_bar);
    if (!kernel_.polynomial || size() == 0) return;
    const PolyCoefficients t = schur_.solve(beta_bar - g_.transpose() * alpha_bar);
    values_bar.noalias() += g_ * t;
  }

 private:
  void solve_a(const Eigen::MatrixXd& b, Eigen::MatrixXd& x) {
    if (b.rows() == 0) {
      x.resize(0, b.cols());
      return;
    }
    if (compact_)
      sparse_.solve(b, x);
    else
      dense_.solve(b, x);
  }

  Points<Dim> centres_;
  RbfKernelSettings kernel_;
  KdTree<Dim> tree_;
  bool compact_ = true;
  LinearSolver sparse_;
  DenseSolver dense_;
  Index nonzeros_ = 0;
  Vec<Dim> shift_ = Vec<Dim>::Zero();
  double scale_ = 1.0;
  Eigen::MatrixXd g_;  ///< A⁻¹ P, k × (Dim + 1)
  Eigen::PartialPivLU<Eigen::Matrix<double, Dim + 1, Dim + 1>> schur_;
};

}  // namespace meshmotion::detail
