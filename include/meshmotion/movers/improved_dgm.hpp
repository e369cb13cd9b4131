#pragma once
/// \file
/// ImprovedDgmMover: Delaunay graph mapping whose graph also holds a layer of interior nodes
/// around the moving bodies, moved by RBF first (thesis section 2.2.4; Xiao et al. use a
/// background mesh moved by springs instead).
///
/// - Layer: from each prescribed node, a walk along mesh edges away from the wall (to the
///   neighbour farthest from it) of k steps, k the median number of steps that reaches
///   `layer_offset` × s, s the median spacing of the prescribed nodes; one node per
///   wall-normal mesh line, all k cells out,
///   thinned so that kept nodes are at least `layer_spacing` × s apart. On boundary-layer
///   meshes these nodes sit on the wall-normal mesh lines about one wall spacing out, so
///   the graph triangles between wall and layer are well shaped, their edges meet the wall
///   nearly normally and the near-wall cells follow the wall (thesis section 3.3.1).
/// - Each move: an RbfMover over the boundary nodes, evaluated only at the layer nodes, gives
///   the layer's displacements; DGM then maps every other node in the graph of the boundary
///   and layer nodes. Linear in the displacements (both stages are).
/// - Setup caches: the layer, the RBF factorization of the boundary system and its
///   evaluation rows at the layer nodes, and DGM's graph and barycentric coordinates.
///   Cost: setup = RbfMover setup on m + L points + DGM setup; move = one RBF solve +
///   L evaluations + DGM's mapping. Graph inversion is refused as in DgmMover.

#include "meshmotion/movers/improved_dgm_options.hpp"
#include "meshmotion/core/error.hpp"
#include "meshmotion/core/mesh.hpp"
#include "meshmotion/core/mesh_like.hpp"
#include "meshmotion/core/topology.hpp"
#include "meshmotion/core/types.hpp"
#include "meshmotion/movers/boundary.hpp"
#include "meshmotion/movers/detail/mover_support.hpp"
#include "meshmotion/movers/dgm.hpp"
#include "meshmotion/movers/detail/graph_mover_base.hpp"
#include "meshmotion/movers/mover.hpp"
#include "meshmotion/movers/rbf.hpp"
#include "meshmotion/spatial/kd_tree.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

namespace meshmotion {

/// The improved DGM mover in Dim dimensions; models MeshMover.
template <int Dim>
class ImprovedDgmMover : public detail::MoveFromMoveInto<ImprovedDgmMover<Dim>, Dim> {
 public:
  using detail::MoveFromMoveInto<ImprovedDgmMover<Dim>, Dim>::move_into;  // into the caller's storage
  static constexpr int dim = Dim;

  explicit ImprovedDgmMover(ImprovedDgmOptions options = {}) : options_(options) {}

  [[nodiscard]] const ImprovedDgmOptions& options() const noexcept { return options_; }
  [[nodiscard]] const MoverStats& stats() const noexcept { return stats_; }
  /// Mesh nodes of the interior layer chosen by the last setup.
  [[nodiscard]] const std::vector<Index>& layer() const noexcept { return layer_; }

  /// Chooses the layer, sets up the RBF stage and the graph. Throws InputError as DgmMover
  /// and RbfMover setups do, and for layer_offset <= 0, a negative layer_spacing or
  /// relative_support_radius ≤ 0.
  template <MeshLike M>
    requires(mesh_dim<M> == Dim)
  void setup(const M& mesh, const ResolvedBoundary<Dim>& boundary) {
    const detail::Stopwatch watch;
    if (!(options_.layer_offset > 0.0) || !(options_.layer_spacing >= 0.0) || !(options_.relative_support_radius > 0.0))
      throw InputError("ImprovedDgmMover::setup: needs layer_offset > 0, layer_spacing >= 0, relative_support_radius > 0 (got " +
                       std::to_string(options_.layer_offset) + ", " + std::to_string(options_.layer_spacing) + ", " +
                       std::to_string(options_.relative_support_radius) + ")");
    Points<Dim> points = copy_points(mesh);
    std::vector<Index> prescribed;
    for (std::size_t k = 0; k < boundary.nodes.size() && k < boundary.kinds.size(); ++k)
      if (boundary.kinds[k] == BoundaryKind::prescribed) prescribed.push_back(boundary.nodes[k]);
    layer_ = choose_layer(mesh, points, boundary, prescribed);

    // The RBF stage runs on the boundary and layer nodes only: a point-only mesh whose first
    // m nodes are the boundary nodes (same order) and whose other nodes are the layer.
    const Index m = boundary.size(), n_layer = static_cast<Index>(layer_.size());
    Mesh<Dim> stage;
    stage.points.resize(Dim, m + n_layer);
    ResolvedBoundary<Dim> stage_boundary = boundary;
    for (Index k = 0; k < m; ++k) {
      const Index v = boundary.nodes[static_cast<std::size_t>(k)];
      if (v < 0 || v >= points.cols())
        throw InputError("ImprovedDgmMover::setup: boundary node " + std::to_string(v) + " is out of range (expected 0 to " +
                         std::to_string(points.cols() - 1) + ")");
      stage.points.col(k) = points.col(v);
      stage_boundary.nodes[static_cast<std::size_t>(k)] = k;
    }
    for (Index k = 0; k < n_layer; ++k) stage.points.col(m + k) = points.col(layer_[static_cast<std::size_t>(k)]);
    RbfOptions rbf = options_.rbf;
    if (options_.auto_support_radius && n_layer > 0 && !prescribed.empty())
      rbf.support_radius = options_.relative_support_radius * std::max(largest_offset(points, prescribed),
                                                                       body_diagonal(points, prescribed));
    rbf_ = RbfMover<Dim>(rbf);
    rbf_.setup(stage, stage_boundary);
    base_.setup(std::move(points), boundary, layer_, std::nullopt, options_.dgm.outside);
    stats_ = base_.stats();
    stats_.factorizations = rbf_.stats().factorizations;
    stats_.nonzeros += rbf_.stats().nonzeros;
    stats_.setup_seconds = watch.seconds();
  }

  /// Displacement of every node (Dim × n_nodes) for `d` (Dim × boundary.size()). Throws
  /// InputError for a wrong shape or non-finite value, InvalidMeshError when the moved graph
  /// inverts (DgmOptions::check_inversion).
  /// move() (inherited) returns the same; move_into writes into `out`, resized only when its
  /// shape differs.
  void move_into(PointsView<Dim> d, Points<Dim>& out) {
    detail::timed_move<Dim>("ImprovedDgmMover::move", base_.ready(), d, base_.boundary().nodes, stats_, [&] {
      rbf_.move_into(d, stage_);
      base_.interpolate_displacements(d, Points<Dim>(stage_.rightCols(static_cast<Index>(layer_.size()))),
                                      options_.dgm.check_inversion, out);
      stats_.iterations = rbf_.stats().iterations;
      stats_.residual = rbf_.stats().residual;
      stats_.solve_seconds = rbf_.stats().solve_seconds;
      stats_.rebuild_seconds = rbf_.stats().rebuild_seconds;
    });
  }

  /// Forward derivative J w (Dim × n_nodes) for a boundary displacement change w: both stages
  /// are linear, so this is the RBF stage's change at the layer followed by the graph's
  /// interpolation (no inversion check, not counted as a move). Throws as move().
  [[nodiscard]] Points<Dim> derivative_forward(PointsView<Dim> w) {
    if (!base_.ready()) throw InputError("ImprovedDgmMover::derivative_forward: setup() was not called");
    const Points<Dim> stage = rbf_.derivative_forward(w);
    return base_.derivative_forward(w, Points<Dim>(stage.rightCols(static_cast<Index>(layer_.size()))));
  }
  /// Reverse derivative Jᵀ v (Dim × boundary.size()) for v (Dim × n_nodes): the graph's
  /// transpose, whose layer share goes back through the RBF stage's. Sliding entries zero.
  [[nodiscard]] Points<Dim> derivative_reverse(PointsView<Dim> v) {
    if (!base_.ready()) throw InputError("ImprovedDgmMover::derivative_reverse: setup() was not called");
    const Points<Dim> graph_bar = base_.derivative_reverse(v);
    const Index m = base_.boundary().size(), n_layer = static_cast<Index>(layer_.size());
    Points<Dim> stage_bar = Points<Dim>::Zero(Dim, m + n_layer);
    stage_bar.rightCols(n_layer) = graph_bar.rightCols(n_layer);
    Points<Dim> gradient = graph_bar.leftCols(m);
    gradient += rbf_.derivative_reverse(stage_bar);
    return gradient;
  }

 private:
  /// For each prescribed node, the node k steps along its outward mesh path (k: the median
  /// number of steps reaching layer_offset wall spacings); boundary nodes excluded; thinned.
  template <class M>
  [[nodiscard]] std::vector<Index> choose_layer(const M& mesh, const Points<Dim>& points, const ResolvedBoundary<Dim>& boundary,
                                                const std::vector<Index>& prescribed) const {
    if (prescribed.size() < 2) return {};
    const auto n = static_cast<std::size_t>(points.cols());
    const double wall_spacing = median_spacing(points, prescribed);
    const double offset = options_.layer_offset * wall_spacing;
    const Points<Dim> wall = gather(points, prescribed);
    const KdTree<Dim> wall_tree(wall);
    std::vector<double> distance(n);
    for (std::size_t v = 0; v < n; ++v) distance[v] = std::sqrt(wall_tree.nearest(points.col(static_cast<Index>(v)), 1).front().second);
    std::vector<char> on_boundary(n, 0);
    for (const Index v : boundary.nodes)
      if (v >= 0 && static_cast<std::size_t>(v) < n) on_boundary[static_cast<std::size_t>(v)] = 1;
    // From each wall node, walk outwards (to the neighbour farthest from the wall); the median
    // number of steps that reaches the offset, taken from every wall node, gives one layer
    // node per wall-normal mesh line, all the same number of cells out (no slivers between
    // layer nodes of neighbouring lines at different depths).
    const Adjacency neighbours = node_neighbours(mesh);
    const auto outward = [&](Index v) {
      Index next = v;
      for (const Index w : neighbours.row(v))
        if (distance[static_cast<std::size_t>(w)] > distance[static_cast<std::size_t>(next)]) next = w;
      return next;
    };
    std::vector<int> steps;
    for (Index v : prescribed) {
      int k = 0;
      for (Index next = outward(v); distance[static_cast<std::size_t>(v)] < offset && next != v; next = outward(v)) {
        v = next;
        ++k;
      }
      if (distance[static_cast<std::size_t>(v)] >= offset) steps.push_back(k);
    }
    if (steps.empty()) return {};
    const auto mid = steps.begin() + static_cast<std::ptrdiff_t>(steps.size() / 2);
    std::nth_element(steps.begin(), mid, steps.end());
    std::vector<char> taken(n, 0);
    std::vector<Index> candidates;
    for (Index v : prescribed) {
      for (int k = 0; k < *mid; ++k) v = outward(v);
      if (!on_boundary[static_cast<std::size_t>(v)] && !taken[static_cast<std::size_t>(v)]) {
        taken[static_cast<std::size_t>(v)] = 1;
        candidates.push_back(v);
      }
    }
    if (options_.layer_spacing == 0.0 || candidates.empty()) return candidates;

    // Greedy thinning: keep a node, drop the candidates closer than the spacing to it.
    const double spacing = options_.layer_spacing * wall_spacing;
    Points<Dim> at(Dim, static_cast<Index>(candidates.size()));
    for (std::size_t k = 0; k < candidates.size(); ++k) at.col(static_cast<Index>(k)) = points.col(candidates[k]);
    const KdTree<Dim> tree(at);
    std::vector<char> dropped(candidates.size(), 0);
    std::vector<Neighbor> found;
    std::vector<Index> kept;
    for (std::size_t k = 0; k < candidates.size(); ++k) {
      if (dropped[k]) continue;
      kept.push_back(candidates[k]);
      tree.radius_search(at.col(static_cast<Index>(k)), spacing, found);
      for (const auto& [j, d2] : found) dropped[j] = 1;
    }
    return kept;
  }

  [[nodiscard]] static Points<Dim> gather(const Points<Dim>& points, const std::vector<Index>& nodes) {
    Points<Dim> p(Dim, static_cast<Index>(nodes.size()));
    for (std::size_t k = 0; k < nodes.size(); ++k) p.col(static_cast<Index>(k)) = points.col(nodes[k]);
    return p;
  }

  /// Median distance from a prescribed node to its nearest other prescribed node.
  [[nodiscard]] static double median_spacing(const Points<Dim>& points, const std::vector<Index>& prescribed) {
    const Points<Dim> at = gather(points, prescribed);
    const KdTree<Dim> tree(at);
    std::vector<double> spacing;
    for (Index k = 0; k < at.cols(); ++k) {
      const auto nn = tree.nearest(at.col(k), 2);
      if (nn.size() == 2) spacing.push_back(std::sqrt(nn[1].second));
    }
    if (spacing.empty()) return 0.0;
    const auto mid = spacing.begin() + static_cast<std::ptrdiff_t>(spacing.size() / 2);
    std::nth_element(spacing.begin(), mid, spacing.end());
    return *mid;
  }

  /// Bounding-box diagonal of the prescribed nodes.
  [[nodiscard]] static double body_diagonal(const Points<Dim>& points, const std::vector<Index>& prescribed) {
    const Points<Dim> at = gather(points, prescribed);
    return (at.rowwise().maxCoeff() - at.rowwise().minCoeff()).norm();
  }

  /// Largest distance from a layer node to its nearest prescribed node.
  [[nodiscard]] double largest_offset(const Points<Dim>& points, const std::vector<Index>& prescribed) const {
    const Points<Dim> at = gather(points, prescribed);
    const KdTree<Dim> tree(at);
    double largest = 0.0;
    for (const Index v : layer_) largest = std::max(largest, std::sqrt(tree.nearest(points.col(v), 1).front().second));
    return largest;
  }

  ImprovedDgmOptions options_;
  std::vector<Index> layer_;
  RbfMover<Dim> rbf_;
  Points<Dim> stage_;
  detail::GraphMoverBase<Dim> base_{"ImprovedDgmMover"};
  MoverStats stats_;
};

}  // namespace meshmotion

// The compiled library (target meshmotion::compiled, src/) holds these for Dim 2 and 3.
#ifdef MESHMOTION_COMPILED
namespace meshmotion {
extern template class ImprovedDgmMover<2>;
extern template class ImprovedDgmMover<3>;
// setup is a template over the mesh type: its Mesh<Dim> form, the one make_mover() uses, too.
extern template void ImprovedDgmMover<2>::setup<Mesh<2>>(const Mesh<2>&, const ResolvedBoundary<2>&);
extern template void ImprovedDgmMover<3>::setup<Mesh<3>>(const Mesh<3>&, const ResolvedBoundary<3>&);
}  // namespace meshmotion
#endif
