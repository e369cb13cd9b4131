#pragma once
/// \file
/// Boundary snapping, the second step of the curving pipeline (thesis section 3.2): the
/// nodes of the boundary facets of a high-order mesh (straight, as to_quadratic() or
/// convert_to_order() make them) are moved onto the true boundary of their group, each at its
/// place along the curved edge or face (at order 2, the midpoint), the true boundary being
/// known either
/// - from the linear mesh alone in 2D: a C² cubic spline through the group's vertices
///   (BoundarySpline; corners by angle or list), an edge node at fraction r of its facet going
///   to the spline at fraction r of the arc length (default) or at parameter r (thesis);
///   vertices stay;
/// - from the linear mesh alone in 3D: the WALF surface reconstruction of the group's
///   triangles (SurfaceReconstruction, ridges sharp above the corner angle), edge nodes to the
///   reconstructed edge, nodes inside a facet to the reconstructed triangle; vertices stay; or
/// - from a closest-point projection (analytic or CAD geometry, any dimension): vertices
///   off the geometry are projected, then every edge node goes to the projection of its
///   place on the straight facet through the projected vertices (or where the geometry's
///   placement puts it), which places it where the true boundary is nearest rather than at a
///   parameter that need not be arc length; nodes inside a facet go to the projection of
///   their place on the facet curved by its edges (inner_nodes.hpp).
/// Groups without geometry keep their straight facets. Only displacements are returned: the
/// caller decides how the interior follows (curving/curve_mesh.hpp).

#include "meshmotion/core/element.hpp"
#include "meshmotion/core/error.hpp"
#include "meshmotion/core/mesh.hpp"
#include "meshmotion/core/option_text.hpp"
#include "meshmotion/core/shape_functions.hpp"
#include "meshmotion/core/topology.hpp"
#include "meshmotion/core/types.hpp"
#include "meshmotion/curving/boundary_spline.hpp"
#include "meshmotion/curving/geometry.hpp"
#include "meshmotion/curving/geometry_distance.hpp"
#include "meshmotion/curving/inner_nodes.hpp"
#include "meshmotion/curving/surface_reconstruction.hpp"

#include <algorithm>
#include <array>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace meshmotion {

/// Where a spline puts the high-order node of a facet.
enum class SplineMidpoint {
  parameter,   ///< r(1/2), the thesis's choice
  arc_length,  ///< the point halving the facet's arc length
};
[[nodiscard]] constexpr std::string_view name(SplineMidpoint m) { return m == SplineMidpoint::parameter ? "parameter" : "arc_length"; }
[[nodiscard]] constexpr std::array<SplineMidpoint, 2> option_choices(SplineMidpoint) {
  return {SplineMidpoint::arc_length, SplineMidpoint::parameter};
}

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
  /// For Kind::projection, optional: where an edge node goes given its facet's vertices
  /// (already on the geometry) and its weights on them; a CAD model follows the vertices'
  /// common CAD edge at equal arc lengths (cad/cad_model.hpp). Without it the node goes to the
  /// projection of its place on the straight facet. Nodes inside a facet always go to the
  /// projection of their place on the facet curved by its edges.
  BoundaryPlacement<Dim> placement{};
  /// For Kind::projection, optional: the projection of a point of a facet searched from its
  /// vertices' places (a CAD model's local search), for the geometric certificate's many
  /// samples. Without it, `projection`.
  BoundaryNearby<Dim> nearby{};

  [[nodiscard]] static BoundaryGeometry straight() { return {Kind::straight, {}, {}, {}}; }
  [[nodiscard]] static BoundaryGeometry spline() { return {Kind::spline, {}, {}, {}}; }
  [[nodiscard]] static BoundaryGeometry project(BoundaryProjection<Dim> p, BoundaryPlacement<Dim> q = {}, BoundaryNearby<Dim> n = {}) {
    return {Kind::projection, std::move(p), std::move(q), std::move(n)};
  }
  /// The closest point of the geometry to x, a point of the facet through `vertices` at `weights`.
  [[nodiscard]] Vec<Dim> project_in_facet(std::span<const Vec<Dim>> vertices, std::span<const double> weights, const Vec<Dim>& x) const {
    return nearby ? nearby(vertices, weights, x) : projection(x);
  }
};

/// Options of snap_boundary().
struct SnapOptions {
  double corner_angle = 30.0;
  std::vector<Index> corner_nodes;
  SplineMidpoint midpoint = SplineMidpoint::arc_length;
  double on_geometry_tolerance = 1e-12;
};

template <class F>
void visit_options(SnapOptions& o, F&& f, const std::string& prefix = {}) {
  f(prefix + "corner_angle", o.corner_angle, OptionHelp{"spline corners: facet directions differing by more (degrees)", range::between(0, 180)});
  f(prefix + "corner_nodes", o.corner_nodes, "spline corners whatever their angle (node indices, comma-separated)");
  f(prefix + "midpoint", o.midpoint, OptionHelp{"spline facet nodes at fractions of its arc_length, or of its parameter (the thesis)", {},
      "Where a spline facet's nodes go: at fractions of its arc length (default), or of its parameter (the "
      "thesis). The parameter need not be arc length, and the tangential offset it gives a wall node is "
      "carried into a thin layer (the measurements: docs/curving.md, \"Spline midpoints\")."});
  f(prefix + "on_geometry_tolerance", o.on_geometry_tolerance,
    OptionHelp{"a vertex closer than this x the mesh diagonal to its projection is on the geometry and stays", range::non_negative});
}

/// Result of snap_boundary(): the nodes that move and by how much.
template <int Dim>
struct SnappedBoundary {
  std::vector<Index> nodes;    ///< sorted nodes given a displacement (curved groups' facet nodes)
  Points<Dim> displacements;   ///< Dim × nodes.size(): to the true boundary (0 for those already on it)
  Index moved_vertices = 0;    ///< linear vertices that were off the geometry
  double max_displacement = 0.0;
  /// Per curved group tag: what its facets are measured against (measure_geometry_distance()).
  std::map<int, GeometryReference<Dim>> references;
};

namespace detail {

// Each high-order node of a facet type: its reference point, and the weights of the facet's
// vertices there (where a straight facet has the node).
struct FacetNodeWeights {
  std::vector<RefPoint> reference;
  std::vector<std::vector<double>> weights;  // [node][vertex]
};

inline const FacetNodeWeights& facet_node_weights(ElementType t) {
  static PerTypeCache<FacetNodeWeights> tables;
  return tables.get(t, [](ElementType type) {
    FacetNodeWeights table;
    const auto x = reference_nodes(type);
    table.reference.assign(x.begin(), x.end());
    for (const RefPoint& r : x) {
      auto& w = table.weights.emplace_back(static_cast<std::size_t>(num_vertices(type)));
      shape_functions(linear_type(type), r, w);
    }
    return table;
  });
}

/// 3D reconstruction of group `tag`: every edge node of its triangle facets to the
/// reconstructed edge at its fraction of the edge, every node inside a facet to the
/// reconstructed triangle at its barycentric place; the vertices stay and join the wall.
/// Returns the reconstruction as the group's reference: the surface at a point's barycentric
/// place, or its ridge curve on a ridge edge (null for a group without facets).
template <class Claim>
[[nodiscard]] FacetReference<3> snap_to_reconstruction(const Mesh<3>& mesh, int tag, const SnapOptions& options, Claim&& claim) {
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
  if (triangles.empty()) return {};
  const auto shared = std::make_shared<const SurfaceReconstruction>(mesh.points, triangles,
                                                                    SurfaceReconstructionOptions{3, options.corner_angle});
  const SurfaceReconstruction& surface = *shared;
  Index triangle = 0;  // the reconstruction's numbering: the facets in the order given above
  for (const auto& block : mesh.facets) {
    const FacetNodeWeights& table = facet_node_weights(block.type);
    const int p = order(block.type);
    const auto local_edges = edges(block.type);
    for (Index e = 0; e < block.size(); ++e) {
      if (block.tags[static_cast<std::size_t>(e)] != tag) continue;
      const auto el = block.element(e);
      for (int k = 0; k < 3; ++k) claim(el[static_cast<std::size_t>(k)], Vec<3>(mesh.points.col(el[static_cast<std::size_t>(k)])));
      for (std::size_t k = 0; k < local_edges.size(); ++k)
        for (int j = 1; j < p; ++j)
          claim(el[3 + k * static_cast<std::size_t>(p - 1) + static_cast<std::size_t>(j - 1)],
                surface.edge_point(el[static_cast<std::size_t>(local_edges[k][0])], el[static_cast<std::size_t>(local_edges[k][1])],
                                   static_cast<double>(j) / p));
      for (std::size_t i = 3 + local_edges.size() * static_cast<std::size_t>(p - 1); i < el.size(); ++i) {
        const auto& w = table.weights[i];
        claim(el[i], surface.point(triangle, Vec<3>(w[0], w[1], w[2])));
      }
      ++triangle;
    }
  }
  return [shared](const FacetPoint<3>& p) -> Vec<3> {
    const std::span<const double> w = p.weights;
    for (int k = 0; k < 3; ++k) {
      const auto a = static_cast<std::size_t>((k + 1) % 3), b = static_cast<std::size_t>((k + 2) % 3);
      if (std::abs(w[static_cast<std::size_t>(k)]) < 1e-12 && shared->is_ridge(p.facet[a], p.facet[b]))
        return shared->edge_point(p.facet[a], p.facet[b], w[b]);
    }
    return shared->point(p.ordinal, Vec<3>(w[0], w[1], w[2]));
  };
}

}  // namespace detail

/// Snaps the facet nodes of the groups in `geometry` (group tag → geometry) of a high-order
/// mesh (any order; each node at its place along the curved edge or face).
/// A node shared by two curved groups takes the first group's (lowest tag) position. Throws
/// InputError for a linear mesh, a 3D reconstruction of quadrilateral facets or a projection
/// without a callback, and what BoundarySpline, SurfaceReconstruction and the projections
/// throw (degenerate chains, too few neighbours, non-finite points).
template <int Dim>
[[nodiscard]] SnappedBoundary<Dim> snap_boundary(const Mesh<Dim>& mesh, const std::map<int, BoundaryGeometry<Dim>>& geometry,
                                                 const SnapOptions& options = {}) {
  for (const auto& block : mesh.facets)
    if (order(block.type) < 2)
      throw InputError("snap_boundary: facet block " + std::string(name(block.type)) +
                       " is linear (expected a high-order mesh from to_quadratic or convert_to_order)");
  std::map<Index, Vec<Dim>> target;  // node -> new position, first group wins
  std::map<int, GeometryReference<Dim>> references;
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
        if (FacetReference<3> at = detail::snap_to_reconstruction(mesh, tag, options, claim))
          references.emplace(tag, GeometryReference<3>{"reconstruction", std::move(at)});
      } else {
        const std::vector<BoundaryChain> chains = boundary_chains(mesh, tag);
        if (chains.empty()) continue;
        const auto shared = std::make_shared<const BoundarySpline>(
            mesh.points, chains, BoundarySplineOptions{options.corner_angle, options.corner_nodes, {}, {}});
        const BoundarySpline& spline = *shared;
        references.emplace(tag, GeometryReference<2>{"spline", [shared](const FacetPoint<2>& p) {
                             const auto f = shared->find_facet(p.facet[0], p.facet[1]);
                             return f ? shared->closest_point(f->facet, p.x).point : p.x;
                           }});
        for (const auto& block : mesh.facets)
          for (Index e = 0; e < block.size(); ++e) {
            if (block.tags[static_cast<std::size_t>(e)] != tag) continue;
            const auto el = block.element(e);
            const auto f = spline.find_facet(el[0], el[1]);
            if (!f) continue;  // a facet on no chain (not a line) cannot happen in 2D
            // The vertices define the spline: they belong to the curved wall and stay.
            claim(el[0], mesh.points.col(el[0]));
            claim(el[1], mesh.points.col(el[1]));
            const detail::FacetNodeWeights& table = detail::facet_node_weights(block.type);
            for (std::size_t i = 2; i < el.size(); ++i) {
              const double r = table.weights[i][1];  // fraction of the way from el[0] to el[1]
              const double t = f->reversed ? 1.0 - r : r;
              claim(el[i], options.midpoint == SplineMidpoint::parameter ? spline.point(f->facet, t)
                                                                         : spline.point(f->facet, spline.arc_length_parameter(f->facet, t)));
            }
          }
      }
      continue;
    }
    if (!geo.projection)
      throw InputError("snap_boundary: group tag " + std::to_string(tag) + " asks for a projection but has no callback");
    references.emplace(tag, GeometryReference<Dim>{"projection", [geo](const FacetPoint<Dim>& p) {
                         return geo.project_in_facet(p.vertices, p.weights, p.x);
                       }});
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
    // Every other facet node: the projection of its place on the straight facet through
    // the projected vertices (an edge's midpoint, a quad9's centre at order 2).
    for (const auto& block : mesh.facets) {
      const int nv = num_vertices(block.type);
      const detail::FacetNodeWeights& table = detail::facet_node_weights(block.type);
      for (Index e = 0; e < block.size(); ++e) {
        if (block.tags[static_cast<std::size_t>(e)] != tag) continue;
        const auto el = block.element(e);
        for (int k = 0; k < nv; ++k) claim(el[static_cast<std::size_t>(k)], vertex_position(el[static_cast<std::size_t>(k)]));
        std::array<Vec<Dim>, 8> corners;
        for (int k = 0; k < nv; ++k) corners[static_cast<std::size_t>(k)] = vertex_position(el[static_cast<std::size_t>(k)]);
        const std::span<const Vec<Dim>> at(corners.data(), static_cast<std::size_t>(nv));
        const auto inside_first = static_cast<std::size_t>(detail::first_inside_node(block.type));
        for (std::size_t i = static_cast<std::size_t>(nv); i < std::min(el.size(), inside_first); ++i) {
          const std::span<const double> w(table.weights[i]);
          if (geo.placement) {
            claim(el[i], geo.placement(at, w));
            continue;
          }
          Vec<Dim> x = Vec<Dim>::Zero();
          for (int k = 0; k < nv; ++k) x += w[static_cast<std::size_t>(k)] * at[static_cast<std::size_t>(k)];
          claim(el[i], geo.projection(x));
        }
        if (inside_first >= el.size()) continue;
        // Nodes inside a face follow its curved edges (inner_nodes.hpp), then go to the
        // geometry: placed from the vertices alone, they would ignore how the edges bend
        // (on a sphere near its pole, parameter lines are far from great circles).
        Eigen::Matrix<double, Dim, Eigen::Dynamic> x(Dim, static_cast<Index>(el.size()));
        for (std::size_t i = 0; i < el.size(); ++i) {
          if (i < inside_first) {
            x.col(static_cast<Index>(i)) = target.at(el[i]);
            continue;
          }
          x.col(static_cast<Index>(i)).setZero();
          for (int k = 0; k < nv; ++k) x.col(static_cast<Index>(i)) += table.weights[i][static_cast<std::size_t>(k)] * at[static_cast<std::size_t>(k)];
        }
        std::array<int, max_facet_nodes> inside{};
        for (std::size_t i = inside_first; i < el.size(); ++i) inside[i - inside_first] = static_cast<int>(i);
        detail::extend_inside<Dim>(block.type, x, std::span<const int>(inside.data(), el.size() - inside_first));
        for (std::size_t i = inside_first; i < el.size(); ++i) claim(el[i], geo.projection(x.col(static_cast<Index>(i))));
      }
    }
  }
  SnappedBoundary<Dim> out;
  out.moved_vertices = moved_vertices;
  out.references = std::move(references);
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
