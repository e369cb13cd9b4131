#pragma once
/// \file
/// Two-level RBF interpolation: a wide radius on a few centres, a narrow one on all of them.
///
/// A large motion wants a support radius of several times its size (suggest_support_radius());
/// over every boundary node that makes the system and the evaluation operator nearly dense, a
/// cost that grows with the motion (a terrain-following bottom of 7,442 nodes: radius 945,
/// gigabytes, seconds a step). Here the wide radius R is carried by a coarse subset of the
/// centres, every centre within `spacing` of one kept and the kept ones at least `spacing`
/// apart (spaced_subset(): fixed by the positions alone, so the map stays linear, the same for
/// any motion and for any numbering of the nodes), and the narrow radius r (ten boundary spacings, the at-rest default) by
/// every centre, on what the coarse level leaves:
///
///   s(x) = Σ_{c ∈ S} a_c φ(|x − x_c| / R) + Σ_{j} b_j φ(|x − x_j| / r),
///   a = A_S⁻¹ d_S,   b = A⁻¹ (d − B a),   B_jc = φ(|x_j − x_c| / R),
///
/// (A_S and A the compact systems of the two levels). It interpolates every centre (the fine
/// level closes what the coarse one leaves there), is linear in d, and reaches as far as R.
/// What it costs does not grow with R beyond the coarse level's few hundred columns; the fine
/// system is factorized once and kept when the motion sets the coarse level up again
/// (set_coarse()).
///
/// The coefficients are stacked [a; b]; evaluation rows hold both levels' kernel weights, so a
/// move is the two solves and one sparse product, as for the global system. Like the partition
/// of unity, one radius per level and no polynomial.

#include "meshmotion/core/error.hpp"
#include "meshmotion/core/threads.hpp"
#include "meshmotion/core/types.hpp"
#include "meshmotion/movers/detail/rbf_system.hpp"
#include "meshmotion/movers/rbf_kernels.hpp"
#include "meshmotion/solvers/solver_options.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <numeric>
#include <vector>

namespace meshmotion::detail {

/// Centres of `centres` (Dim × k), visited in the lexicographic order of their coordinates,
/// kept when no earlier kept one lies within `spacing`: every centre is then within `spacing`
/// of a kept one and the kept ones are at least `spacing` apart. Returned ascending. The
/// positions decide, not the numbering: a distributed mover whose global ids follow its ranks
/// (the OpenFOAM plugin's merged point numbering) keeps the serial mover's centres.
template <int Dim>
[[nodiscard]] std::vector<Index> spaced_subset(const Points<Dim>& centres, double spacing) {
  using Cell = std::array<std::int64_t, Dim>;
  std::map<Cell, std::vector<Index>> grid;
  std::vector<Index> order(static_cast<std::size_t>(centres.cols())), kept;
  std::iota(order.begin(), order.end(), Index{0});
  std::sort(order.begin(), order.end(), [&](Index a, Index b) {
    return std::lexicographical_compare(centres.col(a).data(), centres.col(a).data() + Dim, centres.col(b).data(),
                                        centres.col(b).data() + Dim);
  });
  const Vec<Dim> origin = centres.cols() > 0 ? Vec<Dim>(centres.rowwise().minCoeff()) : Vec<Dim>::Zero();
  const auto cell_of = [&](const Vec<Dim>& x) {
    Cell c;
    for (int a = 0; a < Dim; ++a) c[static_cast<std::size_t>(a)] = static_cast<std::int64_t>(std::floor((x(a) - origin(a)) / spacing));
    return c;
  };
  for (const Index i : order) {
    const Vec<Dim> x = centres.col(i);
    const Cell home = cell_of(x);
    bool covered = false;
    // The 3^Dim cells around home hold every kept centre within one spacing.
    for (int code = 0; code < static_cast<int>(std::pow(3, Dim)) && !covered; ++code) {
      Cell c = home;
      for (int a = 0, rest = code; a < Dim; ++a, rest /= 3) c[static_cast<std::size_t>(a)] += rest % 3 - 1;
      const auto found = grid.find(c);
      if (found == grid.end()) continue;
      covered = std::any_of(found->second.begin(), found->second.end(), [&](Index k) { return (centres.col(k) - x).norm() < spacing; });
    }
    if (covered) continue;
    kept.push_back(i);
    grid[home].push_back(i);
  }
  std::sort(kept.begin(), kept.end());
  return kept;
}

template <int Dim>
class TwoLevelRbf {
 public:
  using PolyCoefficients = typename RbfSystem<Dim>::PolyCoefficients;

  /// The fine level over every centre of `centres` at `fine` (compact, one radius, no
  /// polynomial), and the coarse centres: spaced_subset() at half the fine radius, widened
  /// until at most `most_coarse` remain.
  void setup_fine(const Points<Dim>& centres, const RbfKernelSettings& fine, Index most_coarse, const SolverOptions& solver,
                  double condition_limit) {
    k_ = centres.cols();
    centres_ = centres;
    fine_.setup(centres, fine, solver, DenseSolverKind::partial_piv_lu, 0, condition_limit);
    double spacing = 0.5 * fine.radius;
    coarse_ids_ = spaced_subset(centres, spacing);
    // Counts on a surface of centres fall as spacing^(1 − Dim): a few widening rounds settle it.
    for (int round = 0; round < 8 && static_cast<Index>(coarse_ids_.size()) > most_coarse; ++round) {
      spacing *= std::pow(1.1 * static_cast<double>(coarse_ids_.size()) / static_cast<double>(most_coarse), 1.0 / std::max(1, Dim - 1));
      coarse_ids_ = spaced_subset(centres, spacing);
    }
  }

  /// (Re)builds the coarse level at `coarse` (compact, one radius): its system over the coarse
  /// centres and B, its kernel at every centre. The fine level stays.
  void set_coarse(const RbfKernelSettings& coarse, const SolverOptions& solver, double condition_limit) {
    const auto n = static_cast<Index>(coarse_ids_.size());
    Points<Dim> at(Dim, n);
    for (Index c = 0; c < n; ++c) at.col(c) = centres_.col(coarse_ids_[static_cast<std::size_t>(c)]);
    coarse_.setup(at, coarse, solver, DenseSolverKind::partial_piv_lu, 0, condition_limit);
    std::vector<Index> every(static_cast<std::size_t>(k_));
    for (Index j = 0; j < k_; ++j) every[static_cast<std::size_t>(j)] = j;
    at_centres_ = compact_kernel_rows(centres_, every, coarse_.within(), n, coarse_.kernel());
    refresh_report();
  }

  [[nodiscard]] Index num_coarse() const noexcept { return static_cast<Index>(coarse_ids_.size()); }
  [[nodiscard]] Index num_coefficients() const noexcept { return num_coarse() + k_; }
  [[nodiscard]] Index nonzeros() const noexcept { return coarse_.nonzeros() + fine_.nonzeros() + at_centres_.nonZeros(); }
  [[nodiscard]] double condition() const noexcept { return std::max(coarse_.condition(), fine_.condition()); }
  [[nodiscard]] Index thinned() const noexcept { return coarse_.thinned() + fine_.thinned(); }
  /// The fine level's report of the last solve, with both levels' factorizations counted.
  [[nodiscard]] const SolverReport& report() const noexcept { return report_; }

  /// The stacked coefficients [a; b] (num_coefficients() × Dim) interpolating `values` (k × Dim)
  /// at the centres; β is zero.
  void solve(const Eigen::MatrixXd& values, Eigen::MatrixXd& alpha, PolyCoefficients& beta) {
    const Index n = num_coarse();
    Eigen::MatrixXd picked(n, values.cols()), a, b;
    for (Index c = 0; c < n; ++c) picked.row(c) = values.row(coarse_ids_[static_cast<std::size_t>(c)]);
    PolyCoefficients unused;
    coarse_.solve(picked, a, unused);
    const Eigen::MatrixXd rest = values - at_centres_ * a;
    fine_.solve(rest, b, unused);
    alpha.resize(n + k_, values.cols());
    alpha.topRows(n) = a;
    alpha.bottomRows(k_) = b;
    beta.setZero();
    refresh_report();
  }

  /// Transpose of solve(): the gradient (k × Dim) with respect to the values of ⟨ᾱ, α⟩.
  void solve_transpose(const Eigen::MatrixXd& alpha_bar, const PolyCoefficients&, Eigen::MatrixXd& values_bar) {
    const Index n = num_coarse();
    fine_.solve_transpose(alpha_bar.bottomRows(k_), PolyCoefficients::Zero(), values_bar);
    const Eigen::MatrixXd a_bar = alpha_bar.topRows(n) - at_centres_.transpose() * values_bar;
    Eigen::MatrixXd picked_bar;
    coarse_.solve_transpose(a_bar, PolyCoefficients::Zero(), picked_bar);
    for (Index c = 0; c < n; ++c) values_bar.row(coarse_ids_[static_cast<std::size_t>(c)]) += picked_bar.row(c);
  }

  /// Evaluation rows for the points listed in `rows` of `points`: each level's kernel weights,
  /// the coarse level's columns first (rows.size() × num_coefficients(), row-major). With
  /// `kept`, only rows with a weight are stored, as compact_kernel_rows() does. Two passes over
  /// the rows (count, then fill) instead of compact_kernel_rows()'s list of pairs, 16 bytes a
  /// weight beside the matrix's 12: on a terrain of 77k nodes under a wide radius that list was
  /// most of the plugin's peak memory.
  [[nodiscard]] Eigen::SparseMatrix<double, Eigen::RowMajor, int> evaluation_rows(const Points<Dim>& points,
                                                                                 const std::vector<Index>& rows,
                                                                                 std::vector<Index>* kept = nullptr) const {
    const auto n = static_cast<Index>(rows.size());
    const Index shift = num_coarse();
    // f(coarse hits, fine hits) for row r.
    const auto each_row = [&](auto&& f) {
      RegionErrors errors;
#pragma omp parallel num_threads(::meshmotion::num_threads())
      {
        std::vector<Neighbor> coarse, fine;
#pragma omp for schedule(dynamic, 256)
        for (Index r = 0; r < n; ++r)
          errors.run([&] {
            const Vec<Dim> x = points.col(rows[static_cast<std::size_t>(r)]);
            coarse_.centres_within(x, coarse);
            fine_.centres_within(x, fine);
            f(r, coarse, fine);
          });
      }
      errors.rethrow();
    };
    std::vector<int> count(static_cast<std::size_t>(n));
    each_row([&](Index r, const auto& coarse, const auto& fine) { count[static_cast<std::size_t>(r)] = static_cast<int>(coarse.size() + fine.size()); });
    auto out = rows_of_counts(count, num_coefficients(), kept);
    // Where each listed row starts in `out` (rows without a weight are not stored with `kept`).
    std::vector<int> start(static_cast<std::size_t>(n), 0);
    for (Index r = 0, stored = 0; r < n; ++r) {
      start[static_cast<std::size_t>(r)] = out.outerIndexPtr()[stored];
      if (kept == nullptr || count[static_cast<std::size_t>(r)] > 0) ++stored;
    }
    each_row([&](Index r, const auto& coarse, const auto& fine) {
      int at = start[static_cast<std::size_t>(r)];
      for (const auto& [c, d2] : coarse) {
        out.innerIndexPtr()[at] = static_cast<int>(c);
        out.valuePtr()[at++] = rbf_value(coarse_.kernel().kernel, std::sqrt(d2), coarse_.kernel().radius_of(static_cast<Index>(c)));
      }
      for (const auto& [j, d2] : fine) {
        out.innerIndexPtr()[at] = static_cast<int>(shift + static_cast<Index>(j));
        out.valuePtr()[at++] = rbf_value(fine_.kernel().kernel, std::sqrt(d2), fine_.kernel().radius_of(static_cast<Index>(j)));
      }
    });
    return out;
  }

 private:
  void refresh_report() {
    report_ = fine_.report();
    report_.factorizations += coarse_.report().factorizations;
    report_.analyses += coarse_.report().analyses;
    report_.seconds += coarse_.report().seconds;
  }

  Index k_ = 0;
  Points<Dim> centres_;
  std::vector<Index> coarse_ids_;  ///< the coarse centres, ascending
  RbfSystem<Dim> coarse_, fine_;
  Eigen::SparseMatrix<double, Eigen::RowMajor, int> at_centres_;  ///< B: every centre × coarse centres
  SolverReport report_;
};

}  // namespace meshmotion::detail
