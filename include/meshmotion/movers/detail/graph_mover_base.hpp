#pragma once
/// \file
/// GraphMoverBase: what the Delaunay-graph movers share. The graph holds the boundary nodes
/// (prescribed, fixed and sliding) plus optional extra nodes whose displacement the mover
/// supplies (the improved DGM's interior layer); every other node is a query of the graph.
/// A mover turns graph-node displacements into the quantities it interpolates (displacements,
/// or rotation angles and translations) and back.
///
/// Sliding nodes (exact, as in the RBF mover): a first graph without them interpolates their
/// displacement from the prescribed/fixed/extra nodes; its component along the plane normal is
/// removed (or, on a line, only its component along the line kept); the projected values
/// then join the full graph.

#include "meshmotion/core/error.hpp"
#include "meshmotion/core/threads.hpp"
#include "meshmotion/core/types.hpp"
#include "meshmotion/movers/boundary.hpp"
#include "meshmotion/movers/delaunay_graph_options.hpp"
#include "meshmotion/movers/detail/graph_interpolation.hpp"
#include "meshmotion/movers/detail/mover_support.hpp"
#include "meshmotion/movers/mover.hpp"
#include "meshmotion/solvers/detail/stopwatch.hpp"

#include <cmath>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace meshmotion::detail {

template <int Dim>
class GraphMoverBase {
 public:
  explicit GraphMoverBase(std::string who) : who_(std::move(who)) {}

  /// Builds the graphs. `points` Dim × n reference coordinates; `extra` sorted node indices,
  /// none of them boundary nodes. Throws InputError for inconsistent, unsorted, out-of-range
  /// or non-finite input and for a graph that spans no simplex.
  void setup(Points<Dim> points, const ResolvedBoundary<Dim>& boundary, const std::vector<Index>& extra,
             const std::optional<SimplexRbfOptions>& rbf, OutsideGraph outside) {
    const Stopwatch watch;
    ready_ = false;
    points_ = std::move(points);
    const Index n = points_.cols();
    if (!points_.allFinite()) throw InputError(who_ + "::setup: mesh has a non-finite coordinate");
    check_boundary<Dim>(who_ + "::setup", boundary, n, false);
    boundary_ = boundary;
    std::vector<char> role(static_cast<std::size_t>(n), 0);
    for (const Index v : boundary.nodes) role[static_cast<std::size_t>(v)] = 1;
    for (const Index v : extra) {
      if (v < 0 || v >= n || role[static_cast<std::size_t>(v)] != 0)
        throw InputError(who_ + "::setup: extra graph node " + std::to_string(v) + " is out of range or a boundary node");
      role[static_cast<std::size_t>(v)] = 2;
    }
    graph_nodes_ = boundary.nodes;
    graph_nodes_.insert(graph_nodes_.end(), extra.begin(), extra.end());
    queries_.clear();
    for (Index i = 0; i < n; ++i)
      if (role[static_cast<std::size_t>(i)] == 0) queries_.push_back(i);
    graph_.build(gather(graph_nodes_), gather(queries_), rbf, outside, who_ + "::setup");

    sliding_.clear();
    constrained_.clear();
    for (std::size_t g = 0; g < graph_nodes_.size(); ++g)
      (g < boundary.nodes.size() && boundary.kinds[g] == BoundaryKind::sliding ? sliding_ : constrained_)
          .push_back(static_cast<Index>(g));
    if (!sliding_.empty()) {
      std::vector<Index> from, to;
      for (const Index g : constrained_) from.push_back(graph_nodes_[static_cast<std::size_t>(g)]);
      for (const Index g : sliding_) to.push_back(graph_nodes_[static_cast<std::size_t>(g)]);
      sliding_graph_.build(gather(from), gather(to), rbf, outside, who_ + "::setup (graph without the sliding nodes)");
    }
    stats_ = MoverStats{};
    stats_.boundary_nodes = boundary.size();
    stats_.evaluated_nodes = static_cast<Index>(queries_.size());
    stats_.nonzeros = (Dim + 1) * static_cast<Index>(queries_.size() + (sliding_.empty() ? 0 : sliding_.size()));
    ready_ = true;
    stats_.setup_seconds = watch.seconds();
  }

  [[nodiscard]] bool ready() const noexcept { return ready_; }
  [[nodiscard]] const Points<Dim>& points() const noexcept { return points_; }
  [[nodiscard]] const ResolvedBoundary<Dim>& boundary() const noexcept { return boundary_; }
  [[nodiscard]] const std::vector<Index>& graph_nodes() const noexcept { return graph_nodes_; }
  [[nodiscard]] const GraphInterpolation<Dim>& graph() const noexcept { return graph_; }
  [[nodiscard]] MoverStats& stats() noexcept { return stats_; }
  [[nodiscard]] const MoverStats& stats() const noexcept { return stats_; }

  /// timed_move for the mover using this base: checks `d` (Dim × boundary.size(), finite,
  /// after setup), runs body(), counts and times the move in stats().
  template <class Body>
  void timed_move(PointsView<Dim> d, Body&& body) {
    detail::timed_move<Dim>(who_ + "::move", ready_, d, boundary_.nodes, stats_, std::forward<Body>(body));
  }

  /// The move. `d`: Dim × boundary.size(); `extra_displacements`: Dim × extra.size().
  /// `encode(positions, displacements)` → Rows × k interpolated quantities of k graph nodes
  /// (positions and displacements Dim × k); `decode(position, value)` → the displacement of a
  /// node at `position` for its interpolated value (a Rows vector). With `check_inversion`,
  /// throws InvalidMeshError naming an inverted graph simplex. Writes Dim × n into `out`.
  template <int Rows, class Encode, class Decode>
  void move(PointsView<Dim> d, const Points<Dim>& extra_displacements, Encode&& encode, Decode&& decode,
            bool check_inversion, Points<Dim>& out) {
    timed_move(d, [&] { interpolate<Rows>(d, extra_displacements, encode, decode, check_inversion, out); });
  }

  /// move() interpolating the displacements themselves (DGM, DGRBF).
  void move_displacements(PointsView<Dim> d, const Points<Dim>& extra_displacements, bool check_inversion,
                          Points<Dim>& out) {
    timed_move(d, [&] { interpolate_displacements(d, extra_displacements, check_inversion, out); });
  }

  /// move_displacements() without its checks and timing (the improved DGM times its whole move).
  void interpolate_displacements(PointsView<Dim> d, const Points<Dim>& extra_displacements, bool check_inversion,
                                 Points<Dim>& out) {
    interpolate<Dim>(
        d, extra_displacements, [](const Points<Dim>&, const Points<Dim>& u) -> const Points<Dim>& { return u; },
        [](const Vec<Dim>&, const Vec<Dim>& u) { return u; }, check_inversion, out);
  }

  /// Forward derivative of interpolate_displacements() (linear in the boundary change `w`,
  /// Dim × boundary.size(), and the extra nodes' change `extra`, Dim × extra.size()): their
  /// interpolation, without the inversion check.
  [[nodiscard]] Points<Dim> derivative_forward(PointsView<Dim> w, const Points<Dim>& extra) {
    if (!ready_) throw InputError(who_ + "::derivative_forward: setup() was not called");
    check_displacements<Dim>(who_ + "::derivative_forward", w, boundary_.nodes);
    Points<Dim> out;
    interpolate_displacements(w, extra, false, out);
    return out;
  }

  /// Reverse derivative of interpolate_displacements(): for v (Dim × n_nodes), the gradient of
  /// ⟨v, move(d)⟩ with respect to the graph nodes' displacements (Dim × graph size: the
  /// boundary entries, then the extra nodes). Sliding entries are zero (move() ignores them);
  /// their share reaches the nodes they are interpolated from.
  [[nodiscard]] Points<Dim> derivative_reverse(const PointsView<Dim>& v) const {
    if (!ready_) throw InputError(who_ + "::derivative_reverse: setup() was not called");
    check_node_field<Dim>(who_ + "::derivative_reverse", v, points_.cols());
    const auto n_graph = static_cast<Index>(graph_nodes_.size());
    Points<Dim> graph_bar(Dim, n_graph);
    for (Index g = 0; g < n_graph; ++g) graph_bar.col(g) = v.col(graph_nodes_[static_cast<std::size_t>(g)]);
    Points<Dim> query_bar(Dim, static_cast<Index>(queries_.size()));
    for (std::size_t k = 0; k < queries_.size(); ++k) query_bar.col(static_cast<Index>(k)) = v.col(queries_[k]);
    graph_.interpolate_transpose(query_bar, graph_bar);
    if (!sliding_.empty()) {
      // A sliding entry was overwritten by the projection of the sliding graph's value.
      Points<Dim> sliding_bar(Dim, static_cast<Index>(sliding_.size()));
      for (std::size_t s = 0; s < sliding_.size(); ++s) {
        const Index g = sliding_[s];
        sliding_bar.col(static_cast<Index>(s)) = boundary_.project(g, Vec<Dim>(graph_bar.col(g)));  // symmetric projector
        graph_bar.col(g).setZero();
      }
      Points<Dim> constrained_bar = Points<Dim>::Zero(Dim, static_cast<Index>(constrained_.size()));
      sliding_graph_.interpolate_transpose(sliding_bar, constrained_bar);
      for (std::size_t c = 0; c < constrained_.size(); ++c) graph_bar.col(constrained_[c]) += constrained_bar.col(static_cast<Index>(c));
    }
    return graph_bar;
  }

  /// The interpolation of move() without its checks and timing (for movers that time a
  /// larger move themselves).
  template <int Rows, class Encode, class Decode>
  void interpolate(PointsView<Dim> d, const Points<Dim>& extra_displacements, Encode&& encode, Decode&& decode,
                   bool check_inversion, Points<Dim>& out) {
    const auto m = boundary_.size();
    const auto n_graph = static_cast<Index>(graph_nodes_.size());
    Points<Dim> graph_displacement(Dim, n_graph);
    graph_displacement.leftCols(m) = d;
    graph_displacement.rightCols(n_graph - m) = extra_displacements;
    if (!sliding_.empty()) {
      Points<Dim> at(Dim, static_cast<Index>(constrained_.size())), moved(Dim, at.cols());
      for (Index c = 0; c < at.cols(); ++c) {
        const Index g = constrained_[static_cast<std::size_t>(c)];
        at.col(c) = points_.col(graph_nodes_[static_cast<std::size_t>(g)]);
        moved.col(c) = graph_displacement.col(g);
      }
      Eigen::Matrix<double, Rows, Eigen::Dynamic> values;
      sliding_graph_.interpolate(Eigen::Matrix<double, Rows, Eigen::Dynamic>(encode(at, moved)), values);
      for (std::size_t s = 0; s < sliding_.size(); ++s) {
        const Index g = sliding_[s];
        graph_displacement.col(g) =
            boundary_.project(g, decode(Vec<Dim>(points_.col(graph_nodes_[static_cast<std::size_t>(g)])),
                                        Eigen::Matrix<double, Rows, 1>(values.col(static_cast<Index>(s)))));
      }
    }
    const Points<Dim> graph_points = gather(graph_nodes_);
    if (check_inversion) report_inversion(graph_points + graph_displacement);
    Eigen::Matrix<double, Rows, Eigen::Dynamic> values;
    graph_.interpolate(Eigen::Matrix<double, Rows, Eigen::Dynamic>(encode(graph_points, graph_displacement)), values);
    const Index n = points_.cols();
    if (out.cols() != n) out.resize(Dim, n);
    const auto q = static_cast<Index>(queries_.size());
#pragma omp parallel for num_threads(::meshmotion::num_threads()) schedule(static)
    for (Index k = 0; k < q; ++k) {
      const Index node = queries_[static_cast<std::size_t>(k)];
      out.col(node) = decode(Vec<Dim>(points_.col(node)), Eigen::Matrix<double, Rows, 1>(values.col(k)));
    }
    for (Index g = 0; g < n_graph; ++g) out.col(graph_nodes_[static_cast<std::size_t>(g)]) = graph_displacement.col(g);
  }

 private:
  [[nodiscard]] Points<Dim> gather(const std::vector<Index>& nodes) const {
    Points<Dim> p(Dim, static_cast<Index>(nodes.size()));
    for (std::size_t k = 0; k < nodes.size(); ++k) p.col(static_cast<Index>(k)) = points_.col(nodes[k]);
    return p;
  }

  /// Throws InvalidMeshError when a graph simplex inverts at the moved graph positions.
  void report_inversion(const Points<Dim>& moved) const {
    const std::vector<Index> inverted = graph_.inverted_simplices(moved);
    if (inverted.empty()) return;
    // Name the simplex by mesh nodes: the graph's vertices are graph-node indices.
    std::string nodes;
    const Index s = inverted.front();
    for (int j = 0; j <= Dim; ++j)
      nodes += (j ? ", " : "") + std::to_string(graph_nodes_[static_cast<std::size_t>(graph_.simplices()(j, s))]);
    throw InvalidMeshError(who_ + "::move: the moved Delaunay graph inverts " + std::to_string(inverted.size()) +
                           " simplex(es), first graph simplex " + std::to_string(s) + " (mesh nodes " + nodes +
                           "); the mapped mesh would fold (got a negative or zero simplex volume, expected positive). "
                           "Split the motion into more steps (run_steps / --steps) so the graph is rebuilt each step");
  }

  std::string who_;
  bool ready_ = false;
  Points<Dim> points_;
  ResolvedBoundary<Dim> boundary_;
  std::vector<Index> graph_nodes_;   ///< boundary nodes (boundary order), then extra nodes
  std::vector<Index> queries_;       ///< every other node
  std::vector<Index> constrained_;   ///< graph entries that are not sliding
  std::vector<Index> sliding_;       ///< graph entries of sliding nodes
  GraphInterpolation<Dim> graph_;
  GraphInterpolation<Dim> sliding_graph_;
  MoverStats stats_;
};

}  // namespace meshmotion::detail
