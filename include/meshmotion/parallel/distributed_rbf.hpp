#pragma once
/// \file
/// DistributedRbfMover: the RBF mover on a partitioned mesh, with the serial result.
///
/// - setup: every rank's owned boundary entries (global id, position, kind, sliding plane or
///   line, radius) are gathered on all ranks (allgatherv) and sorted by global id, so every
///   rank holds the same centres in the same order as a serial RbfMover given the boundary of
///   the whole mesh by ascending node index. The interpolation system is then either
///   factorized on every rank (replicated: no communication per move beyond the boundary
///   displacements; any option), or once across the ranks by MUMPS through PETSc
///   (PetscRbfSystem: the factor's memory and the solves split between the ranks; compact
///   kernel, one radius, no sliding node, distinct centres). BoundarySolve::automatic takes
///   PETSc when the options allow it, from BoundarySolveOptions::petsc_min_centres centres on,
///   or on several ranks when centres × ranks per node (× rounds of ranks per core) reach
///   petsc_min_node_centres.
///   Each rank then builds the evaluation operator of its own local nodes (owned and ghost)
///   with its own k-d tree over the centres.
/// - With RbfOptions::partition_of_unity (BoundarySolve::patches, automatic's choice for it),
///   nothing above is gathered: each patch lives on one rank
///   (detail::DistributedPartitionOfUnity, distributed_partition_of_unity.hpp).
/// - move: one allgatherv of the owned entries' displacements (Dim doubles per boundary node),
///   then one solve and the local evaluation. Ghost nodes get the values their owners compute.
/// - derivative_reverse: the transposed evaluation on each rank's owned nodes, summed over the
///   ranks (allreduce of Dim × boundary doubles), then one transposed solve.
///
/// Memory per rank: the boundary's centres and factorization (as serial) plus the evaluation
/// operator of its local nodes. What grows with the boundary is replicated; what grows with
/// the volume is split (docs/parallel.md measures both).
///
/// - Set up once, moved many times: the serial mover's rule (radius_outgrown()) on the largest
///   prescribed displacement over the ranks sets the mover up again, collectively, when a move
///   outgrew the default radius; the mover keeps its own copy of the part for that (a
///   position, a global id and an owner per local node), so the caller's arrays need not
///   outlive setup().
///
/// - The rigid part: set up at rest (nothing prescribed moves yet), as the serial mover, each
///   move's rigid part is fitted (sums over the ranks) and blended in first (RigidPartAtMove);
///   a mover set up with a motion interpolates the whole of it (rigid_part=blend is refused
///   there: setup-time blends are the serial mover's).
///
/// The owner's entry decides: a ghost's boundary entry on another rank is ignored (its kind,
/// plane and displacement come from its owner), so parts need not agree on ghosts.

#include "meshmotion/core/error.hpp"
#include "meshmotion/core/option_text.hpp"
#include "meshmotion/core/types.hpp"
#include "meshmotion/movers/boundary.hpp"
#include "meshmotion/movers/detail/mover_support.hpp"
#include "meshmotion/movers/rbf.hpp"
#include "meshmotion/parallel/communicator.hpp"
#include "meshmotion/parallel/distributed_mesh.hpp"
#include "meshmotion/parallel/distributed_partition_of_unity.hpp"
#include "meshmotion/parallel/parallel_options.hpp"
#include "meshmotion/parallel/petsc_rbf_system.hpp"
#include "meshmotion/solvers/detail/stopwatch.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <memory>
#include <numeric>
#include <string>
#include <vector>

namespace meshmotion::parallel {

template <int Dim>
class DistributedRbfMover {
 public:
  static constexpr int dim = Dim;

  explicit DistributedRbfMover(RbfOptions options = {}, BoundarySolveOptions solve = {})
      : inner_(options), options_(effective_options(std::move(options))), solve_(solve) {}

  /// True when the last setup solves the boundary system through PETSc.
  [[nodiscard]] bool petsc_solve() const noexcept { return petsc_; }
  /// Where the last setup solves the boundary system (never automatic).
  [[nodiscard]] BoundarySolve solved_by() const noexcept {
    return patches_ ? BoundarySolve::patches : petsc_ ? BoundarySolve::petsc : BoundarySolve::replicated;
  }
  /// The distributed partition of unity's patches, all ranks together (0 on other paths).
  [[nodiscard]] Index num_patches() const noexcept { return patches_ ? patches_->num_patches() : 0; }

  [[nodiscard]] const RbfOptions& options() const noexcept { return options_; }
  /// The support radius of the last setup (RbfMover::support_radius(): the default one is
  /// proposed from the gathered boundary, as the serial mover does).
  [[nodiscard]] double support_radius() const noexcept { return radius_; }
  /// The default radius of the last setup was reduced to fit the memory budget
  /// (RbfMover::support_radius_reduced(), decided alike).
  [[nodiscard]] bool support_radius_reduced() const noexcept { return radius_reduced_; }
  /// This rank's figures; boundary_nodes counts the whole boundary's centres.
  [[nodiscard]] const MoverStats& stats() const noexcept { return stats_; }
  /// Entries of the whole boundary (before merging coincident nodes).
  [[nodiscard]] Index global_boundary_size() const noexcept { return global_entries_; }

  /// Collective. `part`: this rank's nodes; `boundary`: entries of local nodes (owned and
  /// ghost; may be empty on a rank). RbfOptions::support_radii, when given, has one radius per
  /// entry of this rank's `boundary`. Throws on every rank what any rank finds wrong: a part
  /// whose arrays disagree, a global id owned by two ranks, a bad boundary, an empty global
  /// boundary, or what RbfMover::setup throws.
  void setup(const PartitionView<Dim>& part, const ResolvedBoundary<Dim>& boundary);
  /// setup() with the rank's cells (`local`: the part's nodes, and the cells assigned to this
  /// rank): a move then repairs the linear cells it folded as the serial mover does
  /// (RbfOptions::repair), on the patch gathered from every rank. Collective.
  void setup(const PartitionView<Dim>& part, const Mesh<Dim>& local, const ResolvedBoundary<Dim>& boundary) {
    setup(part, boundary);
    if (!options_.repair) return;
    std::vector<char> owned(static_cast<std::size_t>(part.size()));
    for (Index v = 0; v < part.size(); ++v) owned[static_cast<std::size_t>(v)] = part.owns(v) ? 1 : 0;
    repair_.prepare(local, boundary, std::vector<std::int64_t>(part.global_ids.begin(), part.global_ids.end()), std::move(owned));
    int linear = repair_.active() ? 1 : 0;
    MPI_Allreduce(MPI_IN_PLACE, &linear, 1, MPI_INT, MPI_MIN, comm_);
    if (linear == 0) repair_.disable();
  }

  /// Collective. Displacement (Dim × part.size()) of every local node for the displacements
  /// `d` (Dim × boundary.size()) of this rank's boundary entries; only owned entries are
  /// read. Throws on every rank for a wrong shape or a non-finite value on any rank, and what
  /// RbfMover::move throws.
  void move_into(PointsView<Dim> d, Points<Dim>& out) { move_to(d, out); }
  /// move_into() straight into the caller's Dim × part.size() storage (an Eigen::Map over a
  /// solver's or numpy's array), with no copy in between. Throws on every rank when any rank's
  /// `out` has another number of columns.
  void move_into(PointsView<Dim> d, Eigen::Ref<Points<Dim>> out);
  [[nodiscard]] Points<Dim> move(PointsView<Dim> d) {
    Points<Dim> out;
    move_into(d, out);
    return out;
  }

  /// Collective. The grid velocity (Dim × part.size()) of every local node for the velocities
  /// `v` of this rank's boundary entries (RbfMover::move's map, linear: J v, without a set-up
  /// again); only owned entries are read.
  [[nodiscard]] Points<Dim> velocity(PointsView<Dim> v);

  /// Collective. For v (Dim × part.size()), the gradient of Σ over ranks of ⟨v, move(d)⟩ on
  /// owned nodes with respect to this rank's boundary entries (Dim × boundary.size()): owned
  /// entries carry it, ghost and sliding entries are zero, so the ranks' gradients add up to
  /// the serial one.
  [[nodiscard]] Points<Dim> derivative_reverse(PointsView<Dim> v);

 private:
  void require_ready(const char* where) const {
    if (!ready_) throw InputError(std::string("DistributedRbfMover::") + where + ": setup() was not called");
  }

  /// The whole boundary's owned entries, as every rank gathers them in rank order.
  struct GatheredBoundary {
    static constexpr int stride = 3 * Dim + 1;
    std::vector<int> kinds;
    std::vector<double> geometry;  ///< per entry: position, normal, direction, radius
    bool radius_per_entry = false;  ///< some rank was given support_radii
  };
  /// setup() on the mover's own copy of the part (part_); with `defer`, everything but the
  /// boundary system's factorization and the evaluation operator (build_interpolation()).
  void set_up(const ResolvedBoundary<Dim>& boundary, bool defer = false);
  /// Collective: what set_up() deferred, built (nothing when nothing was).
  void build_interpolation();
  /// Collective: the rest `rest` of `d` after the blend is more than the fit's round-off
  /// (rigid_fit_round_off, as the serial mover's test) on some rank.
  [[nodiscard]] bool leaves_something(PointsView<Dim> d, PointsView<Dim> rest) const;
  /// Collective: sets the mover up again for `d` when it outgrew the default radius; the
  /// seconds that took (0: nothing set up).
  double follow_motion(PointsView<Dim> d);
  /// Collective: `d` less the rigid part's blend `blend` at the non-sliding entries (rest_).
  [[nodiscard]] const Points<Dim>& without_blend(PointsView<Dim> d, const Points<Dim>& blend);
  /// Collective: derivative_reverse() of the interpolation alone.
  [[nodiscard]] Points<Dim> reverse_interpolation(PointsView<Dim> v);
  /// Collective: refuses (on every rank) `d` of the wrong shape or with a non-finite owned entry.
  void check_entries(const char* where, PointsView<Dim> d);
  /// move_into() into a Points<Dim> or the caller's storage.
  template <class Out>
  void move_to(PointsView<Dim> d, Out& out);
  /// Collective: the map of the current setup applied to `d`.
  template <class Out>
  void apply(PointsView<Dim> d, Out& out) {
    if (patches_) {
      patches_->move_into(d, out);
      solving_ += patches_->solve_seconds();
    } else {
      move_gathered(d, out);
    }
  }
  // set_up()'s stages, in order.
  /// Gathers the owned entries (owned_entries_, counts_) and sorts them by global id
  /// (sorted_ids_, slot_of_gathered_); throws on every rank for no entry or a twice-owned node.
  [[nodiscard]] GatheredBoundary gather_boundary(const PartitionView<Dim>& part, const ResolvedBoundary<Dim>& boundary);
  /// The inner mover's column of each local node (column_, entry_slot_, inner_columns_).
  void number_columns(const PartitionView<Dim>& part, const ResolvedBoundary<Dim>& boundary);
  /// The inner mover's reference points (the centres, then this rank's other nodes), the
  /// centres' radii when given, and its boundary.
  [[nodiscard]] ResolvedBoundary<Dim> inner_boundary(const PartitionView<Dim>& part, const GatheredBoundary& gathered,
                                                     Points<Dim>& points, std::vector<double>& radii) const;
  /// Whether the boundary system goes through PETSc (BoundarySolveOptions); throws on every
  /// rank when PETSc is demanded and cannot take it.
  /// Two levels (`two_levels`) are replicated unless PETSc is demanded.
  [[nodiscard]] bool choose_petsc(const GatheredBoundary& gathered, const Points<Dim>& centres, bool two_levels) const;
  /// Collective: the serial mover's default radius for the whole mesh (`centres`: the
  /// gathered boundary in global id order).
  [[nodiscard]] DefaultSupportRadius default_radius(const PartitionView<Dim>& part, const ResolvedBoundary<Dim>& boundary,
                                                    const GatheredBoundary& gathered, const Points<Dim>& centres) const;
  /// Why PETSc cannot solve this boundary system (empty: it can).
  [[nodiscard]] std::string petsc_obstacle(const std::vector<int>& kinds, bool radius_per_entry, const Points<Dim>& centres) const;
  /// move_into() once the boundary was gathered (replicated or PETSc).
  template <class Out>
  void move_gathered(PointsView<Dim> d, Out& out);
  void setup_petsc(const PartitionView<Dim>& part, Points<Dim> centres);
  template <class Out>
  void move_petsc(Out& out);
  [[nodiscard]] Points<Dim> reverse_petsc(const PointsView<Dim>& v);

  MPI_Comm comm_ = MPI_COMM_NULL;
  Points<Dim> part_points_;  ///< the part setup() was given, and its boundary: what a set up again needs
  std::vector<std::int64_t> part_ids_;
  std::vector<int> part_owners_;
  ResolvedBoundary<Dim> boundary_;
  bool grows_ = false;  ///< the default radius follows the motion (follow_motion())
  RbfMover<Dim> inner_;      ///< replicated: over the gathered centres followed by the local interior nodes
  RbfOptions options_;
  LinearRepair<Dim> repair_;  ///< the rank's cells, when setup() was given them (all linear)
  double radius_ = 0.0;  ///< the last setup's support radius (options_'s, or the default's)
  bool radius_reduced_ = false;
  BoundarySolveOptions solve_;
  bool petsc_ = false;
  std::unique_ptr<detail::PetscRbfSystem<Dim>> system_;  ///< PETSc: the boundary system
  std::unique_ptr<detail::DistributedPartitionOfUnity<Dim>> patches_;  ///< patches: the whole mover
  Index global_entries_ = 0;
  Index n_entries_ = 0;  ///< this rank's boundary entries
  Points<Dim> local_points_;                 ///< PETSc: this rank's nodes
  std::vector<Index> interior_;              ///< PETSc: local nodes that are not centres
  std::vector<Index> evaluated_;             ///< PETSc: those with kernel weights (operator rows)
  meshmotion::detail::KernelRows operator_;  ///< PETSc: evaluated_ × centres
  Eigen::MatrixXd alpha_;
  typename detail::PetscRbfSystem<Dim>::PolyCoefficients beta_;
  MoverStats stats_;
  bool ready_ = false;
  Index n_local_ = 0;
  Index inner_columns_ = 0;
  std::vector<char> owned_;            ///< per local node
  std::vector<Index> owned_entries_;   ///< this rank's boundary entries it owns, in its order
  std::vector<std::int64_t> sorted_ids_;  ///< global ids of the whole boundary, ascending
  std::vector<Index> slot_of_gathered_;   ///< gathered entry (rank order) → sorted position
  std::vector<Index> column_;          ///< local node → column of the inner mover
  std::vector<Index> entry_slot_;      ///< this rank's boundary entry → sorted position (-1: ghost)
  std::vector<int> counts_;            ///< owned entries per rank
  Points<Dim> gathered_, inner_out_;
  RigidPartAtMove<Dim> at_move_;  ///< set up at rest: each move's rigid part
  Points<Dim> blend_, rest_;      ///< the last move's blend (Dim × part.size()), and d less it
  double solving_ = 0.0;          ///< apply()'s solves since move_to() began (the move's solve_seconds)
  bool pending_ = false;          ///< set_up() deferred the build (build_interpolation())
  Points<Dim> pending_points_;    ///< replicated: the inner mover's points; PETSc: the centres
  ResolvedBoundary<Dim> pending_centres_;  ///< replicated: the inner mover's boundary
};

template <int Dim>
void DistributedRbfMover<Dim>::setup(const PartitionView<Dim>& part, const ResolvedBoundary<Dim>& boundary) {
  ready_ = false;
  comm_ = part.comm;
  part_points_ = part.points;
  part_ids_.assign(part.global_ids.begin(), part.global_ids.end());
  part_owners_.assign(part.owner.begin(), part.owner.end());
  boundary_ = boundary;
  at_move_ = {};
  repair_ = {};
  if (options_.rigid_part != RigidPart::none) {
    // At rest: no owned prescribed entry moves (a ghost's entry is its owner's to give).
    std::vector<char> owned(static_cast<std::size_t>(boundary.size()), 0);
    // A malformed boundary blends nothing: set_up() refuses it, naming what is wrong.
    const bool shaped = boundary.displacements.cols() == boundary.size();
    int rest = static_cast<Index>(boundary.kinds.size()) == boundary.size() ? 1 : 0;
    for (Index k = 0; rest != 0 && k < boundary.size(); ++k) {
      const Index v = boundary.nodes[static_cast<std::size_t>(k)];
      owned[static_cast<std::size_t>(k)] = v >= 0 && v < part.size() && part.owns(v) ? 1 : 0;
      if (owned[static_cast<std::size_t>(k)] != 0 && shaped && boundary.kinds[static_cast<std::size_t>(k)] == BoundaryKind::prescribed &&
          !boundary.displacements.col(k).isZero(0.0))
        rest = 0;
    }
    MPI_Allreduce(MPI_IN_PLACE, &rest, 1, MPI_INT, MPI_MIN, comm_);
    if (rest != 0) {
      std::optional<std::string> why;
      collective(comm_, [&] { why = at_move_.prepare(part_points_, boundary, owned, RanksReduction{comm_}); });
      if (why && options_.rigid_part == RigidPart::blend) throw InputError("DistributedRbfMover::setup: rigid_part=blend: " + *why);
    }
  }
  // As the serial mover's: with each move's rigid part taken and the default radius (which the
  // first motion it cannot carry grows), the interpolation waits for the first move that
  // leaves it something. A body moving rigidly never factorizes; the choices (radius, where
  // the system is solved) are made now all the same.
  set_up(boundary, at_move_.active() && options_.support_radius == 0.0 && options_.support_radii.empty());
}

template <int Dim>
bool DistributedRbfMover<Dim>::leaves_something(PointsView<Dim> d, PointsView<Dim> rest) const {
  double figures[2] = {0.0, 0.0};  // off, scale
  for (Index k = 0; k < boundary_.size(); ++k) {
    if (owned_[static_cast<std::size_t>(boundary_.nodes[static_cast<std::size_t>(k)])] == 0) continue;
    figures[1] = std::max(figures[1], d.col(k).norm());
    if (boundary_.kinds[static_cast<std::size_t>(k)] != BoundaryKind::sliding) figures[0] = std::max(figures[0], rest.col(k).norm());
  }
  MPI_Allreduce(MPI_IN_PLACE, figures, 2, MPI_DOUBLE, MPI_MAX, comm_);
  return figures[0] > rigid_fit_round_off * figures[1];
}

template <int Dim>
void DistributedRbfMover<Dim>::build_interpolation() {
  if (!pending_) return;
  const meshmotion::detail::Stopwatch watch;
  pending_ = false;
  const MoverStats before = stats_;
  if (petsc_) {
    setup_petsc(PartitionView<Dim>{comm_, part_points_, part_ids_, part_owners_}, std::move(pending_points_));
  } else {
    collective(comm_, [&] { inner_.setup_reference(std::move(pending_points_), pending_centres_); });
    stats_ = inner_.stats();
    stats_.evaluated_nodes = std::min(stats_.evaluated_nodes, n_local_);
  }
  pending_points_.resize(Dim, 0);
  pending_centres_ = {};
  stats_.support_radius = before.support_radius;
  stats_.radius_reduced = before.radius_reduced;
  stats_.rigid_part = before.rigid_part;
  stats_.moves = before.moves;
  stats_.radius_growths = before.radius_growths;
  stats_.setup_seconds = before.setup_seconds + watch.seconds();
}

template <int Dim>
const Points<Dim>& DistributedRbfMover<Dim>::without_blend(PointsView<Dim> d, const Points<Dim>& blend) {
  rest_ = d;
  for (Index k = 0; k < boundary_.size(); ++k)
    if (boundary_.kinds[static_cast<std::size_t>(k)] != BoundaryKind::sliding) rest_.col(k) -= blend.col(boundary_.nodes[static_cast<std::size_t>(k)]);
  return rest_;
}

template <int Dim>
double DistributedRbfMover<Dim>::follow_motion(PointsView<Dim> d) {
  if (!grows_) return 0.0;
  double largest = 0.0;
  for (const Index k : owned_entries_)
    if (boundary_.kinds[static_cast<std::size_t>(k)] == BoundaryKind::prescribed) largest = std::max(largest, d.col(k).norm());
  MPI_Allreduce(MPI_IN_PLACE, &largest, 1, MPI_DOUBLE, MPI_MAX, comm_);
  if (!radius_outgrown(largest, radius_)) return 0.0;
  const meshmotion::detail::Stopwatch watch;
  ResolvedBoundary<Dim> grown = boundary_;
  grown.displacements.setZero(Dim, grown.size());
  for (const Index k : owned_entries_)
    if (boundary_.kinds[static_cast<std::size_t>(k)] == BoundaryKind::prescribed) grown.displacements.col(k) = radius_growth_margin * d.col(k);
  const double before = radius_;
  const Index moves = stats_.moves, growths = stats_.radius_growths;
  set_up(grown);
  stats_.moves = moves;
  stats_.radius_growths = growths;
  if (radius_ > before)
    ++stats_.radius_growths;
  else
    grows_ = false;  // the memory budget holds the radius where it is
  return watch.seconds();
}

template <int Dim>
void DistributedRbfMover<Dim>::set_up(const ResolvedBoundary<Dim>& boundary, bool defer) {
  const meshmotion::detail::Stopwatch watch;
  ready_ = false;
  pending_ = false;
  const PartitionView<Dim> part{comm_, part_points_, part_ids_, part_owners_};
  const Index n = part.size();
  collective(comm_, [&] {
    part.check("DistributedRbfMover::setup");
    if (boundary.size() > 0) meshmotion::detail::check_boundary<Dim>("DistributedRbfMover::setup", boundary, n, false);
    const auto& radii = options_.support_radii;
    if (!radii.empty() && static_cast<Index>(radii.size()) != boundary.size())
      throw InputError("DistributedRbfMover::setup: " + std::to_string(radii.size()) + " support radii for " +
                       std::to_string(boundary.size()) + " local boundary entries (expected one per entry, or none)");
    if (solve_.boundary_solve == BoundarySolve::patches && !options_.partition_of_unity)
      throw InputError("DistributedRbfMover::setup: BoundarySolve::patches needs RbfOptions::partition_of_unity");
    if (options_.rigid_part == RigidPart::blend && !at_move_.active())
      throw InputError("DistributedRbfMover::setup: rigid_part=blend on a mover set up with a motion is not distributed (the "
                       "ranks blend each move's rigid part when set up at rest; give rigid_part=automatic or none)");
  });
  n_local_ = n;
  n_entries_ = boundary.size();
  owned_.resize(static_cast<std::size_t>(n));
  for (Index i = 0; i < n; ++i) owned_[static_cast<std::size_t>(i)] = part.owns(i) ? 1 : 0;
  patches_.reset();
  radius_reduced_ = false;
  if (options_.partition_of_unity && (solve_.boundary_solve == BoundarySolve::automatic || solve_.boundary_solve == BoundarySolve::patches)) {
    // No rank gathers the boundary: patches own it, and are built whole (they decide at their
    // setup whether they can be spread, so nothing waits for a move).
    auto patches = std::make_unique<detail::DistributedPartitionOfUnity<Dim>>();
    const std::string obstacle = patches->setup(part, boundary, options_);
    if (obstacle.empty()) {
      petsc_ = false;
      system_.reset();
      radius_ = patches->support_radius();
      global_entries_ = patches->global_centres();
      owned_entries_ = patches->entries();
      stats_ = patches->stats();
      stats_.support_radius = radius_;
      grows_ = options_.support_radius == 0.0;
      patches_ = std::move(patches);
      stats_.rigid_part = at_move_.active();
      ready_ = true;
      stats_.setup_seconds = watch.seconds();
      return;
    }
    if (solve_.boundary_solve == BoundarySolve::patches)
      throw InputError("DistributedRbfMover::setup: the partition of unity cannot be spread over the ranks: " + obstacle +
                       " (use BoundarySolve::replicated)");
  }
  const GatheredBoundary gathered = gather_boundary(part, boundary);
  global_entries_ = static_cast<Index>(sorted_ids_.size());
  const auto m = static_cast<Index>(sorted_ids_.size());
  number_columns(part, boundary);
  Points<Dim> points;
  std::vector<double> radii;
  ResolvedBoundary<Dim> centres = inner_boundary(part, gathered, points, radii);

  radius_ = options_.support_radius;
  if (radius_ == 0.0 && !gathered.radius_per_entry) {
    const DefaultSupportRadius fitted = default_radius(part, boundary, gathered, Points<Dim>(points.leftCols(m)));
    radius_ = fitted.radius;
    radius_reduced_ = fitted.reduced;
  }
  gathered_.resize(Dim, m);
  // The serial mover's levels: the inner one is given the radius, which it would keep on one.
  const bool two = two_level_interpolation(options_, options_.support_radius == 0.0 && !gathered.radius_per_entry, m);
  petsc_ = choose_petsc(gathered, points.leftCols(m), two);
  if (!petsc_) {
    system_.reset();
    RbfOptions options = options_;
    options.levels = two ? RbfLevels::two : RbfLevels::one;
    options.support_radius = radius_;
    options.support_radii = std::move(radii);
    options.rigid_part = RigidPart::none;  // as the PETSc and patches solves: the whole motion interpolated
    inner_ = RbfMover<Dim>(std::move(options));
    pending_centres_ = std::move(centres);
  }
  pending_points_ = petsc_ ? Points<Dim>(points.leftCols(m)) : std::move(points);
  pending_ = true;
  stats_ = MoverStats{};
  stats_.boundary_nodes = m;
  stats_.evaluated_nodes = n - boundary.size();  // until built: every node but the boundary's is blended
  if (!defer) build_interpolation();
  stats_.support_radius = radius_;
  stats_.radius_reduced = radius_reduced_;
  grows_ = options_.support_radius == 0.0 && !gathered.radius_per_entry && !radius_reduced_;
  stats_.rigid_part = at_move_.active();
  ready_ = true;
  stats_.setup_seconds = watch.seconds();
}

template <int Dim>
DefaultSupportRadius DistributedRbfMover<Dim>::default_radius(const PartitionView<Dim>& part, const ResolvedBoundary<Dim>& boundary,
                                                              const GatheredBoundary& gathered, const Points<Dim>& centres) const {
  // The serial mover's rule (meshmotion::detail::budgeted_support_radius) on the whole mesh:
  // the gathered centres are in global id order, the largest displacement and the node count
  // are reduced over the ranks, and the estimate's sampled nodes are counted by their owners.
  double largest = 0.0, global_largest = 0.0, owned = 0.0, nodes = 0.0;
  for (const Index k : owned_entries_) largest = std::max(largest, boundary.displacements.col(k).norm());
  for (Index i = 0; i < part.size(); ++i) owned += part.owns(i) ? 1.0 : 0.0;
  MPI_Allreduce(&largest, &global_largest, 1, MPI_DOUBLE, MPI_MAX, comm_);
  MPI_Allreduce(&owned, &nodes, 1, MPI_DOUBLE, MPI_SUM, comm_);
  const auto n = static_cast<Index>(nodes), samples = meshmotion::detail::memory_samples(n);
  std::vector<Index> sampled;  // this rank's owned nodes among the sampled global ids
  for (Index i = 0; i < part.size(); ++i) {
    const std::int64_t g = part.global_ids[static_cast<std::size_t>(i)];
    if (!part.owns(i) || g < 0 || g >= n) continue;
    // g is sampled when some s gives s·n/samples == g: the smallest s with s·n ≥ g·samples.
    const Index s = (static_cast<Index>(g) * samples + n - 1) / n;
    if (s < samples && meshmotion::detail::sampled_node(s, n) == g) sampled.push_back(i);
  }
  const bool sliding = std::any_of(gathered.kinds.begin(), gathered.kinds.end(),
                                   [](int k) { return static_cast<BoundaryKind>(k) == BoundaryKind::sliding; });
  return meshmotion::detail::budgeted_support_radius(
      centres, global_largest, nodes, sliding, options_, [&](const KdTree<Dim>& tree, double radius) {
        std::vector<Neighbor> found;
        double count = 0.0, total = 0.0;
        for (const Index i : sampled) count += static_cast<double>(tree.radius_search(Vec<Dim>(part.points.col(i)), radius, found));
        MPI_Allreduce(&count, &total, 1, MPI_DOUBLE, MPI_SUM, comm_);
        return samples == 0 ? 0.0 : total / static_cast<double>(samples);
      });
}

template <int Dim>
typename DistributedRbfMover<Dim>::GatheredBoundary DistributedRbfMover<Dim>::gather_boundary(
    const PartitionView<Dim>& part, const ResolvedBoundary<Dim>& boundary) {
  // This rank's owned entries, packed for the gather.
  owned_entries_.clear();
  std::vector<std::int64_t> ids;
  std::vector<int> kinds;
  std::vector<double> geometry;
  const bool per_entry_radius = !options_.support_radii.empty();
  int radius_flag = per_entry_radius ? 1 : 0, any_radius = 0;
  MPI_Allreduce(&radius_flag, &any_radius, 1, MPI_INT, MPI_MAX, comm_);
  for (Index k = 0; k < boundary.size(); ++k) {
    const Index node = boundary.nodes[static_cast<std::size_t>(k)];
    if (!part.owns(node)) continue;
    owned_entries_.push_back(k);
    ids.push_back(part.global_ids[static_cast<std::size_t>(node)]);
    kinds.push_back(static_cast<int>(boundary.kinds[static_cast<std::size_t>(k)]));
    for (int d = 0; d < Dim; ++d) geometry.push_back(part.points(d, node));
    for (int d = 0; d < Dim; ++d) geometry.push_back(boundary.normals(d, k));
    for (int d = 0; d < Dim; ++d) geometry.push_back(boundary.directions.cols() > k ? boundary.directions(d, k) : 0.0);
    geometry.push_back(per_entry_radius ? options_.support_radii[static_cast<std::size_t>(k)] : 0.0);
  }
  const std::vector<std::int64_t> all_ids = all_gather(comm_, ids, &counts_);
  GatheredBoundary gathered{all_gather(comm_, kinds), all_gather(comm_, geometry), any_radius != 0};
  const auto m = static_cast<Index>(all_ids.size());

  std::vector<Index> order(static_cast<std::size_t>(m));
  std::iota(order.begin(), order.end(), Index{0});
  std::sort(order.begin(), order.end(), [&](Index a, Index b) { return all_ids[static_cast<std::size_t>(a)] < all_ids[static_cast<std::size_t>(b)]; });
  sorted_ids_.resize(static_cast<std::size_t>(m));
  slot_of_gathered_.resize(static_cast<std::size_t>(m));
  for (Index s = 0; s < m; ++s) {
    sorted_ids_[static_cast<std::size_t>(s)] = all_ids[static_cast<std::size_t>(order[static_cast<std::size_t>(s)])];
    slot_of_gathered_[static_cast<std::size_t>(order[static_cast<std::size_t>(s)])] = s;
  }
  // Every rank sees the same gathered arrays, so these checks agree everywhere.
  if (m == 0) throw InputError("DistributedRbfMover::setup: no rank owns a boundary node (expected at least one)");
  for (Index s = 1; s < m; ++s)
    if (sorted_ids_[static_cast<std::size_t>(s)] == sorted_ids_[static_cast<std::size_t>(s - 1)])
      throw InputError("DistributedRbfMover::setup: global node " + std::to_string(sorted_ids_[static_cast<std::size_t>(s)]) +
                       " is an owned boundary node on two ranks (each node must have one owner)");
  return gathered;
}

template <int Dim>
void DistributedRbfMover<Dim>::number_columns(const PartitionView<Dim>& part, const ResolvedBoundary<Dim>& boundary) {
  // Inner mover: the centres first (sorted), then this rank's nodes that are not centres.
  const Index n = part.size();
  const auto m = static_cast<Index>(sorted_ids_.size());
  column_.assign(static_cast<std::size_t>(n), -1);
  entry_slot_.assign(static_cast<std::size_t>(boundary.size()), -1);
  Index interior = 0;
  for (Index i = 0; i < n; ++i) {
    const std::int64_t g = part.global_ids[static_cast<std::size_t>(i)];
    const auto it = std::lower_bound(sorted_ids_.begin(), sorted_ids_.end(), g);
    if (it != sorted_ids_.end() && *it == g)
      column_[static_cast<std::size_t>(i)] = static_cast<Index>(it - sorted_ids_.begin());
    else
      column_[static_cast<std::size_t>(i)] = m + interior++;
  }
  for (const Index e : owned_entries_)
    entry_slot_[static_cast<std::size_t>(e)] = column_[static_cast<std::size_t>(boundary.nodes[static_cast<std::size_t>(e)])];
  inner_columns_ = m + interior;
}

template <int Dim>
ResolvedBoundary<Dim> DistributedRbfMover<Dim>::inner_boundary(const PartitionView<Dim>& part, const GatheredBoundary& gathered,
                                                               Points<Dim>& points, std::vector<double>& radii) const {
  const auto m = static_cast<Index>(sorted_ids_.size());
  points.resize(Dim, inner_columns_);
  ResolvedBoundary<Dim> centres;
  centres.nodes.resize(static_cast<std::size_t>(m));
  centres.kinds.resize(static_cast<std::size_t>(m));
  centres.displacements.setZero(Dim, m);
  centres.normals.resize(Dim, m);
  centres.directions.resize(Dim, m);
  radii.assign(gathered.radius_per_entry ? static_cast<std::size_t>(m) : 0, 0.0);
  for (Index j = 0; j < m; ++j) {
    const Index s = slot_of_gathered_[static_cast<std::size_t>(j)];
    const double* g = gathered.geometry.data() + j * GatheredBoundary::stride;
    centres.nodes[static_cast<std::size_t>(s)] = s;
    centres.kinds[static_cast<std::size_t>(s)] = static_cast<BoundaryKind>(gathered.kinds[static_cast<std::size_t>(j)]);
    for (int d = 0; d < Dim; ++d) {
      points(d, s) = g[d];
      centres.normals(d, s) = g[Dim + d];
      centres.directions(d, s) = g[2 * Dim + d];
    }
    if (!radii.empty()) radii[static_cast<std::size_t>(s)] = g[3 * Dim];
  }
  for (Index i = 0; i < part.size(); ++i)
    if (column_[static_cast<std::size_t>(i)] >= m) points.col(column_[static_cast<std::size_t>(i)]) = part.points.col(i);
  return centres;
}

template <int Dim>
bool DistributedRbfMover<Dim>::choose_petsc(const GatheredBoundary& gathered, const Points<Dim>& centres, bool two_levels) const {
  // Every rank decides alike: the inputs are the gathered arrays. The obstacles (a k-d tree
  // over the centres among them) are looked for only when PETSc is wanted.
  const Index m = centres.cols();
  const int sharing = ranks_on_node(comm_);
  const int rounds = (sharing + cores_of_node() - 1) / cores_of_node();
  const bool crowded = size_of(comm_) > 1 && m * sharing * rounds >= solve_.petsc_min_node_centres;
  const bool wanted = solve_.boundary_solve == BoundarySolve::petsc ||
                      (solve_.boundary_solve == BoundarySolve::automatic && !two_levels && (m >= solve_.petsc_min_centres || crowded));
  const std::string obstacle = wanted ? petsc_obstacle(gathered.kinds, gathered.radius_per_entry, centres) : std::string();
  if (solve_.boundary_solve == BoundarySolve::petsc && !obstacle.empty())
    throw InputError("DistributedRbfMover::setup: the boundary system cannot go through PETSc: " + obstacle +
                     " (use BoundarySolve::replicated)");
  return wanted && obstacle.empty();
}

template <int Dim>
void DistributedRbfMover<Dim>::check_entries(const char* where, PointsView<Dim> d) {
  collective(comm_, [&] {
    require_ready(where);
    const Index expected = n_entries_;
    if (d.cols() != expected)
      throw InputError(std::string("DistributedRbfMover::") + where + ": got " + std::to_string(d.cols()) +
                       " boundary values (expected " + std::to_string(expected) + ", one per local boundary entry)");
    for (const Index k : owned_entries_)
      if (!d.col(k).allFinite())
        throw InputError(std::string("DistributedRbfMover::") + where + ": boundary entry " + std::to_string(k) +
                         " has a non-finite value");
  });
}

template <int Dim>
void DistributedRbfMover<Dim>::move_into(PointsView<Dim> d, Eigen::Ref<Points<Dim>> out) {
  collective(comm_, [&] {
    if (out.cols() != n_local_)
      throw InputError("DistributedRbfMover::move_into: the output has " + std::to_string(out.cols()) + " columns (expected " +
                       std::to_string(n_local_) + ", one per local node)");
  });
  move_to(d, out);
}

template <int Dim>
template <class Out>
void DistributedRbfMover<Dim>::move_to(PointsView<Dim> d, Out& out) {
  const meshmotion::detail::Stopwatch watch;
  check_entries("move", d);
  solving_ = 0.0;
  double rebuilding = 0.0;
  if (!at_move_.active()) {
    rebuilding += follow_motion(d);
    apply(d, out);
  } else {
    at_move_.blend(part_points_, d, blend_, RanksReduction{comm_});
    const Points<Dim>& rest = without_blend(d, blend_);
    if (pending_ && !leaves_something(d, rest)) {
      // Nothing but the fit's round-off to interpolate, and nothing built to do it with.
      meshmotion::detail::size_output<Dim>(out, n_local_);
      out = blend_;
    } else {
      rebuilding += follow_motion(rest);  // a radius outgrown is set up (and built) for the motion at once
      if (pending_) meshmotion::detail::add_time(rebuilding, [&] { build_interpolation(); });
      apply(rest, out);
      // A shared node's owner and its other ranks add the same two numbers (the rest, the
      // blend): the same point on every rank, d to rounding.
      out += blend_;
    }
  }
  const RepairReport repaired = repair_.repair(out, RanksGather{comm_});
  stats_.folded_cells = repaired.folded;
  stats_.repaired_nodes = repaired.moved_nodes;
  stats_.left_folded = repaired.left_folded;
  ++stats_.moves;
  stats_.move_seconds = watch.seconds();
  stats_.solve_seconds = solving_;
  stats_.rebuild_seconds = rebuilding;
}

template <int Dim>
Points<Dim> DistributedRbfMover<Dim>::velocity(PointsView<Dim> v) {
  check_entries("velocity", v);
  build_interpolation();
  Points<Dim> out;
  if (!at_move_.active()) {
    apply(v, out);
    return out;
  }
  // As the serial mover's derivative_forward: the blend's change and the interpolation of the rest.
  Points<Dim> blended;
  at_move_.derivative_forward(part_points_, v, blended, RanksReduction{comm_});
  apply(without_blend(v, blended), out);
  out += blended;
  return out;
}

template <int Dim>
template <class Out>
void DistributedRbfMover<Dim>::move_gathered(PointsView<Dim> d, Out& out) {
  std::vector<double> mine;
  mine.reserve(owned_entries_.size() * Dim);
  for (const Index k : owned_entries_)
    for (int a = 0; a < Dim; ++a) mine.push_back(d(a, k));
  const std::vector<double> all = all_gather(comm_, mine);
  for (std::size_t j = 0; j < slot_of_gathered_.size(); ++j)
    for (int a = 0; a < Dim; ++a) gathered_(a, slot_of_gathered_[j]) = all[j * Dim + static_cast<std::size_t>(a)];
  if (petsc_) {
    move_petsc(out);
  } else {
    collective(comm_, [&] { inner_.move_into(gathered_, inner_out_); });
    meshmotion::detail::size_output<Dim>(out, n_local_);
    for (Index i = 0; i < n_local_; ++i) out.col(i) = inner_out_.col(column_[static_cast<std::size_t>(i)]);
    const MoverStats& s = inner_.stats();
    solving_ += s.solve_seconds;
    stats_.iterations = s.iterations;
    stats_.residual = s.residual;
    stats_.fell_back = s.fell_back;
  }
}

template <int Dim>
Points<Dim> DistributedRbfMover<Dim>::derivative_reverse(PointsView<Dim> v) {
  collective(comm_, [&] {
    require_ready("derivative_reverse");
    meshmotion::detail::check_node_field<Dim>("DistributedRbfMover::derivative_reverse", v, n_local_);
  });
  build_interpolation();
  Points<Dim> grad = reverse_interpolation(v);
  if (!at_move_.active()) return grad;
  // As the serial mover's: the blend's change meets v less what the interpolation took at the
  // boundary (owned entries: the others' terms are their owners').
  Points<Dim> through_blend = v;
  for (Index k = 0; k < boundary_.size(); ++k) {
    const Index node = boundary_.nodes[static_cast<std::size_t>(k)];
    if (boundary_.kinds[static_cast<std::size_t>(k)] != BoundaryKind::sliding && owned_[static_cast<std::size_t>(node)] != 0)
      through_blend.col(node) -= grad.col(k);
  }
  at_move_.derivative_reverse(part_points_, through_blend, grad, owned_, RanksReduction{comm_});
  return grad;
}

template <int Dim>
Points<Dim> DistributedRbfMover<Dim>::reverse_interpolation(PointsView<Dim> v) {
  if (patches_) return patches_->derivative_reverse(v, owned_, n_entries_);
  if (petsc_) return reverse_petsc(v);
  const Index m = global_boundary_size();
  Points<Dim> seed = Points<Dim>::Zero(Dim, inner_columns_);
  // Owned nodes only: a ghost's term belongs to its owner.
  for (Index i = 0; i < n_local_; ++i)
    if (owned_[static_cast<std::size_t>(i)] != 0) seed.col(column_[static_cast<std::size_t>(i)]) += v.col(i);
  Points<Dim> local;
  collective(comm_, [&] { local = inner_.derivative_reverse(seed); });
  Points<Dim> total(Dim, m);
  MPI_Allreduce(local.data(), total.data(), static_cast<int>(Dim * m), MPI_DOUBLE, MPI_SUM, comm_);
  Points<Dim> grad = Points<Dim>::Zero(Dim, static_cast<Index>(entry_slot_.size()));
  for (std::size_t k = 0; k < entry_slot_.size(); ++k)
    if (entry_slot_[k] >= 0) grad.col(static_cast<Index>(k)) = total.col(entry_slot_[k]);
  return grad;
}

template <int Dim>
std::string DistributedRbfMover<Dim>::petsc_obstacle(const std::vector<int>& kinds, bool radius_per_entry,
                                                     const Points<Dim>& centres) const {
  if (!is_compact(options_.kernel)) return "the kernel is global (dense system)";
  if (options_.partition_of_unity) return "the options ask for a partition of unity (local systems: BoundarySolve::patches)";
  if (radius_per_entry) return "the support radius differs between nodes (nonsymmetric system)";
  if (std::find(kinds.begin(), kinds.end(), static_cast<int>(BoundaryKind::sliding)) != kinds.end())
    return "the boundary has sliding nodes";
  const double diagonal = centres.cols() > 0 ? (centres.rowwise().maxCoeff() - centres.rowwise().minCoeff()).norm() : 0.0;
  const auto rep = meshmotion::detail::coincident_representatives(centres, options_.coincidence_tolerance * diagonal);
  for (std::size_t i = 0; i < rep.size(); ++i)
    if (rep[i] != static_cast<Index>(i)) return "boundary nodes coincide (global ids " + std::to_string(sorted_ids_[static_cast<std::size_t>(rep[i])]) +
                                                " and " + std::to_string(sorted_ids_[i]) + ")";
  return {};
}

template <int Dim>
void DistributedRbfMover<Dim>::setup_petsc(const PartitionView<Dim>& part, Points<Dim> centres) {
  const Index m = centres.cols();
  local_points_ = part.points;
  if (!(radius_ > 0.0) || !std::isfinite(radius_))
    throw InputError("DistributedRbfMover::setup: support radius must be positive (got " + std::to_string(radius_) + ")");
  const meshmotion::detail::RbfKernelSettings kernel{options_.kernel, radius_, options_.polynomial};
  system_ = std::make_unique<detail::PetscRbfSystem<Dim>>();
  system_->setup(comm_, centres, kernel);
  interior_.clear();
  for (Index i = 0; i < n_local_; ++i)
    if (column_[static_cast<std::size_t>(i)] >= m) interior_.push_back(i);
  std::vector<Index> kept;
  operator_ = meshmotion::detail::compact_kernel_rows(local_points_, interior_, system_->within(), m, kernel, &kept);
  evaluated_.clear();
  for (const Index r : kept) evaluated_.push_back(interior_[static_cast<std::size_t>(r)]);
  stats_ = MoverStats{};
  stats_.boundary_nodes = m;
  stats_.evaluated_nodes = options_.polynomial ? static_cast<Index>(interior_.size()) : static_cast<Index>(evaluated_.size());
  stats_.nonzeros = system_->nonzeros() + operator_.nonZeros();
  stats_.factorizations = 1;
}

template <int Dim>
template <class Out>
void DistributedRbfMover<Dim>::move_petsc(Out& out) {
  meshmotion::detail::add_time(solving_, [&] { collective(comm_, [&] { system_->solve(gathered_.transpose(), alpha_, beta_); }); });
  meshmotion::detail::size_output<Dim>(out, n_local_);
  out.setZero();
  Points<Dim> columns;
  meshmotion::detail::kernel_rows_times<Dim>(operator_, alpha_, columns, [&](Index r, const Vec<Dim>& value) {
    out.col(evaluated_[static_cast<std::size_t>(r)]) = value;
  });
  if (options_.polynomial)
    for (const Index i : interior_) out.col(i) += beta_.transpose() * system_->polynomial(local_points_.col(i));
  const Index m = global_boundary_size();
  for (Index i = 0; i < n_local_; ++i)
    if (const Index c = column_[static_cast<std::size_t>(i)]; c < m) out.col(i) = gathered_.col(c);
}

template <int Dim>
Points<Dim> DistributedRbfMover<Dim>::reverse_petsc(const PointsView<Dim>& v) {
  const Index m = global_boundary_size();
  constexpr int poly = (Dim + 1) * Dim;
  // One buffer summed over the ranks: ᾱ (m × Dim), the boundary nodes' own terms (Dim × m), β̄.
  Eigen::VectorXd sums = Eigen::VectorXd::Zero(2 * m * Dim + poly);
  Eigen::Map<Eigen::MatrixXd> alpha_bar(sums.data(), m, Dim);
  Eigen::Map<Points<Dim>> direct(sums.data() + m * Dim, Dim, m);
  Eigen::Map<typename detail::PetscRbfSystem<Dim>::PolyCoefficients> beta_bar(sums.data() + 2 * m * Dim);
  detail::owned_transpose_times<Dim>(operator_, evaluated_, owned_, v, alpha_bar);
  if (options_.polynomial)
    for (const Index i : interior_)
      if (owned_[static_cast<std::size_t>(i)] != 0) beta_bar += system_->polynomial(local_points_.col(i)) * v.col(i).transpose();
  for (Index i = 0; i < n_local_; ++i)
    if (const Index c = column_[static_cast<std::size_t>(i)]; c < m && owned_[static_cast<std::size_t>(i)] != 0) direct.col(c) += v.col(i);
  MPI_Allreduce(MPI_IN_PLACE, sums.data(), static_cast<int>(sums.size()), MPI_DOUBLE, MPI_SUM, comm_);
  Eigen::MatrixXd values_bar;
  collective(comm_, [&] {
    system_->solve_transpose(alpha_bar, typename detail::PetscRbfSystem<Dim>::PolyCoefficients(beta_bar), values_bar);
  });
  Points<Dim> grad = Points<Dim>::Zero(Dim, static_cast<Index>(entry_slot_.size()));
  for (std::size_t k = 0; k < entry_slot_.size(); ++k)
    if (const Index s = entry_slot_[k]; s >= 0) grad.col(static_cast<Index>(k)) = direct.col(s) + values_bar.row(s).transpose();
  return grad;
}

}  // namespace meshmotion::parallel

// The compiled parallel library (target meshmotion::parallel, src/parallel.cpp) holds these.
#ifdef MESHMOTION_PARALLEL_COMPILED
namespace meshmotion::parallel {
extern template class DistributedRbfMover<2>;
extern template class DistributedRbfMover<3>;
}  // namespace meshmotion::parallel
#endif
