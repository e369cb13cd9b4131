#pragma once
/// \file
/// The partition-of-unity RBF over ranks (DistributedRbfMover, BoundarySolve::patches): patches
/// owned by ranks, local factorizations, no boundary replicated on any rank.
///
/// - Layout: patch_layout() over the ranks' owned centres with MPI reductions, so every rank
///   holds the same patch table (a middle, a reach and a count per patch: a few numbers per
///   4000 centres) and the patches are those of the serial PartitionOfUnityRbf over all the
///   centres.
/// - Owners: the patches, in their depth-first order, are cut into one contiguous run per rank
///   (neighbouring patches on one rank). Each centre is sent to the owner of every patch whose
///   ball may hold it; the owner keeps those the serial radius query keeps and factorizes the
///   patch's local system.
/// - Evaluation: each rank asks the owners of the patches covering its nodes for their
///   centres, once, and builds the evaluation rows of its nodes over those patches
///   (PartitionOfUnityRbf::cover).
/// - move: three personalized exchanges, each of what a rank's centres, patches and nodes
///   touch: the owned centres' displacements to their patches' owners, the local solves, the
///   patches' coefficients to the ranks whose nodes they cover, one sparse product there.
/// - derivative_reverse: the same backwards, with the transposed operator and solves.
/// - Default radius: the serial one. Each owner finds its cluster's nearest-neighbour spacings
///   from the centres within a bound of them (2ρ_j; a lone centre: the nearest other cluster's
///   far side), and the median is selected over the ranks by bisection of its bits.
///
/// Sliding nodes (two systems per patch) and coincident centres (which the serial mover
/// merges) are not taken: setup() says why, the same on every rank.

#include "meshmotion/core/error.hpp"
#include "meshmotion/core/types.hpp"
#include "meshmotion/movers/boundary.hpp"
#include "meshmotion/movers/detail/coincident_nodes.hpp"
#include "meshmotion/movers/detail/mover_support.hpp"
#include "meshmotion/movers/detail/rbf_partition_of_unity.hpp"
#include "meshmotion/movers/rbf.hpp"
#include "meshmotion/movers/support_radius.hpp"
#include "meshmotion/parallel/communicator.hpp"
#include "meshmotion/parallel/distributed_mesh.hpp"
#include "meshmotion/spatial/kd_tree.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace meshmotion::parallel::detail {

/// Eᵀ V for kernel rows E of the local nodes `rows` and a seed V of every local node, the
/// nodes this rank does not own left out (a ghost's term belongs to its owner), into `out`.
template <int Dim, class Out>
void owned_transpose_times(const meshmotion::detail::KernelRows& e, const std::vector<Index>& rows,
                           const std::vector<char>& owned, const PointsView<Dim>& v, Out&& out) {
  Points<Dim> sums;
  meshmotion::detail::kernel_rows_transpose_times<Dim>(
      e,
      [&](Index r) -> Vec<Dim> {
        const Index node = rows[static_cast<std::size_t>(r)];
        return owned[static_cast<std::size_t>(node)] != 0 ? Vec<Dim>(v.col(node)) : Vec<Dim>::Zero();
      },
      sums, out);
}

template <int Dim>
class DistributedPartitionOfUnity {
 public:
  /// Collective. Empty: set up. Otherwise why this boundary cannot be taken (the same text on
  /// every rank). Throws on every rank what any rank finds wrong.
  [[nodiscard]] std::string setup(const PartitionView<Dim>& part, const ResolvedBoundary<Dim>& boundary, const RbfOptions& options);
  /// Collective; `d` and `out` as DistributedRbfMover::move_into (checked there): a
  /// Points<Dim>, resized, or the caller's storage of the part's size.
  template <class Out>
  void move_into(PointsView<Dim> d, Out& out);
  /// Collective; as DistributedRbfMover::derivative_reverse (checked there): `owned` per local
  /// node, `n_entries` this rank's boundary entries.
  [[nodiscard]] Points<Dim> derivative_reverse(PointsView<Dim> v, const std::vector<char>& owned, Index n_entries);

  [[nodiscard]] double support_radius() const noexcept { return radius_; }
  [[nodiscard]] Index global_centres() const noexcept { return global_centres_; }
  /// The last move_into()'s patch solves on this rank.
  [[nodiscard]] double solve_seconds() const noexcept { return solve_seconds_; }
  /// This rank's owned boundary entries (its centres), in boundary order.
  [[nodiscard]] const std::vector<Index>& entries() const noexcept { return entries_; }
  [[nodiscard]] Index num_patches() const noexcept { return static_cast<Index>(radius_of_.size()); }
  /// Patches this rank factorized.
  [[nodiscard]] Index owned_patches() const noexcept { return static_cast<Index>(systems_.size()); }
  [[nodiscard]] const MoverStats& stats() const noexcept { return stats_; }

 private:
  /// What a rank received from every rank: per item, (patch, global id, sender's index,
  /// member of the patch's cluster) and Dim coordinates.
  struct Received {
    std::vector<std::vector<std::int64_t>> tags;
    std::vector<std::vector<double>> positions;
    static constexpr int tag_size = 4;
  };
  /// A centre received for an owned patch.
  struct Candidate {
    std::int64_t id;
    int rank;            ///< its owner
    std::int64_t index;  ///< in its owner's entries_
    bool member;         ///< of the patch's cluster
    Vec<Dim> x;
  };
  /// What this rank received, by owned patch, in the order received.
  [[nodiscard]] std::vector<std::vector<Candidate>> by_patch(const Received& got) const;
  [[nodiscard]] int owner(Index patch) const {
    return static_cast<int>(patch * static_cast<Index>(ranks_) / static_cast<Index>(radius_of_.size()));
  }
  /// Sends each owned centre to the owner of every patch j whose middle is within reach[j] of
  /// it (a hair more: the owner applies the exact test).
  [[nodiscard]] Received send_to_patches(const std::vector<double>& reach, const std::vector<Index>& patch_of) const;
  /// The serial default radius (suggest_support_radius over every centre), found over the ranks.
  [[nodiscard]] double default_radius(const meshmotion::detail::PatchLayout<Dim>& layout, double largest) const;
  /// The owned patches' local sets `at` from what this rank received, sources_, and per rank
  /// the indices of its centres asked for (`requests`); the obstacle when two of a patch's
  /// centres coincide. No communication (callers wrap it in collective()).
  [[nodiscard]] std::string gather_patches(const Received& got, double tolerance, std::vector<Points<Dim>>& at,
                                           std::vector<std::vector<std::int64_t>>& requests);
  /// The patches covering this rank's evaluated nodes, their centres from their owners (`at`:
  /// the owned patches' local sets), and the evaluation rows (cover_, served_, operator_,
  /// evaluated_, coefficient_counts_).
  void build_evaluation(const PartitionView<Dim>& part, const std::vector<Points<Dim>>& at);

  MPI_Comm comm_ = MPI_COMM_NULL;
  int ranks_ = 1;
  int rank_ = 0;
  Index n_local_ = 0;
  Index global_centres_ = 0;
  double radius_ = 0.0;
  double solve_seconds_ = 0.0;
  meshmotion::detail::RbfKernelSettings kernel_;
  MoverStats stats_;
  // The patch table, the same on every rank.
  Points<Dim> middle_;
  std::vector<double> radius_of_;
  Index first_ = 0;  ///< this rank's patches: first_ .. first_ + systems_.size()
  // This rank's centres.
  std::vector<Index> entries_;  ///< owned boundary entries (the centres), in boundary order
  std::vector<Index> nodes_;    ///< their local nodes
  Points<Dim> at_;              ///< their positions
  std::vector<std::int64_t> ids_;
  std::vector<std::vector<std::int64_t>> wanted_;  ///< per owner rank: indices into entries_, in its order
  // Owned patches.
  std::vector<meshmotion::detail::RbfSystem<Dim>> systems_;
  std::vector<std::vector<std::pair<int, Index>>> sources_;  ///< per owned patch, per centre: (rank, slot in wanted_)
  std::vector<Index> wanted_count_;                          ///< per rank: how many centres it sends here
  std::vector<std::vector<Index>> served_;                   ///< per rank: owned patches whose coefficients it needs
  std::vector<Eigen::MatrixXd> alpha_;                       ///< per owned patch
  // Evaluation.
  meshmotion::detail::PartitionOfUnityRbf<Dim> cover_;
  std::vector<int> coefficient_counts_;  ///< per owner rank: doubles of coefficients received
  std::vector<Index> evaluated_;
  meshmotion::detail::KernelRows operator_;
};

template <int Dim>
typename DistributedPartitionOfUnity<Dim>::Received DistributedPartitionOfUnity<Dim>::send_to_patches(
    const std::vector<double>& reach, const std::vector<Index>& patch_of) const {
  constexpr double hair = 1.0 + 1e-9;
  const KdTree<Dim> tree(middle_);
  const double largest = reach.empty() ? 0.0 : *std::max_element(reach.begin(), reach.end());
  std::vector<std::vector<std::int64_t>> tags(static_cast<std::size_t>(ranks_));
  std::vector<std::vector<double>> positions(static_cast<std::size_t>(ranks_));
  std::vector<Neighbor> hits;
  for (Index c = 0; c < at_.cols(); ++c) {
    tree.radius_search(Vec<Dim>(at_.col(c)), largest * hair, hits);
    std::sort(hits.begin(), hits.end());
    for (const auto& [j, d2] : hits) {
      const double r = reach[j] * hair;
      if (!(d2 < r * r)) continue;
      const auto to = static_cast<std::size_t>(owner(static_cast<Index>(j)));
      tags[to].insert(tags[to].end(), {static_cast<std::int64_t>(j), ids_[static_cast<std::size_t>(c)], static_cast<std::int64_t>(c),
                                       patch_of[static_cast<std::size_t>(c)] == static_cast<Index>(j) ? 1 : 0});
      for (int d = 0; d < Dim; ++d) positions[to].push_back(at_(d, c));
    }
  }
  return {parallel::exchange(comm_, tags), parallel::exchange(comm_, positions)};
}

template <int Dim>
double DistributedPartitionOfUnity<Dim>::default_radius(const meshmotion::detail::PatchLayout<Dim>& layout, double largest) const {
  if (global_centres_ < 2)
    throw InputError("suggest_support_radius: needs at least 2 boundary nodes (got " + std::to_string(global_centres_) + ")");
  const Index n = num_patches();
  std::vector<double> reach(static_cast<std::size_t>(n));
  for (Index j = 0; j < n; ++j) {
    const auto uj = static_cast<std::size_t>(j);
    double bound = 2.0 * layout.reach[uj];
    if (layout.count[uj] < 2.0) {
      bound = std::numeric_limits<double>::infinity();
      for (Index i = 0; i < n; ++i)
        if (i != j) bound = std::min(bound, (middle_.col(j) - middle_.col(i)).norm() + layout.reach[static_cast<std::size_t>(i)]);
    }
    reach[uj] = layout.reach[uj] + bound;
  }
  // Per owned patch, the nearest other centre of each member, among the centres sent for it.
  std::vector<double> spacing;
  for (const auto& all : by_patch(send_to_patches(reach, layout.patch_of))) {
    Points<Dim> xs(Dim, static_cast<Index>(all.size()));
    for (std::size_t c = 0; c < all.size(); ++c) xs.col(static_cast<Index>(c)) = all[c].x;
    const KdTree<Dim> tree(xs);
    for (const Candidate& c : all) {
      if (!c.member) continue;
      const auto nn = tree.nearest(c.x, 2);
      if (nn.size() == 2 && nn[1].second > 0.0) spacing.push_back(std::sqrt(nn[1].second));
    }
  }
  // The median as the serial nth_element takes it (the element of rank ⌊s/2⌋), by bisecting
  // the bits of non-negative doubles, which order as the values do.
  long long mine = static_cast<long long>(spacing.size()), total = 0;
  MPI_Allreduce(&mine, &total, 1, MPI_LONG_LONG, MPI_SUM, comm_);
  double median = 0.0;
  if (total > 0) {
    std::uint64_t lo = 0, hi = std::bit_cast<std::uint64_t>(std::numeric_limits<double>::infinity());
    const long long wanted = total / 2 + 1;
    while (lo < hi) {
      const std::uint64_t mid = lo + (hi - lo) / 2;
      long long below = 0, all = 0;
      for (const double s : spacing) below += std::bit_cast<std::uint64_t>(s) <= mid ? 1 : 0;
      MPI_Allreduce(&below, &all, 1, MPI_LONG_LONG, MPI_SUM, comm_);
      if (all >= wanted)
        hi = mid;
      else
        lo = mid + 1;
    }
    median = std::bit_cast<double>(lo);
  }
  return support_radius_from(largest, median);
}

template <int Dim>
std::vector<std::vector<typename DistributedPartitionOfUnity<Dim>::Candidate>> DistributedPartitionOfUnity<Dim>::by_patch(
    const Received& got) const {
  std::vector<std::vector<Candidate>> out(systems_.size());
  for (int r = 0; r < ranks_; ++r) {
    const auto& tags = got.tags[static_cast<std::size_t>(r)];
    for (std::size_t t = 0; t < tags.size() / Received::tag_size; ++t) {
      const std::int64_t* tag = tags.data() + Received::tag_size * t;
      Candidate c{tag[1], r, tag[2], tag[3] != 0, Vec<Dim>::Zero()};
      for (int d = 0; d < Dim; ++d) c.x[d] = got.positions[static_cast<std::size_t>(r)][Dim * t + static_cast<std::size_t>(d)];
      out[static_cast<std::size_t>(tag[0] - first_)].push_back(c);
    }
  }
  return out;
}

template <int Dim>
std::string DistributedPartitionOfUnity<Dim>::gather_patches(const Received& got, double tolerance, std::vector<Points<Dim>>& at,
                                                             std::vector<std::vector<std::int64_t>>& requests) {
  const auto owned = systems_.size();
  const std::vector<std::vector<Candidate>> candidates = by_patch(got);
  // The serial radius query over the candidates keeps what it keeps over every centre; the
  // members are then sorted by global id, as the serial patch sorts its centres by index.
  at.assign(owned, {});
  requests.assign(static_cast<std::size_t>(ranks_), {});
  sources_.assign(owned, {});
  std::string obstacle;
  for (std::size_t p = 0; p < owned; ++p) {
    const auto& all = candidates[p];
    Points<Dim> xs(Dim, static_cast<Index>(all.size()));
    for (std::size_t c = 0; c < all.size(); ++c) xs.col(static_cast<Index>(c)) = all[c].x;
    const KdTree<Dim> tree(xs);
    const Index j = first_ + static_cast<Index>(p);
    std::vector<Candidate> members;
    for (const auto& hit : tree.radius_search(Vec<Dim>(middle_.col(j)), radius_of_[static_cast<std::size_t>(j)], false))
      members.push_back(all[hit.first]);
    std::sort(members.begin(), members.end(), [](const Candidate& a, const Candidate& b) { return a.id < b.id; });
    for (std::size_t c = 1; c < members.size(); ++c)
      if (members[c].id == members[c - 1].id)
        throw InputError("DistributedRbfMover::setup: global node " + std::to_string(members[c].id) +
                         " is an owned boundary node on two ranks (each node must have one owner)");
    at[p].resize(Dim, static_cast<Index>(members.size()));
    for (std::size_t c = 0; c < members.size(); ++c) {
      const Candidate& m = members[c];
      at[p].col(static_cast<Index>(c)) = m.x;
      auto& list = requests[static_cast<std::size_t>(m.rank)];
      sources_[p].emplace_back(m.rank, static_cast<Index>(list.size()));
      list.push_back(m.index);
    }
    const auto rep = meshmotion::detail::coincident_representatives(at[p], tolerance);
    for (std::size_t c = 0; c < rep.size() && obstacle.empty(); ++c)
      if (rep[c] != static_cast<Index>(c))
        obstacle = "boundary nodes coincide (global ids " + std::to_string(members[static_cast<std::size_t>(rep[c])].id) + " and " +
                   std::to_string(members[c].id) + ")";
  }
  return obstacle;
}

/// The text of the lowest rank whose `text` is not empty, on every rank (empty when none).
[[nodiscard]] inline std::string first_text(MPI_Comm comm, const std::string& text) {
  const int ranks = size_of(comm);
  int mine = text.empty() ? ranks : rank_of(comm), lowest = ranks;
  MPI_Allreduce(&mine, &lowest, 1, MPI_INT, MPI_MIN, comm);
  if (lowest == ranks) return {};
  int length = static_cast<int>(text.size());
  MPI_Bcast(&length, 1, MPI_INT, lowest, comm);
  std::string out = rank_of(comm) == lowest ? text : std::string(static_cast<std::size_t>(length), ' ');
  MPI_Bcast(out.data(), length, MPI_CHAR, lowest, comm);
  return out;
}

template <int Dim>
std::string DistributedPartitionOfUnity<Dim>::setup(const PartitionView<Dim>& part, const ResolvedBoundary<Dim>& boundary,
                                                    const RbfOptions& options) {
  int radii = options.support_radii.empty() ? 0 : 1;
  MPI_Allreduce(MPI_IN_PLACE, &radii, 1, MPI_INT, MPI_MAX, part.comm);
  // What the serial mover refuses for a partition of unity: the replicated path says it.
  if (!is_compact(options.kernel) || options.polynomial || radii != 0 || options.patch_centres < 1 ||
      !(options.patch_overlap >= 0.0) || !std::isfinite(options.patch_overlap) || !(options.support_radius >= 0.0))
    return "the options do not make a partition of unity (RbfMover::setup says why)";
  comm_ = part.comm;
  ranks_ = size_of(comm_);
  rank_ = rank_of(comm_);
  n_local_ = part.size();
  entries_.clear();
  nodes_.clear();
  ids_.clear();
  int sliding = 0, any_sliding = 0;
  for (Index k = 0; k < boundary.size(); ++k) {
    const Index node = boundary.nodes[static_cast<std::size_t>(k)];
    if (!part.owns(node)) continue;
    entries_.push_back(k);
    nodes_.push_back(node);
    ids_.push_back(part.global_ids[static_cast<std::size_t>(node)]);
    sliding = std::max(sliding, boundary.kinds[static_cast<std::size_t>(k)] == BoundaryKind::sliding ? 1 : 0);
  }
  MPI_Allreduce(&sliding, &any_sliding, 1, MPI_INT, MPI_MAX, comm_);
  if (any_sliding != 0) return "the boundary has sliding nodes (two systems per patch)";
  at_.resize(Dim, static_cast<Index>(nodes_.size()));
  double largest = 0.0;
  for (std::size_t c = 0; c < nodes_.size(); ++c) {
    at_.col(static_cast<Index>(c)) = part.points.col(nodes_[c]);
    largest = std::max(largest, boundary.displacements.col(entries_[c]).norm());
  }
  long long mine = static_cast<long long>(nodes_.size()), total = 0;
  MPI_Allreduce(&mine, &total, 1, MPI_LONG_LONG, MPI_SUM, comm_);
  MPI_Allreduce(MPI_IN_PLACE, &largest, 1, MPI_DOUBLE, MPI_MAX, comm_);
  global_centres_ = static_cast<Index>(total);
  if (total == 0) throw InputError("DistributedRbfMover::setup: no rank owns a boundary node (expected at least one)");

  const auto reduce = [&](std::vector<double>& low, std::vector<double>& high, std::vector<double>& count) {
    if (!low.empty()) MPI_Allreduce(MPI_IN_PLACE, low.data(), static_cast<int>(low.size()), MPI_DOUBLE, MPI_MIN, comm_);
    if (!high.empty()) MPI_Allreduce(MPI_IN_PLACE, high.data(), static_cast<int>(high.size()), MPI_DOUBLE, MPI_MAX, comm_);
    if (!count.empty()) MPI_Allreduce(MPI_IN_PLACE, count.data(), static_cast<int>(count.size()), MPI_DOUBLE, MPI_SUM, comm_);
  };
  const meshmotion::detail::PatchLayout<Dim> layout = meshmotion::detail::patch_layout(at_, std::max<Index>(options.patch_centres, 1), reduce);
  middle_ = layout.middle;
  const Index n = static_cast<Index>(layout.reach.size());
  radius_of_.assign(static_cast<std::size_t>(n), 0.0);
  first_ = (static_cast<Index>(rank_) * n + ranks_ - 1) / ranks_;
  const Index last = (static_cast<Index>(rank_ + 1) * n + ranks_ - 1) / ranks_;
  systems_.clear();
  systems_.resize(static_cast<std::size_t>(last - first_));
  radius_ = options.support_radius != 0.0 ? options.support_radius : default_radius(layout, largest);
  if (!(radius_ > 0.0) || !std::isfinite(radius_))
    throw InputError("DistributedRbfMover::setup: support radius must be positive (got " + std::to_string(radius_) + ")");
  for (Index j = 0; j < n; ++j)
    radius_of_[static_cast<std::size_t>(j)] = meshmotion::detail::patch_radius(layout.reach[static_cast<std::size_t>(j)], options.patch_overlap, radius_);

  const Received got = send_to_patches(radius_of_, layout.patch_of);
  std::vector<Points<Dim>> at;
  std::vector<std::vector<std::int64_t>> requests;
  const double diagonal = (layout.upper - layout.lower).norm();
  std::string obstacle;
  collective(comm_, [&] { obstacle = gather_patches(got, options.coincidence_tolerance * diagonal, at, requests); });
  obstacle = first_text(comm_, obstacle);
  if (!obstacle.empty()) return obstacle;
  wanted_ = parallel::exchange(comm_, requests);
  wanted_count_.resize(static_cast<std::size_t>(ranks_));
  for (int r = 0; r < ranks_; ++r) wanted_count_[static_cast<std::size_t>(r)] = static_cast<Index>(requests[static_cast<std::size_t>(r)].size());

  // Patches are factorized side by side; each factorization runs on one thread.
  kernel_ = {options.kernel, radius_, false};
  collective(comm_, [&] {
    meshmotion::detail::for_each_in_parallel(owned_patches(), [&](Index p) {
      systems_[static_cast<std::size_t>(p)].setup(at[static_cast<std::size_t>(p)], kernel_, options.solver,
                                                  DenseSolverKind::partial_piv_lu, 0);
    });
  });
  alpha_.assign(systems_.size(), {});
  build_evaluation(part, at);

  stats_ = MoverStats{};
  stats_.boundary_nodes = global_centres_;
  stats_.evaluated_nodes = static_cast<Index>(evaluated_.size());
  stats_.nonzeros = operator_.nonZeros();
  stats_.condition = 1.0;
  for (const auto& system : systems_) {
    stats_.nonzeros += system.nonzeros();
    stats_.condition = std::max(stats_.condition, system.condition());
  }
  MPI_Allreduce(MPI_IN_PLACE, &stats_.condition, 1, MPI_DOUBLE, MPI_MAX, comm_);
  stats_.factorizations = static_cast<Index>(systems_.size());
  return {};
}

template <int Dim>
void DistributedPartitionOfUnity<Dim>::build_evaluation(const PartitionView<Dim>& part, const std::vector<Points<Dim>>& at) {
  // Nodes evaluated: every local node but this rank's centres (their values are given).
  std::vector<char> centre(static_cast<std::size_t>(n_local_), 0);
  for (const Index v : nodes_) centre[static_cast<std::size_t>(v)] = 1;
  std::vector<Index> candidates;
  for (Index i = 0; i < n_local_; ++i)
    if (centre[static_cast<std::size_t>(i)] == 0) candidates.push_back(i);
  // The patches whose balls hold one of them (a hair more: a patch without weight anywhere
  // here costs its coefficients, nothing else).
  constexpr double hair = 1.0 + 1e-9;
  const KdTree<Dim> tree(middle_);
  const double largest = *std::max_element(radius_of_.begin(), radius_of_.end());
  std::vector<char> needed(radius_of_.size(), 0);
  std::vector<Neighbor> hits;
  for (const Index i : candidates) {
    tree.radius_search(Vec<Dim>(part.points.col(i)), largest * hair, hits);
    for (const auto& [j, d2] : hits)
      if (const double r = radius_of_[j] * hair; d2 < r * r) needed[j] = 1;
  }
  std::vector<std::vector<std::int64_t>> asks(static_cast<std::size_t>(ranks_));
  for (std::size_t j = 0; j < needed.size(); ++j)
    if (needed[j] != 0) asks[static_cast<std::size_t>(owner(static_cast<Index>(j)))].push_back(static_cast<std::int64_t>(j));
  const auto asked = parallel::exchange(comm_, asks);
  served_.assign(static_cast<std::size_t>(ranks_), {});
  std::vector<std::vector<double>> replies(static_cast<std::size_t>(ranks_));
  std::vector<std::vector<std::int64_t>> sizes(static_cast<std::size_t>(ranks_));
  for (int r = 0; r < ranks_; ++r)
    for (const std::int64_t j : asked[static_cast<std::size_t>(r)]) {
      const auto p = static_cast<std::size_t>(j - first_);
      served_[static_cast<std::size_t>(r)].push_back(static_cast<Index>(p));
      sizes[static_cast<std::size_t>(r)].push_back(at[p].cols());
      replies[static_cast<std::size_t>(r)].insert(replies[static_cast<std::size_t>(r)].end(), at[p].data(), at[p].data() + at[p].size());
    }
  const auto got_sizes = parallel::exchange(comm_, sizes);
  const auto got_points = parallel::exchange(comm_, replies);
  // Owners' runs ascend with the rank, so this is the needed patches in ascending order, as the
  // serial evaluation visits them.
  Points<Dim> middle(Dim, 0);
  std::vector<double> radius;
  std::vector<Points<Dim>> patches;
  coefficient_counts_.assign(static_cast<std::size_t>(ranks_), 0);
  for (int r = 0; r < ranks_; ++r) {
    std::size_t offset = 0;
    const auto& js = asks[static_cast<std::size_t>(r)];
    for (std::size_t q = 0; q < js.size(); ++q) {
      const auto j = static_cast<Index>(js[q]);
      const Index count = got_sizes[static_cast<std::size_t>(r)][q];
      middle.conservativeResize(Dim, middle.cols() + 1);
      middle.col(middle.cols() - 1) = middle_.col(j);
      radius.push_back(radius_of_[static_cast<std::size_t>(j)]);
      patches.push_back(Eigen::Map<const Points<Dim>>(got_points[static_cast<std::size_t>(r)].data() + offset, Dim, count));
      offset += static_cast<std::size_t>(Dim * count);
      coefficient_counts_[static_cast<std::size_t>(r)] += static_cast<int>(Dim * count);
    }
  }
  cover_.cover(std::move(middle), std::move(radius), patches, kernel_);
  std::vector<Index> kept;
  operator_ = cover_.evaluation_rows(Points<Dim>(part.points), candidates, &kept);
  evaluated_.clear();
  for (const Index r : kept) evaluated_.push_back(candidates[static_cast<std::size_t>(r)]);
}

template <int Dim>
template <class Out>
void DistributedPartitionOfUnity<Dim>::move_into(PointsView<Dim> d, Out& out) {
  // The owned centres' displacements to the owners of their patches.
  std::vector<std::vector<double>> send(static_cast<std::size_t>(ranks_));
  for (int r = 0; r < ranks_; ++r)
    for (const std::int64_t c : wanted_[static_cast<std::size_t>(r)])
      for (int a = 0; a < Dim; ++a) send[static_cast<std::size_t>(r)].push_back(d(a, entries_[static_cast<std::size_t>(c)]));
  const auto values = parallel::exchange(comm_, send);
  const meshmotion::detail::Stopwatch solving;
  collective(comm_, [&] {
    meshmotion::detail::for_each_in_parallel(owned_patches(), [&](Index j) {
      const auto p = static_cast<std::size_t>(j);
      Eigen::MatrixXd local(static_cast<Index>(sources_[p].size()), Dim);
      for (std::size_t c = 0; c < sources_[p].size(); ++c) {
        const auto [r, slot] = sources_[p][c];
        for (int a = 0; a < Dim; ++a) local(static_cast<Index>(c), a) = values[static_cast<std::size_t>(r)][static_cast<std::size_t>(Dim * slot + a)];
      }
      typename meshmotion::detail::RbfSystem<Dim>::PolyCoefficients beta;
      systems_[p].solve(local, alpha_[p], beta);
    });
  });
  solve_seconds_ = solving.seconds();
  // Each patch's coefficients to the ranks whose nodes it covers.
  std::vector<std::vector<double>> coefficients(static_cast<std::size_t>(ranks_));
  for (int r = 0; r < ranks_; ++r)
    for (const Index p : served_[static_cast<std::size_t>(r)]) {
      const Eigen::MatrixXd& a = alpha_[static_cast<std::size_t>(p)];
      for (Index i = 0; i < a.rows(); ++i)
        for (int k = 0; k < Dim; ++k) coefficients[static_cast<std::size_t>(r)].push_back(a(i, k));
    }
  const auto got = parallel::exchange(comm_, coefficients);
  Eigen::MatrixXd stacked(cover_.num_coefficients(), Dim);
  Index row = 0;
  for (const auto& block : got)
    for (std::size_t i = 0; i < block.size(); i += Dim, ++row)
      for (int k = 0; k < Dim; ++k) stacked(row, k) = block[i + static_cast<std::size_t>(k)];
  meshmotion::detail::size_output<Dim>(out, n_local_);
  out.setZero();
  Points<Dim> columns;
  meshmotion::detail::kernel_rows_times<Dim>(operator_, stacked, columns, [&](Index r, const Vec<Dim>& value) {
    out.col(evaluated_[static_cast<std::size_t>(r)]) = value;
  });
  for (std::size_t c = 0; c < nodes_.size(); ++c) out.col(nodes_[c]) = d.col(entries_[c]);
}

template <int Dim>
Points<Dim> DistributedPartitionOfUnity<Dim>::derivative_reverse(PointsView<Dim> v, const std::vector<char>& owned, Index n_entries) {
  Points<Dim> grad = Points<Dim>::Zero(Dim, n_entries);
  for (std::size_t c = 0; c < nodes_.size(); ++c) grad.col(entries_[c]) += v.col(nodes_[c]);
  Eigen::MatrixXd stacked_bar;
  owned_transpose_times<Dim>(operator_, evaluated_, owned, v, stacked_bar);
  // Back to the patches' owners, in the layout the coefficients came in.
  std::vector<std::vector<double>> back(static_cast<std::size_t>(ranks_));
  Index row = 0;
  for (int r = 0; r < ranks_; ++r)
    for (int i = 0; i < coefficient_counts_[static_cast<std::size_t>(r)] / Dim; ++i, ++row)
      for (int k = 0; k < Dim; ++k) back[static_cast<std::size_t>(r)].push_back(stacked_bar(row, k));
  const auto sums = parallel::exchange(comm_, back);
  std::vector<Eigen::MatrixXd> alpha_bar(systems_.size());
  for (std::size_t p = 0; p < systems_.size(); ++p) alpha_bar[p].setZero(static_cast<Index>(sources_[p].size()), Dim);
  for (int r = 0; r < ranks_; ++r) {
    std::size_t at = 0;
    for (const Index p : served_[static_cast<std::size_t>(r)]) {
      Eigen::MatrixXd& a = alpha_bar[static_cast<std::size_t>(p)];
      for (Index i = 0; i < a.rows(); ++i)
        for (int k = 0; k < Dim; ++k) a(i, k) += sums[static_cast<std::size_t>(r)][at++];
    }
  }
  // The transposed solves, and each centre's share back to the rank that owns it.
  std::vector<std::vector<double>> shares(static_cast<std::size_t>(ranks_));
  for (int r = 0; r < ranks_; ++r) shares[static_cast<std::size_t>(r)].assign(static_cast<std::size_t>(Dim * wanted_count_[static_cast<std::size_t>(r)]), 0.0);
  // Each centre of a patch has its own slot, so the patches write apart.
  collective(comm_, [&] {
    meshmotion::detail::for_each_in_parallel(owned_patches(), [&](Index j) {
      const auto p = static_cast<std::size_t>(j);
      Eigen::MatrixXd values_bar;
      systems_[p].solve_transpose(alpha_bar[p], meshmotion::detail::RbfSystem<Dim>::PolyCoefficients::Zero(), values_bar);
      for (std::size_t c = 0; c < sources_[p].size(); ++c) {
        const auto [r, slot] = sources_[p][c];
        for (int k = 0; k < Dim; ++k) shares[static_cast<std::size_t>(r)][static_cast<std::size_t>(Dim * slot + k)] += values_bar(static_cast<Index>(c), k);
      }
    });
  });
  const auto mine = parallel::exchange(comm_, shares);
  for (int r = 0; r < ranks_; ++r) {
    const auto& list = wanted_[static_cast<std::size_t>(r)];
    for (std::size_t s = 0; s < list.size(); ++s)
      for (int k = 0; k < Dim; ++k) grad(k, entries_[static_cast<std::size_t>(list[s])]) += mine[static_cast<std::size_t>(r)][Dim * s + static_cast<std::size_t>(k)];
  }
  return grad;
}

}  // namespace meshmotion::parallel::detail
