#pragma once
/// \file
/// The curving pipeline's radius policy: the default support radii from each wall's layer or
/// node spacing, limited to a node budget per support, and a radius per boundary entry.

#include "meshmotion/curving/detail/curving_groups.hpp"

namespace meshmotion {

namespace detail {

/// The largest radius ≤ `radius` whose ball around a node of `moving` holds at most `budget`
/// nodes of `boundary` on average (a sample of up to 256 of them). Supports on a surface hold
/// ~r² nodes, on a curve ~r: a few rescaling rounds settle either.
template <int Dim>
[[nodiscard]] double limit_support_radius(const Mesh<Dim>& mesh, const ResolvedBoundary<Dim>& boundary,
                                          const std::vector<Index>& moving, double radius, double budget) {
  if (moving.empty() || !(budget > 0.0)) return radius;
  Points<Dim> at(Dim, boundary.size());
  for (Index k = 0; k < boundary.size(); ++k) at.col(k) = mesh.points.col(boundary.nodes[static_cast<std::size_t>(k)]);
  const KdTree<Dim> tree(at);
  const std::size_t stride = std::max<std::size_t>(1, moving.size() / 256);
  std::vector<Neighbor> found;
  for (int round = 0; round < 4; ++round) {
    double total = 0.0, samples = 0.0;
    for (std::size_t i = 0; i < moving.size(); i += stride, samples += 1.0)
      total += static_cast<double>(tree.radius_search(Vec<Dim>(mesh.points.col(moving[i])), radius, found));
    const double mean = total / samples;
    if (mean <= budget) break;
    radius *= std::sqrt(budget / mean);
  }
  return radius;
}

/// The wall (index into `walls`) of each node of the facets of the named groups; -1 for other
/// nodes. A node shared by two walls belongs to the first listed.
template <int Dim>
[[nodiscard]] std::vector<int> wall_of_nodes(const Mesh<Dim>& mesh, const std::vector<std::string>& walls) {
  std::vector<int> wall_of(static_cast<std::size_t>(mesh.num_nodes()), -1);
  for (std::size_t w = walls.size(); w-- > 0;) {
    const int tag = mesh.group(walls[w]).tag;
    for (const auto& block : mesh.facets)
      for (Index e = 0; e < block.size(); ++e)
        if (block.tags[static_cast<std::size_t>(e)] == tag)
          for (const Index v : block.element(e)) wall_of[static_cast<std::size_t>(v)] = static_cast<int>(w);
  }
  return wall_of;
}

/// Default support radii from the wall layers (see CurveOptions::support_radius).
struct DefaultRadii {
  double uniform = 0.0;          ///< one radius for every wall: the thickest layer's
  std::vector<double> per_wall;  ///< each wall's own: its layer's, or its largest local radius without a layer
  std::vector<double> per_node;  ///< nodes of walls without a layer: local_spacing_radii() (0 elsewhere)
  bool limited = false;          ///< some wall's layer radius was shrunk to max_support_nodes
};

/// For the nodes of the facets tagged `tag`: 2 × the node spacing of the largest facet holding
/// the node (its mean vertex-to-vertex edge length over the order), written into `radii`
/// (num_nodes entries). A wall without a boundary layer has nothing else to size its motion
/// by, and its spacing varies: on the RAE2822 the leading edge's cells are 0.007 wide where
/// the wall's median spacing gives a radius of 0.058, which spreads the leading edge's
/// displacement over many cells and lowers the snapped quality (0.79 to 0.61 at P2). With 2
/// the RBF raises it instead at orders 2 to 4; 1 leaves it as snapped, 4 lowers it
/// (docs/curving.md, "A radius per node on walls without a layer").
/// A facet snapped away from its cell (detail::bulging_away(): a farfield circle) only enlarges
/// it, and one that hardly moves has nothing to spread: they get half their spacing, which
/// reaches no other node, so their motion stays on them, as the blend leaves the first. At 2
/// spacings the 30P30N's farfield nodes took a radius of 1.03 and the RBF setup 2.5 s for the
/// minimum that a radius of 0.0022 gives in a tenth of the time.
template <int Dim>
void local_spacing_radii(const Mesh<Dim>& mesh, int tag, const SnappedBoundary<Dim>& snapped, std::vector<double>& radii) {
  const std::vector<WallFacet> wall = wall_facets(mesh, std::span<const int>(&tag, 1));
  const auto displacement = [&](Index v) -> Vec<Dim> {
    const auto it = std::lower_bound(snapped.nodes.begin(), snapped.nodes.end(), v);
    if (it == snapped.nodes.end() || *it != v) return Vec<Dim>::Zero();
    return snapped.displacements.col(static_cast<Index>(it - snapped.nodes.begin()));
  };
  const std::vector<char> away = bulging_away(mesh, wall, displacement);
  for (std::size_t i = 0; i < wall.size(); ++i) {
    const WallFacet& f = wall[i];
    const auto sides = edges(f.type);
    double length = 0.0;
    for (const auto& side : sides)
      length += (mesh.points.col(f.nodes[static_cast<std::size_t>(side[0])]) - mesh.points.col(f.nodes[static_cast<std::size_t>(side[1])])).norm();
    const double spacing = length / static_cast<double>(sides.size() * static_cast<std::size_t>(order(f.type)));
    // A facet moved by at most 2% of its spacing dents its cell by as little: the 30P30N
    // farfield's flat side has 49 such facets bulging inward where the spline meets its arc.
    const auto nodes = std::span<const Index>(f.nodes.data(), static_cast<std::size_t>(num_nodes(f.type)));
    const bool slight = std::all_of(nodes.begin(), nodes.end(), [&](Index v) { return displacement(v).norm() <= 0.02 * spacing; });
    const double radius = (away[i] != 0 || slight ? 0.5 : 2.0) * spacing;
    for (int k = 0; k < num_nodes(f.type); ++k) {
      double& r = radii[static_cast<std::size_t>(f.nodes[static_cast<std::size_t>(k)])];
      r = std::max(r, radius);
    }
  }
}

/// suggest_support_radius() over the snapped nodes for which keep(node) holds, with 3 wall
/// node spacings; 0 for fewer than two such nodes. Curving displacements are tiny, so the
/// spacing term decides. The motion default (10 spacings) spans the whole body on the sphere
/// test case (0.75 for radius 0.5) and gives 0.22, below snapping alone; 3 spacings give 0.64
/// (docs/curving.md).
template <int Dim, class Keep>
[[nodiscard]] double spacing_radius(const Mesh<Dim>& mesh, const SnappedBoundary<Dim>& snapped, Keep keep) {
  std::vector<Index> kept;
  for (std::size_t k = 0; k < snapped.nodes.size(); ++k)
    if (keep(snapped.nodes[k])) kept.push_back(static_cast<Index>(k));
  if (kept.size() < 2) return 0.0;
  Points<Dim> at(Dim, static_cast<Index>(kept.size())), moved(Dim, static_cast<Index>(kept.size()));
  for (std::size_t i = 0; i < kept.size(); ++i) {
    at.col(static_cast<Index>(i)) = mesh.points.col(snapped.nodes[static_cast<std::size_t>(kept[i])]);
    moved.col(static_cast<Index>(i)) = snapped.displacements.col(kept[i]);
  }
  SupportRadiusOptions wall_spacing;
  wall_spacing.spacing_factor = 3.0;
  return suggest_support_radius(at, moved, wall_spacing);
}

/// The default radii of the curved `walls` (wall_of: wall_of_nodes()): support_radius_factor ×
/// each wall's layer thickness, limited to max_support_nodes boundary nodes per support around
/// the wall's moving nodes; a wall without a layer gets a radius per node from its facets' node
/// spacing (local_spacing_radii(); per_wall: the largest of them).
/// The uniform radius is the largest layer radius, or spacing_radius() of every snapped node
/// when no wall has a layer.
template <int Dim>
[[nodiscard]] DefaultRadii default_support_radii(const Mesh<Dim>& mesh, const ResolvedBoundary<Dim>& boundary,
                                                 const SnappedBoundary<Dim>& snapped, const std::vector<WallLayer>& layers,
                                                 const std::vector<int>& wall_of, const CurveOptions<Dim>& options) {
  if (options.max_support_nodes < 0.0)
    throw InputError("curve_mesh: max_support_nodes must be non-negative (got " + std::to_string(options.max_support_nodes) + ")");
  DefaultRadii out;
  out.per_wall.assign(layers.size(), 0.0);
  std::vector<std::vector<Index>> moving(layers.size());
  for (const Index v : moving_nodes(boundary))
    if (const int w = wall_of[static_cast<std::size_t>(v)]; w >= 0) moving[static_cast<std::size_t>(w)].push_back(v);
  for (std::size_t w = 0; w < layers.size(); ++w) {
    if (!(layers[w].thickness > 0.0)) continue;
    const double full = options.support_radius_factor * layers[w].thickness;
    out.per_wall[w] = limit_support_radius(mesh, boundary, moving[w], full, options.max_support_nodes);
    out.limited = out.limited || out.per_wall[w] < full;
    out.uniform = std::max(out.uniform, out.per_wall[w]);
  }
  if (!(out.uniform > 0.0)) out.uniform = spacing_radius(mesh, snapped, [](Index) { return true; });
  if (!(out.uniform > 0.0)) out.uniform = 1.0;  // nothing moves: any radius
  for (std::size_t w = 0; w < layers.size(); ++w)
    if (!(out.per_wall[w] > 0.0)) {
      if (out.per_node.empty()) out.per_node.assign(static_cast<std::size_t>(mesh.num_nodes()), 0.0);
      local_spacing_radii(mesh, layers[w].tag, snapped, out.per_node);
      for (const Index v : moving[w]) out.per_wall[w] = std::max(out.per_wall[w], out.per_node[static_cast<std::size_t>(v)]);
      if (!(out.per_wall[w] > 0.0)) out.per_wall[w] = out.uniform;
    }
  return out;
}

/// The radius of each entry of `given`: its own (per_node, when positive) or its wall's, or
/// for a node on no curved wall (fixed, sliding) that of the nearest node that moves.
template <int Dim>
[[nodiscard]] std::vector<double> entry_radii(const Mesh<Dim>& mesh, const ResolvedBoundary<Dim>& given,
                                              const std::vector<int>& wall_of, const std::vector<double>& per_wall,
                                              const std::vector<double>& per_node) {
  const auto radius_of = [&](Index v) {
    if (!per_node.empty() && per_node[static_cast<std::size_t>(v)] > 0.0) return per_node[static_cast<std::size_t>(v)];
    return per_wall[static_cast<std::size_t>(wall_of[static_cast<std::size_t>(v)])];
  };
  std::vector<Index> moving;
  for (const Index v : moving_nodes(given))
    if (wall_of[static_cast<std::size_t>(v)] >= 0) moving.push_back(v);
  Points<Dim> at(Dim, static_cast<Index>(moving.size()));
  for (std::size_t k = 0; k < moving.size(); ++k) at.col(static_cast<Index>(k)) = mesh.points.col(moving[k]);
  const KdTree<Dim> tree(at);
  const double largest = *std::max_element(per_wall.begin(), per_wall.end());
  std::vector<double> radii(given.nodes.size(), largest);
  for (std::size_t k = 0; k < given.nodes.size(); ++k) {
    Index v = given.nodes[k];
    if (wall_of[static_cast<std::size_t>(v)] < 0 && !moving.empty()) v = moving[tree.nearest(Vec<Dim>(mesh.points.col(v))).first];
    if (wall_of[static_cast<std::size_t>(v)] >= 0) radii[k] = radius_of(v);
  }
  return radii;
}

}  // namespace detail

}  // namespace meshmotion
