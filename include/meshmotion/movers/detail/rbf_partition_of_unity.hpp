#pragma once
/// \file
/// Partition-of-unity RBF interpolation: for boundaries too large for one factorization.
///
/// The centres are split by recursive bisection (the middle of the longest side of a cluster's
/// bounding box) into clusters of at most `patch_centres` (patch_layout(): the middle, not the
/// median, so that ranks holding parts of the centres find the same clusters from a few
/// reductions, parallel/distributed_partition_of_unity.hpp). Cluster j, with bounding-box
/// centre p_j and radius ρ_j (its farthest centre), becomes the patch of radius R_j = ρ_j + max(overlap ρ_j, r) (r: the
/// kernel's support radius); the patch's local system is the compact RBF system of every
/// centre within R_j of p_j (RbfSystem), factorized on its own. The interpolant blends the
/// local ones with Shepard weights of Wendland C2 bumps:
///
///   s(x) = Σ_j w_j(x) s_j(x),   w_j = ψ(|x − p_j| / R_j) / Σ_i ψ(|x − p_i| / R_i).
///
/// Properties kept from the global interpolant:
/// - interpolation: a centre inside patch i's ball is in patch i's local set, so every local
///   interpolant with a nonzero weight there reproduces its value, and so does the blend;
/// - support: a point within r of a centre of cluster j lies within R_j of p_j (R_j ≥ ρ_j + r),
///   so it has a weight; a point farther than r from every centre gets zero, as globally;
/// - linearity in the values, so the derivatives are the transposed local solves.
/// The blend differs from the global interpolant by how much data beyond each patch matters
/// inside it; benchmarks/pu_rbf_bench reports that difference.
///
/// The coefficients are the local systems' α stacked patch after patch; evaluation rows carry
/// the weights, so a move is the local solves and one sparse product, as for the global system.

#include "meshmotion/core/error.hpp"
#include "meshmotion/core/threads.hpp"
#include "meshmotion/core/topology.hpp"
#include "meshmotion/core/types.hpp"
#include "meshmotion/movers/detail/rbf_system.hpp"
#include "meshmotion/movers/rbf_kernels.hpp"
#include "meshmotion/solvers/solver_options.hpp"
#include "meshmotion/spatial/kd_tree.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>
#include <string>
#include <vector>

namespace meshmotion::detail {

/// The clusters of a partition of unity: patch_of[c] is centre c's cluster, numbered depth
/// first (left before right); middle[j] the centre of cluster j's bounding box, reach[j] its
/// farthest centre's distance from there (ρ_j), count[j] its centres.
template <int Dim>
struct PatchLayout {
  Points<Dim> middle;
  std::vector<double> reach;
  std::vector<double> count;
  std::vector<Index> patch_of;
  Vec<Dim> lower, upper;  ///< the bounding box of every centre
};

/// Splits clusters at the middle of their bounding box's longest side until each holds at most
/// `most` centres (a cluster whose box is too thin to split stays whole). `reduce(low, high,
/// count)` combines, elementwise, the per-cluster figures of every holder of centres: the
/// minimum of `low`, the maximum of `high`, the sum of `count` (any may be empty). Serially it
/// does nothing; ranks each holding some centres pass MPI reductions and get the layout of all
/// the centres, each rank's patch_of for its own.
template <int Dim, class Reduce>
[[nodiscard]] PatchLayout<Dim> patch_layout(const Points<Dim>& centres, Index most, Reduce&& reduce) {
  struct Cluster {
    Vec<Dim> lo, hi;
    double count = 0.0;
    Index left = -1, right = -1;
    int axis = 0;
    double middle = 0.0;
  };
  constexpr double inf = std::numeric_limits<double>::infinity();
  const Index k = centres.cols();
  std::vector<Cluster> clusters(1);
  std::vector<Index> label(static_cast<std::size_t>(k), 0), active{0};
  while (!active.empty()) {
    const auto a = active.size();
    std::vector<double> low(Dim * a, inf), high(Dim * a, -inf), count(a, 0.0);
    std::vector<Index> slot(clusters.size(), -1);
    for (std::size_t s = 0; s < a; ++s) slot[static_cast<std::size_t>(active[s])] = static_cast<Index>(s);
    for (Index c = 0; c < k; ++c) {
      const Index s = slot[static_cast<std::size_t>(label[static_cast<std::size_t>(c)])];
      if (s < 0) continue;
      for (int d = 0; d < Dim; ++d) {
        low[static_cast<std::size_t>(Dim * s + d)] = std::min(low[static_cast<std::size_t>(Dim * s + d)], centres(d, c));
        high[static_cast<std::size_t>(Dim * s + d)] = std::max(high[static_cast<std::size_t>(Dim * s + d)], centres(d, c));
      }
      count[static_cast<std::size_t>(s)] += 1.0;
    }
    reduce(low, high, count);
    std::vector<Index> next;
    for (std::size_t s = 0; s < a; ++s) {
      const auto id = static_cast<std::size_t>(active[s]);
      for (int d = 0; d < Dim; ++d) {
        clusters[id].lo[d] = low[Dim * s + static_cast<std::size_t>(d)];
        clusters[id].hi[d] = high[Dim * s + static_cast<std::size_t>(d)];
      }
      clusters[id].count = count[s];
      if (count[s] <= static_cast<double>(most)) continue;
      int axis = 0;
      (clusters[id].hi - clusters[id].lo).maxCoeff(&axis);
      const double middle = 0.5 * (clusters[id].lo[axis] + clusters[id].hi[axis]);
      if (!(clusters[id].lo[axis] < middle && middle < clusters[id].hi[axis])) continue;
      clusters[id].axis = axis;
      clusters[id].middle = middle;
      clusters[id].left = static_cast<Index>(clusters.size());
      clusters[id].right = clusters[id].left + 1;
      next.push_back(clusters[id].left);
      next.push_back(clusters[id].right);
      clusters.resize(clusters.size() + 2);
    }
    for (Index c = 0; c < k; ++c) {
      const Cluster& at = clusters[static_cast<std::size_t>(label[static_cast<std::size_t>(c)])];
      if (at.left >= 0) label[static_cast<std::size_t>(c)] = centres(at.axis, c) < at.middle ? at.left : at.right;
    }
    active = std::move(next);
  }

  PatchLayout<Dim> out;
  out.lower = clusters[0].lo;
  out.upper = clusters[0].hi;
  std::vector<Index> patch(clusters.size(), -1), stack{0}, leaves;
  while (!stack.empty()) {
    const Index id = stack.back();
    stack.pop_back();
    const Cluster& at = clusters[static_cast<std::size_t>(id)];
    if (at.left < 0) {
      if (at.count > 0.0) {
        patch[static_cast<std::size_t>(id)] = static_cast<Index>(leaves.size());
        leaves.push_back(id);
      }
      continue;
    }
    stack.push_back(at.right);
    stack.push_back(at.left);
  }
  const auto n = static_cast<Index>(leaves.size());
  out.middle.resize(Dim, n);
  out.count.resize(static_cast<std::size_t>(n));
  for (Index j = 0; j < n; ++j) {
    const Cluster& at = clusters[static_cast<std::size_t>(leaves[static_cast<std::size_t>(j)])];
    out.middle.col(j) = 0.5 * (at.lo + at.hi);
    out.count[static_cast<std::size_t>(j)] = at.count;
  }
  out.patch_of.resize(static_cast<std::size_t>(k));
  out.reach.assign(static_cast<std::size_t>(n), 0.0);
  for (Index c = 0; c < k; ++c) {
    const Index j = patch[static_cast<std::size_t>(label[static_cast<std::size_t>(c)])];
    out.patch_of[static_cast<std::size_t>(c)] = j;
    out.reach[static_cast<std::size_t>(j)] = std::max(out.reach[static_cast<std::size_t>(j)], (centres.col(c) - out.middle.col(j)).norm());
  }
  std::vector<double> none;
  reduce(none, out.reach, none);
  return out;
}

/// f(j) for j in [0, n), side by side on the library's threads (patches: each on one thread);
/// the first error (by j) is rethrown after all ran.
template <class F>
void for_each_in_parallel(Index n, F&& f) {
  std::vector<std::exception_ptr> errors(static_cast<std::size_t>(n));
#pragma omp parallel for num_threads(::meshmotion::num_threads()) schedule(dynamic, 1)
  for (Index j = 0; j < n; ++j) {
    try {
      f(j);
    } catch (...) {
      errors[static_cast<std::size_t>(j)] = std::current_exception();
    }
  }
  for (const auto& e : errors)
    if (e) std::rethrow_exception(e);
}

/// Patch j's radius R_j = ρ_j + max(overlap ρ_j, r).
[[nodiscard]] inline double patch_radius(double reach, double overlap, double support_radius) {
  return reach + std::max(overlap * reach, support_radius);
}

template <int Dim>
class PartitionOfUnityRbf {
 public:
  using PolyCoefficients = typename RbfSystem<Dim>::PolyCoefficients;

  /// Builds and factorizes the patches over `centres` (Dim × k). `kernel` must be compact,
  /// with one radius and no polynomial (the caller checks and says why).
  void setup(const Points<Dim>& centres, const RbfKernelSettings& kernel, Index patch_centres, double overlap,
             const SolverOptions& solver) {
    kernel_ = kernel;
    k_ = centres.cols();
    const double r = kernel.radius;
    const PatchLayout<Dim> layout = patch_layout(centres, std::max<Index>(patch_centres, 1), [](auto&&...) {});
    const auto n_patches = static_cast<Index>(layout.reach.size());
    patch_centre_ = layout.middle;
    patch_radius_.resize(static_cast<std::size_t>(n_patches));
    for (Index j = 0; j < n_patches; ++j)
      patch_radius_[static_cast<std::size_t>(j)] = patch_radius(layout.reach[static_cast<std::size_t>(j)], overlap, r);

    // Local sets, sorted so that a patch's system does not depend on the tree's order.
    centres_ = centres;
    tree_ = KdTree<Dim>{};
    tree_.build(centres_);
    local_.assign(static_cast<std::size_t>(n_patches), {});
    std::vector<Neighbor> found;
    for (Index j = 0; j < n_patches; ++j) {
      tree_.radius_search(Vec<Dim>(patch_centre_.col(j)), patch_radius_[static_cast<std::size_t>(j)], found);
      auto& ids = local_[static_cast<std::size_t>(j)];
      ids.reserve(found.size());
      for (const auto& hit : found) ids.push_back(static_cast<Index>(hit.first));
      std::sort(ids.begin(), ids.end());
    }
    index_patches();

    // Patches are factorized side by side; each factorization runs on one thread.
    systems_.clear();
    systems_.resize(static_cast<std::size_t>(n_patches));
    const RbfKernelSettings local_kernel{kernel.kernel, r, false};
    for_each_patch([&](Index j) {
      const auto& ids = local_[static_cast<std::size_t>(j)];
      Points<Dim> at(Dim, static_cast<Index>(ids.size()));
      for (std::size_t i = 0; i < ids.size(); ++i) at.col(static_cast<Index>(i)) = centres.col(ids[i]);
      systems_[static_cast<std::size_t>(j)].setup(at, local_kernel, solver, DenseSolverKind::partial_piv_lu, 0);
    });
    report_ = SolverReport{};
    nonzeros_ = 0;
    condition_ = 1.0;
    for (const auto& s : systems_) {
      condition_ = std::max(condition_, s.condition());
      report_.factorizations += s.report().factorizations;
      report_.analyses += s.report().analyses;
      report_.seconds += s.report().seconds;
      report_.supernodal = report_.supernodal || s.report().supernodal;
      nonzeros_ += s.nonzeros();
    }
  }

  /// For evaluation only (no systems): the patches of centres `middle`, radii `radius`, local
  /// sets `at` (the stacked coefficients follow them in this order), of a partition of unity
  /// whose other patches do not reach the points to be evaluated: a rank's view of a
  /// distributed one.
  void cover(Points<Dim> middle, std::vector<double> radius, const std::vector<Points<Dim>>& at, const RbfKernelSettings& kernel) {
    kernel_ = kernel;
    patch_centre_ = std::move(middle);
    patch_radius_ = std::move(radius);
    Index total = 0;
    for (const auto& p : at) total += p.cols();
    centres_.resize(Dim, total);
    local_.assign(at.size(), {});
    k_ = 0;
    for (std::size_t j = 0; j < at.size(); ++j)
      for (Index i = 0; i < at[j].cols(); ++i) {
        centres_.col(k_) = at[j].col(i);
        local_[j].push_back(k_++);
      }
    tree_ = KdTree<Dim>{};
    tree_.build(centres_);
    systems_.clear();
    index_patches();
  }

  [[nodiscard]] Index size() const noexcept { return k_; }
  [[nodiscard]] Index num_patches() const noexcept { return static_cast<Index>(local_.size()); }
  /// Rows of the stacked coefficients (the local sets' sizes summed).
  [[nodiscard]] Index num_coefficients() const noexcept { return offsets_.empty() ? 0 : offsets_.back(); }
  [[nodiscard]] Index largest_patch() const {
    Index largest = 0;
    for (const auto& ids : local_) largest = std::max(largest, static_cast<Index>(ids.size()));
    return largest;
  }
  [[nodiscard]] Index nonzeros() const noexcept { return nonzeros_; }
  [[nodiscard]] const SolverReport& report() const noexcept { return report_; }
  /// The largest of the patch systems' condition estimates (RbfSystem::condition()).
  [[nodiscard]] double condition() const noexcept { return condition_; }

  /// The stacked local coefficients (num_coefficients() × Dim) interpolating `values`
  /// (k × Dim) at the centres; β is zero (no polynomial).
  void solve(const Eigen::MatrixXd& values, Eigen::MatrixXd& alpha, PolyCoefficients& beta) {
    alpha.resize(num_coefficients(), values.cols());
    beta.setZero();
    SolverReport last;
    for_each_patch([&](Index j) {
      const auto& ids = local_[static_cast<std::size_t>(j)];
      Eigen::MatrixXd local(static_cast<Index>(ids.size()), values.cols()), a;
      for (std::size_t i = 0; i < ids.size(); ++i) local.row(static_cast<Index>(i)) = values.row(ids[i]);
      PolyCoefficients b;
      systems_[static_cast<std::size_t>(j)].solve(local, a, b);
      alpha.middleRows(offsets_[static_cast<std::size_t>(j)], a.rows()) = a;
    });
    for (const auto& s : systems_) {
      last.iterations = std::max(last.iterations, s.report().iterations);
      last.residual = std::max(last.residual, s.report().residual);
      last.fell_back = last.fell_back || s.report().fell_back;
    }
    report_.iterations = last.iterations;
    report_.residual = last.residual;
    report_.fell_back = last.fell_back;
  }

  /// Transpose of solve(): the gradient (k × Dim) with respect to the values of ⟨ᾱ, α⟩.
  void solve_transpose(const Eigen::MatrixXd& alpha_bar, const PolyCoefficients&, Eigen::MatrixXd& values_bar) {
    std::vector<Eigen::MatrixXd> local_bar(systems_.size());
    for_each_patch([&](Index j) {
      const auto& ids = local_[static_cast<std::size_t>(j)];
      const Eigen::MatrixXd a = alpha_bar.middleRows(offsets_[static_cast<std::size_t>(j)], static_cast<Index>(ids.size()));
      systems_[static_cast<std::size_t>(j)].solve_transpose(a, PolyCoefficients::Zero(), local_bar[static_cast<std::size_t>(j)]);
    });
    values_bar.setZero(k_, alpha_bar.cols());
    for (std::size_t j = 0; j < local_.size(); ++j)
      for (std::size_t i = 0; i < local_[j].size(); ++i) values_bar.row(local_[j][i]) += local_bar[j].row(static_cast<Index>(i));
  }

  /// Evaluation rows: for the points x (columns of `points` listed in `rows`), the weights
  /// w_j(x) φ(|x − c| / r) against the stacked coefficients (rows.size() × num_coefficients(),
  /// row-major). With `kept`, only rows with a weight are stored and their positions in `rows`
  /// written to *kept, as compact_kernel_rows() does.
  [[nodiscard]] Eigen::SparseMatrix<double, Eigen::RowMajor, int> evaluation_rows(const Points<Dim>& points,
                                                                                 const std::vector<Index>& rows,
                                                                                 std::vector<Index>* kept = nullptr) const {
    const auto n = static_cast<Index>(rows.size());
    std::vector<int> count(static_cast<std::size_t>(n), 0);
    const Index chunks = std::clamp<Index>(n / 256, 1, 64);
    struct Entry {
      int column;
      double value;
    };
    std::vector<std::vector<Entry>> found(static_cast<std::size_t>(chunks));
    RegionErrors errors;
#pragma omp parallel num_threads(::meshmotion::num_threads())
    {
      std::vector<Neighbor> patches, hits;
      std::vector<double> share;  // per patch, its weight at x (0: not covering)
      errors.run([&] { share.assign(local_.size(), 0.0); });
#pragma omp for schedule(dynamic, 1)
      for (Index c = 0; c < chunks; ++c)
        errors.run([&] {
          auto& entries = found[static_cast<std::size_t>(c)];
          for (Index r = n * c / chunks; r < n * (c + 1) / chunks; ++r) {
            const Vec<Dim> x = points.col(rows[static_cast<std::size_t>(r)]);
            patch_tree_.radius_search(x, largest_radius_, patches);
            // Patch order, not the tree's: the weights' sum is then the same on any thread count.
            std::sort(patches.begin(), patches.end());
            double total = 0.0;
            for (const auto& [j, d2] : patches) {
              share[j] = rbf_value(RbfKernel::wendland2, std::sqrt(d2), patch_radius_[j]);
              total += share[j];
            }
            const std::size_t before = entries.size();
            if (total > 0.0) {
              tree_.radius_search(x, kernel_.radius, hits);
              for (const auto& [centre, h2] : hits) {
                const double phi = rbf_value(kernel_.kernel, std::sqrt(h2), kernel_.radius) / total;
                for (const Index packed : membership_.row(static_cast<Index>(centre))) {
                  const Index j = packed >> 32;
                  const double w = share[static_cast<std::size_t>(j)];
                  if (w > 0.0)
                    entries.push_back({static_cast<int>(offsets_[static_cast<std::size_t>(j)] + (packed & 0xffffffff)), w * phi});
                }
              }
            }
            for (const auto& [j, d2] : patches) share[j] = 0.0;
            count[static_cast<std::size_t>(r)] = static_cast<int>(entries.size() - before);
          }
        });
    }
    errors.rethrow();
    Eigen::SparseMatrix<double, Eigen::RowMajor, int> m = rows_of_counts(count, num_coefficients(), kept);
    std::size_t at = 0;
    for (const auto& entries : found)
      for (const Entry& e : entries) {
        m.innerIndexPtr()[at] = e.column;
        m.valuePtr()[at] = e.value;
        ++at;
      }
    return m;
  }

 private:
  /// offsets_, membership_ and the patch tree, from the local sets.
  void index_patches() {
    const auto n_patches = static_cast<Index>(local_.size());
    offsets_.assign(static_cast<std::size_t>(n_patches) + 1, 0);
    for (Index j = 0; j < n_patches; ++j)
      offsets_[static_cast<std::size_t>(j) + 1] = offsets_[static_cast<std::size_t>(j)] + static_cast<Index>(local_[static_cast<std::size_t>(j)].size());
    // Centre → the coefficients it has (one per patch holding it): an evaluation then asks the
    // tree once per point, not once per patch covering it.
    // Each entry packs the patch (high 32 bits) and the centre's place in it (low 32 bits).
    membership_ = csr_from_pairs(k_, [&](auto&& f) {
      for (Index j = 0; j < n_patches; ++j) {
        const auto& ids = local_[static_cast<std::size_t>(j)];
        for (std::size_t i = 0; i < ids.size(); ++i) f(ids[i], (j << 32) | static_cast<Index>(i));
      }
    });
    largest_radius_ = patch_radius_.empty() ? 0.0 : *std::max_element(patch_radius_.begin(), patch_radius_.end());
    patch_tree_ = KdTree<Dim>{};
    patch_tree_.build(patch_centre_);
  }

  template <class F>
  void for_each_patch(F&& f) {
    for_each_in_parallel(static_cast<Index>(systems_.size()), f);
  }

  RbfKernelSettings kernel_;
  Index k_ = 0;
  Points<Dim> patch_centre_;
  std::vector<double> patch_radius_;
  double largest_radius_ = 0.0;
  KdTree<Dim> patch_tree_;
  Points<Dim> centres_;                    ///< every centre (the tree reads them in place)
  KdTree<Dim> tree_;
  Adjacency membership_;                   ///< centre → (patch, place in it), packed
  std::vector<std::vector<Index>> local_;  ///< per patch, its centres (ascending)
  std::vector<Index> offsets_;             ///< start of each patch's coefficients
  std::vector<RbfSystem<Dim>> systems_;
  SolverReport report_;
  Index nonzeros_ = 0;
  double condition_ = 1.0;
};

}  // namespace meshmotion::detail
