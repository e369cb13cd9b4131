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

#include <Eigen/Geometry>
#include <Eigen/SVD>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
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

}  // namespace meshmotion
