#pragma once
/// \file
/// SectionMover: moves a 2D case stored in 3D (one cell thick between two parallel planes,
/// core/extrusion.hpp) as its 2D section with any 2D mover, and gives the front and the back
/// the same in-plane displacement. The 3D movers cannot promise that: the elasticity family
/// moves nodes off the planes through the Poisson effect, and the movers that split cells
/// into tetrahedra split the front and the back differently.
///
/// \code
/// SectionMover mover(make_mover(mover_config<2>("le")));
/// const StepResult<3> moved = run_steps(mover, mesh3, spec3);   // spec3 on the 3D groups
/// \endcode

#include "meshmotion/core/error.hpp"
#include "meshmotion/core/extrusion.hpp"
#include "meshmotion/core/mesh.hpp"
#include "meshmotion/core/option_text.hpp"
#include "meshmotion/movers/any_mover.hpp"
#include "meshmotion/movers/boundary.hpp"
#include "meshmotion/movers/mover.hpp"

#include <cmath>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace meshmotion {

/// Conditions or displacements that are not two-dimensional on a mesh one cell thick: the
/// mesh must move in 3D.
class NotTwoDimensional : public InputError {
 public:
  using InputError::InputError;
};

/// A 3D boundary on an extrusion, as the section's boundary: the conditions of each node's
/// front and back copies, which must agree. `columns[j]` is the 3D boundary column whose
/// displacement entry j of the section takes, `partner_columns[j]` the other copy's (−1 when
/// the other copy is not on the boundary).
struct SectionBoundary {
  ResolvedBoundary<2> boundary;
  std::vector<Index> columns, partner_columns;
};

namespace detail {

// Parallel or normal to the axis, to this many radians' sine.
inline constexpr double section_angle_tolerance = 1e-8;

// The relative difference allowed between the displacements of a node's two copies, and
// along the axis: a rigid motion about the axis gives them to round-off.
inline constexpr double section_displacement_tolerance = 1e-9;

}  // namespace detail

/// The section's boundary of `boundary` (resolved on the 3D mesh of `ext`). Throws
/// NotTwoDimensional naming the node when the conditions are not two-dimensional: a displacement along the
/// axis, front and back copies with different conditions or displacements, a sliding plane
/// neither normal nor parallel to the axis. A node sliding in a plane normal to the axis (the
/// front and back themselves) is free in the section.
[[nodiscard]] inline SectionBoundary section_boundary(const Extrusion& ext, const Mesh<3>& mesh,
                                                      const ResolvedBoundary<3>& boundary) {
  const int axis = ext.axis;
  const double scale = boundary.displacements.size() > 0 ? boundary.displacements.cwiseAbs().maxCoeff() : 0.0;
  const double tolerance = detail::section_displacement_tolerance * scale;
  const auto refuse = [&](Index node, const std::string& why) {
    throw NotTwoDimensional("the motion is not two-dimensional: " + mesh.describe_node(node) + " " + why +
                            " (the mesh is one cell thick along " + ext.axis_name() + ")");
  };
  // The section condition of 3D entry k, or nullopt when it leaves the node free in the plane.
  const auto reduce = [&](Index k) -> std::optional<BoundaryEntry<2>> {
    const Index node = boundary.nodes[static_cast<std::size_t>(k)];
    BoundaryEntry<2> e;
    e.kind = boundary.kinds[static_cast<std::size_t>(k)];
    if (e.kind == BoundaryKind::prescribed) {
      const Vec<3> d = boundary.displacements.col(k);
      if (std::abs(d(axis)) > tolerance) refuse(node, "moves along the axis by " + format_option_value(d(axis)));
      e.displacement = ext.project(d);
    } else if (e.kind == BoundaryKind::sliding) {
      const bool line = boundary.slides_on_line(k);
      const Vec<3> t = line ? Vec<3>(boundary.directions.col(k)) : Vec<3>(boundary.normals.col(k));
      const double along = std::abs(t(axis));
      if (along >= 1.0 - detail::section_angle_tolerance) {
        if (!line) return std::nullopt;  // slides in a plane normal to the axis: free in the section
        e.kind = BoundaryKind::fixed;    // slides along the axis only
      } else if (along <= detail::section_angle_tolerance) {
        const Vec<2> in_plane = ext.project(t).normalized();
        e.normal = line ? Vec<2>(-in_plane(1), in_plane(0)) : in_plane;
      } else {
        refuse(node, std::string("slides ") + (line ? "along a line" : "in a plane") + " oblique to the axis");
      }
    }
    return e;
  };
  const auto same = [&](const BoundaryEntry<2>& a, const BoundaryEntry<2>& b) {
    return a.kind == b.kind && (a.displacement - b.displacement).lpNorm<Eigen::Infinity>() <= tolerance &&
           std::abs(std::abs(a.normal.dot(b.normal)) - a.normal.squaredNorm()) <= detail::section_angle_tolerance;
  };
  const auto column_of = [&](Index node) -> Index {
    const auto it = std::lower_bound(boundary.nodes.begin(), boundary.nodes.end(), node);
    return it != boundary.nodes.end() && *it == node ? static_cast<Index>(it - boundary.nodes.begin()) : -1;
  };
  SectionBoundary out;
  const Index m = static_cast<Index>(ext.front_nodes.size());
  out.boundary = detail::collect_boundary<2>(m, [&](auto&& add) {
    for (Index s = 0; s < m; ++s) {
      const Index front = ext.front_nodes[static_cast<std::size_t>(s)], back = ext.back_nodes[static_cast<std::size_t>(s)];
      const Index cf = column_of(front), cb = column_of(back);
      const std::optional<BoundaryEntry<2>> ef = cf >= 0 ? reduce(cf) : std::nullopt;
      const std::optional<BoundaryEntry<2>> eb = cb >= 0 ? reduce(cb) : std::nullopt;
      if (!ef && !eb) continue;
      if (!ef || !eb || !same(*ef, *eb))
        refuse(ef ? front : back, "is " + std::string(name((ef ? ef : eb)->kind)) + " and its copy on the other plane, " +
                                      mesh.describe_node(ef ? back : front) + ", " +
                                      (ef && eb ? "is " + std::string(name(eb->kind)) + " or moves differently" : "is free"));
      add(s, *ef);
      out.columns.push_back(cf);
      out.partner_columns.push_back(cb);
    }
  });
  // collect_boundary sizes its arrays for every section node; keep those of the entries.
  const Index count = out.boundary.size();
  out.boundary.displacements.conservativeResize(2, count);
  out.boundary.normals.conservativeResize(2, count);
  out.boundary.directions.setZero(2, count);
  return out;
}

/// A 3D mover for meshes one cell thick (a 2D case stored in 3D) that moves the 2D section
/// with `mover` and gives each node's two copies the section node's displacement, with none
/// along the axis. setup throws InputError for a mesh that find_extrusion does not recognize
/// and NotTwoDimensional for conditions section_boundary refuses; move throws
/// NotTwoDimensional for displacements
/// along the axis or different between a node's copies.
class SectionMover {
 public:
  static constexpr int dim = 3;

  explicit SectionMover(AnyMover<2> mover) : mover_(std::move(mover)) {}
  /// With the extrusion of the mesh that setup will be given, as find_extrusion() gave it to
  /// the caller: setup does not look for it again (a case moved step after step keeps it, its
  /// section following the moved mesh).
  SectionMover(AnyMover<2> mover, Extrusion ext) : mover_(std::move(mover)), ext_(std::move(ext)), known_(true) {}

  void setup(const Mesh<3>& mesh, const ResolvedBoundary<3>& boundary) {
    if (!known_) {
      std::optional<Extrusion> ext = find_extrusion(mesh);
      if (!ext)
        throw InputError("SectionMover::setup: the mesh is not one cell thick between two parallel coordinate planes "
                         "(every node on one of them, every cell a linear prism or hexahedron joining them)");
      ext_ = std::move(*ext);
    } else if (static_cast<Index>(2 * ext_.front_nodes.size()) != mesh.num_nodes()) {
      throw InputError("SectionMover::setup: the mesh has " + std::to_string(mesh.num_nodes()) +
                       " nodes but the given extrusion pairs " + std::to_string(2 * ext_.front_nodes.size()) +
                       " (expected the mesh it was found on)");
    }
    SectionBoundary b = section_boundary(ext_, mesh, boundary);
    // The section of the mesh given: run_steps sets movers up again on the moved mesh.
    for (std::size_t s = 0; s < ext_.front_nodes.size(); ++s)
      ext_.section.points.col(static_cast<Index>(s)) = ext_.project(mesh.points.col(ext_.front_nodes[s]));
    mover_.setup(ext_.section, b.boundary);
    section_ = std::move(b);
    num_nodes_ = mesh.num_nodes();
    num_columns_ = boundary.size();
  }

  [[nodiscard]] Points<3> move(PointsView<3> d) {
    Points<3> out;
    move_into(d, out);
    return out;
  }

  void move_into(PointsView<3> d, Points<3>& out) {
    if (d.cols() != num_columns_)
      throw InputError("SectionMover::move: " + std::to_string(d.cols()) + " displacements for " +
                       std::to_string(num_columns_) + " boundary nodes");
    const double tolerance = detail::section_displacement_tolerance * (d.size() > 0 ? d.cwiseAbs().maxCoeff() : 0.0);
    d2_.resize(2, section_.boundary.size());
    for (Index j = 0; j < section_.boundary.size(); ++j) {
      const Vec<3> x = d.col(section_.columns[static_cast<std::size_t>(j)]);
      const Index partner = section_.partner_columns[static_cast<std::size_t>(j)];
      if (std::abs(x(ext_.axis)) > tolerance || (partner >= 0 && (d.col(partner) - x).lpNorm<Eigen::Infinity>() > tolerance))
        throw NotTwoDimensional("SectionMover::move: the displacement of section node " + std::to_string(section_.boundary.nodes[static_cast<std::size_t>(j)]) +
                         " is not two-dimensional (along the axis, or different on the front and the back)");
      d2_.col(j) = ext_.project(x);
    }
    mover_.move_into(d2_, out2_);
    out.setZero(3, num_nodes_);
    for (std::size_t s = 0; s < ext_.front_nodes.size(); ++s) {
      const Vec<3> x = ext_.lift(out2_.col(static_cast<Index>(s)));
      out.col(ext_.front_nodes[s]) = x;
      out.col(ext_.back_nodes[s]) = x;
    }
  }

  [[nodiscard]] MoverStats stats() const { return mover_.stats(); }
  /// The extrusion of the last setup's mesh.
  [[nodiscard]] const Extrusion& extrusion() const noexcept { return ext_; }

 private:
  AnyMover<2> mover_;
  Extrusion ext_;
  bool known_ = false;  ///< ext_ was given: setup keeps it
  SectionBoundary section_;
  Index num_nodes_ = 0, num_columns_ = 0;
  Points<2> d2_, out2_;
};

}  // namespace meshmotion
