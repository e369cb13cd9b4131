#pragma once
/// \file
/// Dgrbf2Mover: DGRBF interpolation of rotation angles instead of displacements, combined
/// with translations (Wang, Qin & Zhao, JCP 2015, "DGRBF2"; thesis section 2.2.3,
/// eqs. 2.17–2.18): in 2D an angle about a centre, in 3D a rotation vector about an axis.
///
/// - Each move splits the prescribed displacements into a rigid part: the rotation about the
///   centre (about the axis through it in 3D) and translation that best fit the moving nodes
///   (least squares); each moving node gets its own angle (the fitted angle plus the small
///   correction that carries its exact target) and the translation that completes its target;
///   fixed nodes (zero displacement) get angle 0 and translation 0. Angles and translations
///   are interpolated by DGRBF weights and every node is rotated by its angle (eqs. 2.17–2.18)
///   and translated. Rigid motions of the whole boundary are reproduced exactly (the default
///   normalized weights reproduce constants); boundary targets are met exactly.
/// - Not linear in the displacements (angles enter through rotation matrices).
/// - Angles come from displacements, so one move (one step of run_steps) must rotate less
///   than 180°; larger motions are split by run_steps, which also splits the angle.
/// - The fit assumes one rigid body moves (or several sharing the motion); other prescribed
///   motions still meet their targets but their angles are fitted per node.
/// - Setup caches as DgrbfMover (graph, per-simplex systems, per-node weights); move adds
///   an O(m) fit and one rotation per node.

#include "meshmotion/movers/dgrbf2_options.hpp"
#include "meshmotion/core/mesh_like.hpp"
#include "meshmotion/core/types.hpp"
#include "meshmotion/movers/boundary.hpp"
#include "meshmotion/movers/delaunay_graph_options.hpp"
#include "meshmotion/movers/detail/graph_mover_base.hpp"
#include "meshmotion/movers/detail/mover_support.hpp"
#include "meshmotion/movers/motion.hpp"
#include "meshmotion/movers/mover.hpp"

#include <Eigen/Geometry>

#include <cmath>
#include <optional>
#include <string>
#include <utility>

namespace meshmotion {

/// Options taking the centre (and axis) of a rigid rotation.
[[nodiscard]] inline Dgrbf2Options<2> dgrbf2_options(const Rotation2D& rotation) {
  Dgrbf2Options<2> o;
  o.center = rotation.center;
  return o;
}
/// Options taking the centre and axis of a rigid rotation.
[[nodiscard]] inline Dgrbf2Options<3> dgrbf2_options(const Rotation3D& rotation) {
  Dgrbf2Options<3> o;
  o.center = rotation.center;
  o.axis = rotation.axis;
  return o;
}

/// The DGRBF2 mover in Dim dimensions; models MeshMover.
template <int Dim>
class Dgrbf2Mover : public detail::MoveFromMoveInto<Dgrbf2Mover<Dim>, Dim> {
 public:
  using detail::MoveFromMoveInto<Dgrbf2Mover<Dim>, Dim>::move_into;  // into the caller's storage
  static constexpr int dim = Dim;
  /// Interpolated per node: angle and translation (2D), rotation vector and translation (3D).
  static constexpr int rows = Dim == 2 ? 3 : 6;
  using Values = Eigen::Matrix<double, rows, Eigen::Dynamic>;
  using Value = Eigen::Matrix<double, rows, 1>;

  /// Throws InputError for a zero or non-finite axis or a non-finite centre.
  explicit Dgrbf2Mover(Dgrbf2Options<Dim> options = {}) : options_(std::move(options)) {
    const double length = options_.axis.norm();
    if (!(length > 0.0) || !std::isfinite(length)) throw InputError("Dgrbf2Mover: rotation axis must be non-zero and finite");
    if (options_.center && !options_.center->allFinite()) throw InputError("Dgrbf2Mover: rotation centre is not finite");
    axis_ = options_.axis / length;
  }

  [[nodiscard]] const Dgrbf2Options<Dim>& options() const noexcept { return options_; }
  [[nodiscard]] const MoverStats& stats() const noexcept { return base_.stats(); }
  /// The rotation angle (radians) fitted to the moving nodes by the last move.
  [[nodiscard]] double fitted_angle() const noexcept { return fitted_angle_; }

  /// As DgrbfMover::setup.
  template <MeshLike M>
    requires(mesh_dim<M> == Dim)
  void setup(const M& mesh, const ResolvedBoundary<Dim>& boundary) {
    base_.setup(copy_points(mesh), boundary, {}, options_.rbf, options_.outside);
  }

  /// Displacement of every node (Dim × n_nodes) for `d` (Dim × boundary.size()). Throws
  /// InputError for a wrong shape or a non-finite value.
  /// move() (inherited) returns the same; move_into writes into `out`, resized only when its
  /// shape differs.
  void move_into(PointsView<Dim> d, Points<Dim>& out) {
    base_.timed_move(d, [&] {
      choose_centre(d);
      base_.template interpolate<rows>(
          d, Points<Dim>(Dim, 0), [this](const Points<Dim>& p, const Points<Dim>& u) { return encode(p, u); },
          [this](const Vec<Dim>& x, const Value& v) { return decode(x, v); }, false, out);
    });
  }

 private:
  using Rotation = Eigen::Matrix<double, Dim, Dim>;

  [[nodiscard]] Rotation rotation(double angle) const {
    if constexpr (Dim == 2) {
      return Eigen::Rotation2Dd(angle).toRotationMatrix();
    } else {
      return Eigen::AngleAxisd(angle, axis_).toRotationMatrix();
    }
  }

  /// Coordinates of v in the plane of rotation.
  [[nodiscard]] Eigen::Vector2d in_plane(const Vec<Dim>& v) const {
    if constexpr (Dim == 2) {
      return v;
    } else {
      const Vec<3> e1 = axis_.unitOrthogonal();
      return {e1.dot(v), axis_.cross(e1).dot(v)};
    }
  }

  /// Angle from a to b in the plane of rotation, in (−π, π]; 0 when either vanishes.
  [[nodiscard]] double angle_between(const Vec<Dim>& a, const Vec<Dim>& b) const {
    const Eigen::Vector2d pa = in_plane(a), pb = in_plane(b);
    return std::atan2(pa.x() * pb.y() - pa.y() * pb.x(), pa.dot(pb));
  }

  /// The centre: given, or the centroid of the moving boundary nodes of this move.
  void choose_centre(PointsView<Dim> d) {
    if (options_.center) {
      centre_ = *options_.center;
      return;
    }
    centre_.setZero();
    Index count = 0;
    for (Index b = 0; b < d.cols(); ++b)
      if (d.col(b).squaredNorm() > 0.0) {
        centre_ += base_.points().col(base_.boundary().nodes[static_cast<std::size_t>(b)]);
        ++count;
      }
    if (count > 0) centre_ /= static_cast<double>(count);
  }

  /// Angles (rotation vectors) and translations of graph nodes at `p` displaced by `u`.
  [[nodiscard]] Values encode(const Points<Dim>& p, const Points<Dim>& u) {
    const Index k = p.cols();
    Values v = Values::Zero(rows, k);
    // Least-squares rigid fit q ≈ R(θ) r + t over the moving nodes, r = p − c, q = p + u − c.
    Vec<Dim> r_mean = Vec<Dim>::Zero(), q_mean = Vec<Dim>::Zero();
    Index count = 0;
    for (Index j = 0; j < k; ++j)
      if (u.col(j).squaredNorm() > 0.0) {
        r_mean += p.col(j) - centre_;
        q_mean += p.col(j) + u.col(j) - centre_;
        ++count;
      }
    if (count == 0) return v;
    r_mean /= static_cast<double>(count);
    q_mean /= static_cast<double>(count);
    double cross = 0.0, dot = 0.0, scale = 0.0;
    for (Index j = 0; j < k; ++j)
      if (u.col(j).squaredNorm() > 0.0) {
        const Eigen::Vector2d a = in_plane(Vec<Dim>(p.col(j) - centre_ - r_mean));
        const Eigen::Vector2d b = in_plane(Vec<Dim>(p.col(j) + u.col(j) - centre_ - q_mean));
        cross += a.x() * b.y() - a.y() * b.x();
        dot += a.dot(b);
        scale = std::max(scale, (p.col(j) - centre_).norm());
      }
    fitted_angle_ = (cross == 0.0 && dot == 0.0) ? 0.0 : std::atan2(cross, dot);
    const Rotation fitted = rotation(fitted_angle_);
    const Vec<Dim> t = q_mean - fitted * r_mean;
    for (Index j = 0; j < k; ++j) {
      if (u.col(j).squaredNorm() == 0.0) continue;
      const Vec<Dim> r = p.col(j) - centre_;
      const Vec<Dim> q = r + u.col(j);
      // Each node's own angle carries what the fit misses; a node at the centre has none.
      const double angle =
          r.norm() > 1e-12 * std::max(scale, 1e-300) ? fitted_angle_ + angle_between(fitted * r, q - t) : fitted_angle_;
      const Vec<Dim> translation = q - rotation(angle) * r;
      if constexpr (Dim == 2) {
        v(0, j) = angle;
        v.col(j).template tail<2>() = translation;
      } else {
        v.col(j).template head<3>() = angle * axis_;
        v.col(j).template tail<3>() = translation;
      }
    }
    return v;
  }

  /// Displacement of the node at x for interpolated angle (rotation vector) and translation.
  [[nodiscard]] Vec<Dim> decode(const Vec<Dim>& x, const Value& v) const {
    const Vec<Dim> r = x - centre_;
    if constexpr (Dim == 2) {
      return Eigen::Rotation2Dd(v(0)) * r + v.template tail<2>() - r;
    } else {
      const Vec<3> omega = v.template head<3>();
      const double angle = omega.norm();
      const Vec<3> rotated = angle > 0.0 ? Vec<3>(Eigen::AngleAxisd(angle, omega / angle) * r) : r;
      return rotated + v.template tail<3>() - r;
    }
  }

  Dgrbf2Options<Dim> options_;
  Vec<3> axis_ = Vec<3>::UnitZ();
  Vec<Dim> centre_ = Vec<Dim>::Zero();
  double fitted_angle_ = 0.0;
  detail::GraphMoverBase<Dim> base_{"Dgrbf2Mover"};
};

}  // namespace meshmotion

// The compiled library (target meshmotion::compiled, src/) holds these for Dim 2 and 3.
#ifdef MESHMOTION_COMPILED
namespace meshmotion {
extern template class Dgrbf2Mover<2>;
extern template class Dgrbf2Mover<3>;
// setup is a template over the mesh type: its Mesh<Dim> form, the one make_mover() uses, too.
extern template void Dgrbf2Mover<2>::setup<Mesh<2>>(const Mesh<2>&, const ResolvedBoundary<2>&);
extern template void Dgrbf2Mover<3>::setup<Mesh<3>>(const Mesh<3>&, const ResolvedBoundary<3>&);
}  // namespace meshmotion
#endif
