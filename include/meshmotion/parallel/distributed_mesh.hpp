#pragma once
/// \file
/// What one MPI rank holds of a partitioned mesh.
///
/// - PartitionView: a solver's own partition, seen without a copy: the rank's local node
///   coordinates (owned and ghost nodes, any order), each node's global id and its owner rank.
///   Every global node is owned by exactly one rank; a ghost appears on other ranks with the
///   same global id. This is all the distributed RBF mover needs.
/// - DistributedMesh: a partitioned Mesh<Dim> (partition_mesh() in partition.hpp builds one
///   from a mesh read on one rank): the local cells, the local facets and groups, owned nodes
///   first and then ghosts, with global ids and owners; view() gives its PartitionView.
/// - gather_owned(): a node field of every rank onto one rank, in global numbering.
/// - distribute_boundary(): a boundary resolved on one rank against the whole mesh, given to
///   every rank as the entries of its local nodes (so that a sliding group's plane is fitted
///   once, to all its nodes).

#include "meshmotion/core/error.hpp"
#include "meshmotion/core/mesh.hpp"
#include "meshmotion/core/types.hpp"
#include "meshmotion/movers/boundary.hpp"
#include "meshmotion/parallel/communicator.hpp"

#include <algorithm>
#include <climits>
#include <cstdint>
#include <limits>
#include <utility>
#include <span>
#include <string>
#include <vector>

namespace meshmotion::parallel {

/// A rank's part of a partitioned mesh, as views of the caller's arrays (kept alive by it).
template <int Dim>
struct PartitionView {
  MPI_Comm comm;
  Eigen::Ref<const Points<Dim>> points;      ///< Dim × n_local: owned and ghost nodes
  std::span<const std::int64_t> global_ids;  ///< per local node: its id in the whole mesh
  std::span<const int> owner;                ///< per local node: the rank that owns it

  [[nodiscard]] Index size() const noexcept { return points.cols(); }
  [[nodiscard]] bool owns(Index local) const { return owner[static_cast<std::size_t>(local)] == rank_of(comm); }
  /// Throws InputError unless the arrays agree in length and the owners are ranks of comm.
  void check(const std::string& where) const {
    if (static_cast<std::size_t>(points.cols()) != global_ids.size() || global_ids.size() != owner.size())
      throw InputError(where + ": " + std::to_string(points.cols()) + " local nodes but " +
                       std::to_string(global_ids.size()) + " global ids and " + std::to_string(owner.size()) +
                       " owners (expected one each)");
    const int p = size_of(comm);
    for (std::size_t i = 0; i < owner.size(); ++i)
      if (owner[i] < 0 || owner[i] >= p)
        throw InputError(where + ": local node " + std::to_string(i) + " (global id " + std::to_string(global_ids[i]) +
                         ") has owner " + std::to_string(owner[i]) + " (expected a rank in 0.." + std::to_string(p - 1) + ")");
    if (!points.allFinite()) throw InputError(where + ": a local node has a non-finite coordinate");
  }
};

/// A rank's part of a mesh: local nodes (owned first, then ghosts, each by ascending global
/// id), the cells assigned to this rank, the facets whose nodes are all local, and every group.
/// `local.node_ids` holds each local node's id in the file, so messages name the user's ids.
template <int Dim>
struct DistributedMesh {
  MPI_Comm comm = MPI_COMM_WORLD;
  Mesh<Dim> local;
  std::vector<std::int64_t> global_ids;  ///< per local node: its index in the whole mesh (0-based)
  std::vector<int> owner;                ///< per local node
  Index num_owned = 0;                   ///< local nodes 0..num_owned-1 are owned
  Index num_global_nodes = 0;

  [[nodiscard]] PartitionView<Dim> view() const { return {comm, local.points, global_ids, owner}; }
  /// Local index of a global node, or -1 when this rank does not hold it.
  [[nodiscard]] Index local_index(std::int64_t global) const {
    // Owned and ghost ranges are each sorted by global id.
    for (const auto& [first, last] : {std::pair<Index, Index>{0, num_owned}, {num_owned, static_cast<Index>(global_ids.size())}}) {
      const auto begin = global_ids.begin() + first, end = global_ids.begin() + last;
      const auto it = std::lower_bound(begin, end, global);
      if (it != end && *it == global) return static_cast<Index>(it - global_ids.begin());
    }
    return -1;
  }
};

/// The owned columns of a node field (Dim × view.size()) of every rank, as one Dim ×
/// num_global field on `root` in global-id order (empty elsewhere). Global ids must be
/// 0..num_global-1. Collective.
template <int Dim>
[[nodiscard]] Points<Dim> gather_owned(const PartitionView<Dim>& view, const Points<Dim>& field, Index num_global,
                                       int root = 0) {
  std::vector<std::int64_t> ids;
  std::vector<double> values;
  int bad = field.cols() != view.size() ? 1 : 0;
  for (Index i = 0; i < view.size() && bad == 0; ++i) {
    if (!view.owns(i)) continue;
    const std::int64_t g = view.global_ids[static_cast<std::size_t>(i)];
    if (g < 0 || g >= num_global) bad = 2;
    ids.push_back(g);
    for (int d = 0; d < Dim; ++d) values.push_back(field(d, i));
  }
  collective(view.comm, [&] {
    if (bad == 1)
      throw InputError("parallel::gather_owned: the field has " + std::to_string(field.cols()) + " columns (expected " +
                       std::to_string(view.size()) + ", one per local node)");
    if (bad == 2) throw InputError("parallel::gather_owned: a global id is outside 0.." + std::to_string(num_global - 1));
  });
  const std::vector<std::int64_t> all_ids = gather_to(view.comm, root, ids);
  const std::vector<double> all_values = gather_to(view.comm, root, values);
  Points<Dim> out;
  int missing = 0;
  if (rank_of(view.comm) == root) {
    out.setConstant(Dim, num_global, std::numeric_limits<double>::quiet_NaN());
    std::vector<char> seen(static_cast<std::size_t>(num_global), 0);
    for (std::size_t k = 0; k < all_ids.size(); ++k) {
      seen[static_cast<std::size_t>(all_ids[k])] = 1;
      for (int d = 0; d < Dim; ++d) out(d, all_ids[k]) = all_values[k * Dim + static_cast<std::size_t>(d)];
    }
    missing = static_cast<int>(std::count(seen.begin(), seen.end(), 0));
  }
  collective(view.comm, [&] {
    if (missing > 0)
      throw InputError("parallel::gather_owned: " + std::to_string(missing) + " of " + std::to_string(num_global) +
                       " global nodes are owned by no rank");
  });
  return out;
}

/// The entries of `whole` (a boundary of the whole mesh, significant on `root` only) whose
/// nodes this rank holds, over its local node indices. Collective.
template <int Dim>
[[nodiscard]] ResolvedBoundary<Dim> distribute_boundary(const DistributedMesh<Dim>& mesh, const ResolvedBoundary<Dim>& whole,
                                                        int root = 0) {
  const bool at_root = rank_of(mesh.comm) == root;
  std::int64_t m = at_root ? static_cast<std::int64_t>(whole.size()) : 0;
  MPI_Bcast(&m, 1, MPI_INT64_T, root, mesh.comm);
  std::vector<std::int64_t> nodes(static_cast<std::size_t>(m));
  std::vector<int> kinds(static_cast<std::size_t>(m));
  Points<Dim> disp(Dim, m), normals(Dim, m), directions = Points<Dim>::Zero(Dim, m);
  if (at_root) {
    for (std::int64_t k = 0; k < m; ++k) {
      nodes[static_cast<std::size_t>(k)] = whole.nodes[static_cast<std::size_t>(k)];
      kinds[static_cast<std::size_t>(k)] = static_cast<int>(whole.kinds[static_cast<std::size_t>(k)]);
    }
    disp = whole.displacements;
    normals = whole.normals;
    if (whole.directions.cols() == m) directions = whole.directions;
  }
  const auto count = [&](Index values) {
    if (values > INT_MAX) throw InputError("parallel::distribute_boundary: the boundary exceeds MPI's int count");
    return static_cast<int>(values);
  };
  MPI_Bcast(nodes.data(), count(m), MPI_INT64_T, root, mesh.comm);
  MPI_Bcast(kinds.data(), count(m), MPI_INT, root, mesh.comm);
  for (Points<Dim>* p : {&disp, &normals, &directions}) MPI_Bcast(p->data(), count(Dim * m), MPI_DOUBLE, root, mesh.comm);
  std::vector<std::pair<Index, Index>> mine;  // (local node, entry)
  for (std::int64_t k = 0; k < m; ++k)
    if (const Index i = mesh.local_index(nodes[static_cast<std::size_t>(k)]); i >= 0) mine.emplace_back(i, static_cast<Index>(k));
  std::sort(mine.begin(), mine.end());
  ResolvedBoundary<Dim> out;
  const auto n = static_cast<Index>(mine.size());
  out.displacements.resize(Dim, n);
  out.normals.resize(Dim, n);
  out.directions.resize(Dim, n);
  for (Index j = 0; j < n; ++j) {
    const auto [local, k] = mine[static_cast<std::size_t>(j)];
    out.nodes.push_back(local);
    out.kinds.push_back(static_cast<BoundaryKind>(kinds[static_cast<std::size_t>(k)]));
    out.displacements.col(j) = disp.col(k);
    out.normals.col(j) = normals.col(k);
    out.directions.col(j) = directions.col(k);
  }
  return out;
}

}  // namespace meshmotion::parallel
