#pragma once
/// \file
/// RbfMover: radial basis function interpolation of boundary displacements into the volume
/// (thesis section 2.2.2, eqs. 2.10–2.14; de Boer, van der Schoot & Bijl 2007).
///
/// - Linear in the displacements: move(a d1 + b d2) = a move(d1) + b move(d2); affine when
///   setup took the rigid part of a large rigid motion out (RbfOptions::rigid_part,
///   rigid_part.hpp): move(d) = B + J(d − B_b), B that motion blended over the volume, J the
///   interpolation, which the derivatives give.
/// - Setup caches: merged boundary centres and their k-d tree, the factorized interpolation
///   matrix (sparse SimplicialLDLT for the compact Wendland kernels, dense LU for global
///   kernels), and for compact kernels the evaluation operator E (a sparse matrix of kernel
///   weights between each node and the boundary centres inside its support, found by k-d
///   tree radius queries; nodes beyond every support are skipped).
/// - Cost: setup O(m log m + n log m) queries plus one sparse factorization (m boundary
///   nodes, n nodes); move = one solve with the cached factorization + one sparse
///   mat-vec E α (parallel). Global kernels: dense O(m³) setup, O(n m) per move.
/// - Global kernels: the dense evaluation matrix (evaluated nodes × centres) is cached in
///   setup when it fits RbfOptions::max_evaluation_cache_bytes, making a move one dense
///   matrix product (evaluation_cached() tells); otherwise each move re-evaluates the kernel.
///   A compact kernel whose support reaches more than half of the centres from a sample of
///   nodes gets the same dense matrix when it fits (its sparse operator would be full).
/// - Sliding boundaries (exact): the interpolant over the prescribed and fixed nodes gives
///   the sliding nodes a displacement, which is projected on each node's plane or line
///   (ResolvedBoundary::project), and the projected values join the constraints of a second
///   interpolant over all nodes; both systems are factorized once in setup, so sliding nodes
///   end exactly on their planes and lines.
/// - Set up once, moved many times: with the default radius (no support_radius or
///   support_radii given), a move whose largest prescribed displacement outgrew it
///   (radius_outgrown(): a solver sets the mover up before anything moves, where the default
///   is ten boundary spacings) sets the interpolation up again for radius_growth_margin × that
///   displacement, at most once per doubling of the motion (MoverStats::radius_growths), until
///   the memory budget holds the radius. The map is then that of the grown radius; the
///   derivatives are those of the last move's map.
/// - Optional linear polynomial augmentation reproduces affine motions exactly.
/// - A radius per boundary node (RbfOptions::support_radii), e.g. each wall's own
///   boundary-layer thickness: s(x) = Σ_j α_j φ(|x − c_j| / ρ_j), still interpolating.
/// - derivative_forward / derivative_reverse give J w and Jᵀ v for J = ∂(node displacements)
///   / ∂(boundary displacements), reusing the factorizations (shape optimization).
/// - Boundaries too large for one factorization (RbfOptions::partition_of_unity): local
///   systems on overlapping patches of centres, blended by a partition of unity
///   (detail/rbf_partition_of_unity.hpp); still interpolating, linear, with derivatives.
/// - A radius wider than the boundary's spacing on a large boundary (RbfOptions::levels):
///   a coarse subset of the centres carries it and every centre, at a few boundary spacings,
///   what the coarse level leaves (detail/rbf_two_level.hpp), so that neither the memory nor
///   a move's cost grows with the motion; still interpolating, linear, with derivatives.

#include "meshmotion/movers/rbf_options.hpp"
#include "meshmotion/core/error.hpp"
#include "meshmotion/core/mesh_like.hpp"
#include "meshmotion/core/option_text.hpp"
#include "meshmotion/core/process_memory.hpp"
#include "meshmotion/core/threads.hpp"
#include "meshmotion/core/types.hpp"
#include "meshmotion/movers/boundary.hpp"
#include "meshmotion/movers/detail/coincident_nodes.hpp"
#include "meshmotion/movers/detail/mover_support.hpp"
#include "meshmotion/movers/detail/rbf_partition_of_unity.hpp"
#include "meshmotion/movers/detail/rbf_system.hpp"
#include "meshmotion/movers/detail/rbf_two_level.hpp"
#include "meshmotion/movers/linear_repair.hpp"
#include "meshmotion/movers/mover.hpp"
#include "meshmotion/movers/rbf_kernels.hpp"
#include "meshmotion/movers/rigid_part.hpp"
#include "meshmotion/movers/support_radius.hpp"
#include "meshmotion/spatial/kd_tree.hpp"
#include "meshmotion/solvers/detail/stopwatch.hpp"
#include "meshmotion/solvers/solver_options.hpp"

#include <algorithm>
#include <concepts>
#include <cmath>
#include <cstddef>
#include <limits>
#include <memory>
#include <numeric>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace meshmotion {

/// The options an RBF mover runs with: `options` with the polynomial on where the kernel needs
/// it (needs_polynomial()).
[[nodiscard]] inline RbfOptions effective_options(RbfOptions options) {
  options.polynomial = options.polynomial || needs_polynomial(options.kernel);
  return options;
}

namespace detail {

/// The positions of the boundary's nodes (Dim × boundary.size()); throws InputError for a node
/// outside `points`.
template <int Dim>
[[nodiscard]] Points<Dim> boundary_positions(const Points<Dim>& points, const ResolvedBoundary<Dim>& boundary,
                                             const char* where) {
  Points<Dim> at(Dim, boundary.size());
  for (Index k = 0; k < boundary.size(); ++k) {
    const Index v = boundary.nodes[static_cast<std::size_t>(k)];
    if (v < 0 || v >= points.cols())
      throw InputError(std::string(where) + ": boundary node " + std::to_string(v) + " out of range (expected 0 to " +
                       std::to_string(points.cols() - 1) + ")");
    at.col(k) = points.col(v);
  }
  return at;
}

/// Whether RbfOptions::max_memory_bytes applies: compact kernels with one radius, one system.
[[nodiscard]] inline bool memory_checked(const RbfOptions& o) {
  return is_compact(o.kernel) && !o.partition_of_unity && o.support_radii.empty();
}

/// RbfOptions::max_memory_bytes, or half the machine's memory for 0 (no limit when unknown).
[[nodiscard]] inline double memory_limit(const RbfOptions& o) {
  if (!(o.max_memory_bytes >= 0.0))
    throw InputError("RbfMover::setup: max_memory_bytes must be >= 0 (got " + format_option_value(o.max_memory_bytes) + ")");
  if (o.max_memory_bytes > 0.0) return o.max_memory_bytes;
  const double machine = physical_memory_bytes();
  return machine > 0.0 ? 0.5 * machine : std::numeric_limits<double>::infinity();
}

/// The nodes the memory estimate samples: `count` (≤ 256) of `n`, spread evenly by index
/// (node index, or global id in a distributed mesh: every partition samples the same nodes).
[[nodiscard]] inline Index memory_samples(Index n) { return std::min<Index>(n, 256); }
[[nodiscard]] inline Index sampled_node(Index s, Index n) { return s * n / memory_samples(n); }

/// The mean number of centres of `tree` within `radius` of the sampled nodes of `points`.
template <int Dim>
[[nodiscard]] double mean_centres_within(const KdTree<Dim>& tree, const Points<Dim>& points, double radius) {
  const Index n = points.cols(), samples = memory_samples(n);
  std::vector<Neighbor> found;
  double total = 0.0;
  for (Index s = 0; s < samples; ++s) total += static_cast<double>(tree.radius_search(Vec<Dim>(points.col(sampled_node(s, n))), radius, found));
  return samples == 0 ? 0.0 : total / static_cast<double>(samples);
}

/// Estimated peak bytes of a compact RBF of `radius` with its centres at `centres` (in node
/// order; `tree` holds them) evaluated at the other `nodes` of the mesh, `volume_mean(tree,
/// radius)` giving the mean centre count around the mesh's sampled nodes (mean_centres_within()
/// where one process holds the mesh). The system: 40 bytes a nonzero while it is assembled
/// (the neighbour pairs, 16, and the matrix in both storage orders, 12 each) and its factor
/// (fill taken as 4× the nonzeros, up to a dense triangle), twice when nodes slide. The
/// evaluation operator: 28 bytes a nonzero (pairs and matrix), or 8 an entry where setup
/// stores it dense. Measured against the peak resident memory of move_mesh: within a factor
/// of 1.5.
template <int Dim, class VolumeMean>
[[nodiscard]] double compact_rbf_bytes(double nodes, const Points<Dim>& centres, const KdTree<Dim>& tree, bool sliding,
                                       double radius, const RbfOptions& options, VolumeMean&& volume_mean) {
  const auto k = static_cast<double>(centres.cols());
  const double evaluated = std::max(0.0, nodes - k);
  const double system_nonzeros = mean_centres_within(tree, centres, radius) * k;
  double bytes = 40.0 * system_nonzeros + 8.0 * std::min(0.5 * k * k, 4.0 * system_nonzeros);
  if (sliding) bytes *= 2.0;
  const double operator_nonzeros = volume_mean(tree, radius) * evaluated;
  const double dense = 8.0 * evaluated * k;
  const bool cached = operator_nonzeros > 0.5 * evaluated * k && dense <= static_cast<double>(options.max_evaluation_cache_bytes);
  return bytes + (cached ? dense : 28.0 * operator_nonzeros);
}

[[nodiscard]] inline std::string gigabytes(double bytes) { return format_option_value(bytes / 1e9) + " GB"; }

template <int Dim>
[[nodiscard]] bool any_sliding(const ResolvedBoundary<Dim>& boundary) {
  return std::any_of(boundary.kinds.begin(), boundary.kinds.end(), [](BoundaryKind k) { return k == BoundaryKind::sliding; });
}

}  // namespace detail

/// default_support_radius()'s answer.
struct DefaultSupportRadius {
  double radius = 0.0;
  bool reduced = false;  ///< reduced from suggest_support_radius() to fit the memory budget
  bool rigid_part = false;  ///< taken from what remains once the rigid part is out (RbfOptions::rigid_part)
};

namespace detail {

/// The positions of the boundary's nodes in node order (the order a distributed mover
/// gathers them in, by global id), so that the memory estimate samples the same centres.
template <int Dim>
[[nodiscard]] Points<Dim> centres_in_node_order(const Points<Dim>& points, const ResolvedBoundary<Dim>& boundary) {
  const Points<Dim> at = boundary_positions(points, boundary, "RbfMover::setup");
  std::vector<Index> order(static_cast<std::size_t>(at.cols()));
  std::iota(order.begin(), order.end(), Index{0});
  std::sort(order.begin(), order.end(), [&](Index a, Index b) {
    return boundary.nodes[static_cast<std::size_t>(a)] < boundary.nodes[static_cast<std::size_t>(b)];
  });
  Points<Dim> sorted(Dim, at.cols());
  for (Index k = 0; k < at.cols(); ++k) sorted.col(k) = at.col(order[static_cast<std::size_t>(k)]);
  return sorted;
}

/// The one rule of the default radius, for a mesh held by one process or spread over ranks:
/// suggest_support_radius() of the boundary's `centres` (node order) and its `largest`
/// displacement, reduced until the memory estimate for a mesh of `nodes` nodes
/// (compact_rbf_bytes(), `volume_mean` as there) fits max(1 KiB a node, an eighth of the
/// machine's memory) and RbfOptions::max_memory_bytes.
template <int Dim, class VolumeMean>
[[nodiscard]] DefaultSupportRadius budgeted_support_radius(const Points<Dim>& centres, double largest, double nodes,
                                                           bool sliding, const RbfOptions& options, VolumeMean&& volume_mean) {
  DefaultSupportRadius out{suggest_support_radius(centres, largest), false};
  if (!memory_checked(options)) return out;
  const double limit = memory_limit(options);
  const double machine = physical_memory_bytes();
  const double floor = machine > 0.0 ? machine / 8.0 : 2.0 * 1024.0 * 1024.0 * 1024.0;
  const double budget = std::min(limit, std::max(1024.0 * nodes, floor));
  const KdTree<Dim> tree(centres);
  double bytes = compact_rbf_bytes(nodes, centres, tree, sliding, out.radius, options, volume_mean);
  // Counts around a surface of centres grow as r²: a few rescaling rounds settle the radius.
  for (int round = 0; round < 8 && bytes > budget; ++round) {
    out.radius *= 0.95 * std::sqrt(budget / bytes);
    out.reduced = true;
    bytes = compact_rbf_bytes(nodes, centres, tree, sliding, out.radius, options, volume_mean);
  }
  return out;
}

/// budgeted_support_radius() of a mesh one process holds (`points`, every node), for a
/// boundary whose rigid part is already out (or stays in).
template <int Dim>
[[nodiscard]] DefaultSupportRadius budgeted_support_radius(const Points<Dim>& points, const ResolvedBoundary<Dim>& boundary,
                                                           const RbfOptions& options) {
  if (boundary.displacements.cols() != boundary.size())
    throw InputError("RbfMover::setup: " + std::to_string(boundary.displacements.cols()) + " displacements for " +
                     std::to_string(boundary.size()) + " boundary entries");
  const double largest = boundary.size() > 0 ? boundary.displacements.colwise().norm().maxCoeff() : 0.0;
  return budgeted_support_radius(centres_in_node_order(points, boundary), largest, static_cast<double>(points.cols()),
                                 any_sliding(boundary), options,
                                 [&](const KdTree<Dim>& tree, double radius) { return mean_centres_within(tree, points, radius); });
}

}  // namespace detail

/// The support radius an RbfMover given none takes, for the mesh's nodes `points` (Dim ×
/// n_nodes) and `boundary` (its nodes and displacements): suggest_support_radius() of what the
/// interpolation carries (the displacements less their rigid part where RbfOptions::rigid_part
/// takes it out), reduced until the memory estimate of RbfOptions::max_memory_bytes fits
/// max(1 KiB per node, an eighth of the machine's memory) and that limit (compact kernels, one
/// system). The programs and Python take it from here too. Throws InputError as
/// suggest_support_radius() and rigid_blend() do, or for a boundary node outside `points`.
namespace detail {

/// What a setup decides from its boundary's motion: the default radius (when `default_radius`;
/// none for a given one) and the rigid part's blend, taken out first when RbfOptions::rigid_part
/// says so. The radius is that of what the interpolation then carries.
template <int Dim>
struct RadiusAndBlend {
  std::optional<DefaultSupportRadius> radius;
  std::optional<RigidBlend<Dim>> blend;
};

template <int Dim>
[[nodiscard]] RadiusAndBlend<Dim> radius_and_blend(const Points<Dim>& points, const ResolvedBoundary<Dim>& boundary,
                                                   const RbfOptions& options, bool default_radius) {
  RadiusAndBlend<Dim> out;
  if (default_radius) out.radius = budgeted_support_radius(points, boundary, options);
  // automatic blends where the budget cut the whole motion's radius (or nothing is held).
  out.blend = rigid_blend(points, boundary, options.rigid_part, out.radius && out.radius->reduced);
  if (default_radius && out.blend) {
    out.radius = budgeted_support_radius(points, without_rigid_part(boundary, *out.blend), options);
    out.radius->rigid_part = true;
  }
  return out;
}

}  // namespace detail

template <int Dim>
[[nodiscard]] DefaultSupportRadius default_support_radius(const Points<Dim>& points, const ResolvedBoundary<Dim>& boundary,
                                                          const RbfOptions& options) {
  return *detail::radius_and_blend(points, boundary, options, true).radius;
}

/// Refuses (InputError with the estimate and the limit) a given `radius` whose memory
/// estimate exceeds RbfOptions::max_memory_bytes (compact kernels, one system).
template <int Dim>
void check_support_radius_memory(const Points<Dim>& points, const ResolvedBoundary<Dim>& boundary, double radius,
                                 const RbfOptions& options) {
  if (!detail::memory_checked(options) || boundary.size() == 0) return;
  const double limit = detail::memory_limit(options);
  const Points<Dim> centres = detail::centres_in_node_order(points, boundary);
  const KdTree<Dim> tree(centres);
  const double bytes = detail::compact_rbf_bytes(static_cast<double>(points.cols()), centres, tree, detail::any_sliding(boundary),
                                                 radius, options, [&](const KdTree<Dim>& t, double r) { return detail::mean_centres_within(t, points, r); });
  if (bytes > limit)
    throw InputError("RbfMover::setup: support radius " + format_option_value(radius) + " needs about " +
                     detail::gigabytes(bytes) + " for the system and the evaluation operator, beyond the limit of " +
                     detail::gigabytes(limit) + " (max_memory_bytes; 0: half this machine's memory); give a smaller "
                     "support_radius, partition_of_unity, or a larger max_memory_bytes");
}

/// The RBF mover in Dim dimensions; models MeshMover.
template <int Dim>
class RbfMover : public detail::MoveFromMoveInto<RbfMover<Dim>, Dim> {
 public:
  static constexpr int dim = Dim;
  using Coefficients = Eigen::MatrixXd;

  explicit RbfMover(RbfOptions options = {}) : options_(effective_options(std::move(options))) {}

  [[nodiscard]] const RbfOptions& options() const noexcept { return options_; }
  /// The support radius of the last setup: RbfOptions::support_radius, or the default it
  /// proposed (the largest of support_radii when they are given).
  [[nodiscard]] double support_radius() const noexcept { return radius_; }
  [[nodiscard]] const MoverStats& stats() const noexcept { return stats_; }
  /// True when the last setup stored a dense evaluation matrix: a global kernel, or a compact
  /// one whose support covers most centres (see RbfOptions::max_evaluation_cache_bytes).
  [[nodiscard]] bool evaluation_cached() const noexcept { return dense_operator_.size() > 0; }
  /// True when the last setup reduced the default support radius to fit its memory budget
  /// (RbfOptions::max_memory_bytes).
  [[nodiscard]] bool support_radius_reduced() const noexcept { return radius_reduced_; }
  /// True when the last setup took the rigid part of the boundary's motion out
  /// (RbfOptions::rigid_part); moves then add its blend, rigid_part_displacement().
  [[nodiscard]] bool rigid_part_taken_out() const noexcept { return rigid_.size() > 0 || at_move_.active(); }
  /// The rigid part's displacement of every node (Dim × n_nodes): setup's, or for a mover set
  /// up at rest the last move's (RigidPartAtMove); empty when none was taken out or moved yet.
  [[nodiscard]] const Points<Dim>& rigid_part_displacement() const noexcept { return rigid_; }
  /// Patches of the partition of unity after setup (0: one global system).
  [[nodiscard]] Index patches() const noexcept { return patched_all_ ? patched_all_->num_patches() : 0; }
  /// Centres of the coarse level of a two-level interpolation (RbfOptions::levels; 0: one
  /// level), as the last move or derivative built it.
  [[nodiscard]] Index coarse_centres() const noexcept { return two_all_ ? two_all_->num_coarse() : 0; }

  /// Reference-configuration work (see the file comment). `mesh`: any MeshLike of dimension
  /// Dim; `boundary`: nodes and kinds (its displacements are not used here).
  /// Throws InputError for a non-positive radius (naming the boundary entry when per-entry
  /// radii are given) or a radius list not matching the boundary, out-of-range or non-finite boundary data,
  /// a global kernel beyond max_dense_centres; SolverError when the factorization fails.
  template <MeshLike M>
    requires(mesh_dim<M> == Dim)
  void setup(const M& mesh, const ResolvedBoundary<Dim>& boundary) {
    setup_reference(copy_points(mesh), boundary);
    if (options_.repair) repair_.prepare(mesh, boundary);
  }
  /// setup() from the reference coordinates alone (Dim × n_nodes): all the RBF needs of a mesh,
  /// but the cells the repair of folded cells needs (RbfOptions::repair: not done).
  void setup_reference(Points<Dim> points, const ResolvedBoundary<Dim>& boundary);

  /// Displacement of every node (Dim × n_nodes) for boundary displacements `d`
  /// (Dim × boundary.size(), boundary.nodes order; sliding entries ignored). Boundary nodes
  /// get their targets exactly (sliding ones their projected displacement). Throws
  /// InputError for a wrong shape, a non-finite value, or coincident nodes given different
  /// displacements (naming them); SolverError when an iterative solve fails.
  /// move() (inherited) returns the same; move_into writes into `out`, resized only when its
  /// shape differs.
  void move_into(PointsView<Dim> d, Points<Dim>& out);
  /// move_into() straight into the caller's own Dim × n_nodes storage (an Eigen::Map over a
  /// solver's or numpy's array), with no intermediate copy. Throws InputError when its shape
  /// is not Dim × n_nodes.
  void move_into(PointsView<Dim> d, Eigen::Ref<Points<Dim>> out);

  /// Forward derivative J w: the displacement change of every node (Dim × n_nodes) for a
  /// boundary displacement change w (Dim × boundary.size()). The mover is linear in the
  /// displacements, so this is move(w); coincident nodes must agree in w too.
  [[nodiscard]] Points<Dim> derivative_forward(PointsView<Dim> w);

  /// Reverse derivative Jᵀ v: for v (Dim × n_nodes), the gradient with respect to the
  /// boundary displacements (Dim × boundary.size()) of ⟨v, move(d)⟩. Sliding nodes' entries are
  /// zero (their input is ignored); a merged centre's gradient goes to its first constrained
  /// node. Throws InputError for a wrong shape or a non-finite value.
  [[nodiscard]] Points<Dim> derivative_reverse(PointsView<Dim> v);

 private:
  using Operator = detail::KernelRows;
  using Poly = typename detail::RbfSystem<Dim>::PolyCoefficients;

  [[nodiscard]] const Points<Dim>& all_centres() const { return all_.centres(); }

  // setup_reference()'s stages, in order.
  /// Refuses options the boundary cannot take; radius_ from support_radius.
  void check_options(const ResolvedBoundary<Dim>& boundary);
  /// Merges coincident boundary nodes into centres, constrained ones first and sliding ones
  /// after (centre_of_, source_, n_constrained_, projectors_); returns the centres.
  [[nodiscard]] Points<Dim> merge_centres(const ResolvedBoundary<Dim>& boundary);
  /// Factorizes the systems over every centre and over the constrained ones.
  void factorize(const Points<Dim>& centres, const detail::RbfKernelSettings& kernel);
  /// The operator evaluating the interpolant at the non-boundary nodes.
  void build_evaluation();
  /// factorize() and build_evaluation() of the pending centres, once after each setup.
  void build_interpolation();
  /// Merges boundary_'s centres and makes their interpolation with `radius` pending.
  void prepare_interpolation(double radius);
  /// Sets the interpolation up again for `d` when it outgrew the default radius (the file
  /// comment); the rigid part, when setup took one out, stays.
  void follow_motion(PointsView<Dim> d);

  /// f(the system over every centre), global, patched or two-level; likewise over the
  /// constrained ones.
  template <class F>
  decltype(auto) with_all(F&& f) {
    return patched_all_ ? f(*patched_all_) : two_all_ ? f(*two_all_) : f(all_);
  }
  template <class F>
  decltype(auto) with_constrained(F&& f) {
    return patched_constrained_ ? f(*patched_constrained_) : two_constrained_ ? f(*two_constrained_) : f(constrained_);
  }
  /// Whether the interpolation at `kernel` over `centres` takes two levels
  /// (RbfOptions::levels); fine_radius_ is then the fine level's, chosen at the first.
  [[nodiscard]] bool two_levels(const Points<Dim>& centres, const detail::RbfKernelSettings& kernel) {
    if (!two_level_interpolation(options_, default_radius_, boundary_.size()) || centres.cols() < 2) return false;
    if (fine_radius_ == 0.0)
      fine_radius_ = std::min(kernel.radius, suggest_support_radius(centres, 0.0, SupportRadiusOptions{0.0, options_.fine_spacings}));
    return true;
  }

  void require_ready(const char* where) const {
    if (!ready_) throw InputError(std::string("RbfMover::") + where + ": setup() was not called");
  }

  /// Operator rows (kernel weights) of centres `rows` of `at` against the system's centres.
  [[nodiscard]] static Operator build_operator(const Points<Dim>& at, const std::vector<Index>& rows,
                                               const detail::RbfSystem<Dim>& system) {
    if (is_compact(system.kernel().kernel))
      return detail::compact_kernel_rows(at, rows, system.within(), system.size(), system.kernel());
    Eigen::MatrixXd dense(static_cast<Index>(rows.size()), system.size());
    for (Index r = 0; r < dense.rows(); ++r)
      dense.row(r) = kernel_row(system, at.col(rows[static_cast<std::size_t>(r)]));
    return dense.sparseView();
  }

  /// Σ_r q(x_r) s_rᵀ: transpose of the polynomial evaluation at the listed points.
  [[nodiscard]] Poly polynomial_transpose(const detail::RbfSystem<Dim>& system, const std::vector<Index>& rows,
                                          const Points<Dim>& at, const Eigen::MatrixXd& s) const {
    Poly out = Poly::Zero();
    if (!options_.polynomial) return out;
    for (std::size_t r = 0; r < rows.size(); ++r) out += system.polynomial(at.col(rows[r])) * s.row(static_cast<Index>(r));
    return out;
  }

  /// Projects row r of s (sliding centre n_constrained_ + r) on its plane or line; the
  /// projectors are symmetric, so this is also its own transpose.
  void project_rows(Eigen::MatrixXd& s) const {
    for (Index r = 0; r < s.rows(); ++r) s.row(r) = (projectors_[static_cast<std::size_t>(r)] * s.row(r).transpose()).transpose();
  }

  /// φ(|x − c_j|) for every centre c_j of `system` (a row).
  [[nodiscard]] static Eigen::RowVectorXd kernel_row(const detail::RbfSystem<Dim>& system, const Vec<Dim>& x) {
    const Points<Dim>& centres = system.centres();
    Eigen::RowVectorXd row(centres.cols());
    for (Index c = 0; c < centres.cols(); ++c)
      row(c) = rbf_value(system.kernel().kernel, (x - centres.col(c)).norm(), system.kernel().radius_of(c));
    return row;
  }
  [[nodiscard]] Eigen::RowVectorXd kernel_row(const Vec<Dim>& x) const { return kernel_row(all_, x); }

  /// Mean share of the centres whose support holds a sample of evaluated nodes (up to 64,
  /// evenly spread over interior_): a cheap estimate of the compact operator's density.
  [[nodiscard]] double covered_fraction() const {
    const auto n = static_cast<Index>(interior_.size());
    const Index samples = std::min<Index>(n, 64);
    std::vector<Neighbor> found;
    double covered = 0.0;
    for (Index s = 0; s < samples; ++s) {
      all_.centres_within(points_.col(interior_[static_cast<std::size_t>(s * n / samples)]), found);
      covered += static_cast<double>(found.size());
    }
    return samples == 0 ? 0.0 : covered / (static_cast<double>(samples) * static_cast<double>(all_.size()));
  }

  /// A move: apply() checked, timed and counted, with the solver's report in stats_; the
  /// rigid part, when setup took it out, interpolated no more and added whole.
  template <class Out>
  void timed_apply(PointsView<Dim> d, Out& out) {
    detail::timed_move<Dim>("RbfMover::move", ready_, d, boundary_.nodes, stats_, [&] {
      if (at_move_.active()) {
        at_move_.blend(points_, d, rigid_);
        rigid_scale_ = d.size() > 0 ? d.colwise().norm().maxCoeff() : 0.0;
      }
      solving_ = 0.0;
      follow_motion(d);
      if (rigid_.size() == 0) {
        apply(d, out);
      } else {
        Points<Dim> rest = d;
        double off = 0.0;
        for (std::size_t b = 0; b < boundary_.nodes.size(); ++b) {
          rest.col(static_cast<Index>(b)) -= rigid_.col(boundary_.nodes[b]);
          if (boundary_.kinds[b] != BoundaryKind::sliding) off = std::max(off, rest.col(static_cast<Index>(b)).norm());
        }
        // What the rigid fit leaves of its own motion is round-off: nothing to interpolate.
        if (off > rigid_fit_round_off * rigid_scale_) {
          if (pending_) detail::add_time(stats_.rebuild_seconds, [&] { build_interpolation(); });
          apply(rest, out);
          out += rigid_;
        } else {
          shape_output(out);
          out = rigid_;
        }
        for (std::size_t b = 0; b < boundary_.nodes.size(); ++b)
          if (boundary_.kinds[b] != BoundaryKind::sliding) out.col(boundary_.nodes[b]) = d.col(static_cast<Index>(b));
      }
      const RepairReport repaired = repair_.repair(out);
      stats_.folded_cells = repaired.folded;
      stats_.repaired_nodes = repaired.moved_nodes;
      stats_.left_folded = repaired.left_folded;
      const SolverReport& r = with_all([](auto& system) -> const SolverReport& { return system.report(); });
      stats_.iterations = r.iterations;
      stats_.residual = r.residual;
      stats_.fell_back = r.fell_back;
      stats_.solve_seconds = solving_;
    });
  }

  /// The linear map boundary displacements → node displacements, into a Points<Dim> (resized)
  /// or an Eigen::Ref of the right shape.
  template <class Out>
  void apply(PointsView<Dim> d, Out& out) {
    const Index k = n_centres_;
    const auto m = static_cast<Index>(boundary_.nodes.size());
    values_.resize(k, Dim);
    for (Index c = 0; c < n_constrained_; ++c) values_.row(c) = d.col(source_[static_cast<std::size_t>(c)]).transpose();
    for (Index b = 0; b < m; ++b) {
      const Index c = centre_of_[static_cast<std::size_t>(b)];
      if (boundary_.kinds[static_cast<std::size_t>(b)] == BoundaryKind::sliding || c >= n_constrained_) continue;
      const Index first = source_[static_cast<std::size_t>(c)];
      const double scale = std::max({1.0, d.col(b).norm(), d.col(first).norm()});
      if ((d.col(b) - d.col(first)).norm() > 1e-12 * scale) {
        // Coincident within coincidence_tolerance × the boundary's diagonal, which one node far
        // from the others (a coordinate of 2^31) stretches: the figures say which it was.
        const Index u = boundary_.nodes[static_cast<std::size_t>(first)], v = boundary_.nodes[static_cast<std::size_t>(b)];
        throw InputError("RbfMover::move: boundary nodes " + std::to_string(u) + " and " + std::to_string(v) +
                         " coincide but get different displacements (they are " +
                         format_option_value((points_.col(u) - points_.col(v)).norm()) + " apart, within coincidence_tolerance " +
                         format_option_value(options_.coincidence_tolerance) + " x the boundary's diagonal " +
                         format_option_value(boundary_diagonal_) + ")");
      }
    }
    const detail::Stopwatch solving;
    if (k > n_constrained_) {
      with_constrained([&](auto& system) { system.solve(values_.topRows(n_constrained_), alpha_, beta_); });
      Eigen::MatrixXd s = sliding_operator_ * alpha_;
      if (options_.polynomial)
        for (Index r = 0; r < s.rows(); ++r)
          s.row(r) += constrained_.polynomial(all_centres().col(sliding_rows_[static_cast<std::size_t>(r)])).transpose() * beta_;
      project_rows(s);
      values_.bottomRows(k - n_constrained_) = s;
    }
    with_all([&](auto& system) { system.solve(values_, alpha_, beta_); });
    solving_ += solving.seconds();
    shape_output(out);
    out.setZero();
    evaluate_interior(out);
    for (Index b = 0; b < m; ++b) {
      const Index node = boundary_.nodes[static_cast<std::size_t>(b)];
      out.col(node) = boundary_.kinds[static_cast<std::size_t>(b)] == BoundaryKind::sliding
                          ? Vec<Dim>(values_.row(centre_of_[static_cast<std::size_t>(b)]).transpose())
                          : Vec<Dim>(d.col(b));
    }
  }

  /// Resizes a Points<Dim> `out` to Dim × n_nodes; refuses any other output of another shape.
  template <class Out>
  void shape_output(Out& out) const {
    const Index n = points_.cols();
    if (!std::same_as<Out, Points<Dim>> && out.cols() != n)
      throw InputError("RbfMover::move_into: the output has " + std::to_string(out.cols()) + " columns (expected " +
                       std::to_string(n) + ", one per node)");
    detail::size_output<Dim>(out, n);
  }

  template <class Out>
  void evaluate_interior(Out& out) {
    const auto n_eval = static_cast<Index>(evaluated_.size());
    if (evaluation_cached()) {
      evaluated_values_.noalias() = dense_operator_ * alpha_;
#pragma omp parallel for num_threads(::meshmotion::num_threads()) schedule(static)
      for (Index r = 0; r < n_eval; ++r) out.col(evaluated_[static_cast<std::size_t>(r)]) = evaluated_values_.row(r).transpose();
    } else if (is_compact(options_.kernel)) {
      detail::kernel_rows_times<Dim>(operator_, alpha_, centre_buffer_,
                                     [&](Index r, const Vec<Dim>& value) { out.col(evaluated_[static_cast<std::size_t>(r)]) = value; });
    } else {
      detail::RegionErrors errors;
#pragma omp parallel for num_threads(::meshmotion::num_threads()) schedule(static)
      for (Index r = 0; r < n_eval; ++r)
        errors.run([&] {
          const Index node = evaluated_[static_cast<std::size_t>(r)];
          out.col(node) = (kernel_row(points_.col(node)) * alpha_).transpose();
        });
      errors.rethrow();
    }
    if (!options_.polynomial) return;
    const auto n_interior = static_cast<Index>(interior_.size());
#pragma omp parallel for num_threads(::meshmotion::num_threads()) schedule(static)
    for (Index r = 0; r < n_interior; ++r) {
      const Index node = interior_[static_cast<std::size_t>(r)];
      out.col(node) += beta_.transpose() * all_.polynomial(points_.col(node));
    }
  }

  /// Transpose of evaluate_interior: ᾱ = Eᵀ v_eval, β̄ = Σ q(x_i) v_iᵀ over interior nodes.
  /// Where the seed's rows are gathered, it is into a buffer kept across calls (a reverse
  /// product per optimization iteration should not pay fresh pages for a volume-sized array).
  void interior_transpose(const PointsView<Dim>& v, Eigen::MatrixXd& alpha_bar, Poly& beta_bar) {
    const Index k = n_centres_;
    const auto gather = [&](const std::vector<Index>& nodes) {
      seed_rows_.resize(static_cast<Index>(nodes.size()), Dim);
      for (std::size_t r = 0; r < nodes.size(); ++r) seed_rows_.row(static_cast<Index>(r)) = v.col(nodes[r]).transpose();
    };
    if (evaluation_cached()) {
      gather(evaluated_);
      alpha_bar.noalias() = dense_operator_.transpose() * seed_rows_;
    } else if (is_compact(options_.kernel)) {
      detail::kernel_rows_transpose_times<Dim>(
          operator_, [&](Index r) -> Vec<Dim> { return v.col(evaluated_[static_cast<std::size_t>(r)]); }, centre_buffer_, alpha_bar);
    } else {
      gather(evaluated_);
      alpha_bar.setZero(k, Dim);
      for (std::size_t r = 0; r < evaluated_.size(); ++r)
        alpha_bar += kernel_row(points_.col(evaluated_[r])).transpose() * seed_rows_.row(static_cast<Index>(r));
    }
    beta_bar = Poly::Zero();
    if (!options_.polynomial) return;
    gather(interior_);
    beta_bar = polynomial_transpose(all_, interior_, points_, seed_rows_);
  }

  RbfOptions options_;
  MoverStats stats_;
  bool ready_ = false;
  Points<Dim> points_;                      ///< reference coordinates, Dim × n
  Index n_centres_ = 0;                     ///< boundary centres (merged coincident nodes)
  double boundary_diagonal_ = 0.0;          ///< of the boundary's bounding box: the coincidence tolerance's scale
  ResolvedBoundary<Dim> boundary_;          ///< as given to setup (its nodes and kinds; a set up again starts from it)
  bool grows_ = false;                      ///< the default radius follows the motion (follow_motion())
  double solving_ = 0.0;                    ///< apply()'s solves since timed_apply() began (the move's solve_seconds)
  std::vector<Index> centre_of_;            ///< boundary entry → centre
  std::vector<Index> source_;               ///< centre → boundary entry giving its value
  Index n_constrained_ = 0;                 ///< centres 0..n_constrained_-1 are prescribed/fixed
  using Projector = Eigen::Matrix<double, Dim, Dim>;
  std::vector<Projector> projectors_;       ///< onto the plane or line of each sliding centre
  detail::RbfSystem<Dim> all_;              ///< over every centre
  detail::RbfSystem<Dim> constrained_;      ///< over constrained centres (sliding boundaries only)
  /// Partition of unity: replace all_ and constrained_ (the coefficients are then the patches')
  std::unique_ptr<detail::PartitionOfUnityRbf<Dim>> patched_all_, patched_constrained_;
  /// Two levels: replace all_ and constrained_ (coefficients: the coarse level's, then every
  /// centre's); their fine levels stay through a set up again for a grown radius.
  std::unique_ptr<detail::TwoLevelRbf<Dim>> two_all_, two_constrained_;
  double fine_radius_ = 0.0;  ///< the fine level's radius (0: not yet chosen)
  bool default_radius_ = false;  ///< no radius given: the last setup took the default
  std::vector<Index> sliding_rows_;         ///< sliding centres
  Operator sliding_operator_;               ///< sliding centres × constrained centres
  std::vector<Index> interior_;             ///< non-boundary nodes
  std::vector<Index> evaluated_;            ///< interior nodes with kernel weights
  Operator operator_;                       ///< evaluated_ × centres (compact kernels)
  Eigen::MatrixXd dense_operator_;          ///< evaluated_ × centres, when cached
  Eigen::MatrixXd values_, alpha_, evaluated_values_;
  Eigen::MatrixXd seed_rows_;               ///< a reverse product's seed, gathered by rows
  Points<Dim> centre_buffer_;               ///< Dim × centres: the coefficients of a move, the sums of a reverse product
  Poly beta_ = Poly::Zero();
  double radius_ = 0.0;  ///< the last setup's support radius
  bool radius_reduced_ = false;  ///< the default radius_ was reduced to fit the memory budget
  Points<Dim> rigid_;            ///< the rigid part's blend (Dim × n), empty when not taken out
  double rigid_scale_ = 0.0;     ///< the largest displacement of the motion it was fitted to
  /// Set up at rest: the rigid part found at every move (rigid_ then holds the last move's).
  RigidPartAtMove<Dim> at_move_;
  LinearRepair<Dim> repair_;  ///< the cells setup() was given, when all linear (RbfOptions::repair)
  /// With the rigid part out, the interpolation is factorized at the first move or derivative
  /// that needs it (a move by the setup's own rigid motion does not): its centres and kernel.
  Points<Dim> pending_centres_;
  detail::RbfKernelSettings pending_kernel_;
  bool pending_ = false;
};

template <int Dim>
void RbfMover<Dim>::setup_reference(Points<Dim> points, const ResolvedBoundary<Dim>& boundary) {
  const detail::Stopwatch watch;
  check_options(boundary);
  repair_ = {};
  radius_reduced_ = false;
  rigid_.resize(Dim, 0);
  at_move_ = {};
  two_all_.reset();
  two_constrained_.reset();
  fine_radius_ = 0.0;
  if (!points.allFinite()) throw InputError("RbfMover::setup: mesh has a non-finite coordinate");
  detail::check_boundary<Dim>("RbfMover::setup", boundary, points.cols(), false);
  // Set up before anything moves (a solver's time loop): the rigid part is each move's.
  RbfOptions decided = options_;
  if (options_.rigid_part != RigidPart::none && at_rest(boundary)) {
    if (const auto why = at_move_.prepare(points, boundary); why && options_.rigid_part == RigidPart::blend)
      throw InputError("rigid_part=blend: " + *why);
    decided.rigid_part = RigidPart::none;
  }
  auto [fitted, blend] = detail::radius_and_blend(points, boundary, decided, options_.support_radii.empty() && radius_ == 0.0);
  if (fitted) {
    radius_ = fitted->radius;
    radius_reduced_ = fitted->reduced;
  } else if (options_.support_radii.empty()) {
    check_support_radius_memory(points, boundary, radius_, options_);
  }
  grows_ = fitted && !fitted->reduced;
  default_radius_ = fitted.has_value();
  points_ = std::move(points);
  boundary_ = boundary;
  stats_ = MoverStats{};
  prepare_interpolation(radius_);
  stats_.rigid_part = blend || at_move_.active();
  if (blend) {
    rigid_ = std::move(blend->displacement);
    rigid_scale_ = boundary.displacements.colwise().norm().maxCoeff();
  }
  // With the rigid part out, the interpolation waits for the first move (or derivative) that
  // leaves it something to carry: a rigid body never needs it, and at rest the default radius
  // is provisional (the first motion it cannot carry grows it; one the memory budget cut,
  // a sphere's nearly dense operator in a large box, would cost seconds for nothing).
  if (blend || (at_move_.active() && fitted))
    stats_.evaluated_nodes = points_.cols() - static_cast<Index>(boundary_.nodes.size());
  else
    build_interpolation();
  ready_ = true;
  stats_.setup_seconds = watch.seconds();
}

template <int Dim>
void RbfMover<Dim>::prepare_interpolation(double radius) {
  radius_ = radius;
  pending_centres_ = merge_centres(boundary_);
  pending_kernel_ = detail::RbfKernelSettings{options_.kernel, radius_, options_.polynomial};
  if (!options_.support_radii.empty()) {
    auto& radii = pending_kernel_.radii;
    radii.resize(static_cast<std::size_t>(n_centres_));
    for (Index c = 0; c < n_centres_; ++c)
      radii[static_cast<std::size_t>(c)] = options_.support_radii[static_cast<std::size_t>(source_[static_cast<std::size_t>(c)])];
    radius_ = pending_kernel_.radius = n_centres_ > 0 ? *std::max_element(radii.begin(), radii.end()) : radius_;
  }
  stats_.boundary_nodes = n_centres_;
  stats_.support_radius = radius_;
  stats_.radius_reduced = radius_reduced_;
  pending_ = true;
}

template <int Dim>
void RbfMover<Dim>::follow_motion(PointsView<Dim> d) {
  if (!grows_) return;
  // What the interpolation carries: the motion less the rigid part setup took out.
  const auto carried = [&](std::size_t b) {
    Vec<Dim> out = d.col(static_cast<Index>(b));
    if (rigid_.size() > 0) out -= rigid_.col(boundary_.nodes[b]);
    return out;
  };
  double largest = 0.0;
  for (std::size_t b = 0; b < boundary_.nodes.size(); ++b)
    if (boundary_.kinds[b] == BoundaryKind::prescribed) largest = std::max(largest, carried(b).norm());
  if (!radius_outgrown(largest, radius_)) return;
  ResolvedBoundary<Dim> grown = boundary_;
  grown.displacements.setZero(Dim, grown.size());
  for (std::size_t b = 0; b < boundary_.nodes.size(); ++b)
    if (boundary_.kinds[b] == BoundaryKind::prescribed) grown.displacements.col(static_cast<Index>(b)) = radius_growth_margin * carried(b);
  const DefaultSupportRadius fitted = detail::budgeted_support_radius(points_, grown, options_);
  if (!(fitted.radius > radius_)) {
    grows_ = false;  // the memory budget holds the radius where it is
    return;
  }
  const detail::Stopwatch watch;
  radius_reduced_ = fitted.reduced;
  grows_ = !fitted.reduced;
  prepare_interpolation(fitted.radius);
  ++stats_.radius_growths;
  if (rigid_.size() == 0) build_interpolation();
  stats_.setup_seconds += watch.seconds();
  stats_.rebuild_seconds += watch.seconds();
}

template <int Dim>
void RbfMover<Dim>::build_interpolation() {
  if (!pending_) return;
  pending_ = false;
  factorize(pending_centres_, pending_kernel_);
  build_evaluation();
  pending_centres_.resize(Dim, 0);
  stats_.factorizations = with_all([](auto& system) { return system.report().factorizations; }) +
                          (n_centres_ > n_constrained_ ? with_constrained([](auto& system) { return system.report().factorizations; }) : 0);
  stats_.condition = std::max(with_all([](auto& system) { return system.condition(); }),
                              n_centres_ > n_constrained_ ? with_constrained([](auto& system) { return system.condition(); }) : 0.0);
  if (two_all_)
    stats_.thinned_centres = two_all_->thinned() + (two_constrained_ ? two_constrained_->thinned() : 0);
  else if (!patched_all_)
    stats_.thinned_centres = all_.thinned() + (n_centres_ > n_constrained_ ? constrained_.thinned() : 0);
  stats_.coarse_centres = coarse_centres();
}

template <int Dim>
void RbfMover<Dim>::check_options(const ResolvedBoundary<Dim>& boundary) {
  if (!(options_.support_radius >= 0.0) || !std::isfinite(options_.support_radius))
    throw InputError("RbfMover::setup: support radius must be positive, or 0 for the default (got " +
                     std::to_string(options_.support_radius) + ")");
  radius_ = options_.support_radius;
  (void)detail::memory_limit(options_);  // refuses a negative max_memory_bytes whatever the kernel
  if (!options_.support_radii.empty()) {
    if (static_cast<Index>(options_.support_radii.size()) != boundary.size())
      throw InputError("RbfMover::setup: " + std::to_string(options_.support_radii.size()) +
                       " support radii for a boundary of " + std::to_string(boundary.size()) +
                       " entries (expected one per entry, or none)");
    for (std::size_t b = 0; b < options_.support_radii.size(); ++b)
      if (!(options_.support_radii[b] > 0.0) || !std::isfinite(options_.support_radii[b]))
        throw InputError("RbfMover::setup: support radius of boundary entry " + std::to_string(b) + " (node " +
                         std::to_string(boundary.nodes[b]) + ") must be positive (got " +
                         std::to_string(options_.support_radii[b]) + ")");
  }
  if (options_.levels == RbfLevels::two) {
    const char* why = !is_compact(options_.kernel)      ? "a global kernel"
                      : !options_.support_radii.empty() ? "support_radii"
                      : options_.polynomial             ? "polynomial"
                      : options_.partition_of_unity     ? "partition_of_unity"
                                                        : nullptr;
    if (why != nullptr)
      throw InputError(std::string("RbfMover::setup: levels=two needs a compact kernel with one radius, no polynomial and no "
                                   "partition of unity (got ") + why + ")");
  }
  if (!options_.partition_of_unity) return;
  const auto refuse = [](const std::string& why) { throw InputError("RbfMover::setup: partition_of_unity " + why); };
  if (!is_compact(options_.kernel))
    refuse("needs a compact kernel such as wendland2 (got " + std::string(name(options_.kernel)) + ")");
  if (!options_.support_radii.empty()) refuse("needs one support_radius (got support_radii)");
  if (options_.polynomial) refuse("does not take a polynomial (nodes beyond every patch would lose its affine part)");
  if (options_.patch_centres < 1) refuse("needs patch_centres >= 1 (got " + std::to_string(options_.patch_centres) + ")");
  if (!(options_.patch_overlap >= 0.0) || !std::isfinite(options_.patch_overlap))
    refuse("needs a finite patch_overlap >= 0 (got " + std::to_string(options_.patch_overlap) + ")");
}

template <int Dim>
Points<Dim> RbfMover<Dim>::merge_centres(const ResolvedBoundary<Dim>& boundary) {
  const Index m = boundary.size();
  Points<Dim> positions(Dim, m);
  for (Index b = 0; b < m; ++b) positions.col(b) = points_.col(boundary_.nodes[static_cast<std::size_t>(b)]);
  boundary_diagonal_ = m > 0 ? (positions.rowwise().maxCoeff() - positions.rowwise().minCoeff()).norm() : 0.0;
  const auto rep = detail::coincident_representatives(positions, options_.coincidence_tolerance * boundary_diagonal_);
  std::vector<bool> constrained(static_cast<std::size_t>(m), false);
  for (Index b = 0; b < m; ++b)
    if (boundary_.kinds[static_cast<std::size_t>(b)] != BoundaryKind::sliding) constrained[static_cast<std::size_t>(rep[static_cast<std::size_t>(b)])] = true;
  centre_of_.assign(static_cast<std::size_t>(m), -1);
  source_.clear();
  std::vector<Index> sliding_reps;
  for (Index b = 0; b < m; ++b) {
    if (rep[static_cast<std::size_t>(b)] != b) continue;
    if (constrained[static_cast<std::size_t>(b)]) {
      centre_of_[static_cast<std::size_t>(b)] = static_cast<Index>(source_.size());
      source_.push_back(-1);
    } else {
      sliding_reps.push_back(b);
    }
  }
  n_constrained_ = static_cast<Index>(source_.size());
  for (const Index b : sliding_reps) {
    centre_of_[static_cast<std::size_t>(b)] = static_cast<Index>(source_.size());
    source_.push_back(b);
  }
  for (Index b = 0; b < m; ++b) centre_of_[static_cast<std::size_t>(b)] = centre_of_[static_cast<std::size_t>(rep[static_cast<std::size_t>(b)])];
  // A constrained centre takes its value from its first constrained member node.
  for (Index b = m - 1; b >= 0; --b)
    if (boundary_.kinds[static_cast<std::size_t>(b)] != BoundaryKind::sliding && centre_of_[static_cast<std::size_t>(b)] < n_constrained_)
      source_[static_cast<std::size_t>(centre_of_[static_cast<std::size_t>(b)])] = b;
  n_centres_ = static_cast<Index>(source_.size());
  Points<Dim> centres(Dim, n_centres_);
  projectors_.clear();
  for (Index c = 0; c < n_centres_; ++c) {
    const Index b = source_[static_cast<std::size_t>(c)];
    centres.col(c) = positions.col(b);
    if (c < n_constrained_) continue;
    Projector p;
    for (int a = 0; a < Dim; ++a) p.col(a) = boundary.project(b, Vec<Dim>::Unit(a));
    projectors_.push_back(p);
  }
  return centres;
}

template <int Dim>
void RbfMover<Dim>::factorize(const Points<Dim>& centres, const detail::RbfKernelSettings& kernel) {
  const Index k = n_centres_;
  patched_all_.reset();
  patched_constrained_.reset();
  const auto patched = [&](const Points<Dim>& at, const detail::RbfKernelSettings& settings) {
    auto system = std::make_unique<detail::PartitionOfUnityRbf<Dim>>();
    system->setup(at, settings, options_.patch_centres, options_.patch_overlap, options_.solver);
    return system;
  };
  const bool two = two_levels(centres, kernel);
  // The fine level is the same system through every set up again for a grown radius.
  const auto leveled = [&](std::unique_ptr<detail::TwoLevelRbf<Dim>>& system, const Points<Dim>& at) {
    if (!system) {
      system = std::make_unique<detail::TwoLevelRbf<Dim>>();
      system->setup_fine(at, detail::RbfKernelSettings{kernel.kernel, fine_radius_, false}, options_.coarse_centres, options_.solver,
                         options_.condition_limit);
    }
    system->set_coarse(kernel, options_.solver, options_.condition_limit);
  };
  if (options_.partition_of_unity) {
    all_ = detail::RbfSystem<Dim>{};
    patched_all_ = patched(centres, kernel);
  } else if (two) {
    leveled(two_all_, centres);
  } else {
    all_.setup(centres, kernel, options_.solver, options_.dense_solver, options_.max_dense_centres, options_.condition_limit);
  }
  stats_.nonzeros = with_all([](auto& system) { return system.nonzeros(); });
  if (k == n_constrained_) return;
  const Points<Dim> constrained_centres = centres.leftCols(n_constrained_);
  sliding_rows_.resize(static_cast<std::size_t>(k - n_constrained_));
  for (Index c = n_constrained_; c < k; ++c) sliding_rows_[static_cast<std::size_t>(c - n_constrained_)] = c;
  if (options_.partition_of_unity) {
    patched_constrained_ = patched(constrained_centres, kernel.leading(n_constrained_));
    sliding_operator_ = patched_constrained_->evaluation_rows(centres, sliding_rows_);
  } else if (two) {
    leveled(two_constrained_, constrained_centres);
    sliding_operator_ = two_constrained_->evaluation_rows(centres, sliding_rows_);
  } else {
    constrained_.setup(constrained_centres, kernel.leading(n_constrained_), options_.solver, options_.dense_solver,
                       options_.max_dense_centres, options_.condition_limit);
    sliding_operator_ = build_operator(centres, sliding_rows_, constrained_);
  }
  stats_.nonzeros += with_constrained([](auto& system) { return system.nonzeros(); }) + sliding_operator_.nonZeros();
}

template <int Dim>
void RbfMover<Dim>::build_evaluation() {
  // Nodes evaluated: every non-boundary node inside some support (all of them for global
  // kernels); the polynomial part reaches every non-boundary node.
  const Index n = points_.cols(), k = n_centres_;
  std::vector<bool> is_boundary(static_cast<std::size_t>(n), false);
  for (const Index v : boundary_.nodes) is_boundary[static_cast<std::size_t>(v)] = true;
  interior_.clear();
  for (Index i = 0; i < n; ++i)
    if (!is_boundary[static_cast<std::size_t>(i)]) interior_.push_back(i);
  evaluated_.clear();
  // A set up again for a grown radius builds the next operator: the last one goes first.
  operator_ = Operator{};
  dense_operator_.resize(0, 0);
  const bool fits = !interior_.empty() && static_cast<double>(interior_.size()) * static_cast<double>(k) * sizeof(double) <=
                                              static_cast<double>(options_.max_evaluation_cache_bytes);
  // A compact support that reaches most centres from most nodes (a radius far larger than the
  // moving body, as rotations want) makes the sparse operator a full one stored with indices:
  // building it dense is several times cheaper and so is every move.
  const bool dense = !patched_all_ && !two_all_ && fits && (!is_compact(options_.kernel) || covered_fraction() > 0.5);
  const auto keep_rows = [&](Operator rows, const std::vector<Index>& kept) {
    operator_ = std::move(rows);
    evaluated_.reserve(kept.size());
    for (const Index r : kept) evaluated_.push_back(interior_[static_cast<std::size_t>(r)]);
    stats_.nonzeros += operator_.nonZeros();
  };
  std::vector<Index> kept;
  if (patched_all_) {
    keep_rows(patched_all_->evaluation_rows(points_, interior_, &kept), kept);
  } else if (two_all_) {
    keep_rows(two_all_->evaluation_rows(points_, interior_, &kept), kept);
  } else if (is_compact(options_.kernel) && !dense) {
    // Only rows with weights are kept, so skipped nodes cost nothing per move.
    // The system's radii, which thinning may have changed from the ones asked for.
    keep_rows(detail::compact_kernel_rows(points_, interior_, all_.within(), k, all_.kernel(), &kept), kept);
  } else {
    evaluated_ = interior_;
    operator_.resize(0, 0);
    if (dense) {
      dense_operator_.resize(static_cast<Index>(evaluated_.size()), k);
      const auto n_eval = static_cast<Index>(evaluated_.size());
      detail::RegionErrors errors;
#pragma omp parallel for num_threads(::meshmotion::num_threads()) schedule(static)
      for (Index r = 0; r < n_eval; ++r)
        errors.run([&] { dense_operator_.row(r) = kernel_row(points_.col(evaluated_[static_cast<std::size_t>(r)])); });
      errors.rethrow();
      stats_.nonzeros += dense_operator_.size();
    }
  }
  stats_.evaluated_nodes = options_.polynomial ? static_cast<Index>(interior_.size()) : static_cast<Index>(evaluated_.size());
}

template <int Dim>
void RbfMover<Dim>::move_into(PointsView<Dim> d, Points<Dim>& out) {
  timed_apply(d, out);
}

template <int Dim>
void RbfMover<Dim>::move_into(PointsView<Dim> d, Eigen::Ref<Points<Dim>> out) {
  timed_apply(d, out);
}

template <int Dim>
Points<Dim> RbfMover<Dim>::derivative_forward(PointsView<Dim> w) {
  require_ready("derivative_forward");
  detail::check_displacements<Dim>("RbfMover::derivative_forward", w, boundary_.nodes);
  build_interpolation();
  Points<Dim> out;
  if (!at_move_.active()) {
    apply(w, out);
    return out;
  }
  // move(d) = B(d) + apply(d − B_b(d)): the blend's change, and the interpolation of the rest.
  Points<Dim> blended;
  at_move_.derivative_forward(points_, w, blended);
  Points<Dim> rest = w;
  for (std::size_t b = 0; b < boundary_.nodes.size(); ++b)
    if (boundary_.kinds[b] != BoundaryKind::sliding) rest.col(static_cast<Index>(b)) -= blended.col(boundary_.nodes[b]);
  apply(rest, out);
  out += blended;
  return out;
}

template <int Dim>
Points<Dim> RbfMover<Dim>::derivative_reverse(PointsView<Dim> v) {
  require_ready("derivative_reverse");
  detail::check_node_field<Dim>("RbfMover::derivative_reverse", v, points_.cols());
  build_interpolation();
  const Index m = static_cast<Index>(boundary_.nodes.size());
  const Index k = n_centres_;
  Points<Dim> grad = Points<Dim>::Zero(Dim, m);
  // Boundary nodes output their target directly.
  Eigen::MatrixXd values_bar = Eigen::MatrixXd::Zero(k, Dim);
  for (Index b = 0; b < m; ++b) {
    const Index node = boundary_.nodes[static_cast<std::size_t>(b)];
    if (boundary_.kinds[static_cast<std::size_t>(b)] != BoundaryKind::sliding)
      grad.col(b) += v.col(node);
    else
      values_bar.row(centre_of_[static_cast<std::size_t>(b)]) += v.col(node).transpose();
  }
  Eigen::MatrixXd alpha_bar;
  typename detail::RbfSystem<Dim>::PolyCoefficients beta_bar;
  interior_transpose(v, alpha_bar, beta_bar);
  Eigen::MatrixXd through_all;
  with_all([&](auto& system) { system.solve_transpose(alpha_bar, beta_bar, through_all); });
  values_bar += through_all;
  if (k > n_constrained_) {
    Eigen::MatrixXd s_bar = values_bar.bottomRows(k - n_constrained_);
    project_rows(s_bar);
    const Eigen::MatrixXd a_bar = sliding_operator_.transpose() * s_bar;
    typename detail::RbfSystem<Dim>::PolyCoefficients b_bar = polynomial_transpose(constrained_, sliding_rows_, all_centres(), s_bar);
    Eigen::MatrixXd through_constrained;
    with_constrained([&](auto& system) { system.solve_transpose(a_bar, b_bar, through_constrained); });
    values_bar.topRows(n_constrained_) += through_constrained;
  }
  for (Index c = 0; c < n_constrained_; ++c) grad.col(source_[static_cast<std::size_t>(c)]) += values_bar.row(c).transpose();
  if (!at_move_.active()) return grad;
  // The transpose of derivative_forward's: the blend's change B′ meets v less what the
  // interpolation's transpose took at the boundary nodes (where it carried −B′_b).
  Points<Dim> through_blend = v;
  for (Index b = 0; b < m; ++b)
    if (boundary_.kinds[static_cast<std::size_t>(b)] != BoundaryKind::sliding) through_blend.col(boundary_.nodes[static_cast<std::size_t>(b)]) -= grad.col(b);
  at_move_.derivative_reverse(points_, through_blend, grad);
  return grad;
}

}  // namespace meshmotion

// The compiled library (target meshmotion::compiled, src/) holds these for Dim 2 and 3.
#ifdef MESHMOTION_COMPILED
namespace meshmotion {
extern template class RbfMover<2>;
extern template class RbfMover<3>;
// setup is a template over the mesh type: its Mesh<Dim> form, the one make_mover() uses, too.
extern template void RbfMover<2>::setup<Mesh<2>>(const Mesh<2>&, const ResolvedBoundary<2>&);
extern template void RbfMover<3>::setup<Mesh<3>>(const Mesh<3>&, const ResolvedBoundary<3>&);
extern template DefaultSupportRadius default_support_radius<2>(const Points<2>&, const ResolvedBoundary<2>&, const RbfOptions&);
extern template DefaultSupportRadius default_support_radius<3>(const Points<3>&, const ResolvedBoundary<3>&, const RbfOptions&);
}  // namespace meshmotion
#endif
