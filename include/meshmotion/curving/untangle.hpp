#pragma once
/// \file
/// Untangling and optimization of a curved mesh, the last stage of the curving pipeline before
/// certification: where cells are invalid or below a threshold of the certified scaled
/// Jacobian, the nodes inside the domain of those cells and of `layers` rings of neighbours
/// around them (vertices and high-order nodes; boundary nodes stay on the geometry) move to
/// raise the worst scaled Jacobian they touch (the patch approach of Gmsh's HighOrderOptimize
/// and of NekMesh's variational optimiser, with the objective the certification uses). A wall
/// edge bent across the first layer's far vertices cannot be repaired by the high-order nodes
/// alone: those vertices must move too.
///
/// A cell's value is the smallest Bézier coefficient of its det J over its straight measure (a
/// lower bound of its scaled Jacobian, so no sampling gap). Each free node in turn takes the
/// position that minimizes the squared shortfall below the threshold summed over the cells
/// around it (every cell holding it, inside the patch or not), by a compass search whose step
/// starts at a tenth of the node's neighbourhood and halves down to a thousandth of it; sweeps
/// repeat while the patch's total shortfall falls. The nodes the caller
/// marks fixed (the boundary) stay. Every cell the sweeps touched is then certified again
/// (Bézier bounds) and the caller's per-cell values replaced; a result with more invalid cells
/// or a lower certified minimum than the input is undone (UntangleReport::reverted).
///
/// Then the worst cells are raised (UntangleOptions::raise_rounds): the same search on the
/// nodes of the few worst cells, aiming a little above the minimum, round after round while
/// the minimum rises, within a budget of cell evaluations proportional to the mesh (about the
/// certification's cost). A threshold high enough to reach the worst cells would take in most
/// of a boundary-layer mesh instead (the NACA0012 quadrilaterals: seconds at 0.8).

#include "meshmotion/core/error.hpp"
#include "meshmotion/core/mesh.hpp"
#include "meshmotion/core/option_text.hpp"
#include "meshmotion/core/types.hpp"
#include "meshmotion/quality/scaled_jacobian.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

namespace meshmotion {

/// Options of untangle().
struct UntangleOptions {
  bool enabled = true;      ///< false: leave the regularized mesh as it is
  double threshold = 0.1;   ///< cells whose certified scaled Jacobian is below this are optimized
  int layers = 3;           ///< rings of neighbouring cells that move with them
  int max_sweeps = 20;      ///< node sweeps at most per pass
  /// After the cells below the threshold, rounds that raise the certified minimum: each
  /// optimizes the `raise_cells` worst cells (those within `raise_margin` of the minimum) and
  /// `raise_layers` rings around them towards the minimum plus the margin; the rounds stop when
  /// the minimum no longer rises.
  int raise_rounds = 4;
  int raise_cells = 16;
  int raise_layers = 0;
  double raise_margin = 0.05;
  /// The rounds' work at most: this many cell evaluations per cell of the mesh (one evaluation
  /// costs about what the certification spends on a cell).
  double raise_budget = 4.0;
};

/// What untangle() did.
struct UntangleReport {
  Index cells_below = 0;     ///< cells under the threshold before
  Index invalid_before = 0;
  Index invalid_after = 0;
  double min_before = 0.0;   ///< certified minimum over all cells before and after
  double min_after = 0.0;
  Index patch_cells = 0;     ///< cells in the optimized patches (summed over the passes)
  Index free_nodes = 0;      ///< nodes that were allowed to move (summed over the passes)
  int sweeps = 0;            ///< node sweeps of every pass
  int raise_rounds = 0;      ///< rounds that raised the minimum
  long long evaluations = 0; ///< cell evaluations of the optimization (each a Bézier bound of det J)
  bool reverted = false;     ///< the untangling's result was worse than its input and was undone
};

/// The keys of UntangleOptions (core/fields.hpp): flat, since they sit among the curving
/// pipeline's own keys.
template <class F>
void visit_options(UntangleOptions& o, F&& f, const std::string& prefix = {}) {
  f(prefix + "untangle", o.enabled, "optimize the cells below untangle_threshold after the regularization");
  f(prefix + "untangle_threshold", o.threshold, "optimize the high-order nodes around cells whose certified scaled Jacobian is below this");
  f(prefix + "untangle_layers", o.layers, "rings of neighbouring cells that move with a cell below the threshold");
  f(prefix + "untangle_sweeps", o.max_sweeps, "node sweeps at most per pass");
  f(prefix + "raise_rounds", o.raise_rounds, "then rounds raising the worst cells while the minimum rises (0: none)");
  f(prefix + "raise_cells", o.raise_cells, "worst cells optimized per round");
  f(prefix + "raise_layers", o.raise_layers, "rings of cells around them that move too");
  f(prefix + "raise_margin", o.raise_margin, "cells within this of the minimum are the worst; the round aims at minimum + margin");
  f(prefix + "raise_budget", o.raise_budget, "the rounds' cell evaluations at most, per cell of the mesh");
}

template <class F>
void visit_fields(const UntangleReport& r, F&& f) {
  f("cells_below", r.cells_below, "cells under the threshold before");
  f("invalid_before", r.invalid_before, "invalid cells before");
  f("invalid_after", r.invalid_after, "invalid cells after");
  f("min_before", r.min_before, "certified minimum over all cells before");
  f("min_after", r.min_after, "certified minimum over all cells after");
  f("patch_cells", r.patch_cells, "cells in the optimized patches (summed over the passes)");
  f("free_nodes", r.free_nodes, "nodes allowed to move (summed over the passes)");
  f("sweeps", r.sweeps, "node sweeps of every pass");
  f("raise_rounds", r.raise_rounds, "rounds that raised the minimum");
  f("evaluations", r.evaluations, "cell evaluations of the optimization (each a Bezier bound of det J)");
  f("reverted", r.reverted, "the result was worse than the input and was undone");
}

namespace detail {

// Cells holding each node (compressed rows), in cell order.
template <int Dim>
void node_cells(const Mesh<Dim>& mesh, std::vector<Index>& offsets, std::vector<Index>& cells,
                std::vector<std::pair<std::size_t, Index>>& where) {
  const Index n = mesh.num_nodes();
  offsets.assign(static_cast<std::size_t>(n) + 1, 0);
  where.clear();
  for (std::size_t b = 0; b < mesh.cells.size(); ++b)
    for (Index e = 0; e < mesh.cells[b].size(); ++e) {
      where.emplace_back(b, e);
      for (const Index v : mesh.cells[b].element(e)) ++offsets[static_cast<std::size_t>(v) + 1];
    }
  for (std::size_t i = 0; i < static_cast<std::size_t>(n); ++i) offsets[i + 1] += offsets[i];
  cells.assign(static_cast<std::size_t>(offsets.back()), 0);
  std::vector<Index> fill(offsets.begin(), offsets.end() - 1);
  for (std::size_t c = 0; c < where.size(); ++c)
    for (const Index v : mesh.cells[where[c].first].element(where[c].second)) cells[static_cast<std::size_t>(fill[static_cast<std::size_t>(v)]++)] = static_cast<Index>(c);
}

}  // namespace detail

namespace detail {

// The optimization of a patch of cells and its undoing, over the node-to-cell adjacency of one
// mesh (built once for every pass).
template <int Dim>
class PatchOptimizer {
 public:
  struct Pass {
    Index patch_cells = 0;
    Index free_nodes = 0;
    int sweeps = 0;
    bool reverted = false;
  };

  PatchOptimizer(Mesh<Dim>& mesh, std::span<const char> fixed) : mesh_(mesh), fixed_(fixed) {
    node_cells(mesh, offsets_, cells_, where_);
  }

  // Optimizes the nodes of the `seeds` cells and of `layers` rings around them towards every
  // cell at or above `target`, stopping once evaluations() reaches `max_evaluations` (and,
  // with `raise`, after a sweep that did not lift the seeds' lowest value), then certifies the
  // touched cells again into `quality`; a result with more invalid cells or a lower certified
  // minimum is undone.
  Pass run(const std::vector<Index>& seeds, double target, int layers, int max_sweeps, long long max_evaluations,
           bool raise, std::vector<double>& quality) {
    Pass pass;
    std::vector<char> in_patch(where_.size(), 0);
    std::vector<Index> frontier = seeds, patch = seeds;
    for (const Index c : seeds) in_patch[static_cast<std::size_t>(c)] = 1;
    for (int layer = 0; layer < layers; ++layer) {
      std::vector<Index> next;
      for (const Index c : frontier)
        for (const Index v : nodes_of(c))
          for (const Index d : cells_of(v))
            if (!in_patch[static_cast<std::size_t>(d)]) in_patch[static_cast<std::size_t>(d)] = 1, next.push_back(d);
      patch.insert(patch.end(), next.begin(), next.end());
      frontier = std::move(next);
    }
    pass.patch_cells = static_cast<Index>(patch.size());
    std::vector<Index> free_nodes;
    std::vector<char> is_free(static_cast<std::size_t>(mesh_.num_nodes()), 0);
    for (const Index c : patch)
      for (const Index v : nodes_of(c))
        if (!fixed_[static_cast<std::size_t>(v)] && !is_free[static_cast<std::size_t>(v)]) is_free[static_cast<std::size_t>(v)] = 1, free_nodes.push_back(v);
    pass.free_nodes = static_cast<Index>(free_nodes.size());

    // How far a cell is below the target, squared. A move is taken when it lowers the sum of
    // these over the cells around the node and no cell falls below the lower of its value and
    // the target: cells above stay above, the others only rise, so no cell is folded to lift
    // another (a plain max-min or sum search took such moves and multiplied the invalid cells).
    const auto deficit = [&](double j) { return j >= target ? 0.0 : (target - j) * (target - j); };
    std::vector<double> current, trial_values;
    const auto values_around = [&](Index v, std::vector<double>& out) {
      out.clear();
      for (const Index c : cells_of(v)) out.push_back(bound(c));
    };
    const auto score = [&](const std::vector<double>& values) {
      double sum = 0.0;
      for (const double j : values) sum += deficit(j);
      return -sum;
    };
    const auto admissible = [&](const std::vector<double>& before, const std::vector<double>& after) {
      for (std::size_t k = 0; k < before.size(); ++k)
        if (after[k] < std::min(before[k], target)) return false;
      return true;
    };
    const auto patch_deficit = [&] {
      double sum = 0.0;
      for (const Index c : patch) sum += deficit(bound(c));
      return sum;
    };
    std::vector<Vec<Dim>> original;
    for (const Index v : free_nodes) original.emplace_back(mesh_.points.col(v));
    double total = patch_deficit();
    const auto lowest_seed = [&] {
      double low = std::numeric_limits<double>::infinity();
      for (const Index c : seeds) low = std::min(low, bound(c));
      return low;
    };
    double lowest = raise ? lowest_seed() : 0.0;
    for (int sweep = 0; sweep < max_sweeps && evaluations_ < max_evaluations; ++sweep) {
      ++pass.sweeps;
      for (const Index v : free_nodes) {
        if (evaluations_ >= max_evaluations) break;
        values_around(v, current);
        double best = score(current);
        if (best == 0.0) continue;  // every cell around it already at the target
        const double start = 0.1 * reach(v);
        for (double h = start; h > 1e-3 * start; h *= 0.5) {
          bool improved = true;
          while (improved) {
            improved = false;
            for (int d = 0; d < Dim && !improved; ++d)
              for (const double s : {h, -h}) {
                mesh_.points(d, v) += s;
                values_around(v, trial_values);
                const double trial = score(trial_values);
                if (trial > best && admissible(current, trial_values)) {
                  best = trial;
                  current.swap(trial_values);
                  improved = true;
                  break;
                }
                mesh_.points(d, v) -= s;
              }
          }
        }
      }
      const double now = patch_deficit();
      bool progress = now < total * (1.0 - 1e-3);
      if (raise) {
        const double low = lowest_seed();
        progress = progress && low > lowest;
        lowest = low;
      }
      total = now;
      if (!progress || now == 0.0) break;
    }

    // Certify again every cell a free node belongs to.
    const std::vector<double> input_quality = quality;
    const double min_before = *std::min_element(quality.begin(), quality.end());
    const auto invalid = [](const std::vector<double>& q) { return std::count_if(q.begin(), q.end(), [](double j) { return j <= 0.0; }); };
    std::vector<char> touched(where_.size(), 0);
    for (const Index v : free_nodes)
      for (const Index c : cells_of(v)) touched[static_cast<std::size_t>(c)] = 1;
    ScaledJacobianOptions certified;
    certified.sharp_max = false;
    for (std::size_t c = 0; c < where_.size(); ++c)
      if (touched[c]) quality[c] = scaled_jacobian_fixed<Dim>(type_of(static_cast<Index>(c)), coords(static_cast<Index>(c)), certified).certified_min;
    // The sweeps raise the cells' lower bounds; the certified values (subdivided) follow them
    // but not strictly. A result worse than the input by the certified count or minimum is undone.
    if (invalid(quality) > invalid(input_quality) || *std::min_element(quality.begin(), quality.end()) < min_before) {
      for (std::size_t k = 0; k < free_nodes.size(); ++k) mesh_.points.col(free_nodes[k]) = original[k];
      quality = input_quality;
      pass.reverted = true;
    }
    return pass;
  }

  [[nodiscard]] long long evaluations() const noexcept { return evaluations_; }

 private:
  std::span<const Index> cells_of(Index v) const {
    return {cells_.data() + offsets_[static_cast<std::size_t>(v)],
            static_cast<std::size_t>(offsets_[static_cast<std::size_t>(v) + 1] - offsets_[static_cast<std::size_t>(v)])};
  }
  auto nodes_of(Index c) const {
    const auto& [b, e] = where_[static_cast<std::size_t>(c)];
    return mesh_.cells[b].element(e);
  }
  ElementType type_of(Index c) const { return mesh_.cells[where_[static_cast<std::size_t>(c)].first].type; }
  ElementCoords<Dim> coords(Index c) const {
    const auto el = nodes_of(c);
    ElementCoords<Dim> x(Dim, static_cast<Index>(el.size()));
    for (std::size_t i = 0; i < el.size(); ++i) x.col(static_cast<Index>(i)) = mesh_.points.col(el[i]);
    return x;
  }
  // The value a cell is optimized for: the smallest Bézier coefficient of its det J over its
  // straight measure (a lower bound of its scaled Jacobian, no subdivision: no sampling gap,
  // and cheap).
  double bound(Index c) {
    ++evaluations_;
    ScaledJacobianOptions options;
    options.sharp = false;
    options.sharp_max = false;
    options.max_depth = 0;
    const ScaledJacobian j = scaled_jacobian_fixed<Dim>(type_of(c), coords(c), options);
    return j.degenerate ? -std::numeric_limits<double>::infinity() : j.certified_min;
  }
  // A node's neighbourhood size: its farthest neighbour in its cells.
  double reach(Index v) const {
    double r = 0.0;
    for (const Index c : cells_of(v))
      for (const Index w : nodes_of(c)) r = std::max(r, (mesh_.points.col(w) - mesh_.points.col(v)).norm());
    return r;
  }

  Mesh<Dim>& mesh_;
  std::span<const char> fixed_;
  std::vector<Index> offsets_, cells_;
  std::vector<std::pair<std::size_t, Index>> where_;
  long long evaluations_ = 0;
};

}  // namespace detail

/// Throws InputError naming the key of a negative count, margin or budget.
inline void check_untangle_options(const UntangleOptions& options) {
  UntangleOptions copy = options;
  visit_options(copy, [](const std::string& key, auto& value, std::string_view) {
    if constexpr (!std::is_same_v<std::remove_cvref_t<decltype(value)>, bool>)
      if (key != "untangle_threshold" && !(value >= 0))
        throw InputError("untangle: option '" + key + "' must be non-negative (got " + format_option_value(value) + ")");
  });
}

/// Optimizes the nodes around the cells of `mesh` whose value in `quality` (the certified
/// scaled Jacobian of each cell, in cell order) is below options.threshold, then raises the
/// worst cells (options.raise_rounds); nodes with fixed[node] set do not move. `quality` is
/// updated for every cell that was certified again. Throws InputError when the sizes do not
/// match the mesh.
template <int Dim>
UntangleReport untangle(Mesh<Dim>& mesh, std::span<const char> fixed, std::vector<double>& quality, const UntangleOptions& options = {}) {
  if (quality.size() != static_cast<std::size_t>(mesh.num_cells()) || fixed.size() != static_cast<std::size_t>(mesh.num_nodes()))
    throw InputError("untangle: " + std::to_string(quality.size()) + " cell values and " + std::to_string(fixed.size()) +
                     " node flags for a mesh of " + std::to_string(mesh.num_cells()) + " cells and " +
                     std::to_string(mesh.num_nodes()) + " nodes");
  check_untangle_options(options);
  UntangleReport report;
  if (quality.empty()) return report;
  const auto minimum = [&] { return *std::min_element(quality.begin(), quality.end()); };
  report.min_before = minimum();
  report.min_after = report.min_before;
  std::vector<Index> below;
  for (std::size_t c = 0; c < quality.size(); ++c) {
    if (quality[c] < options.threshold) below.push_back(static_cast<Index>(c));
    report.invalid_before += quality[c] <= 0.0 ? 1 : 0;
  }
  report.cells_below = static_cast<Index>(below.size());
  report.invalid_after = report.invalid_before;
  const bool raise = options.raise_rounds > 0 && options.raise_cells > 0;
  if (!options.enabled || (below.empty() && !raise)) return report;

  detail::PatchOptimizer<Dim> optimizer(mesh, fixed);
  const auto add = [&](const typename detail::PatchOptimizer<Dim>::Pass& pass) {
    report.patch_cells += pass.patch_cells;
    report.free_nodes += pass.free_nodes;
    report.sweeps += pass.sweeps;
  };
  if (!below.empty()) {
    const auto pass = optimizer.run(below, options.threshold, options.layers, options.max_sweeps,
                                    std::numeric_limits<long long>::max(), false, quality);
    add(pass);
    report.reverted = pass.reverted;
  }
  // The worst cells first: each round moves the nodes of the `raise_cells` worst cells towards
  // the minimum plus the margin, so it costs a small patch; the rounds stop when the minimum no
  // longer rises (a cell no free node can lift) or the budget is spent.
  std::vector<Index> order(quality.size());
  const long long budget = optimizer.evaluations() +
                           static_cast<long long>(std::max(0.0, options.raise_budget) * static_cast<double>(quality.size()));
  for (int round = 0; raise && round < options.raise_rounds && optimizer.evaluations() < budget; ++round) {
    const double low = minimum();
    if (low < options.threshold) break;  // the untangling could not lift these; a round would not either
    std::iota(order.begin(), order.end(), Index{0});
    const auto count = std::min<std::size_t>(static_cast<std::size_t>(options.raise_cells), order.size());
    std::nth_element(order.begin(), order.begin() + static_cast<std::ptrdiff_t>(count - 1), order.end(),
                     [&](Index a, Index b) { return quality[static_cast<std::size_t>(a)] < quality[static_cast<std::size_t>(b)]; });
    // The worst cells and every cell tied with the last of them, worst first and tied cells in
    // cell order: on a mesh with symmetries many cells share a value to round-off, and choosing
    // among them (or ordering the sweep) by round-off curved one geometry stored as a circle and
    // as a B-spline 0.05 apart.
    const auto level = [&](Index c) { return std::round(quality[static_cast<std::size_t>(c)] * 1e9); };
    const double last = level(order[count - 1]);
    const double target = low + options.raise_margin;
    std::vector<Index> seeds;
    for (Index c = 0; c < static_cast<Index>(quality.size()); ++c)
      if (level(c) <= last && quality[static_cast<std::size_t>(c)] < target) seeds.push_back(c);
    std::stable_sort(seeds.begin(), seeds.end(), [&](Index a, Index b) { return level(a) < level(b); });
    add(optimizer.run(seeds, target, options.raise_layers, options.max_sweeps, budget, true, quality));
    if (!(minimum() > low + 1e-4)) break;
    ++report.raise_rounds;
  }
  report.evaluations = optimizer.evaluations();
  report.min_after = minimum();
  report.invalid_after = static_cast<Index>(std::count_if(quality.begin(), quality.end(), [](double q) { return q <= 0.0; }));
  return report;
}

}  // namespace meshmotion
