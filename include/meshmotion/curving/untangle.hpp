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

#include "meshmotion/core/error.hpp"
#include "meshmotion/core/mesh.hpp"
#include "meshmotion/core/types.hpp"
#include "meshmotion/quality/scaled_jacobian.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <span>
#include <string>
#include <utility>
#include <vector>

namespace meshmotion {

/// Options of untangle().
struct UntangleOptions {
  bool enabled = true;      ///< false: leave the regularized mesh as it is
  double threshold = 0.1;   ///< cells whose certified scaled Jacobian is below this are optimized
  int layers = 3;           ///< rings of neighbouring cells that move with them
  int max_sweeps = 20;      ///< node sweeps at most
};

/// What untangle() did.
struct UntangleReport {
  Index cells_below = 0;     ///< cells under the threshold before
  Index invalid_before = 0;
  Index invalid_after = 0;
  double min_before = 0.0;   ///< certified minimum over all cells before and after
  double min_after = 0.0;
  Index patch_cells = 0;     ///< cells in the optimized patch
  Index free_nodes = 0;      ///< nodes that were allowed to move
  int sweeps = 0;
  bool reverted = false;     ///< the result was worse than the input and was undone
};

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

/// Optimizes the high-order nodes around the cells of `mesh` whose value in `quality` (the
/// certified scaled Jacobian of each cell, in cell order) is below options.threshold; nodes
/// with fixed[node] set do not move. `quality` is updated for every cell that was certified
/// again. Throws InputError when the sizes do not match the mesh.
template <int Dim>
UntangleReport untangle(Mesh<Dim>& mesh, std::span<const char> fixed, std::vector<double>& quality, const UntangleOptions& options = {}) {
  if (quality.size() != static_cast<std::size_t>(mesh.num_cells()) || fixed.size() != static_cast<std::size_t>(mesh.num_nodes()))
    throw InputError("untangle: " + std::to_string(quality.size()) + " cell values and " + std::to_string(fixed.size()) +
                     " node flags for a mesh of " + std::to_string(mesh.num_cells()) + " cells and " +
                     std::to_string(mesh.num_nodes()) + " nodes");
  UntangleReport report;
  report.min_before = quality.empty() ? 0.0 : *std::min_element(quality.begin(), quality.end());
  report.min_after = report.min_before;
  for (const double q : quality) {
    report.cells_below += q < options.threshold ? 1 : 0;
    report.invalid_before += q <= 0.0 ? 1 : 0;
  }
  report.invalid_after = report.invalid_before;
  if (!options.enabled || report.cells_below == 0) return report;
  const std::vector<double> input_quality = quality;

  std::vector<Index> offsets, cells;
  std::vector<std::pair<std::size_t, Index>> where;
  detail::node_cells(mesh, offsets, cells, where);
  const auto cells_of = [&](Index v) {
    return std::span<const Index>(cells.data() + offsets[static_cast<std::size_t>(v)],
                                  static_cast<std::size_t>(offsets[static_cast<std::size_t>(v) + 1] - offsets[static_cast<std::size_t>(v)]));
  };
  const auto nodes_of = [&](Index c) {
    const auto& [b, e] = where[static_cast<std::size_t>(c)];
    return mesh.cells[b].element(e);
  };
  // The patch: the cells below the threshold and `layers` rings of neighbours.
  std::vector<char> in_patch(where.size(), 0);
  std::vector<Index> frontier;
  for (std::size_t c = 0; c < quality.size(); ++c)
    if (quality[c] < options.threshold) in_patch[c] = 1, frontier.push_back(static_cast<Index>(c));
  for (int layer = 0; layer < options.layers; ++layer) {
    std::vector<Index> next;
    for (const Index c : frontier)
      for (const Index v : nodes_of(c))
        for (const Index d : cells_of(v))
          if (!in_patch[static_cast<std::size_t>(d)]) in_patch[static_cast<std::size_t>(d)] = 1, next.push_back(d);
    frontier = std::move(next);
  }
  std::vector<Index> free_nodes;
  std::vector<char> is_free(static_cast<std::size_t>(mesh.num_nodes()), 0);
  for (std::size_t c = 0; c < where.size(); ++c) {
    if (!in_patch[c]) continue;
    ++report.patch_cells;
    for (const Index v : nodes_of(static_cast<Index>(c)))
      if (!fixed[static_cast<std::size_t>(v)] && !is_free[static_cast<std::size_t>(v)]) is_free[static_cast<std::size_t>(v)] = 1, free_nodes.push_back(v);
  }
  report.free_nodes = static_cast<Index>(free_nodes.size());

  // The value of a cell: the smallest Bézier coefficient of its det J over its straight measure
  // (a lower bound of its scaled Jacobian, no subdivision: no sampling gap, and cheap).
  ScaledJacobianOptions bound;
  bound.sharp = false;
  bound.sharp_max = false;
  bound.max_depth = 0;
  const auto objective = [&](Index c) {
    const auto& [b, e] = where[static_cast<std::size_t>(c)];
    const auto el = mesh.cells[b].element(e);
    detail::ElementCoords<Dim> x(Dim, static_cast<Index>(el.size()));
    for (std::size_t i = 0; i < el.size(); ++i) x.col(static_cast<Index>(i)) = mesh.points.col(el[i]);
    const ScaledJacobian j = detail::scaled_jacobian_fixed<Dim>(mesh.cells[b].type, x, bound);
    return j.degenerate ? -std::numeric_limits<double>::infinity() : j.certified_min;
  };
  // How far a cell is below the threshold, squared. A move is taken when it lowers the sum of
  // these over the cells around the node and no cell falls below the lower of its value and
  // the threshold: cells above stay above, the others only rise, so no cell is folded to lift
  // another (a plain max-min or sum search took such moves and multiplied the invalid cells).
  const double target = options.threshold;
  const auto deficit = [&](double j) { return j >= target ? 0.0 : (target - j) * (target - j); };
  std::vector<double> current, trial_values;
  const auto values_around = [&](Index v, std::vector<double>& out) {
    out.clear();
    for (const Index c : cells_of(v)) out.push_back(objective(c));
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
  // A node's neighbourhood size: its farthest neighbour in its cells.
  const auto reach = [&](Index v) {
    double r = 0.0;
    for (const Index c : cells_of(v))
      for (const Index w : nodes_of(c)) r = std::max(r, (mesh.points.col(w) - mesh.points.col(v)).norm());
    return r;
  };
  std::vector<Vec<Dim>> original;
  for (const Index v : free_nodes) original.emplace_back(mesh.points.col(v));
  const auto patch_deficit = [&] {
    double sum = 0.0;
    for (std::size_t c = 0; c < where.size(); ++c)
      if (in_patch[c]) sum += deficit(objective(static_cast<Index>(c)));
    return sum;
  };
  double total = patch_deficit();
  for (int sweep = 0; sweep < options.max_sweeps; ++sweep) {
    ++report.sweeps;
    for (const Index v : free_nodes) {
      values_around(v, current);
      double best = score(current);
      if (best == 0.0) continue;  // every cell around it already above the threshold
      const double start = 0.1 * reach(v);
      for (double h = start; h > 1e-3 * start; h *= 0.5) {
        bool improved = true;
        while (improved) {
          improved = false;
          for (int d = 0; d < Dim && !improved; ++d)
            for (const double s : {h, -h}) {
              mesh.points(d, v) += s;
              values_around(v, trial_values);
              const double trial = score(trial_values);
              if (trial > best && admissible(current, trial_values)) {
                best = trial;
                current.swap(trial_values);
                improved = true;
                break;
              }
              mesh.points(d, v) -= s;
            }
        }
      }
    }
    const double now = patch_deficit();
    const bool progress = now < total * (1.0 - 1e-3);
    total = now;
    if (!progress || now == 0.0) break;
  }

  // Certify again every cell a free node belongs to.
  std::vector<char> touched(where.size(), 0);
  for (const Index v : free_nodes)
    for (const Index c : cells_of(v)) touched[static_cast<std::size_t>(c)] = 1;
  for (std::size_t c = 0; c < where.size(); ++c) {
    if (!touched[c]) continue;
    const auto& [b, e] = where[c];
    const auto el = mesh.cells[b].element(e);
    detail::ElementCoords<Dim> x(Dim, static_cast<Index>(el.size()));
    for (std::size_t i = 0; i < el.size(); ++i) x.col(static_cast<Index>(i)) = mesh.points.col(el[i]);
    ScaledJacobianOptions certified;
    certified.sharp_max = false;
    quality[c] = detail::scaled_jacobian_fixed<Dim>(mesh.cells[b].type, x, certified).certified_min;
  }
  report.min_after = *std::min_element(quality.begin(), quality.end());
  report.invalid_after = static_cast<Index>(std::count_if(quality.begin(), quality.end(), [](double q) { return q <= 0.0; }));
  // The sweeps raise the cells' lower bounds; the certified values (subdivided) follow them but
  // not strictly. A result worse than the input by the certified count or minimum is undone.
  if (report.invalid_after > report.invalid_before || report.min_after < report.min_before) {
    for (std::size_t k = 0; k < free_nodes.size(); ++k) mesh.points.col(free_nodes[k]) = original[k];
    quality = input_quality;
    report.min_after = report.min_before;
    report.invalid_after = report.invalid_before;
    report.reverted = true;
  }
  return report;
}

}  // namespace meshmotion
