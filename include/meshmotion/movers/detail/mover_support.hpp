#pragma once
/// \file
/// What every mover does around its own work: validate the resolved boundary given to setup,
/// validate the displacements given to move, and count and time each move in its stats.

#include "meshmotion/core/error.hpp"
#include "meshmotion/core/types.hpp"
#include "meshmotion/movers/boundary.hpp"
#include "meshmotion/movers/mover.hpp"
#include "meshmotion/solvers/detail/stopwatch.hpp"

#include <cmath>
#include <concepts>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace meshmotion::detail {

/// Throws InputError (messages start with `where`) unless `b` is a valid resolved boundary
/// for n nodes: one kind, normal (and displacement, when `with_displacements`) per node; at
/// least one node; sorted unique indices in [0, n); unit normals on sliding nodes; line
/// directions (when given) unit, perpendicular to the normal and on sliding nodes only.
template <int Dim>
void check_boundary(std::string_view where, const ResolvedBoundary<Dim>& b, Index n, bool with_displacements = true) {
  const std::string w(where);
  const Index m = b.size();
  if (static_cast<Index>(b.kinds.size()) != m || b.normals.cols() != m ||
      (with_displacements && b.displacements.cols() != m) || (b.directions.cols() != 0 && b.directions.cols() != m))
    throw InputError(w + ": boundary has " + std::to_string(m) + " nodes but " + std::to_string(b.kinds.size()) +
                     " kinds, " + std::to_string(b.normals.cols()) + " normals, " +
                     std::to_string(b.displacements.cols()) + " displacements and " +
                     std::to_string(b.directions.cols()) + " line directions (expected one each; directions may be empty)");
  if (m == 0) throw InputError(w + ": the boundary has no nodes (expected at least one)");
  for (Index k = 0; k < m; ++k) {
    const Index v = b.nodes[static_cast<std::size_t>(k)];
    if (v < 0 || v >= n)
      throw InputError(w + ": boundary node " + std::to_string(v) + " is out of range (expected 0 to " +
                       std::to_string(n - 1) + ")");
    if (k > 0 && v <= b.nodes[static_cast<std::size_t>(k - 1)])
      throw InputError(w + ": boundary nodes must be sorted and unique (node " + std::to_string(v) + " follows " +
                       std::to_string(b.nodes[static_cast<std::size_t>(k - 1)]) + ")");
    const bool sliding = b.kinds[static_cast<std::size_t>(k)] == BoundaryKind::sliding;
    if (sliding && !(std::abs(b.normals.col(k).norm() - 1.0) <= 1e-8))
      throw InputError(w + ": sliding node " + std::to_string(v) + " needs a unit normal (got length " +
                       std::to_string(b.normals.col(k).norm()) + ")");
    if (b.slides_on_line(k)) {
      const Vec<Dim> t = b.directions.col(k);
      if (!sliding || !(std::abs(t.norm() - 1.0) <= 1e-8) || !(std::abs(t.dot(b.normals.col(k))) <= 1e-8))
        throw InputError(w + ": node " + std::to_string(v) +
                         " has a line direction but is not sliding, or the direction is not a unit vector "
                         "perpendicular to its normal (got length " + std::to_string(t.norm()) + ")");
    }
  }
}

/// Throws InputError unless d is finite and Dim × nodes.size().
template <int Dim>
void check_displacements(std::string_view where, PointsView<Dim> d, const std::vector<Index>& nodes) {
  const auto m = static_cast<Index>(nodes.size());
  if (d.cols() != m)
    throw InputError(std::string(where) + ": got " + std::to_string(d.cols()) + " displacement columns (expected " +
                     std::to_string(m) + ", one per boundary node)");
  for (Index b = 0; b < m; ++b)
    if (!d.col(b).allFinite())
      throw InputError(std::string(where) + ": displacement of node " + std::to_string(nodes[static_cast<std::size_t>(b)]) +
                       " is not finite");
}

/// A move's output sized for `n` nodes: a Points<Dim> is resized, a caller's storage (an
/// Eigen::Ref) is written as it is, its shape checked by whoever took it.
template <int Dim, class Out>
void size_output(Out& out, Index n) {
  if constexpr (std::same_as<Out, Points<Dim>>)
    if (out.cols() != n) out.resize(Dim, n);
}

/// Throws InputError unless v (a field over the nodes, e.g. a reverse derivative's seed) is
/// finite and Dim × n_nodes, naming the first non-finite node.
template <int Dim>
void check_node_field(std::string_view where, const PointsView<Dim>& v, Index n_nodes) {
  if (v.cols() != n_nodes)
    throw InputError(std::string(where) + ": got " + std::to_string(v.cols()) + " columns (expected " +
                     std::to_string(n_nodes) + ", one per node)");
  for (Index i = 0; i < n_nodes; ++i)
    if (!v.col(i).allFinite()) throw InputError(std::string(where) + ": value of node " + std::to_string(i) + " is not finite");
}

/// Runs body() and adds its time to `seconds` (a move's phase: MoverStats::solve_seconds, ...).
template <class Body>
void add_time(double& seconds, Body&& body) {
  const Stopwatch watch;
  std::forward<Body>(body)();
  seconds += watch.seconds();
}

/// One move: throws InputError unless `ready` (setup ran) and `d` fits `nodes`
/// (check_displacements), runs body() (which adds its phases to `stats`, from zero), then
/// counts the move and records its time in `stats`.
template <int Dim, class Body>
void timed_move(std::string_view where, bool ready, PointsView<Dim> d, const std::vector<Index>& nodes,
                MoverStats& stats, Body&& body) {
  const Stopwatch watch;
  if (!ready) throw InputError(std::string(where) + ": setup() was not called");
  check_displacements<Dim>(where, d, nodes);
  stats.solve_seconds = stats.rebuild_seconds = 0.0;
  std::forward<Body>(body)();
  ++stats.moves;
  stats.move_seconds = watch.seconds();
}

/// Copies a mover's result into the caller's own storage (an Eigen::Map over a solver's
/// array), which must already be Dim × n_nodes. Throws InputError naming both shapes otherwise.
template <int Dim>
void copy_to_caller(const char* where, const Points<Dim>& result, Eigen::Ref<Points<Dim>> out) {
  if (out.cols() != result.cols())
    throw InputError(std::string(where) + ": the output has " + std::to_string(out.cols()) + " columns (expected " +
                     std::to_string(result.cols()) + ", one per node)");
  out = result;
}

/// CRTP base giving a mover the allocating `move(d)` from its `move_into(d, out)`, and
/// `move_into` into the caller's own storage (derived movers bring it in with a using
/// declaration, since their own move_into hides it).
template <class Derived, int Dim>
class MoveFromMoveInto {
 public:
  /// move_into() into an Eigen::Map (or any Eigen::Ref) of the caller's Dim × n_nodes array.
  void move_into(PointsView<Dim> d, Eigen::Ref<Points<Dim>> out) {
    static_cast<Derived&>(*this).move_into(d, scratch_);
    copy_to_caller<Dim>("move_into", scratch_, out);
  }
  /// Displacement of every node (Dim × n_nodes) for boundary displacements `d`
  /// (Dim × boundary.size()); see the mover's move_into for what it throws.
  [[nodiscard]] Points<Dim> move(PointsView<Dim> d) {
    Points<Dim> out;
    static_cast<Derived&>(*this).move_into(d, out);
    return out;
  }

 private:
  Points<Dim> scratch_;
};

}  // namespace meshmotion::detail
