#pragma once
/// \file
/// Boundary snapping, the second step of the curving pipeline (thesis section 3.2): the
/// nodes of the boundary facets of a P2 mesh (straight, as to_quadratic() makes them) are
/// moved onto the true boundary of their group, which is known either
/// - from the linear mesh alone in 2D: a C² cubic spline through the group's vertices
///   (BoundarySpline; corners by angle or list), each edge node going to its facet's
///   parameter midpoint (thesis) or arc-length midpoint; vertices stay; or
/// - from the linear mesh alone in 3D: the WALF surface reconstruction of the group's
///   triangles (SurfaceReconstruction, ridges sharp above the corner angle), each edge node
///   going to the reconstructed edge midpoint; vertices stay; or
/// - from a closest-point projection (analytic or CAD geometry, any dimension): vertices
///   off the geometry are projected, then every edge (face) node goes to the projection of
///   the straight midpoint (centre) of its projected vertices, which places it where the
///   true boundary is nearest rather than at the midpoint of a parameter that need not be
///   arc length.
/// Groups without geometry keep their straight facets. Only displacements are returned: the
/// caller decides how the interior follows (curving/curve_mesh.hpp).

#include "meshmotion/core/element.hpp"
#include "meshmotion/core/error.hpp"
#include "meshmotion/core/mesh.hpp"
#include "meshmotion/core/topology.hpp"
#include "meshmotion/core/types.hpp"
#include "meshmotion/curving/boundary_spline.hpp"
#include "meshmotion/curving/geometry.hpp"
#include "meshmotion/curving/surface_reconstruction.hpp"

#include <algorithm>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace meshmotion {

/// Where a spline puts the high-order node of a facet.
enum class SplineMidpoint {
  parameter,   ///< r(1/2), the thesis's choice
  arc_length,  ///< the point halving the facet's arc length
};

/// How the true boundary of one group is known.
template <int Dim>
struct BoundaryGeometry {
  enum class Kind {
    straight,    ///< keep the straight facets (flat walls, farfields that need no curving)
    spline,      ///< reconstructed from the linear mesh: 2D cubic spline, 3D WALF surface (triangles)
    projection,  ///< closest-point callback onto the true boundary
  };
  Kind kind = Kind::straight;
  BoundaryProjection<Dim> projection{};  ///< for Kind::projection

  [[nodiscard]] static BoundaryGeometry straight() { return {Kind::straight, {}}; }
  [[nodiscard]] static BoundaryGeometry spline() { return {Kind::spline, {}}; }
  [[nodiscard]] static BoundaryGeometry project(BoundaryProjection<Dim> p) { return {Kind::projection, std::move(p)}; }
};

/// Options of snap_boundary().
struct SnapOptions {
  double corner_angle = 30.0;       ///< spline corners: facet directions differing by more (degrees)
  std::vector<Index> corner_nodes;  ///< spline corners whatever their angle
  SplineMidpoint midpoint = SplineMidpoint::parameter;
  /// A vertex whose projection is closer than this (relative to the mesh's bounding-box
  /// diagonal) is already on the geometry and stays.
  double on_geometry_tolerance = 1e-12;
};

/// Result of snap_boundary(): the nodes that move and by how much.
template <int Dim>
struct SnappedBoundary {
  std::vector<Index> nodes;    ///< sorted nodes given a displacement (curved groups' facet nodes)
  Points<Dim> displacements;   ///< Dim × nodes.size(): to the true boundary (0 for those already on it)
  Index moved_vertices = 0;    ///< linear vertices that were off the geometry
  double max_displacement = 0.0;
};

namespace detail {

/// 3D reconstruction of group `tag`: every edge node of its (tri6) facets to the
/// reconstructed edge midpoint; the vertices stay and join the wall.
template <class Claim>
void snap_to_reconstruction(const Mesh<3>& mesh, int tag, const SnapOptions& options, Claim&& claim) {
  std::vector<Index> triangles;
  for (const auto& block : mesh.facets)
    for (Index e = 0; e < block.size(); ++e) {
      if (block.tags[static_cast<std::size_t>(e)] != tag) continue;
      if (shape(block.type) != Shape::triangle)
        throw InputError("snap_boundary: surface reconstruction of group tag " + std::to_string(tag) + " needs triangle facets (got " +
                         std::string(name(block.type)) + "; give a projection callback)");
      const auto el = block.element(e);
      triangles.insert(triangles.end(), el.begin(), el.begin() + 3);
    }
  if (triangles.empty()) return;
  const SurfaceReconstruction surface(mesh.points, triangles, SurfaceReconstructionOptions{3, options.corner_angle});
  for (const auto& block : mesh.facets)
    for (Index e = 0; e < block.size(); ++e) {
      if (block.tags[static_cast<std::size_t>(e)] != tag) continue;
      const auto el = block.element(e);
      for (int k = 0; k < 3; ++k) claim(el[static_cast<std::size_t>(k)], Vec<3>(mesh.points.col(el[static_cast<std::size_t>(k)])));
      const auto local_edges = edges(block.type);
      for (std::size_t k = 0; k < local_edges.size(); ++k)
        claim(el[3 + k], surface.edge_midpoint(el[static_cast<std::size_t>(local_edges[k][0])], el[static_cast<std::size_t>(local_edges[k][1])]));
    }
}

}  // namespace detail

/// Snaps the facet nodes of the groups in `geometry` (group tag → geometry) of a P2 mesh.
/// A node shared by two curved groups takes the first group's (lowest tag) position. Throws
/// InputError for a linear mesh, a 3D reconstruction of quadrilateral facets or a projection
/// without a callback, and what BoundarySpline, SurfaceReconstruction and the projections
/// throw (degenerate chains, too few neighbours, non-finite points).
template <int Dim>
[[nodiscard]] SnappedBoundary<Dim> snap_boundary(const Mesh<Dim>& mesh, const std::map<int, BoundaryGeometry<Dim>>& geometry,
                                                 const SnapOptions& options = {}) {
  for (const auto& block : mesh.facets)
    if (order(block.type) != 2)
      throw InputError("snap_boundary: facet block " + std::string(name(block.type)) +
                       " is not quadratic (expected a P2 mesh from to_quadratic)");
  std::map<Index, Vec<Dim>> target;  // node -> new position, first group wins
  const auto claim = [&](Index v, const Vec<Dim>& x) { target.emplace(v, x); };
  Index moved_vertices = 0;
  const double extent = mesh.num_nodes() > 0
                            ? (mesh.points.rowwise().maxCoeff() - mesh.points.rowwise().minCoeff()).norm()
                            : 0.0;
  for (const auto& entry : geometry) {
    // Named, not a structured binding: the lambdas below capture them (clang 14 cannot).
    const int tag = entry.first;
    const BoundaryGeometry<Dim>& geo = entry.second;
    using Kind = typename BoundaryGeometry<Dim>::Kind;
    if (geo.kind == Kind::straight) continue;
    if (geo.kind == Kind::spline) {
      if constexpr (Dim == 3) {
        detail::snap_to_reconstruction(mesh, tag, options, claim);
      } else {
        const std::vector<BoundaryChain> chains = boundary_chains(mesh, tag);
        if (chains.empty()) continue;
        const BoundarySpline spline(mesh.points, chains,
                                    BoundarySplineOptions{options.corner_angle, options.corner_nodes, {}, {}});
        for (const auto& block : mesh.facets)
          for (Index e = 0; e < block.size(); ++e) {
            if (block.tags[static_cast<std::size_t>(e)] != tag) continue;
            const auto el = block.element(e);
            const auto f = spline.find_facet(el[0], el[1]);
            if (!f) continue;  // a facet on no chain (not a line) cannot happen in 2D
            // The vertices define the spline: they belong to the curved wall and stay.
            claim(el[0], mesh.points.col(el[0]));
            claim(el[1], mesh.points.col(el[1]));
            claim(el[2], options.midpoint == SplineMidpoint::parameter ? spline.midpoint(f->facet)
                                                                        : spline.arc_length_midpoint(f->facet));
          }
      }
      continue;
    }
    if (!geo.projection)
      throw InputError("snap_boundary: group tag " + std::to_string(tag) + " asks for a projection but has no callback");
    // Vertices first: the edge and face nodes are placed from the projected vertices.
    std::map<Index, Vec<Dim>> vertex;
    const auto vertex_position = [&](Index v) -> const Vec<Dim>& {
      auto it = vertex.find(v);
      if (it != vertex.end()) return it->second;
      const Vec<Dim> x = mesh.points.col(v);
      const Vec<Dim> q = geo.projection(x);
      const bool on = (q - x).norm() <= options.on_geometry_tolerance * extent;
      if (!on) ++moved_vertices;
      return vertex.emplace(v, on ? x : q).first->second;
    };
    for (const auto& block : mesh.facets) {
      const int nv = num_vertices(block.type);
      const auto local_edges = edges(block.type);
      for (Index e = 0; e < block.size(); ++e) {
        if (block.tags[static_cast<std::size_t>(e)] != tag) continue;
        const auto el = block.element(e);
        for (int k = 0; k < nv; ++k) claim(el[static_cast<std::size_t>(k)], vertex_position(el[static_cast<std::size_t>(k)]));
        for (std::size_t k = 0; k < local_edges.size(); ++k) {
          const Vec<Dim> mid = 0.5 * (vertex_position(el[static_cast<std::size_t>(local_edges[k][0])]) +
                                      vertex_position(el[static_cast<std::size_t>(local_edges[k][1])]));
          claim(el[static_cast<std::size_t>(nv) + k], geo.projection(mid));
        }
        if (num_nodes(block.type) > nv + static_cast<int>(local_edges.size())) {  // quad9 face node
          Vec<Dim> centre = Vec<Dim>::Zero();
          for (int k = 0; k < nv; ++k) centre += vertex_position(el[static_cast<std::size_t>(k)]) / nv;
          claim(el.back(), geo.projection(centre));
        }
      }
    }
  }
  SnappedBoundary<Dim> out;
  out.moved_vertices = moved_vertices;
  out.displacements.resize(Dim, static_cast<Index>(target.size()));
  Index k = 0;
  for (const auto& [node, x] : target) {
    out.nodes.push_back(node);
    out.displacements.col(k) = x - mesh.points.col(node);
    out.max_displacement = std::max(out.max_displacement, out.displacements.col(k).norm());
    ++k;
  }
  return out;
}

}  // namespace meshmotion
