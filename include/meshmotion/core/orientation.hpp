#pragma once
/// \file
/// Element orientation: the signed measure (area in 2D, volume in 3D) of a cell's linear
/// vertices, a count of inverted cells, and a fix that reorders the nodes of inverted cells.
/// Files differ here (SU2 meshes exist that are all clockwise), so readers keep the file's
/// order and fixing is only ever done on request.

#include "meshmotion/core/element.hpp"
#include "meshmotion/core/mesh.hpp"
#include "meshmotion/core/shape_functions.hpp"
#include "meshmotion/core/types.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <span>
#include <string_view>
#include <vector>

namespace meshmotion {

/// Signed measure of the linear vertices of one cell (Dim-dimensional element): shoelace area
/// in 2D; in 3D the volume enclosed by the outward-listed facets (quadrilaterals split in two
/// triangles). Positive for elements ordered as Gmsh orders them.
template <int Dim>
[[nodiscard]] double signed_measure(const Mesh<Dim>& mesh, ElementType type, std::span<const Index> nodes) {
  if constexpr (Dim == 2) {
    const int nv = num_vertices(type);
    double twice_area = 0;
    for (int k = 0; k < nv; ++k) {
      const auto a = mesh.points.col(nodes[static_cast<std::size_t>(k)]);
      const auto b = mesh.points.col(nodes[static_cast<std::size_t>((k + 1) % nv)]);
      twice_area += a.x() * b.y() - a.y() * b.x();
    }
    return 0.5 * twice_area;
  } else {
    Vec<3> centre = Vec<3>::Zero();
    const int nv = num_vertices(type);
    for (int k = 0; k < nv; ++k) centre += mesh.points.col(nodes[static_cast<std::size_t>(k)]);
    centre /= nv;
    double six_volume = 0;
    for (const LocalFacet& f : facets(type)) {
      const auto p = [&](int k) -> Vec<3> {
        return mesh.points.col(nodes[static_cast<std::size_t>(f.vertices[static_cast<std::size_t>(k)])]) - centre;
      };
      for (int t = 1; t + 1 < f.num_vertices; ++t) six_volume += p(0).dot(p(t).cross(p(t + 1)));
    }
    return six_volume / 6.0;
  }
}

/// How a mesh's cells are listed, from the signs of their measures.
enum class CellOrientation {
  positive,  ///< every cell of nonzero measure positive
  reversed,  ///< every cell of nonzero measure negative: the file's convention, reversed
  mixed,     ///< some of each: inverted cells, or a file listing cells inconsistently
};

/// "positive", "reversed", "mixed".
[[nodiscard]] constexpr std::string_view name(CellOrientation o) {
  switch (o) {
    case CellOrientation::positive: return "positive";
    case CellOrientation::reversed: return "reversed";
    case CellOrientation::mixed: return "mixed";
  }
  return "unknown";
}

/// Orientation count of a mesh's cells.
struct OrientationReport {
  Index num_cells = 0;
  Index num_negative = 0;     ///< cells with negative signed measure
  Index num_degenerate = 0;   ///< cells with zero signed measure
  Index first_negative = -1;  ///< position in cell order of the first negative cell, -1 if none

  [[nodiscard]] CellOrientation orientation() const noexcept {
    if (num_negative == 0) return CellOrientation::positive;
    return num_negative + num_degenerate == num_cells ? CellOrientation::reversed : CellOrientation::mixed;
  }
};

/// Counts the cells whose signed_measure() is negative or zero.
template <int Dim>
[[nodiscard]] OrientationReport orientation_report(const Mesh<Dim>& mesh) {
  OrientationReport report;
  for (const auto& b : mesh.cells)
    for (Index e = 0; e < b.size(); ++e, ++report.num_cells) {
      const double m = signed_measure(mesh, b.type, b.element(e));
      if (m < 0) {
        if (report.first_negative < 0) report.first_negative = report.num_cells;
        ++report.num_negative;
      } else if (m == 0) {
        ++report.num_degenerate;
      }
    }
  return report;
}

namespace detail {

/// Full node permutation (vertices, edge, face and inside nodes) mirroring an element of type
/// t: new local node k is old local node result[k]. Every reference element is symmetric under
/// swapping its first two coordinates, which exchanges vertices 1 and 2 of simplices and prisms
/// and 1 and 3 of quadrilaterals, hexahedra and pyramids; new node k sits where the old node at
/// the swapped reference point did, so high-order nodes stay where they are in space.
[[nodiscard]] inline std::vector<int> mirror_permutation(ElementType t) {
  const auto nodes = reference_nodes(t);
  std::vector<int> perm;
  perm.reserve(nodes.size());
  for (const RefPoint& x : nodes) {
    const RefPoint swapped{x[1], x[0], x[2]};
    const auto at = std::find_if(nodes.begin(), nodes.end(), [&](const RefPoint& y) {
      return std::abs(y[0] - swapped[0]) + std::abs(y[1] - swapped[1]) + std::abs(y[2] - swapped[2]) < 1e-9;
    });
    perm.push_back(static_cast<int>(at - nodes.begin()));
  }
  return perm;
}

}  // namespace detail

/// Reorders the nodes of every cell with negative signed_measure() so it becomes positive
/// (high-order nodes permuted consistently). Returns the number of cells changed. Facets are
/// left as they are. Never called by the readers: use it when orientation_report() says so.
template <int Dim>
Index fix_orientation(Mesh<Dim>& mesh) {
  Index changed = 0;
  std::vector<Index> old_nodes;
  for (auto& b : mesh.cells) {
    const auto perm = detail::mirror_permutation(b.type);
    for (Index e = 0; e < b.size(); ++e) {
      auto nodes = b.element(e);
      if (signed_measure(mesh, b.type, std::span<const Index>(nodes.data(), nodes.size())) >= 0) continue;
      old_nodes.assign(nodes.begin(), nodes.end());
      for (std::size_t k = 0; k < nodes.size(); ++k) nodes[k] = old_nodes[static_cast<std::size_t>(perm[k])];
      ++changed;
    }
  }
  return changed;
}

/// What orient_consistently() found and did.
struct OrientationFix {
  using Found = CellOrientation;
  Found found = Found::positive;
  Index num_cells = 0;
  Index num_negative = 0;      ///< before any fix
  Index first_negative = -1;   ///< position in cell order, -1 if none
  Index reoriented = 0;        ///< cells whose nodes were reordered
};

/// Makes a consistently reversed mesh positive (every cell mirrored, as fix_orientation()),
/// and leaves a positive or a mixed mesh as it is: a consistently reversed mesh is a
/// convention (SU2 files exist that list every cell clockwise), while in a mixed one the
/// negative cells may be truly inverted and mirroring them would hide it. Facets are left as
/// they are. Returns what was found and done.
template <int Dim>
OrientationFix orient_consistently(Mesh<Dim>& mesh) {
  const OrientationReport r = orientation_report(mesh);
  OrientationFix fix;
  fix.num_cells = r.num_cells;
  fix.num_negative = r.num_negative;
  fix.first_negative = r.first_negative;
  fix.found = r.orientation();
  if (fix.found != CellOrientation::reversed) return fix;
  fix.reoriented = fix_orientation(mesh);
  return fix;
}

}  // namespace meshmotion
