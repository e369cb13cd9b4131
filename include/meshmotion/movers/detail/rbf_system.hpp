#pragma once
/// \file
/// The interpolation system of the RBF mover over a set of centres (thesis eqs. 2.10–2.13):
/// A α + P β = d, Pᵀ α = 0, with A_ij = φ(|c_i - c_j| / ρ_j) and P the optional linear
/// polynomial [1, x]. Compact kernels give a sparse A (assembled with k-d tree radius
/// queries), global kernels a dense one. The saddle-point system is never factorized: A is
/// factorized once and the polynomial part eliminated through the small Schur complement
/// S = Pᵀ A⁻¹ P, which keeps SimplicialLDLT applicable (A is SPD for Wendland kernels) and
/// costs Dim + 1 extra solves in setup.
///
/// One radius ρ for every centre gives a symmetric A. A radius per centre (a support that
/// follows each wall's boundary layer) keeps the interpolant s(x) = Σ_j α_j φ(|x - c_j| / ρ_j)
/// consistent between the system and the evaluation, but A is then symmetric only where every
/// pair of centres within each other's support shares its radius (walls whose supports do not
/// meet, a far field whose radius reaches no other node). A compact A that is not is
/// factorized by LU (symmetric solver kinds are replaced by sparse LU, dense Cholesky by
/// partial-pivoting LU), and transposed solves (the mover's reverse derivative) factorize Aᵀ
/// on first use.

#include "meshmotion/core/error.hpp"
#include "meshmotion/core/threads.hpp"
#include "meshmotion/core/types.hpp"
#include "meshmotion/movers/rbf_kernels.hpp"
#include "meshmotion/solvers/dense_solver.hpp"
#include "meshmotion/solvers/linear_solver.hpp"
#include "meshmotion/spatial/kd_tree.hpp"

#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <vector>

namespace meshmotion::detail {

/// Kernel settings shared by the system and the evaluation operators.
struct RbfKernelSettings {
  RbfKernel kernel = RbfKernel::wendland2;
  /// The radius of every centre; with `radii`, their maximum (the reach of radius queries).
  double radius = 1.0;
  bool polynomial = false;
  /// Radius of each centre (empty: `radius` for all).
  std::vector<double> radii{};

  [[nodiscard]] double radius_of(Index centre) const {
    return radii.empty() ? radius : radii[static_cast<std::size_t>(centre)];
  }
  /// Settings of the first `count` centres (the radii follow the centres).
  [[nodiscard]] RbfKernelSettings leading(Index count) const {
    RbfKernelSettings out = *this;
    if (!radii.empty()) out.radii.resize(static_cast<std::size_t>(count));
    return out;
  }
  /// True when the centres' radii differ (A is then not symmetric).
  [[nodiscard]] bool varying() const {
    return std::any_of(radii.begin(), radii.end(), [&](double r) { return r != radii.front(); });
  }
};

/// A row-major matrix (columns `cols`) with rows of count[r] entries, its inner indices and
/// values left to fill; with `kept`, rows of no entry are left out and the positions of the
/// others written to *kept.
[[nodiscard]] inline Eigen::SparseMatrix<double, Eigen::RowMajor, int> rows_of_counts(const std::vector<int>& count,
                                                                                     Index cols, std::vector<Index>* kept) {
  std::vector<int> outer;
  outer.reserve(count.size() + 1);
  outer.push_back(0);
  if (kept != nullptr) kept->clear();
  for (std::size_t r = 0; r < count.size(); ++r) {
    if (kept != nullptr) {
      if (count[r] == 0) continue;
      kept->push_back(static_cast<Index>(r));
    }
    outer.push_back(outer.back() + count[r]);
  }
  Eigen::SparseMatrix<double, Eigen::RowMajor, int> m(static_cast<Index>(outer.size()) - 1, cols);
  m.resizeNonZeros(outer.back());
  std::copy(outer.begin(), outer.end(), m.outerIndexPtr());
  return m;
}

/// Rows of φ(|x_i - c_j| / ρ_j) for the points x_i (columns of `points` listed in `rows`)
/// against the centres that `within(x, out)` lists for x (pairs of centre index and squared
/// distance, each centre within its own radius), compact kernels only: a row-major sparse
/// matrix (rows.size() × n_centres; with `kept`, only the rows with some centre inside the
/// support, their positions in `rows` written to *kept). The column indices of a row are in
/// query order: enough for products and for a storage-order conversion (which sorts), not for
/// coefficient access. Parallel over ranges of rows, each queried into one
/// buffer that is copied once into the matrix; `within` must be safe to call concurrently.
template <int Dim, class Within>
[[nodiscard]] Eigen::SparseMatrix<double, Eigen::RowMajor, int> compact_kernel_rows(
    const Points<Dim>& points, const std::vector<Index>& rows, Within&& within, Index n_centres,
    const RbfKernelSettings& k, std::vector<Index>* kept = nullptr) {
  const auto n = static_cast<Index>(rows.size());
  std::vector<int> count(static_cast<std::size_t>(n));
  // Contiguous row ranges, more of them than threads so that dynamic scheduling balances
  // rows with many and with no neighbours; each range's pairs go to one buffer, in row order.
  const Index chunks = std::clamp<Index>(n / 256, 1, 64);
  std::vector<std::vector<Neighbor>> found(static_cast<std::size_t>(chunks));
  RegionErrors errors;
#pragma omp parallel num_threads(::meshmotion::num_threads())
  {
    std::vector<Neighbor> buffer;
#pragma omp for schedule(dynamic, 1)
    for (Index c = 0; c < chunks; ++c)
      errors.run([&] {
        std::vector<Neighbor>& pairs = found[static_cast<std::size_t>(c)];
        for (Index r = n * c / chunks; r < n * (c + 1) / chunks; ++r) {
          within(Vec<Dim>(points.col(rows[static_cast<std::size_t>(r)])), buffer);
          count[static_cast<std::size_t>(r)] = static_cast<int>(buffer.size());
          pairs.insert(pairs.end(), buffer.begin(), buffer.end());
        }
      });
  }
  errors.rethrow();
  Eigen::SparseMatrix<double, Eigen::RowMajor, int> m = rows_of_counts(count, n_centres, kept);
  // Where each range's pairs start.
  std::vector<Index> start(found.size() + 1, 0);
  for (std::size_t c = 0; c < found.size(); ++c) start[c + 1] = start[c] + static_cast<Index>(found[c].size());
#pragma omp parallel for num_threads(::meshmotion::num_threads()) schedule(dynamic, 1)
  for (Index c = 0; c < chunks; ++c) {
    const auto& pairs = found[static_cast<std::size_t>(c)];
    int* inner = m.innerIndexPtr() + start[static_cast<std::size_t>(c)];
    double* value = m.valuePtr() + start[static_cast<std::size_t>(c)];
    for (std::size_t i = 0; i < pairs.size(); ++i) {
      inner[i] = static_cast<int>(pairs[i].first);
      value[i] = rbf_value(k.kernel, std::sqrt(pairs[i].second), k.radius_of(pairs[i].first));
    }
  }
  return m;
}

/// Kernel rows (compact_kernel_rows(), evaluation_rows()): a row-major sparse matrix E whose
/// columns are centres.
using KernelRows = Eigen::SparseMatrix<double, Eigen::RowMajor, int>;

/// Row r of E X for each row r, handed to `put(r, value)` (Vec<Dim>) on the library's threads:
/// X has a row per column of E (a centre's or a patch coefficient's values), copied transposed
/// into `columns` (a caller's buffer) so that one pass over E gives every component from
/// contiguous values. Eigen's product makes a pass over E per component, each through a column
/// of X: on a volume-sized E, Dim times the memory traffic. Each component is Eigen's sum, in
/// the same order.
template <int Dim, class Put>
void kernel_rows_times(const KernelRows& e, const Eigen::MatrixXd& x, Points<Dim>& columns, Put&& put) {
  columns = x.transpose();
  const Index n = e.outerSize();
  // Eigen's own threshold for a threaded sparse product: below it the threads cost more.
  const bool threaded = e.nonZeros() > 20000;
#pragma omp parallel for num_threads(::meshmotion::num_threads()) schedule(static) if (threaded)
  for (Index r = 0; r < n; ++r) {
    Vec<Dim> sum = Vec<Dim>::Zero();
    for (KernelRows::InnerIterator it(e, r); it; ++it) sum += it.value() * columns.col(it.index());
    put(r, sum);
  }
}

/// Eᵀ V (E's columns × Dim, into `out`: a matrix, or a map of that shape) for the seed V whose
/// row r is `seed(r)` (Vec<Dim>): one pass over E, each nonzero adding its row's seed to its
/// column's Dim contiguous sums (`sums`, a caller's buffer). Serial: every sum runs over the
/// rows in order whatever the threads, as in Eigen's transposed product, which scatters each
/// nonzero into Dim columns a column's length apart.
template <int Dim, class Seed, class Out>
void kernel_rows_transpose_times(const KernelRows& e, Seed&& seed, Points<Dim>& sums, Out&& out) {
  sums.setZero(Dim, e.cols());
  for (Index r = 0; r < e.outerSize(); ++r) {
    const Vec<Dim> s = seed(r);
    for (KernelRows::InnerIterator it(e, r); it; ++it) sums.col(it.index()) += it.value() * s;
  }
  out = sums.transpose();
}

/// The linear polynomial part of an augmented system over its centres, eliminated through the
/// Schur complement S = Pᵀ A⁻¹ P: with α₀ = A⁻¹ d, β = S⁻¹ Pᵀ α₀ and α = α₀ - G β (G = A⁻¹ P).
/// The basis [1, (x - shift)/scale] is scaled to the centres for conditioning. Shared by the
/// serial system and the distributed one (parallel/petsc_rbf_system.hpp), which differ only in
/// how they solve with A.
template <int Dim>
class RbfPolynomial {
 public:
  using Coefficients = Eigen::Matrix<double, Dim + 1, Dim>;  ///< β, (Dim + 1) × Dim

  /// Scales the basis to `centres` and, when `augmented`, factorizes S with `solve_a(b, x)`
  /// solving A x = b. Throws InputError (naming `where`) when the centres lie on a line or a
  /// plane, where S is singular.
  template <class SolveA>
  void setup(const Points<Dim>& centres, bool augmented, SolveA&& solve_a, const char* where) {
    const Index k = centres.cols();
    shift_ = k > 0 ? Vec<Dim>(centres.rowwise().mean()) : Vec<Dim>::Zero();
    scale_ = k > 0 ? std::max((centres.colwise() - shift_).colwise().norm().maxCoeff(), 1e-300) : 1.0;
    p_.resize(0, 0);
    g_.resize(0, 0);
    if (!augmented || k == 0) return;
    p_.resize(k, Dim + 1);
    for (Index i = 0; i < k; ++i) p_.row(i) = (*this)(centres.col(i)).transpose();
    solve_a(p_, g_);
    const Eigen::Matrix<double, Dim + 1, Dim + 1> s = p_.transpose() * g_;
    schur_.compute(s);
    if (!(std::abs(schur_.determinant()) > 1e-14 * std::max(1.0, s.norm())))
      throw InputError(std::string(where) +
                       ": linear polynomial augmentation needs boundary nodes that span the space "
                       "(got them all on a line or plane)");
  }

  /// The basis at x.
  [[nodiscard]] Vec<Dim + 1> operator()(const Vec<Dim>& x) const {
    Vec<Dim + 1> q;
    q[0] = 1.0;
    q.template tail<Dim>() = (x - shift_) / scale_;
    return q;
  }

  /// α₀ = A⁻¹ d in, α out, and β (zero without augmentation).
  void eliminate(Eigen::MatrixXd& alpha, Coefficients& beta) const {
    beta.setZero();
    if (p_.rows() == 0) return;
    beta = schur_.solve(p_.transpose() * alpha);
    alpha.noalias() -= g_ * beta;
  }

  /// The transpose of eliminate(): ᾱ + P S⁻ᵀ (β̄ - Gᵀ ᾱ), the right-hand side that Aᵀ
  /// turns into the gradient with respect to d.
  [[nodiscard]] Eigen::MatrixXd transpose_rhs(const Eigen::MatrixXd& alpha_bar, const Coefficients& beta_bar) const {
    Eigen::MatrixXd rhs = alpha_bar;
    if (p_.rows() > 0) rhs.noalias() += p_ * schur_.transpose().solve(beta_bar - g_.transpose() * alpha_bar);
    return rhs;
  }

 private:
  Vec<Dim> shift_ = Vec<Dim>::Zero();
  double scale_ = 1.0;
  Eigen::MatrixXd p_;  ///< P, k × (Dim + 1); empty without augmentation
  Eigen::MatrixXd g_;  ///< A⁻¹ P, k × (Dim + 1)
  Eigen::PartialPivLU<Eigen::Matrix<double, Dim + 1, Dim + 1>> schur_;
};

template <int Dim>
class RbfSystem {
 public:
  using Coefficients = Eigen::Matrix<double, Eigen::Dynamic, Dim>;       ///< n_centres × Dim
  using PolyCoefficients = typename RbfPolynomial<Dim>::Coefficients;

  /// Assembles and factorizes the system over `centres` (Dim × k, distinct points; with
  /// kernel.radii, one radius each). Throws InputError when a global kernel has more than
  /// `max_dense` centres, SolverError when the factorization fails.
  ///
  /// A compact system whose estimated condition exceeds `condition_limit` (> 0) is thinned:
  /// centres within a spacing h of an earlier kept one keep their value but take as radius
  /// their distance to the nearest other centre, so no other centre sees them and A becomes
  ///   [A_kk 0; A_tk I]
  /// (k kept, t thinned): its condition is that of the kept centres' system, which h bounds.
  /// The interpolant still meets every centre's value: the kept centres carry the motion at
  /// their radius, each thinned one adds a bump that closes what is left at it, no wider than
  /// the gap to its neighbour. h starts from the closest pair, scaled by the cube root of the
  /// excess (the condition grows about as (radius / closest pair)³), and grows until the
  /// estimate is within the limit or a few rounds are spent (thinned() says how many centres).
  void setup(const Points<Dim>& centres, const RbfKernelSettings& kernel, SolverOptions sparse_options,
             DenseSolverKind dense_kind, Index max_dense, double condition_limit = 0.0) {
    thinned_ = 0;
    const bool cure = is_compact(kernel.kernel) && condition_limit > 0.0 && centres.cols() > 1;
    std::exception_ptr failure;
    try {
      assemble(centres, kernel, sparse_options, dense_kind, max_dense);
    } catch (const SolverError&) {
      // A system too ill-conditioned to factorize or to pass the residual check is what
      // thinning cures.
      if (!cure) throw;
      failure = std::current_exception();
      condition_ = std::numeric_limits<double>::infinity();
    }
    if (!cure || condition_ <= condition_limit) return;
    KdTree<Dim> tree;
    tree.build(centres);  // indexes `centres` in place: it outlives the tree
    std::vector<double> gap(static_cast<std::size_t>(centres.cols()));
    double spacing = std::numeric_limits<double>::infinity();
    for (Index i = 0; i < centres.cols(); ++i) {
      const auto found = tree.nearest(Vec<Dim>(centres.col(i)), 2);
      gap[static_cast<std::size_t>(i)] = std::sqrt(found.back().second);
      spacing = std::min(spacing, gap[static_cast<std::size_t>(i)]);
    }
    const double diameter = (centres.rowwise().maxCoeff() - centres.rowwise().minCoeff()).norm();
    for (int round = 0; round < thinning_rounds && condition_ > condition_limit && spacing < diameter; ++round) {
      spacing *= std::clamp(1.5 * std::cbrt(condition_ / condition_limit), 2.0, 1e3);
      RbfKernelSettings thinned = kernel;
      thinned.radii.resize(static_cast<std::size_t>(centres.cols()));
      for (Index i = 0; i < centres.cols(); ++i) thinned.radii[static_cast<std::size_t>(i)] = kernel.radius_of(i);
      const Index count = thin(tree, centres, spacing, gap, thinned.radii);
      failure = nullptr;
      try {
        assemble(centres, thinned, sparse_options, dense_kind, max_dense);
      } catch (const SolverError&) {
        failure = std::current_exception();
        condition_ = std::numeric_limits<double>::infinity();
      }
      thinned_ = count;
    }
    // The rounds may end (out of rounds, or the spacing past the centres' extent) on a failed
    // assembly: its half-built system must not be used.
    if (failure) std::rethrow_exception(failure);
  }

  /// Centres thinned by setup's condition_limit (0: none).
  [[nodiscard]] Index thinned() const noexcept { return thinned_; }

 private:
  void assemble(const Points<Dim>& centres, const RbfKernelSettings& kernel, SolverOptions sparse_options,
                DenseSolverKind dense_kind, Index max_dense) {
    centres_ = centres;
    kernel_ = kernel;
    const Index k = centres_.cols();
    compact_ = is_compact(kernel.kernel);
    varying_ = kernel.varying();
    symmetric_ = !varying_;
    transposed_.reset();
    dense_transposed_.reset();
    build_radius_classes();
    // The tree of all centres answers centres_within() unless radius classes do; global kernels
    // query neither.
    tree_ = KdTree<Dim>{};
    if (compact_ && classes_.empty()) tree_.build(centres_);
    if (compact_) {
      std::vector<Index> all(static_cast<std::size_t>(k));
      for (Index i = 0; i < k; ++i) all[static_cast<std::size_t>(i)] = i;
      // Row i holds A_i·, its centres in k-d tree order: the storage-order conversion sorts
      // them by a counting pass, cheaper than sorting each row (sliding centres on a side
      // plane through a wall's layer have a hundred neighbours).
      matrix_ = SparseMatrix(compact_kernel_rows(centres_, all, within(), k, kernel_));
      nonzeros_ = matrix_.nonZeros();
      if (varying_) symmetric_ = radii_agree_on_pattern();
      if (!symmetric_ && sparse_options.solver != SolverKind::bicgstab) sparse_options.solver = SolverKind::sparse_lu;
      sparse_options_ = sparse_options;
      sparse_ = LinearSolver(sparse_options);
      sparse_.compute(matrix_);
    } else {
      if (k > max_dense)
        throw InputError("RbfMover::setup: " + std::to_string(k) + " boundary nodes give a dense " +
                         std::string(name(kernel.kernel)) + " system beyond the limit (expected at most " +
                         std::to_string(max_dense) + "); use a compact kernel such as wendland2 or raise max_dense_centres");
      dense_matrix_.resize(k, k);
      for (Index j = 0; j < k; ++j)
        for (Index i = 0; i < k; ++i)
          dense_matrix_(i, j) = rbf_value(kernel.kernel, (centres_.col(i) - centres_.col(j)).norm(), kernel_.radius_of(j));
      nonzeros_ = k * k;
      if (!symmetric_) dense_kind = DenseSolverKind::partial_piv_lu;
      dense_ = DenseSolver(dense_kind);
      dense_.compute(dense_matrix_);
    }
    polynomial_.setup(centres_, kernel.polynomial, [this](const Eigen::MatrixXd& b, Eigen::MatrixXd& x) { solve_a(b, x); },
                      "RbfMover::setup");
    estimate_condition();
    if (symmetric_) {
      matrix_.resize(0, 0);
      dense_matrix_.resize(0, 0);
    }
  }

  /// Keeps centres in index order unless an earlier kept one lies within `spacing`; a thinned
  /// centre's radius becomes min(its radius, gap to its nearest centre). Returns the number
  /// thinned.
  static Index thin(const KdTree<Dim>& tree, const Points<Dim>& centres, double spacing, const std::vector<double>& gap,
                    std::vector<double>& radii) {
    std::vector<char> thinned(radii.size(), 0);
    std::vector<Neighbor> near;
    Index count = 0;
    for (Index i = 0; i < centres.cols(); ++i) {
      if (thinned[static_cast<std::size_t>(i)] != 0) continue;
      tree.radius_search(Vec<Dim>(centres.col(i)), spacing, near);
      for (const auto& [j, d2] : near) {
        if (static_cast<Index>(j) <= i || thinned[j] != 0) continue;
        thinned[j] = 1;
        radii[j] = std::min(radii[j], gap[j]);
        ++count;
      }
    }
    return count;
  }

 public:
  [[nodiscard]] Index size() const noexcept { return centres_.cols(); }
  [[nodiscard]] const Points<Dim>& centres() const noexcept { return centres_; }
  /// The centres whose support holds x, as (centre, squared distance) pairs in `out`. With
  /// differing radii each radius class is queried at its own radius: one query at the largest
  /// radius would return, around a thin wall's nodes, every centre of a thick one's support.
  void centres_within(const Vec<Dim>& x, std::vector<Neighbor>& out) const {
    if (classes_.empty()) {
      tree_.radius_search(x, kernel_.radius, out);
      return;
    }
    thread_local std::vector<Neighbor> hits;
    out.clear();
    for (const RadiusClass& c : classes_) {
      c.tree.radius_search(x, c.radius, hits);
      for (const auto& [id, d2] : hits) {
        const auto centre = static_cast<std::size_t>(c.ids[id]);
        if (c.uniform || d2 < kernel_.radii[centre] * kernel_.radii[centre]) out.emplace_back(centre, d2);
      }
    }
  }
  /// centres_within() as a callable for compact_kernel_rows().
  [[nodiscard]] auto within() const {
    return [this](const Vec<Dim>& x, std::vector<Neighbor>& out) { centres_within(x, out); };
  }
  [[nodiscard]] const RbfKernelSettings& kernel() const noexcept { return kernel_; }
  [[nodiscard]] Index nonzeros() const noexcept { return nonzeros_; }
  /// A lower bound of A's 2-norm condition number from setup (see estimate_condition()): the
  /// factor by which rounding in the boundary values may grow in the coefficients, and in a
  /// derivative's values, through this system.
  [[nodiscard]] double condition() const noexcept { return condition_; }
  /// True when A is symmetric (one radius, or differing radii that no pair of coupled centres
  /// differs in): factorized by the solver asked for, transposed solves reuse it.
  [[nodiscard]] bool symmetric() const noexcept { return symmetric_; }
  [[nodiscard]] const SolverReport& report() const noexcept { return compact_ ? sparse_.report() : dense_.report(); }

  /// The polynomial basis [1, (x - shift)/scale] (scaled for conditioning).
  [[nodiscard]] Vec<Dim + 1> polynomial(const Vec<Dim>& x) const { return polynomial_(x); }

  /// Coefficients interpolating `values` (k × Dim) at the centres. β is zero without
  /// augmentation.
  void solve(const Eigen::MatrixXd& values, Eigen::MatrixXd& alpha, PolyCoefficients& beta) {
    solve_a(values, alpha);
    polynomial_.eliminate(alpha, beta);
  }

  /// Transpose of solve(): the gradient with respect to `values` of ⟨ᾱ, α⟩ + ⟨β̄, β⟩,
  /// A⁻ᵀ (ᾱ + P S⁻ᵀ (β̄ - Gᵀ ᾱ)).
  void solve_transpose(const Eigen::MatrixXd& alpha_bar, const PolyCoefficients& beta_bar, Eigen::MatrixXd& values_bar) {
    const Eigen::MatrixXd rhs = polynomial_.transpose_rhs(alpha_bar, beta_bar);
    if (symmetric_) {
      solve_a(rhs, values_bar);
    } else if (compact_) {
      if (!transposed_) {
        transposed_ = std::make_unique<LinearSolver>(sparse_options_);
        transposed_->compute(SparseMatrix(matrix_.transpose()));
        matrix_.resize(0, 0);
      }
      transposed_->solve(rhs, values_bar);
    } else {
      if (!dense_transposed_) {
        dense_transposed_ = Eigen::PartialPivLU<Eigen::MatrixXd>(dense_matrix_.transpose());
        dense_matrix_.resize(0, 0);
      }
      values_bar = dense_transposed_->solve(rhs);
    }
  }

 private:
  /// A few distinct radii (one per wall) get a k-d tree each. Many (a radius per node, from
  /// its facets' size) are grouped into classes spanning a factor of two at most, each queried
  /// at its largest radius and filtered: one tree at the largest radius of all would return,
  /// around an airfoil, every wall centre to every node within a far field's radius.
  void build_radius_classes() {
    classes_.clear();
    if (!varying_ || !compact_) return;
    std::vector<double> distinct = kernel_.radii;
    std::sort(distinct.begin(), distinct.end());
    distinct.erase(std::unique(distinct.begin(), distinct.end()), distinct.end());
    const bool exact = distinct.size() <= max_exact_classes;
    std::vector<double> lowest;  // the smallest radius of each class, ascending
    for (const double r : distinct) {
      if (exact || lowest.empty() || r > 2.0 * lowest.back()) {
        lowest.push_back(r);
        classes_.emplace_back();
      }
      classes_.back().radius = r;
    }
    for (std::size_t c = 0; c < classes_.size(); ++c) classes_[c].uniform = classes_[c].radius == lowest[c];
    for (Index i = 0; i < centres_.cols(); ++i) {
      const double r = kernel_.radii[static_cast<std::size_t>(i)];
      const auto c = static_cast<std::size_t>(std::upper_bound(lowest.begin(), lowest.end(), r) - lowest.begin()) - 1;
      classes_[c].ids.push_back(i);
    }
    for (RadiusClass& c : classes_) {
      c.at.resize(Dim, static_cast<Index>(c.ids.size()));
      for (std::size_t j = 0; j < c.ids.size(); ++j) c.at.col(static_cast<Index>(j)) = centres_.col(c.ids[j]);
      c.tree.build(c.at);
    }
  }

  /// ||A x|| / ||x|| and ||A⁻¹ y|| / ||y|| after power iterations from random starts: each is
  /// a lower bound of its operator's 2-norm and tends to it, so their product bounds the
  /// condition number from below (within a factor 1.3 of it on the systems tested).
  /// Centres a hair apart beside a large support give large values: the NACA0012's boundary
  /// (trailing-edge nodes 7e-5 apart) 6e12 at radius 2, relative rounding of 1e-3 in a
  /// gradient, and 9e15 at radius 20.
  /// Eight products and eight single-column solves: less than three moves' solves in 3D.
  void estimate_condition() {
    const Index k = size();
    condition_ = 1.0;
    if (k == 0) return;
    std::mt19937_64 random(k);
    std::normal_distribution<double> normal;
    const auto start = [&] {
      Eigen::MatrixXd x(k, 1);
      for (Index i = 0; i < k; ++i) x(i, 0) = normal(random);
      return Eigen::MatrixXd(x / x.norm());
    };
    const auto largest_gain = [&](const auto& apply) {
      Eigen::MatrixXd x = start(), y;
      double gain = 0.0;
      for (int step = 0; step < condition_steps; ++step) {
        apply(x, y);
        gain = y.norm();
        if (!(gain > 0.0) || !std::isfinite(gain)) return gain;
        x = y / gain;
      }
      return gain;
    };
    const double norm = largest_gain([&](const Eigen::MatrixXd& x, Eigen::MatrixXd& y) {
      if (compact_) y = matrix_ * x;
      else y = dense_matrix_ * x;
    });
    // The start converges to A's least singular direction, whose solve's residual is about
    // machine precision times the condition: the residual says nothing of the solve here.
    const double inverse_norm =
        largest_gain([&](const Eigen::MatrixXd& x, Eigen::MatrixXd& y) { solve_a(x, y, ResidualCheck::off); });
    condition_ = std::isfinite(norm * inverse_norm) ? std::max(1.0, norm * inverse_norm) : std::numeric_limits<double>::infinity();
  }

  /// A_ij = φ(|c_i - c_j| / ρ_j) equals A_ji exactly when ρ_i = ρ_j (the distance is the
  /// same number both ways), and a pair with a zero one way and not the other has radii that
  /// differ: so A is symmetric iff every stored entry joins centres of one radius.
  [[nodiscard]] bool radii_agree_on_pattern() const {
    for (Index j = 0; j < matrix_.outerSize(); ++j)
      for (SparseMatrix::InnerIterator it(matrix_, j); it; ++it)
        if (kernel_.radius_of(it.row()) != kernel_.radius_of(it.col())) return false;
    return true;
  }

  void solve_a(const Eigen::MatrixXd& b, Eigen::MatrixXd& x, ResidualCheck check = ResidualCheck::enforced) {
    if (b.rows() == 0) {
      x.resize(0, b.cols());
      return;
    }
    if (compact_)
      sparse_.solve(b, x, check);
    else
      dense_.solve(b, x, check);
  }

  struct RadiusClass {
    double radius = 0.0;     ///< the largest radius of its centres
    bool uniform = true;     ///< all its centres have that radius (no filtering)
    std::vector<Index> ids;  ///< its centres
    Points<Dim> at;          ///< their positions (the tree indexes this storage)
    KdTree<Dim> tree;
  };
  static constexpr std::size_t max_exact_classes = 16;
  static constexpr int condition_steps = 8;
  static constexpr int thinning_rounds = 4;

  Points<Dim> centres_;
  RbfKernelSettings kernel_;
  KdTree<Dim> tree_;
  std::vector<RadiusClass> classes_;  ///< when radii differ (see build_radius_classes)
  bool compact_ = true;
  bool varying_ = false;    ///< the centres' radii differ
  bool symmetric_ = true;
  SolverOptions sparse_options_;
  SparseMatrix matrix_;             ///< A, kept past setup only when not symmetric, until Aᵀ is factorized
  Eigen::MatrixXd dense_matrix_;    ///< dense A, likewise
  std::unique_ptr<LinearSolver> transposed_;  ///< factorized Aᵀ, on first transposed solve
  std::optional<Eigen::PartialPivLU<Eigen::MatrixXd>> dense_transposed_;  ///< dense Aᵀ, likewise
  LinearSolver sparse_;
  DenseSolver dense_;
  Index nonzeros_ = 0;
  double condition_ = 1.0;
  Index thinned_ = 0;
  RbfPolynomial<Dim> polynomial_;
};

}  // namespace meshmotion::detail

// The compiled library (target meshmotion::compiled, src/movers_rbf.cpp) holds these for Dim 2
// and 3.
#ifdef MESHMOTION_COMPILED
namespace meshmotion::detail {
extern template class RbfSystem<2>;
extern template class RbfSystem<3>;
}  // namespace meshmotion::detail
#endif
