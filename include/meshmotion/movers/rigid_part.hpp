#pragma once
/// \file
/// The rigid part of a boundary's motion, blended into the volume before an interpolation
/// (RbfOptions::rigid_part). A body turning by a large angle inside a still boundary is what
/// interpolated displacements handle worst: halfway between the body and the held boundary
/// they are half a chord, which pulls cells towards the axis, and a compact support wide
/// enough to spread them (5 × the largest displacement) reaches across the whole domain and
/// makes the system dense (22.7 GB on a 28k-node case turned 90°). Here the prescribed nodes'
/// displacements are fitted by one rigid motion, written as a screw: a rotation by θ about an
/// axis through c and a translation τ along it (in 2D a rotation about c and a translation).
/// Every node x then first moves to c + R(wθ)(x − c) + wτ, the motion's angle and translation
/// scaled by a weight w that is 1 on the moving nodes and falls smoothly to 0 at the distance
/// D of the nearest held node (fixed, or sliding in a plane the motion does not keep): w = s(1 − d/D), s(t) = t²(3 − 2t), d the
/// distance to the nearest moving node. Cells near the body turn with it; the held boundary
/// does not move; what lies between is sheared, not compressed. This is how solvers move
/// bodies in rigid-body motion (OpenFOAM's rigidBodyMeshMotion blends a rotation the same way);
/// the interpolation then carries only what is not rigid (nothing, for a rigid body).
///
/// The map's Jacobian determinant is 1 + ∇w · (θ a × (x − c) + R(wθ)ᵀ τ): 1 wherever the
/// weight falls along the direction of the rotation's axis or across its path (a sphere turning
/// about any axis), smaller where the body's surface is not round about the axis. It is
/// evaluated at every node, and RigidPart::automatic takes the rigid part out only when its
/// smallest value is at least min_blend_determinant.
///
/// Where the interpolation can spread the motion with the radius it wants, it spreads it at
/// least as well (a cylinder orbiting a point 4 radii away in a 2D far field, turned 90°:
/// minimum skewness quality 0.36 interpolated, 0.28 blended), so automatic blends only where
/// the memory budget cuts that radius, or where nothing is held (every node then moves rigidly).

#include "meshmotion/core/error.hpp"
#include "meshmotion/core/option_text.hpp"
#include "meshmotion/core/threads.hpp"
#include "meshmotion/core/types.hpp"
#include "meshmotion/movers/rbf_options.hpp"
#include "meshmotion/movers/boundary.hpp"
#include "meshmotion/spatial/kd_tree.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <Eigen/LU>
#include <Eigen/SVD>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace meshmotion {

/// RigidPart::automatic's floor on the blend's smallest Jacobian determinant at the nodes.
inline constexpr double min_blend_determinant = 0.3;

/// The rigid part of a boundary's motion, blended into the volume.
template <int Dim>
struct RigidBlend {
  Points<Dim> displacement;  ///< of every node (Dim × n)
  double angle = 0.0;        ///< θ, radians (signed in 2D)
  double gap = 0.0;          ///< D: the distance from the moving nodes to the nearest held node (∞ when none)
  double min_determinant = 1.0;  ///< the blend's smallest Jacobian determinant at the nodes
};

namespace detail {

/// x ↦ R x + t fitted to the prescribed entries of `boundary` (their positions in `points`, and
/// positions plus displacements) by least squares (Kabsch), its largest miss, and the
/// largest displacement.
template <int Dim>
struct RigidFit {
  Eigen::Matrix<double, Dim, Dim> rotation = Eigen::Matrix<double, Dim, Dim>::Identity();
  Vec<Dim> translation = Vec<Dim>::Zero();
  double miss = 0.0;
  double largest = 0.0;
};

template <int Dim>
[[nodiscard]] RigidFit<Dim> fit_rigid_motion(const Points<Dim>& from, const Points<Dim>& to) {
  RigidFit<Dim> fit;
  const Index m = from.cols();
  if (m == 0) return fit;
  const Vec<Dim> p = from.rowwise().mean(), q = to.rowwise().mean();
  const Eigen::Matrix<double, Dim, Dim> h = (from.colwise() - p) * (to.colwise() - q).transpose();
  const Eigen::JacobiSVD<Eigen::Matrix<double, Dim, Dim>> svd(h, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix<double, Dim, Dim> flip = Eigen::Matrix<double, Dim, Dim>::Identity();
  flip(Dim - 1, Dim - 1) = (svd.matrixV() * svd.matrixU().transpose()).determinant() < 0.0 ? -1.0 : 1.0;
  fit.rotation = svd.matrixV() * flip * svd.matrixU().transpose();
  fit.translation = q - fit.rotation * p;
  fit.miss = ((fit.rotation * from).colwise() + fit.translation - to).colwise().norm().maxCoeff();
  fit.largest = (to - from).colwise().norm().maxCoeff();
  return fit;
}

/// R(α) about the unit `axis` (2D: counterclockwise; the axis is unused).
template <int Dim>
[[nodiscard]] Eigen::Matrix<double, Dim, Dim> rotation_by(double alpha, const Vec<3>& axis) {
  if constexpr (Dim == 2) {
    return Eigen::Rotation2Dd(alpha).toRotationMatrix();
  } else {
    return Eigen::AngleAxisd(alpha, axis).toRotationMatrix();
  }
}

/// a × r for the unit rotation axis a (2D: the z axis).
template <int Dim>
[[nodiscard]] Vec<Dim> turn_direction(const Vec<3>& axis, const Vec<Dim>& r) {
  if constexpr (Dim == 2) {
    return Vec<2>(-r.y(), r.x());
  } else {
    return axis.cross(r);
  }
}

}  // namespace detail

/// The rigid part of `boundary`'s motion blended over `points` (Dim × n, the reference
/// positions), as `mode` decides (see RigidPart); none when it is not taken out.
/// `radius_cut`: the memory budget cut the interpolation's default radius for this boundary
/// (automatic's condition when something is held). Throws InputError for RigidPart::blend when the prescribed nodes
/// do not move as one rigid body or touch a held node, naming the figures.
template <int Dim>
[[nodiscard]] std::optional<RigidBlend<Dim>> rigid_blend(const Points<Dim>& points, const ResolvedBoundary<Dim>& boundary,
                                                         RigidPart mode, bool radius_cut) {
  if (mode == RigidPart::none) return std::nullopt;
  const auto refuse = [&](const std::string& why) -> std::optional<RigidBlend<Dim>> {
    if (mode == RigidPart::blend) throw InputError("rigid_part=blend: " + why);
    return std::nullopt;
  };
  if (boundary.displacements.cols() != boundary.size() || static_cast<Index>(boundary.kinds.size()) != boundary.size())
    return refuse("the boundary has " + std::to_string(boundary.displacements.cols()) + " displacements for " +
                  std::to_string(boundary.size()) + " nodes");
  std::vector<Index> moving;
  for (Index k = 0; k < boundary.size(); ++k) {
    const Index v = boundary.nodes[static_cast<std::size_t>(k)];
    if (v < 0 || v >= points.cols()) return refuse("boundary node " + std::to_string(v) + " out of range");
    if (boundary.kinds[static_cast<std::size_t>(k)] == BoundaryKind::prescribed) moving.push_back(k);
  }
  if (moving.empty()) return refuse("no prescribed node");
  Points<Dim> from(Dim, static_cast<Index>(moving.size())), to(Dim, from.cols());
  for (std::size_t i = 0; i < moving.size(); ++i) {
    from.col(static_cast<Index>(i)) = points.col(boundary.nodes[static_cast<std::size_t>(moving[i])]);
    to.col(static_cast<Index>(i)) = from.col(static_cast<Index>(i)) + boundary.displacements.col(moving[i]);
  }
  if (!from.allFinite() || !to.allFinite()) return refuse("a prescribed node or displacement is not finite");
  const detail::RigidFit<Dim> fit = detail::fit_rigid_motion(from, to);
  if (!(fit.largest > 0.0)) return refuse("the prescribed nodes do not move");
  if (fit.miss > 1e-3 * fit.largest)
    return refuse("the prescribed nodes do not move as one rigid body (the best rigid fit misses one by " +
                  format_option_value(fit.miss) + ", the largest displacement is " + format_option_value(fit.largest) + ")");

  // The screw: angle θ about the axis a through c, translation τ = t − (I − R) c along a. The
  // point c nearest the moving nodes' centroid makes τ the smallest translation.
  RigidBlend<Dim> out;
  Vec<3> axis = Vec<3>::UnitZ();
  if constexpr (Dim == 2) {
    out.angle = std::atan2(fit.rotation(1, 0), fit.rotation(0, 0));
  } else {
    const Eigen::AngleAxisd turn(fit.rotation);
    out.angle = turn.angle();
    if (out.angle > 0.0) axis = turn.axis();
  }
  const Vec<Dim> centroid = from.rowwise().mean();
  const Eigen::Matrix<double, Dim, Dim> i_minus_r = Eigen::Matrix<double, Dim, Dim>::Identity() - fit.rotation;
  Vec<Dim> along = Vec<Dim>::Zero();
  if constexpr (Dim == 3) along = axis.dot(fit.translation) * axis;
  Vec<Dim> c = centroid;
  if (std::abs(out.angle) > 1e-12)
    c += Eigen::JacobiSVD<Eigen::Matrix<double, Dim, Dim>>(i_minus_r, Eigen::ComputeFullU | Eigen::ComputeFullV)
             .solve(Vec<Dim>(fit.translation - along - i_minus_r * centroid));
  const Vec<Dim> tau = fit.translation - i_minus_r * c;

  // Held: the fixed nodes, and the sliding ones whose plane the blended motion would leave (a
  // plane normal to the rotation's axis, the translation in it, is kept at every weight: a
  // symmetry plane across a pitching half-model). D: how far the nearest is from the moving nodes.
  std::vector<Index> held;
  for (Index k = 0; k < boundary.size(); ++k) {
    const BoundaryKind kind = boundary.kinds[static_cast<std::size_t>(k)];
    if (kind == BoundaryKind::fixed) held.push_back(k);
    if (kind != BoundaryKind::sliding) continue;
    const Vec<Dim> normal = boundary.normals.col(k);
    const bool kept = !boundary.slides_on_line(k) && (fit.rotation * normal - normal).norm() <= 1e-9 &&
                      std::abs(normal.dot(tau)) <= 1e-9 * fit.largest;
    if (!kept) held.push_back(k);
  }
  Points<Dim> at_held(Dim, static_cast<Index>(held.size()));
  for (std::size_t i = 0; i < held.size(); ++i) at_held.col(static_cast<Index>(i)) = points.col(boundary.nodes[static_cast<std::size_t>(held[i])]);
  out.gap = std::numeric_limits<double>::infinity();
  if (!held.empty()) {
    const KdTree<Dim> held_tree(at_held);
    for (Index i = 0; i < from.cols(); ++i) out.gap = std::min(out.gap, std::sqrt(held_tree.nearest(Vec<Dim>(from.col(i))).second));
    if (!(out.gap > 0.0)) return refuse("a prescribed node coincides with a fixed or sliding one");
    if (mode == RigidPart::automatic && !radius_cut) return std::nullopt;
  }

  const KdTree<Dim> moving_tree(from);
  if (mode == RigidPart::automatic && std::isfinite(out.gap) && from.cols() > 1) {
    // A gap of a few of the body's node spacings holds too few nodes to blend over: the
    // nodes' determinants below would all read 1 while the cells between fold.
    std::vector<double> spacing;
    spacing.reserve(static_cast<std::size_t>(from.cols()));
    for (Index i = 0; i < from.cols(); ++i) {
      const auto nn = moving_tree.nearest(Vec<Dim>(from.col(i)), 2);
      if (nn.size() == 2 && nn[1].second > 0.0) spacing.push_back(std::sqrt(nn[1].second));
    }
    if (!spacing.empty()) {
      const auto mid = spacing.begin() + static_cast<std::ptrdiff_t>(spacing.size() / 2);
      std::nth_element(spacing.begin(), mid, spacing.end());
      if (out.gap < 4.0 * *mid) return std::nullopt;
    }
  }
  const Index n = points.cols();
  out.displacement.resize(Dim, n);
  double smallest = 1.0;
#pragma omp parallel for num_threads(::meshmotion::num_threads()) schedule(static) reduction(min : smallest)
  for (Index v = 0; v < n; ++v) {
    const Vec<Dim> x = points.col(v);
    double w = 1.0, slope = 0.0;
    Vec<Dim> towards = Vec<Dim>::Zero();
    if (std::isfinite(out.gap)) {
      const auto near = moving_tree.nearest_within(x, out.gap);
      if (!near) {
        out.displacement.col(v).setZero();
        continue;
      }
      const double d = std::sqrt(near->second), t = 1.0 - d / out.gap;
      w = t * t * (3.0 - 2.0 * t);
      slope = 6.0 * t * (1.0 - t) / out.gap;  // |∇w|, pointing towards the nearest moving node
      if (d > 0.0) towards = (Vec<Dim>(from.col(static_cast<Index>(near->first))) - x) / d;
    }
    const Eigen::Matrix<double, Dim, Dim> r = detail::rotation_by<Dim>(w * out.angle, axis);
    out.displacement.col(v) = c + r * (x - c) + w * tau - x;
    if (slope > 0.0)
      smallest = std::min(smallest, 1.0 + slope * towards.dot(out.angle * detail::turn_direction<Dim>(axis, Vec<Dim>(x - c)) +
                                                               r.transpose() * tau));
  }
  out.min_determinant = smallest;
  if (mode == RigidPart::automatic && out.min_determinant < min_blend_determinant) return std::nullopt;
  return out;
}

/// `boundary` with the blend's displacement taken from its prescribed entries' (held entries
/// have none: the blend is zero there).
template <int Dim>
[[nodiscard]] ResolvedBoundary<Dim> without_rigid_part(ResolvedBoundary<Dim> boundary, const RigidBlend<Dim>& blend) {
  for (Index k = 0; k < boundary.size(); ++k)
    if (boundary.kinds[static_cast<std::size_t>(k)] == BoundaryKind::prescribed)
      boundary.displacements.col(k) -= blend.displacement.col(boundary.nodes[static_cast<std::size_t>(k)]);
  return boundary;
}

/// True when no prescribed entry of `boundary` moves (or it carries no displacements): a
/// mover set up before anything moves, whose rigid part is then each move's (RigidPartAtMove).
template <int Dim>
[[nodiscard]] bool at_rest(const ResolvedBoundary<Dim>& boundary) {
  if (boundary.displacements.cols() != boundary.size()) return boundary.displacements.cols() == 0;
  for (Index k = 0; k < boundary.size(); ++k)
    if (boundary.kinds[static_cast<std::size_t>(k)] == BoundaryKind::prescribed && !boundary.displacements.col(k).isZero(0.0))
      return false;
  return true;
}

/// What a rigid fit leaves of its own motion, relative to the largest prescribed displacement,
/// and is round-off: below it the rest is not interpolated (serial and distributed alike).
inline constexpr double rigid_fit_round_off = 1e-10;

/// RigidPartAtMove's sums and extremes over the processes sharing a mesh, for one process:
/// nothing to add (RanksReduction, parallel/communicator.hpp, is the MPI one).
struct LocalReduction {
  void sum(double*, int) const {}
  void max(double&) const {}
  void min(double&) const {}
};

/// The rigid part of each move's motion, for a mover set up before anything moves (a solver's
/// time loop, an optimizer, the OpenFOAM plugin): found at every move, blended by weights fixed
/// at setup. The prescribed nodes' displacements are fitted by one rigid motion about their
/// reference centroid p, x ↦ p + t + R(x − p) (least squares: t their mean displacement, R the
/// rotation of the polar decomposition M = R S of M = Σ (y_i − q)(x_i − p)ᵀ). Every node then
/// moves to p + v(ρ) t + R(w(ρ) φ)(x − p), φ = log R (the rotation vector, continued from the
/// last move's so that a body turning past a half turn keeps turning the same way), ρ = |x − p|.
///
/// The weights depend on ρ alone, so the blend's rotation is a twist about the axis whatever
/// the axis is: its Jacobian determinant is exactly 1 for any angle (a weight that falls with
/// the distance to the body, as rigid_blend()'s, has ∂w/∂(angle about the axis) ≠ 0 where the
/// body is not round about the axis, and folds past ~90°: a plate turned in a held box left
/// 1,902 cells invalid at 180° with that profile, 102 with this one: cells too coarse for the
/// twist, docs/interpolation.md). w is 1 inside the ball of radius r0 holding every prescribed
/// node and 0 beyond R1, the distance from p to the nearest held (fixed or sliding) node;
/// between them it falls linearly in ln ρ (a twist's shear ρ θ w′ is then the same everywhere,
/// θ / ln(R1/r0), the least any profile can have), with quadratic ends over a tenth of that
/// range each so that no cell straddles a kink. The translation's
/// weight v falls as a smoothstep of ρ over the same range (a translation's strain is |t| v′,
/// smallest when spread evenly). Nothing held: w = v = 1, every node moves rigidly.
///
/// The blend is not linear in the displacements; its derivatives are exact: with dR = R Ω,
/// Ω S + S Ω = Rᵀ dM − dMᵀ R gives Ω ((tr S) I − S in 3D, tr S in 2D), and the rotation
/// vector's change through the inverse of SO(3)'s left Jacobian.
///
/// Over MPI every process prepares its own nodes and counts the entries (and, for the reverse
/// derivative, the nodes) it owns; the fit's sums go through `reduce` (a Reduction: sum, max and
/// min over the processes in place; LocalReduction for one process), so every process blends
/// the serial fit.
template <int Dim>
class RigidPartAtMove {
 public:
  using Matrix = Eigen::Matrix<double, Dim, Dim>;
  /// The rotation vector: an angle in 2D, φ in 3D.
  using Turn = Eigen::Matrix<double, Dim == 2 ? 1 : 3, 1>;

  /// Prepares the blend of `boundary`'s motion over `points` (Dim × n, the reference). Returns
  /// why it cannot (nothing prepared): no prescribed node, prescribed nodes on one line (3D:
  /// a turn about it is not seen) or on one point, or a held node inside their ball.
  /// `owned` (per entry; empty: every entry): the entries this process counts.
  template <class Reduce = LocalReduction>
  [[nodiscard]] std::optional<std::string> prepare(const Points<Dim>& points, const ResolvedBoundary<Dim>& boundary,
                                                   const std::vector<char>& owned = {}, const Reduce& reduce = {}) {
    *this = RigidPartAtMove{};
    std::vector<Index> moving, held;
    for (Index k = 0; k < boundary.size(); ++k)
      if (owned.empty() || owned[static_cast<std::size_t>(k)] != 0)
        (boundary.kinds[static_cast<std::size_t>(k)] == BoundaryKind::prescribed ? moving : held).push_back(k);
    // Their count and the sum of their positions, then Σ o oᵀ: one reduction each.
    std::array<double, Dim + 1> sums{};
    for (const Index k : moving)
      for (int a = 0; a < Dim; ++a) sums[static_cast<std::size_t>(a)] += points(a, boundary.nodes[static_cast<std::size_t>(k)]);
    sums[Dim] = static_cast<double>(moving.size());
    reduce.sum(sums.data(), Dim + 1);
    if (sums[Dim] == 0.0) return "no prescribed node";
    const Vec<Dim> p = Eigen::Map<const Vec<Dim>>(sums.data()) / sums[Dim];
    Points<Dim> offsets(Dim, static_cast<Index>(moving.size()));
    for (std::size_t i = 0; i < moving.size(); ++i)
      offsets.col(static_cast<Index>(i)) = points.col(boundary.nodes[static_cast<std::size_t>(moving[i])]) - p;
    Matrix spread = offsets * offsets.transpose();
    reduce.sum(spread.data(), Dim * Dim);
    const Eigen::SelfAdjointEigenSolver<Matrix> eigen(spread);
    if (!(eigen.eigenvalues()(1) > 1e-12 * eigen.eigenvalues()(Dim - 1)))
      return Dim == 2 ? "the prescribed nodes coincide" : "the prescribed nodes lie on one line";
    double r0 = offsets.cols() > 0 ? offsets.colwise().norm().maxCoeff() : 0.0;
    reduce.max(r0);
    double r1 = std::numeric_limits<double>::infinity();
    for (const Index k : held) r1 = std::min(r1, (points.col(boundary.nodes[static_cast<std::size_t>(k)]) - p).norm());
    reduce.min(r1);
    // A ball a fifth wider than the body at least: a narrower shell holds too few cells to twist.
    if (r1 < 1.2 * r0)
      return "a held node lies " + format_option_value(r1) + " from the prescribed nodes' centroid, within 1.2 x their ball's radius " +
             format_option_value(r0);
    const Index n = points.cols();
    turn_weight_.resize(n);
    shift_weight_.resize(n);
    const double span = std::log(r1 / r0), ends = 0.1, slope = 1.0 / (1.0 - ends);
    for (Index v = 0; v < n; ++v) {
      const double rho = (points.col(v) - p).norm();
      if (!std::isfinite(r1) || rho <= r0) {
        turn_weight_(v) = shift_weight_(v) = 1.0;
      } else if (rho >= r1) {
        turn_weight_(v) = shift_weight_(v) = 0.0;
      } else {
        const double s = std::log(rho / r0) / span, u = (r1 - rho) / (r1 - r0);
        const double fallen = s < ends         ? slope * s * s / (2.0 * ends)
                              : s > 1.0 - ends ? 1.0 - slope * (1.0 - s) * (1.0 - s) / (2.0 * ends)
                                               : slope * (s - ends / 2.0);
        turn_weight_(v) = 1.0 - fallen;
        shift_weight_(v) = u * u * (3.0 - 2.0 * u);
      }
    }
    moving_ = std::move(moving);
    offsets_ = std::move(offsets);
    spread_ = stretch_ = spread;
    centre_ = p;
    count_ = sums[Dim];
    return std::nullopt;
  }

  [[nodiscard]] bool active() const noexcept { return count_ > 0.0; }
  /// The last fit's angle (radians, ≥ 0).
  [[nodiscard]] double angle() const { return turn_.norm(); }

  /// Fits `d`'s rigid part (Dim × boundary.size()) and writes its blend over every node of
  /// `points` (prepare()'s) into `out` (Dim × n); the fit is kept for the derivatives.
  template <class Reduce = LocalReduction>
  void blend(const Points<Dim>& points, PointsView<Dim> d, Points<Dim>& out, const Reduce& reduce = {}) {
    Matrix m;
    first_moments(d, shift_, m, reduce);
    m += spread_;
    const Eigen::JacobiSVD<Matrix> svd(m, Eigen::ComputeFullU | Eigen::ComputeFullV);
    Matrix flip = Matrix::Identity();
    flip(Dim - 1, Dim - 1) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0.0 ? -1.0 : 1.0;
    rotation_ = svd.matrixU() * flip * svd.matrixV().transpose();
    stretch_ = rotation_.transpose() * m;
    turn_ = continued(rotation_);
    const Index n = points.cols();
    out.resize(Dim, n);
#pragma omp parallel for num_threads(::meshmotion::num_threads()) schedule(static)
    for (Index v = 0; v < n; ++v) {
      const Vec<Dim> r = Vec<Dim>(points.col(v)) - centre_;
      out.col(v) = shift_weight_(v) * shift_ + turned(turn_weight_(v), r) - r;
    }
  }

  /// The blend's change (Dim × n) for a change `w` of the boundary displacements, at the last fit.
  template <class Reduce = LocalReduction>
  void derivative_forward(const Points<Dim>& points, PointsView<Dim> w, Points<Dim>& out, const Reduce& reduce = {}) const {
    Vec<Dim> dt;
    Matrix dm;
    first_moments(w, dt, dm, reduce);
    const Turn dphi = turn_change(dm);
    const Index n = points.cols();
    out.resize(Dim, n);
#pragma omp parallel for num_threads(::meshmotion::num_threads()) schedule(static)
    for (Index v = 0; v < n; ++v) {
      const double wt = turn_weight_(v);
      const Vec<Dim> r = turned(wt, Vec<Dim>(points.col(v)) - centre_);
      out.col(v) = shift_weight_(v) * dt + turned_change(wt, dphi, r);
    }
  }

  /// Adds to `grad` (Dim × boundary.size()) the gradient of ⟨v, the blend's change⟩ for `v`
  /// (Dim × n): the transpose of derivative_forward(). `owned` (per node; empty: every node):
  /// the nodes whose term this process adds.
  template <class Reduce = LocalReduction>
  void derivative_reverse(const Points<Dim>& points, PointsView<Dim> v, Points<Dim>& grad, const std::vector<char>& owned = {},
                          const Reduce& reduce = {}) const {
    Eigen::Matrix<double, Dim + Turn::RowsAtCompileTime, 1> sums = decltype(sums)::Zero();
    for (Index x = 0; x < points.cols(); ++x) {
      if (!owned.empty() && owned[static_cast<std::size_t>(x)] == 0) continue;
      const double wt = turn_weight_(x);
      sums.template head<Dim>() += shift_weight_(x) * v.col(x);
      if (wt == 0.0) continue;
      const Vec<Dim> r = turned(wt, Vec<Dim>(points.col(x)) - centre_);
      sums.template tail<Turn::RowsAtCompileTime>() += turned_change_transpose(wt, r, Vec<Dim>(v.col(x)));
    }
    reduce.sum(sums.data(), static_cast<int>(sums.size()));
    // ⟨gphi, dφ⟩ = ⟨q, dM⟩: dM = Σ w_i o_iᵀ gives w_i's share q o_i.
    const Matrix q = rotation_ * generator(skew_adjoint(Turn(sums.template tail<Turn::RowsAtCompileTime>())));
    const Vec<Dim> gt = sums.template head<Dim>() / count_;
    for (std::size_t i = 0; i < moving_.size(); ++i) grad.col(moving_[i]) += gt + q * offsets_.col(static_cast<Index>(i));
  }

 private:
  /// The mean of `d` over the prescribed entries and Σ d_i o_iᵀ, over every process.
  template <class Reduce>
  void first_moments(PointsView<Dim> d, Vec<Dim>& mean, Matrix& moment, const Reduce& reduce) const {
    Eigen::Matrix<double, Dim + Dim * Dim, 1> sums = decltype(sums)::Zero();
    for (std::size_t i = 0; i < moving_.size(); ++i) {
      sums.template head<Dim>() += d.col(moving_[i]);
      Eigen::Map<Matrix>(sums.data() + Dim) += d.col(moving_[i]) * offsets_.col(static_cast<Index>(i)).transpose();
    }
    reduce.sum(sums.data(), static_cast<int>(sums.size()));
    mean = sums.template head<Dim>() / count_;
    moment = Eigen::Map<const Matrix>(sums.data() + Dim);
  }

  /// The unit rotation's generator times g: [g]× in 3D, g J in 2D (J the quarter turn).
  [[nodiscard]] static Matrix generator(const Turn& g) {
    Matrix out;
    if constexpr (Dim == 2) {
      out << 0.0, -g(0), g(0), 0.0;
    } else {
      out << 0.0, -g(2), g(1), g(2), 0.0, -g(0), -g(1), g(0), 0.0;
    }
    return out;
  }
  /// The skew part of a matrix as a Turn: K(1,0) in 2D, vex(K) in 3D, for K = X − Xᵀ.
  [[nodiscard]] static Turn skew_of(const Matrix& x) {
    const Matrix k = x - x.transpose();
    if constexpr (Dim == 2) {
      return Turn(k(1, 0));
    } else {
      return Turn(k(2, 1), k(0, 2), k(1, 0));
    }
  }
  /// SO(3)'s left Jacobian at φ: exp(φ + dφ) = exp([J_l dφ]×) exp(φ) to first order.
  [[nodiscard]] static Eigen::Matrix3d left_jacobian(const Eigen::Vector3d& phi) {
    const double a = phi.norm();
    Eigen::Matrix3d k;
    k << 0.0, -phi(2), phi(1), phi(2), 0.0, -phi(0), -phi(1), phi(0), 0.0;
    if (a < 1e-6) return Eigen::Matrix3d::Identity() + 0.5 * k + k * k / 6.0;
    return Eigen::Matrix3d::Identity() + (1.0 - std::cos(a)) / (a * a) * k + (a - std::sin(a)) / (a * a * a) * k * k;
  }
  /// log R, the branch nearest the last move's (a body past a half turn keeps its sense).
  [[nodiscard]] Turn continued(const Matrix& r) const {
    constexpr double two_pi = 2.0 * std::numbers::pi;
    if constexpr (Dim == 2) {
      const double a = std::atan2(r(1, 0), r(0, 0));
      return Turn(a + two_pi * std::round((turn_(0) - a) / two_pi));
    } else {
      const Eigen::AngleAxisd aa(r);
      if (aa.angle() == 0.0) return Turn::Zero();
      const Turn phi = aa.angle() * aa.axis(), other = (aa.angle() - two_pi) * aa.axis();
      return (other - turn_).norm() < (phi - turn_).norm() ? other : phi;
    }
  }
  /// R(w φ) r for the last fit's φ.
  [[nodiscard]] Vec<Dim> turned(double w, const Vec<Dim>& r) const {
    if (w == 0.0) return r;
    if constexpr (Dim == 2) {
      return Eigen::Rotation2Dd(w * turn_(0)) * r;
    } else {
      const double a = turn_.norm();
      return a == 0.0 ? r : Vec<Dim>(Eigen::AngleAxisd(w * a, turn_ / a) * r);
    }
  }
  /// dφ for dM (the fit's rotation moves by dR = R Ω, Ω S + S Ω = Rᵀ dM − dMᵀ R).
  [[nodiscard]] Turn turn_change(const Matrix& dm) const {
    const Turn k = skew_of(rotation_.transpose() * dm);
    if constexpr (Dim == 2) {
      return Turn(k(0) / stretch_.trace());
    } else {
      const Eigen::Vector3d omega = (stretch_.trace() * Eigen::Matrix3d::Identity() - stretch_).partialPivLu().solve(k);
      return left_jacobian(turn_).partialPivLu().solve(rotation_ * omega);
    }
  }
  /// The transpose of turn_change: the Turn g with ⟨g, skew_of(Rᵀ dM)⟩ = ⟨gphi, turn_change(dM)⟩.
  [[nodiscard]] Turn skew_adjoint(const Turn& gphi) const {
    if constexpr (Dim == 2) {
      return Turn(gphi(0) / stretch_.trace());
    } else {
      const Eigen::Vector3d through = rotation_.transpose() * left_jacobian(turn_).transpose().partialPivLu().solve(gphi);
      return (stretch_.trace() * Eigen::Matrix3d::Identity() - stretch_).transpose().partialPivLu().solve(through);
    }
  }
  /// d(R(w φ) r0) for dφ, with r = R(w φ) r0: w dφ × r in 2D's sense; 3D through J_l(w φ).
  [[nodiscard]] Vec<Dim> turned_change(double w, const Turn& dphi, const Vec<Dim>& r) const {
    if (w == 0.0) return Vec<Dim>::Zero();
    if constexpr (Dim == 2) {
      return w * dphi(0) * Vec<Dim>(-r.y(), r.x());
    } else {
      return (left_jacobian(w * turn_) * (w * dphi)).cross(r);
    }
  }
  /// The transpose of turned_change in dφ: ⟨v, turned_change(w, dφ, r)⟩ = ⟨result, dφ⟩.
  [[nodiscard]] Turn turned_change_transpose(double w, const Vec<Dim>& r, const Vec<Dim>& v) const {
    if constexpr (Dim == 2) {
      return Turn(w * (r.x() * v.y() - r.y() * v.x()));
    } else {
      return w * (left_jacobian(w * turn_).transpose() * r.cross(v));
    }
  }

  std::vector<Index> moving_;            ///< the prescribed entries
  Points<Dim> offsets_;                  ///< their reference positions less their centroid
  Matrix spread_ = Matrix::Zero();       ///< Σ offsets offsetsᵀ
  Vec<Dim> centre_ = Vec<Dim>::Zero();   ///< p
  double count_ = 0.0;                   ///< prescribed entries over every process
  Eigen::VectorXd turn_weight_, shift_weight_;  ///< w and v of every node
  // The last fit.
  Matrix rotation_ = Matrix::Identity(), stretch_ = Matrix::Identity();
  Vec<Dim> shift_ = Vec<Dim>::Zero();
  Turn turn_ = Turn::Zero();
};

}  // namespace meshmotion
