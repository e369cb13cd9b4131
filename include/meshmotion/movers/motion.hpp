#pragma once
/// \file
/// Rigid motions given as objects rather than per-node arrays: Translation, Rotation2D about a
/// point, Rotation3D about an axis through a point, and their composition, wrapped in the
/// type-erased Motion<Dim>. Every motion can be evaluated at a fraction t in [0, 1] of itself
/// (fraction of the offset, fraction of the angle), which the step driver uses to split a
/// large motion into increments that stay rigid.

#include "meshmotion/core/error.hpp"
#include "meshmotion/core/types.hpp"

#include <Eigen/Geometry>

#include <cmath>
#include <functional>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

namespace meshmotion {

/// A rigid motion type: `position(x, t)` is where point x goes at fraction t of the motion
/// (t = 0: x itself, t = 1: the full motion).
template <class M, int Dim>
concept RigidMotion = requires(const M& m, const Vec<Dim>& x, double t) {
  { m.position(x, t) } -> std::convertible_to<Vec<Dim>>;
};

/// Translation by `offset`.
template <int Dim>
struct Translation {
  Vec<Dim> offset = Vec<Dim>::Zero();
  [[nodiscard]] Vec<Dim> position(const Vec<Dim>& x, double t = 1.0) const { return x + t * offset; }
};

/// Rotation in the plane by `angle` radians (counter-clockwise) about `center`.
struct Rotation2D {
  Vec<2> center = Vec<2>::Zero();
  double angle = 0.0;  ///< radians
  [[nodiscard]] Vec<2> position(const Vec<2>& x, double t = 1.0) const {
    return center + Eigen::Rotation2Dd(t * angle) * (x - center);
  }
};

/// Rotation in space by `angle` radians (right-hand rule) about the axis through `center`
/// along `axis` (any non-zero length).
struct Rotation3D {
  Vec<3> center = Vec<3>::Zero();
  Vec<3> axis = Vec<3>::UnitZ();
  double angle = 0.0;  ///< radians
  [[nodiscard]] Vec<3> position(const Vec<3>& x, double t = 1.0) const {
    const double length = axis.norm();
    if (!(length > 0.0)) throw InputError("Rotation3D: axis has zero length");
    return center + Eigen::AngleAxisd(t * angle, axis / length) * (x - center);
  }
};

/// Degrees to radians, for building rotations from user input.
[[nodiscard]] constexpr double radians(double degrees) { return degrees * std::numbers::pi / 180.0; }

/// Any rigid motion in Dim dimensions (type-erased, copyable). Built from a Translation,
/// Rotation2D/3D or Composition.
template <int Dim>
class Motion {
 public:
  /// The identity.
  Motion() : position_([](const Vec<Dim>& x, double) { return x; }) {}

  template <RigidMotion<Dim> M>
  Motion(M motion)  // NOLINT(google-explicit-constructor): motions convert implicitly
      : position_([m = std::move(motion)](const Vec<Dim>& x, double t) { return Vec<Dim>(m.position(x, t)); }) {}

  /// Where x goes at fraction t of the motion.
  [[nodiscard]] Vec<Dim> position(const Vec<Dim>& x, double t = 1.0) const { return position_(x, t); }
  /// Displacement of x between fractions `from` and `to` of the motion (both in [0, 1]),
  /// x being the reference (t = 0) position.
  [[nodiscard]] Vec<Dim> displacement(const Vec<Dim>& x, double to = 1.0, double from = 0.0) const {
    return position(x, to) - position(x, from);
  }

 private:
  std::function<Vec<Dim>(const Vec<Dim>&, double)> position_;
};

/// Composition of motions applied in order: `Composition<2>{{Rotation2D{...}, Translation<2>{...}}}`.
template <int Dim>
struct Composition {
  std::vector<Motion<Dim>> motions;
  [[nodiscard]] Vec<Dim> position(const Vec<Dim>& x, double t = 1.0) const {
    Vec<Dim> y = x;
    for (const auto& m : motions) y = m.position(y, t);
    return y;
  }
};

}  // namespace meshmotion
