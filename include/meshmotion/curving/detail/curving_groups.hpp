#pragma once
/// \file
/// The curving pipeline's group roles: which groups are planar, walls, curved onto which
/// geometry, sliding or held, and the boundary the mover sees.

#include "meshmotion/curving/curve_options.hpp"
#include "meshmotion/curving/curve_report.hpp"

namespace meshmotion {

/// The tags of the facet groups (dim - 1) that lie in one plane, a line in 2D, to round-off
/// (PlaneFit::planar()): what CurveOptions::slide_planar_groups keeps straight.
template <int Dim>
[[nodiscard]] std::set<int> planar_group_tags(const Mesh<Dim>& mesh) {
  std::set<int> out;
  for (const auto& g : mesh.groups)
    if (g.dim == Dim - 1) {
      const std::vector<Index> nodes = mesh.group_nodes(g.tag);
      if (static_cast<Index>(nodes.size()) >= Dim && fit_plane(mesh.points, nodes).planar()) out.insert(g.tag);
    }
  return out;
}

namespace detail {

/// Whether a group's name says it is a solid wall: it holds "wall", or names a body
/// ("body", "airfoil", "wing", "blade", "hull", "sphere", "cylinder"), whatever the case.
[[nodiscard]] inline bool looks_like_wall(std::string name) {
  for (char& c : name) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  for (const char* word : {"wall", "body", "airfoil", "wing", "blade", "hull", "sphere", "cylinder"})
    if (name.find(word) != std::string::npos) return true;
  return false;
}

/// Whether every facet of group `tag` is a triangle (what the surface reconstruction takes).
template <int Dim>
[[nodiscard]] bool all_triangles(const Mesh<Dim>& mesh, int tag) {
  bool any = false;
  for (const auto& block : mesh.facets)
    for (const int t : block.tags)
      if (t == tag) {
        if (shape(block.type) != Shape::triangle) return false;
        any = true;
      }
  return any;
}

/// Group names and tags of the facet groups and the geometry each gets.
template <int Dim>
[[nodiscard]] std::map<int, BoundaryGeometry<Dim>> resolve_geometry(const Mesh<Dim>& mesh, const CurveOptions<Dim>& options,
                                                                    const std::set<int>& planar) {
  std::map<int, BoundaryGeometry<Dim>> out;
  for (const auto& [group, geo] : options.geometry) {
    const PhysicalGroup& g = mesh.group(group);
    if (g.dim != Dim - 1)
      throw InputError("curve_mesh: group '" + group + "' has dimension " + std::to_string(g.dim) + " (expected " +
                       std::to_string(Dim - 1) + ")");
    out[g.tag] = geo;
  }
  const auto is_sliding = [&](const std::string& n) {
    return std::find(options.sliding.begin(), options.sliding.end(), n) != options.sliding.end();
  };
  for (const auto& g : mesh.groups)
    if (g.dim == Dim - 1 && !out.count(g.tag)) {
      const bool by_default = Dim == 2 ? options.spline_by_default
                                       : options.reconstruct_walls_by_default && looks_like_wall(g.name) && all_triangles(mesh, g.tag);
      const bool flat = planar.count(g.tag) > 0 && !looks_like_wall(g.name);
      out[g.tag] = by_default && !is_sliding(g.name) && !flat ? BoundaryGeometry<Dim>::spline() : BoundaryGeometry<Dim>::straight();
    }
  return out;
}

/// The groups that slide: those given, then the planar groups (planar_group_tags()) that
/// are not `curved` and share a node with a `moving` wall.
template <int Dim>
[[nodiscard]] std::vector<std::string> sliding_groups(const Mesh<Dim>& mesh, const CurveOptions<Dim>& options,
                                                      const std::vector<std::string>& curved,
                                                      const std::vector<std::string>& moving, const std::set<int>& planar) {
  std::vector<std::string> out = options.sliding;
  if (planar.empty() || moving.empty()) return out;
  std::vector<char> on_wall(static_cast<std::size_t>(mesh.num_nodes()), 0);
  for (const std::string& w : moving)
    for (const Index v : mesh.group_nodes(std::string_view(w))) on_wall[static_cast<std::size_t>(v)] = 1;
  const auto listed = [](const std::vector<std::string>& list, const std::string& name) {
    return std::find(list.begin(), list.end(), name) != list.end();
  };
  for (const auto& g : mesh.groups) {
    if (g.dim != Dim - 1 || !planar.count(g.tag) || listed(curved, g.name) || listed(out, g.name)) continue;
    const std::vector<Index> nodes = mesh.group_nodes(g.tag);
    if (std::any_of(nodes.begin(), nodes.end(), [&](Index v) { return on_wall[static_cast<std::size_t>(v)] != 0; }))
      out.push_back(g.name);
  }
  return out;
}

/// Removes from `walls` the groups whose snapped nodes all moved less than the snapping's
/// on-geometry tolerance, and returns a flag per node: 1 for the nodes of those groups that
/// are on no remaining wall.
template <int Dim>
[[nodiscard]] std::vector<char> drop_unmoved_walls(const Mesh<Dim>& mesh, const SnappedBoundary<Dim>& snapped,
                                                   std::vector<std::string>& walls, const SnapOptions& snap) {
  std::vector<Index> slot(static_cast<std::size_t>(mesh.num_nodes()), -1);
  for (std::size_t k = 0; k < snapped.nodes.size(); ++k) slot[static_cast<std::size_t>(snapped.nodes[k])] = static_cast<Index>(k);
  const double tolerance =
      snap.on_geometry_tolerance * (mesh.points.rowwise().maxCoeff() - mesh.points.rowwise().minCoeff()).norm();
  std::vector<char> still(static_cast<std::size_t>(mesh.num_nodes()), 0), on_moving(still.size(), 0);
  std::vector<std::string> moving;
  for (const std::string& w : walls) {
    const std::vector<Index> nodes = mesh.group_nodes(std::string_view(w));
    const bool moves = std::any_of(nodes.begin(), nodes.end(), [&](Index v) {
      const Index k = slot[static_cast<std::size_t>(v)];
      return k >= 0 && snapped.displacements.col(k).norm() > tolerance;
    });
    for (const Index v : nodes) (moves ? on_moving : still)[static_cast<std::size_t>(v)] = 1;
    if (moves) moving.push_back(w);
  }
  for (std::size_t v = 0; v < still.size(); ++v) still[v] = still[v] && !on_moving[v];
  walls = std::move(moving);
  return still;
}

/// The boundary the mover sees: snapped nodes prescribed (but those flagged `still`), sliding
/// groups sliding, every other boundary node (tagged or not) fixed. `topology` is
/// unique_facets(mesh).
template <int Dim>
[[nodiscard]] ResolvedBoundary<Dim> curving_boundary(const Mesh<Dim>& mesh, const SnappedBoundary<Dim>& snapped,
                                                     const std::vector<char>& still, const std::vector<std::string>& sliding,
                                                     const FacetTopology& topology) {
  using Entry = BoundaryEntry<Dim>;
  BoundaryCollector<Dim> entries(mesh.num_nodes());
  for (std::size_t k = 0; k < snapped.nodes.size(); ++k)
    if (!still[static_cast<std::size_t>(snapped.nodes[k])])
      entries.add(snapped.nodes[k], Entry{BoundaryKind::prescribed, Vec<Dim>(snapped.displacements.col(static_cast<Index>(k)))});
  if (!sliding.empty()) {
    BoundarySpec<Dim> spec;
    for (const auto& g : sliding) spec.sliding(g);
    const ResolvedBoundary<Dim> slide = spec.resolve(mesh);
    for (Index k = 0; k < slide.size(); ++k)
      entries.add(slide.nodes[static_cast<std::size_t>(k)],
                  Entry{slide.kinds[static_cast<std::size_t>(k)], Vec<Dim>::Zero(), Vec<Dim>(slide.normals.col(k)),
                        Vec<Dim>(slide.directions.col(k))});
  }
  const auto fix = [&](const std::vector<ElementBlock>& blocks) {
    for (const auto& b : blocks)
      for (const Index v : b.connectivity) entries.add(v, Entry{BoundaryKind::fixed});
  };
  fix(mesh.facets);
  fix(boundary_facets(mesh, topology));
  return entries.resolve();
}

/// The nodes of `boundary` with a nonzero displacement.
template <int Dim>
[[nodiscard]] std::vector<Index> moving_nodes(const ResolvedBoundary<Dim>& boundary) {
  std::vector<Index> moving;
  for (Index k = 0; k < boundary.size(); ++k)
    if (boundary.displacements.col(k).squaredNorm() > 0.0) moving.push_back(boundary.nodes[static_cast<std::size_t>(k)]);
  return moving;
}

/// The entries of `boundary` within `reach` of an entry with a nonzero displacement. The RBF
/// system of a compact kernel couples centres only through overlapping supports, so the
/// coefficients of zero-displacement centres decay with their distance from the motion; those
/// beyond a couple of radii change the interpolant by a small fraction of the displacement.
template <int Dim>
[[nodiscard]] ResolvedBoundary<Dim> near_motion(const Mesh<Dim>& mesh, const ResolvedBoundary<Dim>& boundary, double reach) {
  const std::vector<Index> moving = moving_nodes(boundary);
  if (moving.empty()) return boundary;
  Points<Dim> at(Dim, static_cast<Index>(moving.size()));
  for (std::size_t k = 0; k < moving.size(); ++k) at.col(static_cast<Index>(k)) = mesh.points.col(moving[k]);
  const KdTree<Dim> tree(at);
  std::vector<Index> kept;  // entries of `boundary`, whose nodes ascend
  for (Index k = 0; k < boundary.size(); ++k) {
    const Vec<Dim> p = mesh.points.col(boundary.nodes[static_cast<std::size_t>(k)]);
    // Most boundary nodes (inflow, outflow, farfield) lie far outside the moving nodes' box.
    if (tree.box_squared_distance(p) <= reach * reach && tree.nearest(p).second <= reach * reach) kept.push_back(k);
  }
  return detail::collect_boundary<Dim>(static_cast<Index>(kept.size()), [&](auto&& add) {
    for (const Index k : kept)
      add(boundary.nodes[static_cast<std::size_t>(k)],
          BoundaryEntry<Dim>{boundary.kinds[static_cast<std::size_t>(k)], Vec<Dim>(boundary.displacements.col(k)),
                             Vec<Dim>(boundary.normals.col(k)), Vec<Dim>(boundary.directions.col(k))});
  });
}

}  // namespace detail

}  // namespace meshmotion
