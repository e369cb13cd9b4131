#pragma once
/// \file
/// find_extrusion: recognizes a 2D case stored in 3D (a mesh one cell thick between two
/// parallel coordinate planes, as OpenFOAM's 2D cases with their `empty` front and back, or a
/// slab exported from a 2D mesher) and gives its 2D section, so that a motion in the plane can
/// be computed in 2D and the front and back move alike (movers/section_mover.hpp).

#include "meshmotion/core/element.hpp"
#include "meshmotion/core/mesh.hpp"
#include "meshmotion/core/types.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

namespace meshmotion {

/// A mesh one cell thick along a coordinate axis: its 2D section and the node maps.
///
/// The section's coordinates are the two other axes in cyclic order (x, y along z; y, z
/// along x; z, x along y), so that a rotation about +axis is counter-clockwise in the section.
/// Section node s is front_nodes[s] (on the plane axis = front) and its partner
/// back_nodes[s] (axis = back), numbered in the order of the front nodes.
struct Extrusion {
  int axis = 2;
  double front = 0.0;  ///< the smaller coordinate of the two planes
  double back = 0.0;
  /// tri3 and quad4 cells (counter-clockwise), line2 facets from the lateral facets with the
  /// 3D groups' tags and names; the file ids of the front nodes.
  Mesh<2> section;
  std::vector<Index> front_nodes, back_nodes;
  /// 3D facet groups lying in the two planes (the `empty` front and back): the section has
  /// no facets of theirs.
  std::vector<std::string> plane_groups;

  [[nodiscard]] int u_axis() const noexcept { return (axis + 1) % 3; }
  [[nodiscard]] int v_axis() const noexcept { return (axis + 2) % 3; }
  [[nodiscard]] char axis_name() const noexcept { return static_cast<char>('x' + axis); }
  /// The 3D vector of in-plane components (u, v) and none along the axis.
  [[nodiscard]] Vec<3> lift(const Vec<2>& uv) const {
    Vec<3> out = Vec<3>::Zero();
    out(u_axis()) = uv(0);
    out(v_axis()) = uv(1);
    return out;
  }
  [[nodiscard]] Vec<2> project(const Vec<3>& x) const { return {x(u_axis()), x(v_axis())}; }
};

namespace detail {

// The pairs of opposite faces of a hexahedron, each face's vertices in cyclic order, and of
// a prism's two triangles: vertex k of the first face is joined by an edge to vertex k of
// the second.
struct OppositeFaces {
  int count;
  std::array<int, 4> first, second;
};
inline constexpr std::array<OppositeFaces, 3> hex_opposite_faces{{
    {4, {0, 1, 2, 3}, {4, 5, 6, 7}},
    {4, {0, 1, 5, 4}, {3, 2, 6, 7}},
    {4, {0, 3, 7, 4}, {1, 2, 6, 5}},
}};
inline constexpr OppositeFaces prism_triangles{3, {0, 1, 2, 0}, {3, 4, 5, 0}};

// The extrusion along `axis` when every node lies on one of its two planes and every cell
// spans them; nullopt otherwise.
[[nodiscard]] inline std::optional<Extrusion> extrusion_along(const Mesh<3>& mesh, int axis, double tolerance) {
  const Index n = mesh.num_nodes();
  Extrusion ext;
  ext.axis = axis;
  ext.front = mesh.points.row(axis).minCoeff();
  ext.back = mesh.points.row(axis).maxCoeff();
  if (!(ext.back - ext.front > 1e3 * tolerance)) return std::nullopt;
  // side: 0 front, 1 back.
  std::vector<char> side(static_cast<std::size_t>(n));
  for (Index v = 0; v < n; ++v) {
    const double x = mesh.points(axis, v);
    if (std::abs(x - ext.front) <= tolerance) side[static_cast<std::size_t>(v)] = 0;
    else if (std::abs(x - ext.back) <= tolerance) side[static_cast<std::size_t>(v)] = 1;
    else return std::nullopt;
  }
  const auto in_plane_distance = [&](Index a, Index b) {
    return std::hypot(mesh.points(ext.u_axis(), a) - mesh.points(ext.u_axis(), b),
                      mesh.points(ext.v_axis(), a) - mesh.points(ext.v_axis(), b));
  };
  std::vector<Index> partner(static_cast<std::size_t>(n), -1);
  // The front face of each cell (3D front node indices, cyclic), in cell order.
  std::vector<std::pair<int, std::array<Index, 4>>> faces;
  faces.reserve(static_cast<std::size_t>(mesh.num_cells()));
  for (const auto& block : mesh.cells) {
    const bool hex = block.type == ElementType::hex8;
    for (Index e = 0; e < block.size(); ++e) {
      const auto el = block.element(e);
      const OppositeFaces* across = nullptr;
      bool flipped = false;
      for (const auto& pair : hex ? std::span<const OppositeFaces>(hex_opposite_faces)
                                  : std::span<const OppositeFaces>(&prism_triangles, 1)) {
        const auto on = [&](const std::array<int, 4>& face, char s) {
          for (int k = 0; k < pair.count; ++k)
            if (side[static_cast<std::size_t>(el[static_cast<std::size_t>(face[static_cast<std::size_t>(k)])])] != s) return false;
          return true;
        };
        if (on(pair.first, 0) && on(pair.second, 1)) across = &pair;
        else if (on(pair.first, 1) && on(pair.second, 0)) across = &pair, flipped = true;
        if (across != nullptr) break;
      }
      if (across == nullptr) return std::nullopt;
      std::array<Index, 4> face{};
      for (int k = 0; k < across->count; ++k) {
        Index f = el[static_cast<std::size_t>(across->first[static_cast<std::size_t>(k)])];
        Index b = el[static_cast<std::size_t>(across->second[static_cast<std::size_t>(k)])];
        if (flipped) std::swap(f, b);
        Index& pf = partner[static_cast<std::size_t>(f)];
        Index& pb = partner[static_cast<std::size_t>(b)];
        if ((pf >= 0 && pf != b) || (pb >= 0 && pb != f) || in_plane_distance(f, b) > tolerance) return std::nullopt;
        pf = b;
        pb = f;
        face[static_cast<std::size_t>(k)] = f;
      }
      faces.emplace_back(across->count, face);
    }
  }
  // Every node on a cell: a node of no cell has no partner and would not move with the section.
  std::vector<Index> section_of(static_cast<std::size_t>(n), -1);
  for (Index v = 0; v < n; ++v) {
    if (partner[static_cast<std::size_t>(v)] < 0) return std::nullopt;
    if (side[static_cast<std::size_t>(v)] == 0) {
      section_of[static_cast<std::size_t>(v)] = static_cast<Index>(ext.front_nodes.size());
      ext.front_nodes.push_back(v);
      ext.back_nodes.push_back(partner[static_cast<std::size_t>(v)]);
    }
  }
  for (Index v = 0; v < n; ++v)
    if (side[static_cast<std::size_t>(v)] == 1) section_of[static_cast<std::size_t>(v)] = section_of[static_cast<std::size_t>(partner[static_cast<std::size_t>(v)])];

  Mesh<2>& s = ext.section;
  const Index m = static_cast<Index>(ext.front_nodes.size());
  s.points.resize(2, m);
  for (Index k = 0; k < m; ++k) s.points.col(k) = ext.project(mesh.points.col(ext.front_nodes[static_cast<std::size_t>(k)]));
  s.node_ids.reserve(static_cast<std::size_t>(m));
  for (const Index v : ext.front_nodes) s.node_ids.push_back(mesh.node_id(v));
  std::size_t next = 0;
  for (const auto& block : mesh.cells) {
    ElementBlock& out = s.block(block.type == ElementType::hex8 ? ElementType::quad4 : ElementType::tri3);
    out.reserve(out.size() + block.size());
    for (Index e = 0; e < block.size(); ++e) {
      auto [count, face] = faces[next++];
      std::array<Index, 4> nodes{};
      double area = 0.0;
      for (int k = 0; k < count; ++k) {
        nodes[static_cast<std::size_t>(k)] = section_of[static_cast<std::size_t>(face[static_cast<std::size_t>(k)])];
        const auto a = s.points.col(nodes[static_cast<std::size_t>(k)]);
        const auto b = s.points.col(section_of[static_cast<std::size_t>(face[static_cast<std::size_t>((k + 1) % count)])]);
        area += a(0) * b(1) - a(1) * b(0);
      }
      if (area < 0.0) std::reverse(nodes.begin() + 1, nodes.begin() + count);
      out.add(std::span<const Index>(nodes.data(), static_cast<std::size_t>(count)), block.tags[static_cast<std::size_t>(e)]);
    }
  }
  // Lateral facets (two nodes on each plane) become the section's edges; facets in a plane
  // are the front and back.
  std::vector<int> lateral_tags, plane_tags;
  for (const auto& block : mesh.facets) {
    if (block.type != ElementType::quad4 && block.type != ElementType::tri3) return std::nullopt;
    for (Index e = 0; e < block.size(); ++e) {
      const auto el = block.element(e);
      const int tag = block.tags[static_cast<std::size_t>(e)];
      std::array<Index, 4> on_front{};
      int fronts = 0;
      for (const Index v : el)
        if (side[static_cast<std::size_t>(v)] == 0) on_front[static_cast<std::size_t>(fronts++)] = section_of[static_cast<std::size_t>(v)];
      if (fronts == 0 || fronts == static_cast<int>(el.size())) {
        plane_tags.push_back(tag);
      } else if (block.type == ElementType::quad4 && fronts == 2 && on_front[0] != on_front[1]) {
        s.block(ElementType::line2).add({on_front[0], on_front[1]}, tag);
        lateral_tags.push_back(tag);
      } else {
        return std::nullopt;
      }
    }
  }
  const auto has = [](const std::vector<int>& tags, int tag) { return std::find(tags.begin(), tags.end(), tag) != tags.end(); };
  for (const auto& g : mesh.groups) {
    if (g.dim == 3) s.groups.push_back({2, g.tag, g.name});
    if (g.dim != 2) continue;
    if (has(lateral_tags, g.tag)) s.groups.push_back({1, g.tag, g.name});
    else if (has(plane_tags, g.tag)) ext.plane_groups.push_back(g.name);
  }
  return ext;
}

}  // namespace detail

/// The extrusion when `mesh` is one cell thick between two planes normal to a coordinate
/// axis: every node on one of the planes (to 1e-9 of the mesh's extent), every cell a linear
/// prism or hexahedron joining a face on one plane to its copy on the other, every node
/// paired with one node of the same in-plane position, every facet either in a plane or
/// joining the two. nullopt otherwise (a tetrahedron, a second layer of cells, a high-order
/// cell, an auxiliary node of a cut polyhedron, or a mesh one cell thick along two axes,
/// which has no one plane).
[[nodiscard]] inline std::optional<Extrusion> find_extrusion(const Mesh<3>& mesh) {
  if (mesh.num_nodes() == 0 || mesh.num_cells() == 0 || mesh.num_auxiliary_nodes > 0 || !mesh.points.allFinite())
    return std::nullopt;
  for (const auto& block : mesh.cells)
    if (block.type != ElementType::hex8 && block.type != ElementType::prism6) return std::nullopt;
  const Vec<3> extent = mesh.points.rowwise().maxCoeff() - mesh.points.rowwise().minCoeff();
  const double tolerance = 1e-9 * extent.maxCoeff();
  std::optional<Extrusion> found;
  for (int axis = 0; axis < 3; ++axis)
    if (auto ext = detail::extrusion_along(mesh, axis, tolerance)) {
      if (found) return std::nullopt;
      found = std::move(ext);
    }
  return found;
}

}  // namespace meshmotion
