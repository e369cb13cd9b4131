#pragma once
/// \file
/// Boundary-layer thickness of each wall, estimated from the mesh alone: the layer is the
/// region of anisotropic cells connected to the wall, and its thickness the wall distance
/// where those cells stop being thin across the wall. The curving pipeline derives its default RBF
/// support radius and blending length from it (issue 5: a radius much larger than the
/// layer makes the interpolant overshoot away from the wall).
///
/// Method: cells whose aspect ratio (longest over shortest vertex edge) is at least
/// `aspect_ratio_threshold` and that lie on a wall with a long wall edge (stretched along
/// the wall, not across it) seed a flood fill through shared facets restricted to cells
/// thin across the wall: longest vertex edge at least the threshold times the cell's extent
/// in wall distance (largest minus smallest distance of its vertices). Cells stretched
/// across the wall, or in a spanwise or streamwise direction far from it (the outer cells of
/// a channel grid, anisotropic everywhere), are no boundary layer. Every vertex reached is
/// measured against the straight wall facets (exact point-facet distance) and credited to
/// its nearest wall vertex; a wall vertex's thickness is the largest distance credited to
/// it, a wall's thickness the median over its vertices (robust to the wake of a trailing
/// edge, which is anisotropic too).
/// Cost: linear in the cells of the layer, plus a k-d tree query per vertex reached.

#include "meshmotion/movers/boundary_layer_options.hpp"
#include "meshmotion/core/element.hpp"
#include "meshmotion/core/error.hpp"
#include "meshmotion/core/mesh.hpp"
#include "meshmotion/core/topology.hpp"
#include "meshmotion/core/types.hpp"
#include "meshmotion/movers/detail/wall_distance.hpp"

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace meshmotion {

/// The estimated layer of one wall group.
struct WallLayer {
  std::string group;
  int tag = 0;
  double thickness = 0.0;      ///< median over the wall's vertices of their layer thickness
  double max_thickness = 0.0;  ///< largest over the wall's vertices
  Index layer_cells = 0;       ///< anisotropic cells credited to this wall
};

template <class F>
void visit_fields(const WallLayer& w, F&& f) {
  f("group", w.group, "wall group");
  f("tag", w.tag, "its tag");
  f("thickness", w.thickness, "median layer thickness over the wall's vertices");
  f("max_thickness", w.max_thickness, "largest layer thickness at a wall vertex");
  f("layer_cells", w.layer_cells, "anisotropic cells credited to the wall");
}

/// Layer thickness per wall and per wall vertex.
struct BoundaryLayerEstimate {
  std::vector<WallLayer> walls;       ///< in the order the groups were given
  std::vector<Index> wall_nodes;      ///< sorted wall vertices of all walls
  std::vector<double> node_thickness;  ///< thickness at each of wall_nodes (0: no layer there)

  /// The layer of the named wall; throws InputError when it was not estimated.
  [[nodiscard]] const WallLayer& wall(std::string_view group) const {
    for (const auto& w : walls)
      if (w.group == group) return w;
    throw InputError("BoundaryLayerEstimate::wall: no estimate for group '" + std::string(group) + "'");
  }
};

/// Longest over shortest edge among the vertex edges of one cell (1 for an equilateral
/// cell, large for a stretched one; infinite for a degenerate edge).
template <int Dim>
[[nodiscard]] double cell_aspect_ratio(const Points<Dim>& points, ElementType type, std::span<const Index> nodes) {
  double longest = 0.0, shortest = std::numeric_limits<double>::infinity();
  for (const auto& e : edges(type)) {
    const double length = (points.col(nodes[static_cast<std::size_t>(e[1])]) - points.col(nodes[static_cast<std::size_t>(e[0])])).norm();
    longest = std::max(longest, length);
    shortest = std::min(shortest, length);
  }
  return shortest > 0.0 ? longest / shortest : std::numeric_limits<double>::infinity();
}

namespace detail {

/// A wall's thickness from its vertices' values: their median (nth_element of the middle).
[[nodiscard]] inline double median_thickness(std::vector<double>& values) {
  if (values.empty()) return 0.0;
  auto mid = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), mid, values.end());
  return *mid;
}

/// Each wall's thickness from an estimate made on the same mesh for the same wall vertices
/// grouped differently (a vertex's thickness depends on every wall's facets, not on how they
/// are grouped), without a second estimate; a vertex of two walls counts for the first, as
/// in the estimate. Empty when the estimate's wall vertices are not exactly those of `walls`.
template <class Walls>
[[nodiscard]] std::vector<double> regrouped_thickness(const BoundaryLayerEstimate& estimate, const Walls& walls) {
  std::vector<Index> vertices;
  for (const auto& wall : walls)
    for (const auto& f : wall)
      for (int k = 0; k < num_vertices(f.type); ++k) vertices.push_back(f.nodes[static_cast<std::size_t>(k)]);
  std::sort(vertices.begin(), vertices.end());
  vertices.erase(std::unique(vertices.begin(), vertices.end()), vertices.end());
  if (vertices != estimate.wall_nodes) return {};
  std::vector<double> thickness;
  std::vector<char> seen(vertices.size(), 0);
  for (const auto& wall : walls) {
    std::vector<double> values;
    for (const auto& f : wall)
      for (int k = 0; k < num_vertices(f.type); ++k) {
        const auto s = static_cast<std::size_t>(
            std::lower_bound(vertices.begin(), vertices.end(), f.nodes[static_cast<std::size_t>(k)]) - vertices.begin());
        if (seen[s]) continue;
        seen[s] = 1;
        values.push_back(estimate.node_thickness[s]);
      }
    thickness.push_back(median_thickness(values));
  }
  return thickness;
}

}  // namespace detail

/// Layer thickness of walls given as straight facet lists (`walls[w]`: the facets of wall
/// w, P1 or P2; only vertices are used) in a mesh of any cells. WallLayer::group and tag are
/// left empty. A vertex shared by two walls belongs to the first. `topology`, when given, is
/// unique_facets(mesh) made by the caller (numbered here otherwise). Throws InputError for a
/// threshold below 1 or a facet node out of range.
template <int Dim>
[[nodiscard]] BoundaryLayerEstimate estimate_boundary_layer(const Mesh<Dim>& mesh,
                                                            const std::vector<std::vector<detail::WallFacet>>& walls,
                                                            const BoundaryLayerOptions& options = {},
                                                            const FacetTopology* topology = nullptr) {
  if (!(options.aspect_ratio_threshold >= 1.0))
    throw InputError("estimate_boundary_layer: aspect_ratio_threshold " + std::to_string(options.aspect_ratio_threshold) +
                     " (expected >= 1)");
  BoundaryLayerEstimate out;
  out.walls.resize(walls.size());
  std::vector<detail::WallFacet> all;
  for (const auto& w : walls) all.insert(all.end(), w.begin(), w.end());
  const detail::WallDistance<Dim> wall(mesh.points, std::move(all));
  if (wall.empty()) return out;
  out.wall_nodes = wall.vertices();
  out.node_thickness.assign(out.wall_nodes.size(), 0.0);
  const auto slot = [&](Index v) {
    return static_cast<std::size_t>(std::lower_bound(out.wall_nodes.begin(), out.wall_nodes.end(), v) - out.wall_nodes.begin());
  };
  // The wall (index into out.walls) of each wall vertex: the first listed wall holding it.
  std::vector<std::size_t> owner(out.wall_nodes.size(), out.walls.size());
  for (std::size_t w = walls.size(); w-- > 0;)
    for (const auto& f : walls[w])
      for (int k = 0; k < num_vertices(f.type); ++k) owner[slot(f.nodes[static_cast<std::size_t>(k)])] = w;

  std::vector<Index> block_start{0};
  for (const auto& b : mesh.cells) block_start.push_back(block_start.back() + b.size());
  const auto locate = [&](Index cell) {
    const auto b = static_cast<Index>(std::upper_bound(block_start.begin(), block_start.end(), cell) - block_start.begin()) - 1;
    return std::pair<Index, Index>{b, cell - block_start[static_cast<std::size_t>(b)]};
  };
  const auto cell_nodes = [&](Index cell) {
    const auto [b, e] = locate(cell);
    const auto& block = mesh.cells[static_cast<std::size_t>(b)];
    return std::pair{block.type, block.element(e)};
  };
  std::vector<double> aspect(static_cast<std::size_t>(block_start.back()), -1.0);
  const auto anisotropic = [&](Index cell) {
    double& a = aspect[static_cast<std::size_t>(cell)];
    if (a < 0.0) {
      const auto [type, nodes] = cell_nodes(cell);
      a = cell_aspect_ratio<Dim>(mesh.points, type, nodes.first(static_cast<std::size_t>(num_vertices(type))));
    }
    return a >= options.aspect_ratio_threshold;
  };

  // Wall distance of each vertex, computed when first needed (negative: not yet).
  std::vector<double> distance(static_cast<std::size_t>(mesh.num_nodes()), -1.0);
  const auto wall_distance = [&](Index v) {
    double& d = distance[static_cast<std::size_t>(v)];
    if (d < 0.0) d = wall.closest(Vec<Dim>(mesh.points.col(v))).distance;
    return d;
  };
  const auto thin_across_wall = [&](Index cell) {
    const auto [type, nodes] = cell_nodes(cell);
    double nearest = std::numeric_limits<double>::infinity(), farthest = 0.0;
    for (int k = 0; k < num_vertices(type); ++k) {
      const double d = wall_distance(nodes[static_cast<std::size_t>(k)]);
      nearest = std::min(nearest, d);
      farthest = std::max(farthest, d);
    }
    double longest = 0.0;
    for (const auto& e : edges(type))
      longest = std::max(longest, (mesh.points.col(nodes[static_cast<std::size_t>(e[1])]) -
                                   mesh.points.col(nodes[static_cast<std::size_t>(e[0])])).norm());
    return longest >= options.aspect_ratio_threshold * (farthest - nearest);
  };

  // The wall vertex nearest to each vertex, computed when first needed: a vertex is met once
  // per cell around it.
  std::vector<Index> nearest(static_cast<std::size_t>(mesh.num_nodes()), -1);
  const auto nearest_slot = [&](Index v) {
    Index& s = nearest[static_cast<std::size_t>(v)];
    if (s < 0) s = static_cast<Index>(slot(wall.nearest_vertex(Vec<Dim>(mesh.points.col(v))).first));
    return static_cast<std::size_t>(s);
  };
  std::vector<char> is_wall(static_cast<std::size_t>(mesh.num_nodes()), 0);
  for (const Index v : out.wall_nodes) is_wall[static_cast<std::size_t>(v)] = 1;
  std::vector<char> reached(aspect.size(), 0);
  std::deque<Index> queue;
  // Seeds: anisotropic cells stretched along the wall (a wall edge at least threshold times
  // their shortest edge). Cells stretched across it, as the outer cells of an O-mesh at a
  // farfield, are no boundary layer.
  const auto stretched_along_wall = [&](ElementType type, std::span<const Index> nodes) {
    double shortest = std::numeric_limits<double>::infinity(), wall_edge = 0.0;
    for (const auto& e : edges(type)) {
      const Index a = nodes[static_cast<std::size_t>(e[0])], b = nodes[static_cast<std::size_t>(e[1])];
      const double length = (mesh.points.col(a) - mesh.points.col(b)).norm();
      shortest = std::min(shortest, length);
      if (is_wall[static_cast<std::size_t>(a)] && is_wall[static_cast<std::size_t>(b)]) wall_edge = std::max(wall_edge, length);
    }
    return wall_edge >= options.aspect_ratio_threshold * shortest;
  };
  for (Index cell = 0; cell < block_start.back(); ++cell) {
    const auto [type, nodes] = cell_nodes(cell);
    if (anisotropic(cell) && stretched_along_wall(type, nodes)) {
      reached[static_cast<std::size_t>(cell)] = 1;
      queue.push_back(cell);
    }
  }
  const FacetTopology numbered = topology != nullptr ? FacetTopology{} : unique_facets(mesh);
  const FacetTopology& topo = topology != nullptr ? *topology : numbered;
  std::vector<char> measured(static_cast<std::size_t>(mesh.num_nodes()), 0);
  while (!queue.empty()) {
    const Index cell = queue.front();
    queue.pop_front();
    const auto [type, nodes] = cell_nodes(cell);
    std::size_t credited = out.walls.size();
    for (int k = 0; k < num_vertices(type); ++k) {
      const Index v = nodes[static_cast<std::size_t>(k)];
      const std::size_t s = nearest_slot(v);
      credited = std::min(credited, owner[s]);
      if (measured[static_cast<std::size_t>(v)] || is_wall[static_cast<std::size_t>(v)]) continue;
      measured[static_cast<std::size_t>(v)] = 1;
      out.node_thickness[s] = std::max(out.node_thickness[s], wall_distance(v));
    }
    if (credited < out.walls.size()) ++out.walls[credited].layer_cells;
    const auto [b, e] = locate(cell);
    for (const Index f : topo.element_facets.of(b, e))
      for (const Index next : topo.elements[static_cast<std::size_t>(f)])
        if (next >= 0 && !reached[static_cast<std::size_t>(next)] && thin_across_wall(next)) {
          reached[static_cast<std::size_t>(next)] = 1;
          queue.push_back(next);
        }
  }
  for (std::size_t w = 0; w < out.walls.size(); ++w) {
    std::vector<double> values;
    for (std::size_t s = 0; s < out.wall_nodes.size(); ++s)
      if (owner[s] == w) values.push_back(out.node_thickness[s]);
    if (values.empty()) continue;
    out.walls[w].max_thickness = *std::max_element(values.begin(), values.end());
    out.walls[w].thickness = detail::median_thickness(values);
  }
  return out;
}

/// Estimates the boundary-layer thickness of each of `wall_groups` (groups of dimension
/// Dim - 1) of a linear or quadratic mesh (only vertices are used); `topology` as above.
/// Throws InputError for an empty group list, an unknown group or one that is not a facet
/// group, and a threshold below 1.
template <int Dim>
[[nodiscard]] BoundaryLayerEstimate estimate_boundary_layer(const Mesh<Dim>& mesh,
                                                            std::span<const std::string> wall_groups,
                                                            const BoundaryLayerOptions& options = {},
                                                            const FacetTopology* topology = nullptr) {
  if (wall_groups.empty()) throw InputError("estimate_boundary_layer: no wall group given (expected at least one)");
  std::vector<std::vector<detail::WallFacet>> walls;
  for (const auto& name : wall_groups) {
    const PhysicalGroup& g = mesh.group(name);
    if (g.dim != Dim - 1)
      throw InputError("estimate_boundary_layer: group '" + name + "' has dimension " + std::to_string(g.dim) +
                       " (expected a wall of dimension " + std::to_string(Dim - 1) + ")");
    const int tag = g.tag;
    walls.push_back(detail::wall_facets(mesh, std::span<const int>(&tag, 1)));
  }
  BoundaryLayerEstimate out = estimate_boundary_layer(mesh, walls, options, topology);
  for (std::size_t w = 0; w < wall_groups.size(); ++w) {
    out.walls[w].group = wall_groups[w];
    out.walls[w].tag = mesh.group(wall_groups[w]).tag;
  }
  return out;
}

}  // namespace meshmotion
