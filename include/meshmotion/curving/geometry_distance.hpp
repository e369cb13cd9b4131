#pragma once
/// \file
/// The geometric certificate of a curved mesh: how far each curved wall lies from the
/// geometry it was curved onto. The validity certificate (det J > 0) cannot see a wall that
/// is valid but in the wrong place (a node taken the long way round a closed curve, a model
/// that fits the mesh badly); this one measures it.
///
/// Each facet of a curved group is sampled on a lattice of order 2p (p the facet's order: 5
/// points along a P2 edge, 15 on a P2 triangle) and at its nodes. At each sample x the error
/// d = x - g(x) is taken against the group's geometry g:
/// - a projection (analytic shape, CAD model): g is the closest point, |d| the distance;
/// - a 2D spline: g is the closest point of the facet's own spline segment (an upper bound);
/// - a 3D surface reconstruction: g is the reconstructed surface at the same barycentric place
///   (its ridge curve on a ridge edge), an upper bound on the distance.
/// Between samples the error is bounded by the largest sampled |d| plus the largest second
/// difference of d along the lattice's lines times 1/4 (a line) or 1/2 (a face): twice what
/// an error quadratic between samples needs, since the error of a P2 facet on a circle is
/// quartic (zero at its nodes, largest between them), and checked against dense sampling by
/// the tests. A
/// facet's bound is reported absolute and relative to its size (the longest distance between
/// two of its vertices); a facet whose relative bound exceeds the tolerance is off the geometry.

#include "meshmotion/core/element.hpp"
#include "meshmotion/core/mesh.hpp"
#include "meshmotion/core/shape_functions.hpp"
#include "meshmotion/core/types.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <map>
#include <span>
#include <string>
#include <vector>

namespace meshmotion {

/// How far one curved wall lies from its geometry (geometry_distance.hpp's file comment).
struct GeometryDistance {
  std::string group;
  std::string geometry;                ///< "projection", "spline" (2D) or "reconstruction" (3D)
  Index facets = 0;
  double max_node_distance = 0.0;      ///< the farthest facet node
  double max_distance = 0.0;           ///< the largest bound inside a facet
  double max_relative_distance = 0.0;  ///< the largest bound of a facet over its size
  Index facets_off = 0;                ///< facets whose relative bound exceeds the tolerance
  std::array<double, 3> worst_at{};    ///< the mean of the vertices of the facet of max_relative_distance
};

template <class F>
void visit_fields(const GeometryDistance& w, F&& f) {
  f("group", w.group, "curved group");
  f("geometry", w.geometry, "what it was curved onto: projection (analytic or CAD), spline (2D), reconstruction (3D)");
  f("facets", w.facets, "its facets");
  f("max_node_distance", w.max_node_distance, "largest distance of a facet node to the geometry");
  f("max_distance", w.max_distance, "largest bound of a facet's distance to the geometry (sampled inside it)");
  f("max_relative_distance", w.max_relative_distance, "largest bound of a facet's distance over the facet's size");
  f("facets_off", w.facets_off, "facets farther than the tolerance (relative) from the geometry");
  f("worst_at", w.worst_at, "the mean of the vertices of the farthest facet (relative)");
}

/// A point of a curved facet, where it is measured against the geometry.
template <int Dim>
struct FacetPoint {
  std::span<const Index> facet;        ///< the facet's nodes, vertices first
  std::span<const Vec<Dim>> vertices;  ///< the vertices' positions
  Index ordinal = 0;                   ///< the facet's number among its group's facets (blocks in order)
  std::span<const double> weights;     ///< the vertices' weights at the point
  Vec<Dim> x;
};

/// The point of a group's geometry that a point of one of its facets is measured against.
template <int Dim>
using FacetReference = std::function<Vec<Dim>(const FacetPoint<Dim>&)>;

/// What a curved group is measured against: the kind (GeometryDistance::geometry) and the point.
template <int Dim>
struct GeometryReference {
  std::string kind;
  FacetReference<Dim> at;
};

namespace detail {

/// A sample lattice of order m on a facet's reference shape: (i, j) with i + j <= m on a
/// triangle, i, j <= m on a quadrilateral, j = 0 on a line.
struct FacetLattice {
  Shape shape;
  int m;
  [[nodiscard]] bool has(int i, int j) const {
    if (i < 0 || j < 0 || i > m || j > m) return false;
    if (shape == Shape::line) return j == 0;
    return shape != Shape::triangle || i + j <= m;
  }
  [[nodiscard]] RefPoint point(int i, int j) const {
    const double u = static_cast<double>(i) / m, v = static_cast<double>(j) / m;
    if (shape == Shape::triangle) return {u, v, 0.0};
    return {2.0 * u - 1.0, shape == Shape::line ? 0.0 : 2.0 * v - 1.0, 0.0};
  }
};

struct FacetDistance {
  double node = 0.0;   // largest |d| at the facet's nodes
  double bound = 0.0;  // bound of |d| over the facet
  double size = 0.0;
};

template <int Dim>
[[nodiscard]] FacetDistance facet_distance(const Mesh<Dim>& mesh, ElementType type, std::span<const Index> facet, Index ordinal,
                                           const FacetReference<Dim>& reference) {
  const int nv = num_vertices(type);
  const auto n = facet.size();
  std::array<double, max_facet_nodes> values{};
  std::array<double, 8> weights{};
  const std::span<double> N(values.data(), n), w(weights.data(), static_cast<std::size_t>(nv));
  const ElementType linear = linear_type(type);
  std::array<Vec<Dim>, 8> corners;
  for (int k = 0; k < nv; ++k) corners[static_cast<std::size_t>(k)] = mesh.points.col(facet[static_cast<std::size_t>(k)]);
  FacetPoint<Dim> point{facet, std::span<const Vec<Dim>>(corners.data(), static_cast<std::size_t>(nv)), ordinal, w, Vec<Dim>::Zero()};
  const auto error = [&](const RefPoint& r) -> Vec<Dim> {
    shape_functions(type, r, N);
    shape_functions(linear, r, w);
    point.x.setZero();
    for (std::size_t i = 0; i < n; ++i) point.x += N[i] * mesh.points.col(facet[i]);
    return point.x - reference(point);
  };
  FacetDistance out;
  for (int a = 0; a < nv; ++a)
    for (int b = a + 1; b < nv; ++b)
      out.size = std::max(out.size, (corners[static_cast<std::size_t>(a)] - corners[static_cast<std::size_t>(b)]).norm());

  const FacetLattice lattice{shape(type), 2 * order(type)};
  const int m = lattice.m;
  std::vector<Vec<Dim>> d(static_cast<std::size_t>((m + 1) * (m + 1)), Vec<Dim>::Zero());
  const auto at = [&](int i, int j) -> Vec<Dim>& { return d[static_cast<std::size_t>(i * (m + 1) + j)]; };
  // The nodes lie on the lattice of order 2p (Gmsh's nodes are equally spaced): their errors
  // come with the lattice's, and a node off it is sampled on its own.
  const auto nodes = reference_nodes(type);
  std::array<char, max_facet_nodes> sampled{};
  double largest = 0.0, curvature = 0.0;
  for (int i = 0; i <= m; ++i)
    for (int j = 0; j <= m; ++j) {
      if (!lattice.has(i, j)) continue;
      const RefPoint r = lattice.point(i, j);
      const double e = (at(i, j) = error(r)).norm();
      largest = std::max(largest, e);
      for (std::size_t k = 0; k < n; ++k)
        if (std::abs(nodes[k][0] - r[0]) + std::abs(nodes[k][1] - r[1]) < 1e-12) {
          sampled[k] = 1;
          out.node = std::max(out.node, e);
        }
    }
  for (std::size_t k = 0; k < n; ++k)
    if (!sampled[k]) out.node = std::max(out.node, error(nodes[k]).norm());
  largest = std::max(largest, out.node);
  // Second differences along the lattice's lines: i, j, and the triangle's third direction.
  constexpr std::array<std::array<int, 2>, 3> directions{{{1, 0}, {0, 1}, {1, -1}}};
  const int lines = lattice.shape == Shape::line ? 1 : lattice.shape == Shape::triangle ? 3 : 2;
  for (int i = 0; i <= m; ++i)
    for (int j = 0; j <= m; ++j)
      for (int k = 0; k < lines; ++k) {
        const auto [di, dj] = directions[static_cast<std::size_t>(k)];
        if (lattice.has(i - di, j - dj) && lattice.has(i, j) && lattice.has(i + di, j + dj))
          curvature = std::max(curvature, (at(i - di, j - dj) - 2.0 * at(i, j) + at(i + di, j + dj)).norm());
      }
  out.bound = largest + curvature * (lattice.shape == Shape::line ? 0.25 : 0.5);
  return out;
}

}  // namespace detail

/// The geometric certificate (file comment) of the groups in `references` (group tag → what
/// it is measured against), in tag order; `tolerance` bounds a facet's distance relative to
/// its size (GeometryDistance::facets_off).
template <int Dim>
[[nodiscard]] std::vector<GeometryDistance> measure_geometry_distance(const Mesh<Dim>& mesh,
                                                                  const std::map<int, GeometryReference<Dim>>& references,
                                                                  double tolerance) {
  std::vector<GeometryDistance> out;
  for (const auto& [tag, reference] : references) {
    GeometryDistance& wall = out.emplace_back();
    wall.geometry = reference.kind;
    for (const auto& g : mesh.groups)
      if (g.dim == Dim - 1 && g.tag == tag) wall.group = g.name;
    for (const auto& block : mesh.facets)
      for (Index e = 0; e < block.size(); ++e) {
        if (block.tags[static_cast<std::size_t>(e)] != tag) continue;
        const auto facet = block.element(e);
        const detail::FacetDistance f = detail::facet_distance<Dim>(mesh, block.type, facet, wall.facets++, reference.at);
        wall.max_node_distance = std::max(wall.max_node_distance, f.node);
        wall.max_distance = std::max(wall.max_distance, f.bound);
        const double relative = f.size > 0.0 ? f.bound / f.size : (f.bound > 0.0 ? INFINITY : 0.0);
        if (relative > tolerance) ++wall.facets_off;
        if (relative > wall.max_relative_distance || wall.facets == 1) {
          wall.max_relative_distance = relative;
          wall.worst_at = {};
          const int nv = num_vertices(block.type);
          for (int k = 0; k < nv; ++k)
            for (int c = 0; c < Dim; ++c) wall.worst_at[static_cast<std::size_t>(c)] += mesh.points(c, facet[static_cast<std::size_t>(k)]) / nv;
        }
      }
  }
  return out;
}

}  // namespace meshmotion
