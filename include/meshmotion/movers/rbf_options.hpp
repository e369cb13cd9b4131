#pragma once
/// \file
/// RbfOptions: the options of RbfMover (movers/rbf.hpp), and RigidPart.
/// Light: the options and their one description (visit_options: key, field, doc), no mover.

#include "meshmotion/core/option_text.hpp"
#include "meshmotion/core/types.hpp"
#include "meshmotion/movers/rbf_kernels.hpp"
#include "meshmotion/solvers/solver_options.hpp"

#include <array>
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace meshmotion {

/// Whether an RBF mover takes the rigid part of the boundary's motion out first
/// (movers/rigid_part.hpp).
enum class RigidPart {
  /// Set up at rest (no prescribed node moves yet: a solver's time loop): each move's rigid
  /// part, fitted at the move and blended by weights of the distance to the prescribed nodes'
  /// centroid (RigidPartAtMove), when their ball clears the held nodes by a fifth or nothing
  /// is held. Set up with a motion: when the prescribed nodes move as one rigid body (within
  /// 1e-3 of the largest displacement) and either nothing is held, or the memory budget cut the
  /// interpolation's default radius (RbfOptions::max_memory_bytes: it cannot spread the
  /// motion) while the gap to the held nodes is at least 4 of the body's node spacings and the
  /// blend keeps every node's Jacobian determinant ≥ min_blend_determinant.
  automatic,
  /// always; InputError when the prescribed nodes do not move as one rigid body (set up with a
  /// motion) or their ball reaches a held node (set up at rest)
  blend,
  none,  ///< never: the interpolation carries the whole motion
};

[[nodiscard]] constexpr std::string_view name(RigidPart r) {
  switch (r) {
    case RigidPart::automatic: return "automatic";
    case RigidPart::blend: return "blend";
    case RigidPart::none: return "none";
  }
  return "unknown";
}
[[nodiscard]] constexpr std::array<RigidPart, 3> option_choices(RigidPart) {
  return {RigidPart::automatic, RigidPart::blend, RigidPart::none};
}

/// How an RBF mover carries a support radius wider than its boundary's spacing
/// (detail/rbf_two_level.hpp).
enum class RbfLevels {
  /// two levels for the default radius (none given) when the boundary has more than
  /// RbfOptions::two_level_centres nodes, for a compact kernel with no polynomial and no
  /// partition of unity; one otherwise
  automatic,
  one,  ///< one system over every centre at the radius
  /// a coarse subset of the centres at the radius, every centre at RbfOptions::fine_spacings
  /// boundary spacings (compact kernels with one radius, no polynomial, no partition of unity)
  two,
};

[[nodiscard]] constexpr std::string_view name(RbfLevels l) {
  switch (l) {
    case RbfLevels::automatic: return "automatic";
    case RbfLevels::one: return "one";
    case RbfLevels::two: return "two";
  }
  return "unknown";
}
[[nodiscard]] constexpr std::array<RbfLevels, 3> option_choices(RbfLevels) {
  return {RbfLevels::automatic, RbfLevels::one, RbfLevels::two};
}

/// Options of RbfMover.
struct RbfOptions {
  RbfKernel kernel = RbfKernel::wendland2;
  double support_radius = 0.0;
  std::vector<double> support_radii{};
  bool polynomial = false;
  /// Solver of the sparse system of compact kernels.
  SolverOptions solver = {};
  DenseSolverKind dense_solver = DenseSolverKind::partial_piv_lu;
  Index max_dense_centres = 4000;
  double coincidence_tolerance = 1e-10;
  std::size_t max_evaluation_cache_bytes = std::size_t{256} << 20;
  bool partition_of_unity = false;
  Index patch_centres = 4000;
  double patch_overlap = 0.25;
  double max_memory_bytes = 0.0;
  RigidPart rigid_part = RigidPart::automatic;
  double condition_limit = 1e10;
  RbfLevels levels = RbfLevels::automatic;
  Index two_level_centres = 2000;
  Index coarse_centres = 1000;
  double fine_spacings = 4.0;
  bool repair = true;
};

// visit_options(o, f) calls f(key, field, help) for every field of `o` that text may set.
template <class F>
void visit_options(RbfOptions& o, F&& f, const std::string& prefix = {}) {
  f(prefix + "kernel", o.kernel, "radial function");
  f(prefix + "support_radius", o.support_radius, OptionHelp{"support radius (scale of global kernels), mesh units; 0: from the boundary", range::non_negative,
      "Support radius of compact kernels (shape scale of global ones), in mesh units; 0 (default): "
      "suggest_support_radius() of the boundary each setup is given (its nodes and displacements), so that "
      "the same mesh in millimetres and in metres moves alike; RbfMover::support_radius() says what setup "
      "took."});
  f(prefix + "support_radii", o.support_radii, OptionHelp{"a radius per boundary entry (comma-separated), replacing support_radius", range::positive,
      "A radius per boundary entry (in the order of the boundary given to setup), replacing support_radius; "
      "empty: support_radius everywhere. Coincident nodes share the radius of the one that gives their value. "
      "Lets each wall's support follow its own boundary layer. Radii that differ between centres within each "
      "other's support make the interpolation matrix nonsymmetric: it is then factorized by sparse LU "
      "whatever `solver` says (BiCGSTAB is kept). Walls whose supports do not meet keep it symmetric, and "
      "`solver` applies."});
  f(prefix + "polynomial", o.polynomial, OptionHelp{"add a linear polynomial (affine motions exact)", {},
      "Add a linear polynomial (reproduces affine motions exactly). Always on for the kernels that need it "
      "(needs_polynomial(): tps, multiquadric; without it a rotation moved by tps gave a scaled Jacobian of "
      "-230): see effective_options()."});
  visit_options(o.solver, f, prefix);
  f(prefix + "dense_solver", o.dense_solver, "factorization of the dense system of global kernels");
  f(prefix + "max_dense_centres", o.max_dense_centres, OptionHelp{"largest centre count of a global kernel", range::at_least(1)});
  f(prefix + "coincidence_tolerance", o.coincidence_tolerance, OptionHelp{"boundary nodes closer than this × the diagonal are one", range::non_negative});
  f(prefix + "max_evaluation_cache_bytes", o.max_evaluation_cache_bytes, OptionHelp{"largest dense evaluation matrix kept", range::between(0, 0x1p50),
      "Global kernels: setup stores the dense evaluation matrix (evaluated nodes × centres, 8 bytes an entry) "
      "when it takes at most this many bytes, so a move is one dense matrix product instead of n × m kernel "
      "evaluations; larger matrices are recomputed every move. 0 never caches. Compact kernels keep a sparse "
      "operator unless their support reaches most centres from most nodes and the dense matrix fits here."});
  f(prefix + "partition_of_unity", o.partition_of_unity, OptionHelp{"local systems on overlapping patches (boundaries of ~100k+ nodes)", {},
      "Interpolate with local systems on overlapping patches of the boundary, blended by a partition of "
      "unity, instead of one system over every centre: for boundaries too large to factorize at once (from "
      "~100k nodes). Needs a compact kernel, one support_radius and no polynomial. Interpolating and linear "
      "like the global system, not equal to it: the difference is what data beyond a patch contributes inside "
      "it (docs/interpolation.md)."});
  f(prefix + "patch_centres", o.patch_centres, OptionHelp{"partition of unity: most centres per patch before the overlap", range::at_least(1)});
  f(prefix + "patch_overlap", o.patch_overlap, OptionHelp{"partition of unity: overlap, x each patch's radius (at least the support radius)", range::non_negative});
  f(prefix + "max_memory_bytes", o.max_memory_bytes,
    OptionHelp{"compact kernels: estimated memory allowed, bytes (0: half the machine's); a default radius is reduced to fit", range::non_negative,
      "Compact kernels with one radius, without partition of unity: the most memory (bytes) the system, its "
      "factor and the evaluation operator may take, estimated before assembly from a sample of nodes and "
      "centres; 0 (default): half the machine's memory. A radius given beyond it is refused. The default "
      "radius is reduced until the estimate fits max(1 KiB per mesh node, an eighth of the machine's memory) "
      "and this limit: a large rotation's default radius (5 × the largest displacement) can reach the whole "
      "domain, which made the system and the operator dense (22 GB on a 28k-node case). "
      "support_radius_reduced() says when it was."});
  f(prefix + "rigid_part", o.rigid_part, OptionHelp{"blend a large rigid motion into the volume before interpolating the rest", {},
      "Take the rigid part of the boundary's motion out before interpolating (rigid_part.hpp): every "
      "node follows the prescribed nodes' rigid motion, its angle and translation blended to nothing at the "
      "nearest held node, and the interpolation carries the rest. A mover set up before anything moves (a "
      "solver's time loop) fits each move's rigid part and blends it by the distance to the body's centre, a "
      "twist valid at any angle; the default (automatic) does so whenever the body's ball clears the held "
      "nodes. Set up with the motion, automatic blends a rigid motion the default radius cannot spread within "
      "the memory budget (a body turned 90° in a box), or when nothing is held."});
  f(prefix + "condition_limit", o.condition_limit,
    OptionHelp{"compact kernels: thin centres closer than the radius resolves when the condition exceeds this (0: never)", range::or_zero(range::at_least(1)),
      "Compact kernels without partition of unity: a system whose estimated condition number "
      "(MoverStats::condition) exceeds this is thinned: centres closer together than its radius can resolve "
      "(a blunt trailing edge's two sides 1e-6 apart under a radius of 2) keep their value through a bump no "
      "wider than the gap to their neighbour, and the system is that of the centres kept "
      "(detail::RbfSystem::setup). Rounding in a move or a derivative grows by up to the condition: 1e10 "
      "keeps derivatives to about 1e-6 relative. 0 never thins. MoverStats::thinned_centres says how many "
      "were."});
  f(prefix + "levels", o.levels, OptionHelp{"carry the radius on a coarse subset of the centres, the rest on a few boundary spacings", {},
      "How the interpolation carries its support radius (detail/rbf_two_level.hpp). one: one system "
      "over every centre, which a large motion's radius (5 x its size) makes nearly dense: its memory "
      "and its cost a move grow with the motion. two: centres at least half the fine radius apart (at "
      "most coarse_centres of them) carry the radius, and every centre, at the fine radius "
      "(fine_spacings boundary spacings, at most the radius), what they leave; still interpolating and "
      "linear, with the same reach. automatic (default): two for the default radius on a boundary of "
      "more than two_level_centres nodes (compact kernel, no polynomial, no partition of unity); one "
      "otherwise, and always for a radius given."});
  f(prefix + "two_level_centres", o.two_level_centres, OptionHelp{"levels=automatic: most boundary nodes carried by one level", range::at_least(1)});
  f(prefix + "coarse_centres", o.coarse_centres, OptionHelp{"two levels: most centres of the coarse level", range::at_least(1)});
  f(prefix + "fine_spacings", o.fine_spacings, OptionHelp{"two levels: the fine level's radius, x the median boundary spacing", range::positive});
  f(prefix + "repair", o.repair, OptionHelp{"move the free nodes around linear cells a move folded until they unfold", {},
      "Set up with a mesh whose cells are all linear: after each move, the cells valid at the reference that "
      "the move folded, and two rings of neighbours around them, have their free nodes (no boundary entry) "
      "moved until the cells unfold (linear_repair.hpp): a body turned a half turn in held walls twists "
      "the space between more than a coarse mesh's slivers take. A move that folds nothing is unchanged "
      "(one pass of corner determinants). MoverStats::folded_cells, repaired_nodes and left_folded say what "
      "it found and did; derivatives are those of the move before the repair. Over MPI the same repair, "
      "on the patch gathered: the serial result."});
}

/// Whether an RBF mover with options `o` (effective_options()) interpolates on two levels
/// (RbfOptions::levels), for a boundary of `entries` nodes whose radius is the default one
/// (`default_radius`: none given). The serial and the distributed movers decide by it alike.
[[nodiscard]] inline bool two_level_interpolation(const RbfOptions& o, bool default_radius, Index entries) {
  if (o.levels == RbfLevels::one || !is_compact(o.kernel) || !o.support_radii.empty() || o.polynomial || o.partition_of_unity)
    return false;
  return o.levels == RbfLevels::two || (default_radius && entries > o.two_level_centres);
}

}  // namespace meshmotion
