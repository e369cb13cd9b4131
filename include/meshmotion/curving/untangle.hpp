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
/// around it (every cell holding it, inside the patch or not), by line searches along the
/// axes and the diagonals, on which every cell's Bézier coefficients are polynomials of the
/// step (two to four evaluations of a cell give its whole line); sweeps repeat while the
/// patch's total shortfall falls. The nodes the caller
/// marks fixed (the boundary) stay, except those it lets slide (SlidingNodes: a wall node
/// inside a face of its geometry, or on an edge between two facets that meet smoothly): during
/// the untangling (not the raising rounds below) each of them moves along its geometry, every
/// trial place projected back onto it, in the tangent directions it is given; det J is no
/// longer a polynomial of the step there, so each trial evaluates the cells around it. A cell
/// whose nodes are all on the walls (across a sharp trailing edge, at a wing's tip) has no
/// other node to move. Every cell the sweeps touched is then certified again
/// (Bézier bounds) and the caller's per-cell values replaced; a result with more invalid cells
/// or a lower certified minimum than the input is undone (UntangleReport::reverted).
///
/// Cells the node-by-node search leaves invalid (it cannot make the coordinated moves a twisted
/// patch needs: a shaken P3 square kept 20 of its triangles and every quadrilateral folded) get
/// their patch's free nodes moved together (UntangleOptions::untangle_joint,
/// PatchOptimizer::run_together(): conjugate gradients on a log barrier of the patch's det J
/// Bézier coefficients, under a barrier that moves up with the lowest), the patch doubled
/// while some stay invalid (three passes at most); those cells are certified again and a worse
/// result undone, as for the search.
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
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <numeric>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>
#include <unordered_map>
#include <utility>
#include <vector>

namespace meshmotion {

/// Options of untangle().
struct UntangleOptions {
  bool untangle = true;
  double untangle_threshold = 0.1;
  int untangle_layers = 3;
  int untangle_sweeps = 20;
  bool untangle_slide = true;
  bool untangle_joint = true;
  int raise_rounds = 4;
  int raise_cells = 16;
  int raise_layers = 0;
  double raise_margin = 0.05;
  double raise_budget = 4.0;
};

/// A boundary node that untangle() may move along its geometry: the unit directions of its
/// tangent line or plane that it searches, and the projection of a nearby point onto the
/// geometry it lies on.
template <int Dim>
struct SlidingNode {
  std::vector<Vec<Dim>> directions;
  std::function<Vec<Dim>(const Vec<Dim>&)> project;
};

/// Sliding nodes by node index.
template <int Dim>
using SlidingNodes = std::unordered_map<Index, SlidingNode<Dim>>;

/// What untangle() did.
struct UntangleReport {
  Index cells_below = 0;     ///< cells under the threshold before
  Index invalid_before = 0;
  Index invalid_after = 0;
  double min_before = 0.0;   ///< certified minimum over all cells before and after
  double min_after = 0.0;
  Index patch_cells = 0;     ///< cells in the optimized patches (summed over the passes)
  Index free_nodes = 0;      ///< nodes that were allowed to move (summed over the passes)
  Index slid_nodes = 0;      ///< boundary nodes that moved along their geometry
  int sweeps = 0;            ///< node sweeps of every pass
  int raise_rounds = 0;      ///< rounds that raised the minimum
  int joint_passes = 0;      ///< passes moving a patch's nodes together (cells left invalid; the patch doubled each pass)
  long long evaluations = 0; ///< cell evaluations of the optimization (each a Bézier bound of det J)
  bool reverted = false;     ///< the untangling's result was worse than its input and was undone
};

/// The keys of UntangleOptions (core/fields.hpp): flat, since they sit among the curving
/// pipeline's own keys.
template <class F>
void visit_options(UntangleOptions& o, F&& f, const std::string& prefix = {}) {
  f(prefix + "untangle", o.untangle, "optimize the cells below untangle_threshold after the regularization (false: leave the mesh as it is)");
  f(prefix + "untangle_threshold", o.untangle_threshold, OptionHelp{"optimize the high-order nodes around cells whose certified scaled Jacobian is below this", range::at_most(1)});
  f(prefix + "untangle_layers", o.untangle_layers, OptionHelp{"rings of neighbouring cells that move with a cell below the threshold", range::non_negative});
  f(prefix + "untangle_sweeps", o.untangle_sweeps, OptionHelp{"node sweeps at most per pass", range::at_least(1)});
  f(prefix + "untangle_slide", o.untangle_slide, OptionHelp{"wall nodes and sliding planes' nodes move along their geometry while untangling", {},
      "Boundary nodes the caller lets slide (untangle()'s `sliding`; in the curving pipeline the wall nodes "
      "on their faces, those on a CAD model's edges along the edges, and the symmetry planes' nodes) move along "
      "their geometry."});
  f(prefix + "untangle_joint", o.untangle_joint, OptionHelp{"then move the nodes of a patch around each cell left invalid together", {},
      "Cells the node-by-node search leaves invalid: the free nodes of a patch around them (untangle_layers "
      "rings, doubled while some stay invalid, three passes at most) move together, by conjugate gradients "
      "on a log barrier of their det J's Bezier coefficients under a moving barrier (Toulorge et al. 2013); "
      "false: the node-by-node search alone."});
  f(prefix + "raise_rounds", o.raise_rounds, OptionHelp{"then rounds raising the worst cells while the minimum rises (0: none)", range::non_negative,
      "After the cells below the threshold, rounds that raise the certified minimum: each optimizes the "
      "`raise_cells` worst cells (those within `raise_margin` of the minimum) and `raise_layers` rings around "
      "them towards the minimum plus the margin; the rounds stop when the minimum no longer rises."});
  f(prefix + "raise_cells", o.raise_cells, OptionHelp{"worst cells optimized per round", range::at_least(1)});
  f(prefix + "raise_layers", o.raise_layers, OptionHelp{"rings of cells around them that move too", range::non_negative});
  f(prefix + "raise_margin", o.raise_margin, OptionHelp{"cells within this of the minimum are the worst; the round aims at minimum + margin", range::non_negative});
  f(prefix + "raise_budget", o.raise_budget, OptionHelp{"the rounds' cell evaluations at most, per cell of the mesh", range::non_negative,
      "The rounds' work at most: this many cell evaluations per cell of the mesh (one evaluation costs about "
      "what the certification spends on a cell)."});
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
  f("slid_nodes", r.slid_nodes, "boundary nodes that moved along their geometry");
  f("sweeps", r.sweeps, "node sweeps of every pass");
  f("raise_rounds", r.raise_rounds, "rounds that raised the minimum");
  f("joint_passes", r.joint_passes, "passes moving a patch's nodes together (cells the node-by-node search left invalid)");
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

// A det J's lattice values or Bézier coefficients: a tet165's 2,024, a hex729's 13,824. On the
// heap, kept from one line search to the next (each cell line's storage is reused): they are
// allocated again only where the cells around a node change type.
using UntangleLattice = Eigen::VectorXd;

// The optimization of a patch of cells and its undoing, over the node-to-cell adjacency of one
// mesh (built once for every pass).
template <int Dim>
class PatchOptimizer {
 public:
  struct Pass {
    Index patch_cells = 0;
    Index free_nodes = 0;
    Index slid_nodes = 0;
    int sweeps = 0;
    bool reverted = false;
  };

  PatchOptimizer(Mesh<Dim>& mesh, std::span<const char> fixed, const SlidingNodes<Dim>& sliding)
      : mesh_(mesh), fixed_(fixed), sliding_(sliding) {
    node_cells(mesh, offsets_, cells_, where_);
  }

  // Optimizes the nodes of the `seeds` cells and of `layers` rings around them towards every
  // cell at or above `target`, stopping once evaluations() reaches `max_evaluations` (and,
  // with `raise`, after a sweep that did not lift the seeds' lowest value), then certifies the
  // touched cells again into `quality`; a result with more invalid cells or a lower certified
  // minimum is undone. With `slide`, the sliding nodes of the patch move too.
  Pass run(const std::vector<Index>& seeds, double target, int layers, int max_sweeps, long long max_evaluations,
           bool raise, bool slide, std::vector<double>& quality) {
    Pass pass;
    const std::vector<Index> patch = patch_around(seeds, layers);
    pass.patch_cells = static_cast<Index>(patch.size());
    std::vector<Index> free_nodes;
    std::vector<const SlidingNode<Dim>*> slides;  // per free node: how it slides, or null
    std::vector<char> is_free(static_cast<std::size_t>(mesh_.num_nodes()), 0);
    for (const Index c : patch)
      for (const Index v : nodes_of(c)) {
        if (is_free[static_cast<std::size_t>(v)]) continue;
        const SlidingNode<Dim>* on = nullptr;
        if (fixed_[static_cast<std::size_t>(v)]) {
          const auto it = slide ? sliding_.find(v) : sliding_.end();
          if (it == sliding_.end()) continue;
          on = &it->second;
        }
        is_free[static_cast<std::size_t>(v)] = 1;
        free_nodes.push_back(v);
        slides.push_back(on);
      }
    pass.free_nodes = static_cast<Index>(free_nodes.size());

    const auto patch_deficit = [&] {
      double sum = 0.0;
      for (const Index c : patch) sum += deficit(bound(c), target);
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
      for (std::size_t k = 0; k < free_nodes.size() && evaluations_ < max_evaluations; ++k) {
        if (slides[k] != nullptr) slide_node(free_nodes[k], *slides[k], target);
        else optimize_node(free_nodes[k], target);
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

    pass.reverted = certify_or_undo(free_nodes, original, quality);
    for (std::size_t k = 0; k < free_nodes.size(); ++k)
      if (slides[k] != nullptr && mesh_.points.col(free_nodes[k]) != original[k]) ++pass.slid_nodes;
    return pass;
  }

  // Moves the free nodes of the patch (the `seeds` cells and `layers` rings around them; the
  // boundary held) together, as Gmsh's HighOrderOptimize (Toulorge et al., J. Comput. Phys.
  // 237, 2013) and NekMesh's optimiser do, for what the node-by-node search leaves folded (it
  // cannot make the coordinated moves a twisted patch needs). A moving-barrier descent on
  //   F = Σ over the cells holding a free node, over their det J's Bézier coefficients q (over
  //       the cell's straight measure at the start) below `target`, of log²((q − ε)/(target − ε)),
  // ε under the lowest q: F is infinite where a coefficient reaches ε, so no step takes a cell
  // below it, and each of `rounds` rounds raises ε under the new lowest. A coefficient is affine
  // in each coordinate of a node (det J is linear in each column of J), so one more evaluation
  // of each cell per coordinate gives its exact derivative. Nonlinear conjugate gradients
  // (Polak–Ribière, restarted along the gradient when not a descent), each step halved from a
  // fifth of the nearest node's reach until F falls, at most `iterations` a round, within
  // `max_evaluations`. The cells are then certified again and a worse result undone, as run().
  Pass run_together(const std::vector<Index>& seeds, double target, int layers, int rounds, int iterations,
                    long long max_evaluations, std::vector<double>& quality) {
    Pass pass;
    const std::vector<Index> patch = patch_around(seeds, layers);
    pass.patch_cells = static_cast<Index>(patch.size());
    std::vector<Index> free_nodes;
    std::vector<Index> slot(static_cast<std::size_t>(mesh_.num_nodes()), -1);  // node → its column among the free
    for (const Index c : patch)
      for (const Index v : nodes_of(c))
        if (!fixed_[static_cast<std::size_t>(v)] && slot[static_cast<std::size_t>(v)] < 0) {
          slot[static_cast<std::size_t>(v)] = static_cast<Index>(free_nodes.size());
          free_nodes.push_back(v);
        }
    pass.free_nodes = static_cast<Index>(free_nodes.size());
    if (free_nodes.empty()) return pass;
    std::vector<char> held(where_.size(), 0);
    std::vector<Index> cells;  // every cell a free node moves
    for (const Index v : free_nodes)
      for (const Index c : cells_of(v))
        if (!held[static_cast<std::size_t>(c)]) held[static_cast<std::size_t>(c)] = 1, cells.push_back(c);
    std::vector<double> scale(cells.size());
    double step_limit = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < cells.size(); ++i) {
      double linear = 0.0;
      const ElementCoords<Dim> x = coords(cells[i]);
      coefficients(type_of(cells[i]), x, samples_[0], linear);
      if (!(std::abs(linear) > degenerate_below(type_of(cells[i]), x))) return pass;  // no straight measure to scale by
      scale[i] = 1.0 / std::abs(linear);
    }
    for (const Index v : free_nodes) step_limit = std::min(step_limit, 0.2 * reach(v));
    if (!(step_limit > 0.0)) return pass;
    std::vector<Vec<Dim>> original;
    for (const Index v : free_nodes) original.emplace_back(mesh_.points.col(v));

    using Field = Eigen::Matrix<double, Dim, Eigen::Dynamic>;
    const auto lowest = [&] {
      double low = std::numeric_limits<double>::infinity();
      for (std::size_t i = 0; i < cells.size(); ++i) {
        double linear = 0.0;
        coefficients(type_of(cells[i]), coords(cells[i]), samples_[0], linear);
        low = std::min(low, samples_[0].minCoeff() * scale[i]);
      }
      return low;
    };
    // F at the nodes' places, and with `gradient` its gradient (Dim × free nodes); a call with
    // the gradient (always at the accepted places) also leaves their lowest q in `accepted_low`.
    double epsilon = 0.0, accepted_low = 0.0;
    const auto objective = [&](Field* gradient) {
      if (gradient != nullptr) gradient->setZero(Dim, static_cast<Index>(free_nodes.size()));
      double sum = 0.0, seen_low = std::numeric_limits<double>::infinity();
      UntangleLattice& q = samples_[0];
      UntangleLattice& moved = samples_[1];
      for (std::size_t i = 0; i < cells.size(); ++i) {
        const Index c = cells[i];
        ElementCoords<Dim> x = coords(c);
        double linear = 0.0;
        coefficients(type_of(c), x, q, linear);
        q *= scale[i];
        seen_low = std::min(seen_low, q.minCoeff());
        if (q.minCoeff() >= target) continue;
        if (!(q.minCoeff() > epsilon)) return std::numeric_limits<double>::infinity();
        UntangleLattice& slope = samples_[2];
        slope.resize(q.size());
        for (Index k = 0; k < q.size(); ++k) {
          if (q(k) >= target) {
            slope(k) = 0.0;
            continue;
          }
          const double l = std::log((q(k) - epsilon) / (target - epsilon));
          sum += l * l;
          slope(k) = 2.0 * l / (q(k) - epsilon);
        }
        if (gradient == nullptr) continue;
        const auto nodes = nodes_of(c);
        const double h = (x.rowwise().maxCoeff() - x.rowwise().minCoeff()).maxCoeff() * 0.1;
        for (std::size_t n = 0; n < nodes.size(); ++n) {
          const Index column = slot[static_cast<std::size_t>(nodes[n])];
          if (column < 0) continue;
          for (int a = 0; a < Dim; ++a) {
            const double keep = x(a, static_cast<Index>(n));
            x(a, static_cast<Index>(n)) = keep + h;
            coefficients(type_of(c), x, moved, linear);
            x(a, static_cast<Index>(n)) = keep;
            (*gradient)(a, column) += slope.dot(moved * scale[i] - q) / h;
          }
        }
      }
      if (gradient != nullptr) accepted_low = seen_low;
      return sum;
    };
    const auto place = [&](const Field& at) {
      for (std::size_t k = 0; k < free_nodes.size(); ++k) mesh_.points.col(free_nodes[k]) = at.col(static_cast<Index>(k));
    };
    Field at(Dim, static_cast<Index>(free_nodes.size()));
    for (std::size_t k = 0; k < free_nodes.size(); ++k) at.col(static_cast<Index>(k)) = mesh_.points.col(free_nodes[k]);
    double low = lowest();
    for (int round = 0; round < rounds && low < target && evaluations_ < max_evaluations; ++round) {
      epsilon = low - 0.25 * (target - low);
      Field gradient, previous, direction;
      double f = objective(&gradient);
      direction = -gradient;
      for (int it = 0; it < iterations && f > 0.0 && evaluations_ < max_evaluations; ++it) {
        if (direction.cwiseProduct(gradient).sum() >= 0.0) direction = -gradient;
        const double longest = direction.colwise().norm().maxCoeff();
        if (!(longest > 0.0)) break;
        double alpha = step_limit / longest, trial = std::numeric_limits<double>::infinity();
        for (int halvings = 0; halvings < 30; ++halvings, alpha *= 0.5) {
          place(at + alpha * direction);
          if ((trial = objective(nullptr)) < f) break;
        }
        if (!(trial < f)) {
          place(at);
          break;
        }
        at += alpha * direction;
        const bool stalled = trial > f * (1.0 - 1e-6);
        f = trial;
        previous = gradient;
        f = objective(&gradient);
        if (stalled) break;
        const double beta = std::max(0.0, gradient.cwiseProduct(gradient - previous).sum() / previous.squaredNorm());
        direction = -gradient + beta * direction;
      }
      if (!(accepted_low > low + 1e-6)) break;
      low = accepted_low;
    }
    pass.reverted = certify_or_undo(free_nodes, original, quality);
    return pass;
  }

  [[nodiscard]] long long evaluations() const noexcept { return evaluations_; }

 private:
  // The `seeds` cells and `layers` rings of their neighbours (cells sharing a node), seeds first.
  std::vector<Index> patch_around(const std::vector<Index>& seeds, int layers) const {
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
    return patch;
  }

  // Certifies again every cell a node of `moved` belongs to, into `quality`. The optimizations
  // raise the cells' lower bounds; the certified values (subdivided) follow them but not
  // strictly: a result worse than the input by the certified count or minimum puts the nodes
  // back at `original` and `quality` as it was. Whether it did.
  bool certify_or_undo(const std::vector<Index>& moved, const std::vector<Vec<Dim>>& original, std::vector<double>& quality) {
    const std::vector<double> input_quality = quality;
    const double min_before = *std::min_element(quality.begin(), quality.end());
    const auto invalid = [](const std::vector<double>& q) { return std::count_if(q.begin(), q.end(), [](double j) { return j <= 0.0; }); };
    std::vector<char> touched(where_.size(), 0);
    for (const Index v : moved)
      for (const Index c : cells_of(v)) touched[static_cast<std::size_t>(c)] = 1;
    ScaledJacobianOptions certified;
    certified.sharp_max = false;
    for (std::size_t c = 0; c < where_.size(); ++c)
      if (touched[c]) quality[c] = scaled_jacobian_fixed<Dim>(type_of(static_cast<Index>(c)), coords(static_cast<Index>(c)), certified).certified_min;
    if (invalid(quality) > invalid(input_quality) || *std::min_element(quality.begin(), quality.end()) < min_before) {
      for (std::size_t k = 0; k < moved.size(); ++k) mesh_.points.col(moved[k]) = original[k];
      quality = input_quality;
      return true;
    }
    return false;
  }

  // How far a cell is below the target, squared.
  static double deficit(double j, double target) { return j >= target ? 0.0 : (target - j) * (target - j); }

  // One cell around the node being moved, as a function of the node's place on a line (its
  // place now plus t along a unit direction): det J at each lattice point is linear in each
  // column of J, and moving the node along an axis changes one column, along any direction at
  // most all Dim, so det J's Bézier coefficients and the straight measure are polynomials in t
  // of degree 1 along an axis, Dim otherwise. The cell's value is min_k c_k(t) / |l(t)|.
  struct CellLine {
    std::array<UntangleLattice, 4> c;  // c[0] + t c[1] + t² c[2] + t³ c[3]
    std::array<double, 4> l{};
    int degree = 1;
    double degenerate_below = 0.0, at_zero = 0.0;
    [[nodiscard]] double value(double t) const {
      double measure = l[static_cast<std::size_t>(degree)];
      for (int i = degree; i-- > 0;) measure = measure * t + l[static_cast<std::size_t>(i)];
      measure = std::abs(measure);
      if (!(measure > degenerate_below)) return -std::numeric_limits<double>::infinity();
      double low = 0.0;
      switch (degree) {
        case 1: low = (c[0] + t * c[1]).minCoeff(); break;
        case 2: low = (c[0] + t * (c[1] + t * c[2])).minCoeff(); break;
        default: low = (c[0] + t * (c[1] + t * (c[2] + t * c[3]))).minCoeff(); break;
      }
      return low / measure;
    }
  };

  // det J's Bézier coefficients (a pyramid's on its collapsed cube) at the cell's nodes `x`,
  // unscaled, and its straight measure.
  void coefficients(ElementType type, const ElementCoords<Dim>& x, UntangleLattice& values, double& linear) {
    ++evaluations_;
    const detail::JacobianSpace& s = detail::jacobian_space(type);
    detail::lattice_dets<Dim>(s, x, 1.0, values);
    if (s.bezier) detail::to_bezier(s, values);
    linear = detail::linear_det<Dim>(s, x);
  }

  // The straight measure below which a cell at `x` counts as degenerate: 1e-12 of its vertices'
  // extent to the power Dim.
  static double degenerate_below(ElementType type, const ElementCoords<Dim>& x) {
    const auto vertices = x.leftCols(num_vertices(type));
    return 1e-12 * std::pow((vertices.rowwise().maxCoeff() - vertices.rowwise().minCoeff()).maxCoeff(), Dim);
  }

  // `line` for cell c along `direction` from node v's place: the polynomials from their values
  // at t = 0, s, -s, 2s (as many as the degree needs), s = `span`.
  void make_line(Index c, Index v, const Vec<Dim>& direction, bool axis, double span, CellLine& line) {
    const auto nodes = nodes_of(c);
    const auto local = static_cast<Index>(std::find(nodes.begin(), nodes.end(), v) - nodes.begin());
    ElementCoords<Dim> x = coords(c);
    line.degenerate_below = degenerate_below(type_of(c), x);
    line.degree = axis ? 1 : Dim;
    const Vec<Dim> at = x.col(local);
    std::array<UntangleLattice, 4>& f = samples_;
    std::array<double, 4> g{};
    constexpr std::array<double, 4> taus{0.0, 1.0, -1.0, 2.0};
    for (int j = 0; j <= line.degree; ++j) {
      x.col(local) = at + taus[static_cast<std::size_t>(j)] * span * direction;
      coefficients(type_of(c), x, f[static_cast<std::size_t>(j)], g[static_cast<std::size_t>(j)]);
    }
    // Monomial coefficients in tau = t / s, then in t.
    const auto fit = [&](const auto& f0, const auto& f1, const auto& fm, const auto& f2, auto& c0, auto& c1, auto& c2, auto& c3) {
      c0 = f0;
      if (line.degree == 1) {
        c1 = (f1 - f0) / span;
        return;
      }
      const auto even = ((f1 + fm) / 2 - f0);
      const auto odd = ((f1 - fm) / 2);
      if (line.degree == 2) {
        c1 = odd / span;
        c2 = even / (span * span);
        return;
      }
      c3 = (f2 - f0 - 4 * even - 2 * odd) / (6 * span * span * span);
      c1 = (odd - c3 * (span * span * span)) / span;
      c2 = even / (span * span);
    };
    fit(f[0], f[1], f[2], f[3], line.c[0], line.c[1], line.c[2], line.c[3]);
    fit(g[0], g[1], g[2], g[3], line.l[0], line.l[1], line.l[2], line.l[3]);
    line.at_zero = line.value(0.0);
  }

  // The directions a node moves along: the axes, then the diagonals (the axes alone stall where
  // the worst of two cells is lowest along a ridge across them).
  static const std::vector<Vec<Dim>>& directions() {
    static const std::vector<Vec<Dim>> list = [] {
      std::vector<Vec<Dim>> d;
      for (int a = 0; a < Dim; ++a) d.push_back(Vec<Dim>::Unit(a));
      for (int signs = 0; signs < (1 << (Dim - 1)); ++signs) {
        Vec<Dim> u = Vec<Dim>::Ones();
        for (int a = 0; a < Dim - 1; ++a)
          if (signs & (1 << a)) u(a) = -1.0;
        d.push_back(u.normalized());
      }
      return d;
    }();
    return list;
  }

  // Moves free node v along each direction in turn to the best place on that line, until no
  // direction gains: the place lowers the sum of the squared deficits of the cells holding v,
  // and no cell falls below the lower of its value and the target (cells above stay above, the
  // others only rise, so no cell is folded to lift another: a plain max-min or sum search took
  // such moves and multiplied the invalid cells). A line costs two to four evaluations of each
  // cell (CellLine) and is searched on those: the steps ±h for h from 0.4 of the node's
  // neighbourhood halving to 2e-4 of it, then halving steps around the best (from 0.2 or 0.3,
  // the NACA0012 quadrilaterals at P4 ended at 0.258 or 0.283; from 0.4 at 0.320). A gain
  // must exceed 1e-12 of the score: a gain at round-off, taken on one input and not on the
  // same input read from another file, made the curved meshes differ by 4e-3.
  void optimize_node(Index v, double target) {
    const auto around = cells_of(v);
    if (lines_.size() < around.size()) lines_.resize(around.size());  // never shrunk: each keeps its storage
    const std::span<const CellLine> active(lines_.data(), around.size());
    const double span = 0.4 * reach(v);
    if (!(span > 0.0)) return;
    const auto score = [&](double t) {
      double sum = 0.0;
      for (const CellLine& line : active) {
        const double j = line.value(t);
        if (j < std::min(line.at_zero, target)) return -std::numeric_limits<double>::infinity();
        sum += deficit(j, target);
      }
      return -sum;
    };
    const auto& along = directions();
    const int count = static_cast<int>(along.size());
    int still = 0;  // lines in a row along which v did not move
    for (int k = 0, lines = 0; still < count && lines < 4 * count; k = (k + 1) % count, ++lines) {
      for (std::size_t i = 0; i < around.size(); ++i) make_line(around[i], v, along[static_cast<std::size_t>(k)], k < Dim, span, lines_[i]);
      double best = score(0.0), step = 0.0;
      if (best == 0.0) return;  // every cell around it already at the target
      const auto gains = [&](double value) { return std::isinf(best) ? value > best : value > best + 1e-12 * std::abs(best); };
      for (double h = span; h > 5e-4 * span; h *= 0.5)
        for (const double t : {h, -h})
          if (const double trial = score(t); gains(trial)) best = trial, step = t;
      for (double h = 0.25 * std::abs(step); step != 0.0 && h > 1e-10 * span;) {
        bool moved = false;
        for (const double t : {step + h, step - h})
          if (const double trial = score(t); gains(trial)) {
            best = trial, step = t, moved = true;
            break;
          }
        if (!moved) h *= 0.5;
      }
      if (step == 0.0) {
        ++still;
        continue;
      }
      mesh_.points.col(v) += step * along[static_cast<std::size_t>(k)];
      still = 0;
    }
  }

  // A cell's value with its nodes at `x` (CellLine::value at a point).
  double value(ElementType type, const ElementCoords<Dim>& x, double degenerate_below) {
    double linear = 0.0;
    coefficients(type, x, samples_[0], linear);
    const double measure = std::abs(linear);
    return measure > degenerate_below ? samples_[0].minCoeff() / measure : -std::numeric_limits<double>::infinity();
  }

  // Moves sliding node v along its geometry: optimize_node's search and acceptance, each trial
  // place the projection of the node's place plus the step (the step's direction in its tangent
  // plane), the cells evaluated there (a projected line is no polynomial). The steps halve from
  // 0.4 of its neighbourhood to 1/64 of that: each costs a projection (a local search on a CAD
  // face) besides the cells.
  void slide_node(Index v, const SlidingNode<Dim>& slide, double target) {
    const auto around = cells_of(v);
    const double span = 0.4 * reach(v);
    if (!(span > 0.0) || slide.directions.empty()) return;
    struct Around {
      ElementCoords<Dim> x;
      Index local = 0;
      double degenerate_below = 0.0, at_zero = 0.0;
    };
    std::vector<Around> cells(around.size());
    for (std::size_t i = 0; i < around.size(); ++i) {
      const Index c = around[i];
      const auto nodes = nodes_of(c);
      Around& a = cells[i];
      a.x = coords(c);
      a.local = static_cast<Index>(std::find(nodes.begin(), nodes.end(), v) - nodes.begin());
      a.degenerate_below = degenerate_below(type_of(c), a.x);
    }
    const auto score = [&](const Vec<Dim>& p, bool first) {
      double sum = 0.0;
      for (std::size_t i = 0; i < cells.size(); ++i) {
        Around& a = cells[i];
        a.x.col(a.local) = p;
        const double j = value(type_of(around[i]), a.x, a.degenerate_below);
        if (first) a.at_zero = j;
        if (j < std::min(a.at_zero, target)) return -std::numeric_limits<double>::infinity();
        sum += deficit(j, target);
      }
      return -sum;
    };
    double best = score(mesh_.points.col(v), true);
    const auto count = static_cast<int>(slide.directions.size());
    int still = 0;
    for (int k = 0, lines = 0; still < count && lines < 4 * count && best != 0.0; k = (k + 1) % count, ++lines) {
      const Vec<Dim> at = mesh_.points.col(v);
      const Vec<Dim>& d = slide.directions[static_cast<std::size_t>(k)];
      const auto gains = [&](double trial) { return std::isinf(best) ? trial > best : trial > best + 1e-12 * std::abs(best); };
      Vec<Dim> place = at;
      double step = 0.0;
      const auto trial = [&](double t) {
        const Vec<Dim> p = slide.project(at + t * d);
        if (const double s = score(p, false); gains(s)) best = s, step = t, place = p;
      };
      for (double h = span; h > span / 64; h *= 0.5) trial(h), trial(-h);
      for (double h = 0.25 * std::abs(step); step != 0.0 && h > span / 1024; h *= 0.5) trial(step + h), trial(step - h);
      if (step == 0.0) {
        ++still;
        continue;
      }
      mesh_.points.col(v) = place;
      still = 0;
    }
  }

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
  const SlidingNodes<Dim>& sliding_;
  std::vector<Index> offsets_, cells_;
  std::vector<std::pair<std::size_t, Index>> where_;
  std::vector<CellLine> lines_;
  std::array<UntangleLattice, 4> samples_;
  long long evaluations_ = 0;
};

}  // namespace detail

/// Optimizes the nodes around the cells of `mesh` whose value in `quality` (the certified
/// scaled Jacobian of each cell, in cell order) is below options.untangle_threshold, then raises the
/// worst cells (options.raise_rounds); nodes with fixed[node] set do not move, except the
/// `sliding` ones, which move along their geometry while the cells below the threshold are
/// optimized. `quality` is updated for every cell that was certified again. Throws InputError
/// when the sizes do not match the mesh.
template <int Dim>
UntangleReport untangle(Mesh<Dim>& mesh, std::span<const char> fixed, std::vector<double>& quality, const UntangleOptions& options = {},
                        const SlidingNodes<Dim>& sliding = {}) {
  if (quality.size() != static_cast<std::size_t>(mesh.num_cells()) || fixed.size() != static_cast<std::size_t>(mesh.num_nodes()))
    throw InputError("untangle: " + std::to_string(quality.size()) + " cell values and " + std::to_string(fixed.size()) +
                     " node flags for a mesh of " + std::to_string(mesh.num_cells()) + " cells and " +
                     std::to_string(mesh.num_nodes()) + " nodes");
  check_option_ranges(options);
  UntangleReport report;
  if (quality.empty()) return report;
  const auto minimum = [&] { return *std::min_element(quality.begin(), quality.end()); };
  report.min_before = minimum();
  report.min_after = report.min_before;
  std::vector<Index> below;
  for (std::size_t c = 0; c < quality.size(); ++c) {
    if (quality[c] < options.untangle_threshold) below.push_back(static_cast<Index>(c));
    report.invalid_before += quality[c] <= 0.0 ? 1 : 0;
  }
  report.cells_below = static_cast<Index>(below.size());
  report.invalid_after = report.invalid_before;
  const bool raise = options.raise_rounds > 0 && options.raise_cells > 0;
  if (!options.untangle || (below.empty() && !raise)) return report;

  detail::PatchOptimizer<Dim> optimizer(mesh, fixed, sliding);
  const auto add = [&](const typename detail::PatchOptimizer<Dim>::Pass& pass) {
    report.patch_cells += pass.patch_cells;
    report.free_nodes += pass.free_nodes;
    report.slid_nodes += pass.slid_nodes;
    report.sweeps += pass.sweeps;
  };
  if (!below.empty()) {
    const auto pass = optimizer.run(below, options.untangle_threshold, options.untangle_layers, options.untangle_sweeps,
                                    std::numeric_limits<long long>::max(), false, options.untangle_slide, quality);
    add(pass);
    report.reverted = pass.reverted;
  }
  // What the node-by-node search left invalid: the nodes of a patch around those cells moved
  // together, the patch doubled while some stay invalid (three passes at most), within ten times
  // the search's cell evaluations (at least 100,000, or 50 a cell): a cell's evaluation costs
  // alike in both, so on a mesh of any size and order the passes take at most about ten times
  // the search's time (the shaken P4 squares took 5.5 times) or a fixed allowance.
  const long long joint_budget =
      optimizer.evaluations() +
      std::max({10 * optimizer.evaluations(), 50 * static_cast<long long>(quality.size()), 100'000LL});
  for (int layers = std::max(options.untangle_layers, 1);
       options.untangle_joint && report.joint_passes < 3 && optimizer.evaluations() < joint_budget; layers *= 2) {
    std::vector<Index> invalid;
    for (std::size_t c = 0; c < quality.size(); ++c)
      if (quality[c] <= 0.0) invalid.push_back(static_cast<Index>(c));
    if (invalid.empty() || below.empty()) break;
    add(optimizer.run_together(invalid, options.untangle_threshold, layers, 8, 50, joint_budget, quality));
    ++report.joint_passes;
  }
  // The worst cells first: each round moves the nodes of the `raise_cells` worst cells towards
  // the minimum plus the margin, so it costs a small patch; the rounds stop when the minimum no
  // longer rises (a cell no free node can lift) or the budget is spent.
  std::vector<Index> order(quality.size());
  const long long budget = optimizer.evaluations() +
                           static_cast<long long>(std::max(0.0, options.raise_budget) * static_cast<double>(quality.size()));
  for (int round = 0; raise && round < options.raise_rounds && optimizer.evaluations() < budget; ++round) {
    const double low = minimum();
    if (low < options.untangle_threshold) break;  // the untangling could not lift these; a round would not either
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
    add(optimizer.run(seeds, target, options.raise_layers, options.untangle_sweeps, budget, true, false, quality));
    if (!(minimum() > low + 1e-4)) break;
    ++report.raise_rounds;
  }
  report.evaluations = optimizer.evaluations();
  report.min_after = minimum();
  report.invalid_after = static_cast<Index>(std::count_if(quality.begin(), quality.end(), [](double q) { return q <= 0.0; }));
  return report;
}

}  // namespace meshmotion
