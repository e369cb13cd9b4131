#pragma once
/// \file
/// The nodes the curving pipeline's untangling may slide: wall nodes along their geometry,
/// symmetry planes' nodes in their planes.

#include "meshmotion/curving/detail/curving_groups.hpp"

#include <optional>

namespace meshmotion {

namespace detail {

/// The directions a sliding node searches: the columns of `basis` (an orthonormal basis of its
/// tangent line or plane) and, in a plane, their two diagonals (as the inside nodes search the
/// axes and diagonals).
template <int Dim, class Basis>
[[nodiscard]] std::vector<Vec<Dim>> tangent_directions(const Basis& basis) {
  std::vector<Vec<Dim>> out;
  for (Index c = 0; c < basis.cols(); ++c) out.emplace_back(basis.col(c));
  if (basis.cols() == 2) {
    out.emplace_back((basis.col(0) + basis.col(1)).normalized());
    out.emplace_back((basis.col(0) - basis.col(1)).normalized());
  }
  return out;
}

/// A high-order node on edge (a, b) of a facet (block, element; the node's local index
/// `local`) sliding along the edge's curve on `geo`, when `geo` places edge nodes
/// (BoundaryGeometry::placement: a CAD model's common edge of a and b, at a fraction of its arc
/// length): a trial place x goes to the curve's point at x's fraction of the chord ab, kept
/// within 1%–99% of it (a node at an end would collapse its edge).
template <int Dim>
[[nodiscard]] std::optional<SlidingNode<Dim>> edge_sliding_node(const Mesh<Dim>& mesh, std::size_t block_index, Index element,
                                                                int local, const BoundaryGeometry<Dim>& geo) {
  const auto& block = mesh.facets[block_index];
  const int nv = num_vertices(block.type), p = order(block.type);
  if (!geo.placement || p < 2 || local < nv || local >= first_inside_node(block.type)) return std::nullopt;
  const std::array<int, 2> edge = edges(block.type)[static_cast<std::size_t>((local - nv) / (p - 1))];
  const auto el = block.element(element);
  std::array<Vec<Dim>, 4> vertices;
  for (int k = 0; k < nv; ++k) vertices[static_cast<std::size_t>(k)] = mesh.points.col(el[static_cast<std::size_t>(k)]);
  const Vec<Dim> a = vertices[static_cast<std::size_t>(edge[0])], chord = vertices[static_cast<std::size_t>(edge[1])] - a;
  if (!(chord.squaredNorm() > 0.0)) return std::nullopt;
  SlidingNode<Dim> node;
  node.directions = {chord.normalized()};
  node.project = [g = &geo, vertices, nv, a, chord, edge](const Vec<Dim>& x) {
    const double r = std::clamp((x - a).dot(chord) / chord.squaredNorm(), 0.01, 0.99);
    std::array<double, 4> weights{};
    weights[static_cast<std::size_t>(edge[0])] = 1.0 - r;
    weights[static_cast<std::size_t>(edge[1])] = r;
    return g->placement(std::span<const Vec<Dim>>(vertices.data(), static_cast<std::size_t>(nv)),
                        std::span<const double>(weights.data(), static_cast<std::size_t>(nv)));
  };
  return node;
}

/// The wall nodes the untangling may slide along their geometry (untangle.hpp): every
/// high-order node of a facet of a group curved by projection (an analytic shape, a CAD model)
/// that lies inside its facet, or on an edge between two facets of that group whose straight
/// normals differ by at most `corner_angle` degrees. Each projects through its facet
/// (BoundaryGeometry::project_in_facet(): a CAD model's local search from the facet's vertices)
/// and searches its facets' tangent plane (in 2D, line). In 3D a node on a sharp edge (a
/// trailing edge, a wing's tip) or on the border with another group slides along the edge
/// (edge_sliding_node()) where a group holding it places edge nodes on the model's edges (a CAD
/// model), and otherwise stays: sliding on a surface would take it off the edge.
/// `geometry` must outlive the result.
template <int Dim>
[[nodiscard]] SlidingNodes<Dim> wall_sliding_nodes(const Mesh<Dim>& mesh, const std::map<int, BoundaryGeometry<Dim>>& geometry,
                                                   double corner_angle) {
  struct Holder {
    std::size_t block;
    Index element;
    int local;
  };
  std::unordered_map<Index, std::vector<Holder>> holders;
  for (std::size_t b = 0; b < mesh.facets.size(); ++b) {
    const auto& block = mesh.facets[b];
    for (Index e = 0; e < block.size(); ++e) {
      const auto el = block.element(e);
      for (std::size_t k = static_cast<std::size_t>(num_vertices(block.type)); k < el.size(); ++k)
        holders[el[k]].push_back({b, e, static_cast<int>(k)});
    }
  }
  // A facet's straight normal (3D; in 2D its direction); whether it runs from vertex a to b.
  const auto normal = [&](const Holder& h) {
    const auto el = mesh.facets[h.block].element(h.element);
    const auto x = [&](int k) { return Vec<Dim>(mesh.points.col(el[static_cast<std::size_t>(k)])); };
    if constexpr (Dim == 2) {
      return Vec<2>((x(1) - x(0)).normalized());
    } else {
      const Vec<3> n = num_vertices(mesh.facets[h.block].type) == 4 ? Vec<3>((x(2) - x(0)).cross(x(3) - x(1))) : Vec<3>((x(1) - x(0)).cross(x(2) - x(0)));
      return Vec<3>(n.normalized());
    }
  };
  const auto runs = [&](const Holder& h, Index a, Index b) {
    const auto el = mesh.facets[h.block].element(h.element);
    const int nv = num_vertices(mesh.facets[h.block].type);
    for (int k = 0; k < nv; ++k)
      if (el[static_cast<std::size_t>(k)] == a) return el[static_cast<std::size_t>((k + 1) % nv)] == b;
    return false;
  };
  const double smooth = std::cos(corner_angle * std::numbers::pi / 180.0);
  SlidingNodes<Dim> out;
  const auto projected = [&](const Holder& h) {
    const auto it = geometry.find(mesh.facets[h.block].tags[static_cast<std::size_t>(h.element)]);
    return it == geometry.end() || it->second.kind != BoundaryGeometry<Dim>::Kind::projection ? nullptr : &it->second;
  };
  for (const auto& [v, on] : holders) {
    // On an edge the surface's slide cannot take: along it, when a group holding it can.
    const auto along_edge = [&, v = v, &on = on] {
      if constexpr (Dim == 3)
        for (const Holder& g : on)
          if (const BoundaryGeometry<Dim>* geo = projected(g))
            if (auto node = edge_sliding_node(mesh, g.block, g.element, g.local, *geo)) {
              out.emplace(v, std::move(*node));
              return;
            }
    };
    const Holder& h = on.front();
    const auto& block = mesh.facets[h.block];
    const int tag = block.tags[static_cast<std::size_t>(h.element)];
    const BoundaryGeometry<Dim>* geo = projected(h);
    if (geo == nullptr) {
      along_edge();
      continue;
    }
    Vec<Dim> n = normal(h);
    if (on.size() == 2 && Dim == 3) {
      const Holder& g = on.back();
      if (mesh.facets[g.block].tags[static_cast<std::size_t>(g.element)] != tag) {
        along_edge();
        continue;
      }
      // The two facets' common vertices are the edge's ends; facets oriented alike run along it in
      // opposite directions.
      std::vector<Index> common;
      const auto first = block.element(h.element), second = mesh.facets[g.block].element(g.element);
      for (int k = 0; k < num_vertices(block.type); ++k)
        if (const Index a = first[static_cast<std::size_t>(k)];
            std::find(second.begin(), second.begin() + num_vertices(mesh.facets[g.block].type), a) != second.begin() + num_vertices(mesh.facets[g.block].type))
          common.push_back(a);
      if (common.size() != 2) continue;
      Vec<Dim> m = normal(g);
      if (runs(h, common[0], common[1]) == runs(g, common[0], common[1])) m = -m;
      if (n.dot(m) < smooth) {
        along_edge();
        continue;
      }
      n = (n + m).normalized();
    } else if (on.size() != 1 || (Dim == 3 && h.local < detail::first_inside_node(block.type))) {
      along_edge();  // on the border of its group (or of the tagged boundary)
      continue;
    }
    const auto el = block.element(h.element);
    const int nv = num_vertices(block.type);
    std::array<Vec<Dim>, 4> vertices;
    for (int k = 0; k < nv; ++k) vertices[static_cast<std::size_t>(k)] = mesh.points.col(el[static_cast<std::size_t>(k)]);
    const std::vector<double> weights = detail::facet_node_weights(block.type).weights[static_cast<std::size_t>(h.local)];
    SlidingNode<Dim> node;
    if constexpr (Dim == 2) node.directions = {n};
    else node.directions = tangent_directions<3>(plane_basis<3>(n));
    node.project = [g = geo, vertices, nv, weights](const Vec<Dim>& x) {
      return g->project_in_facet(std::span<const Vec<Dim>>(vertices.data(), static_cast<std::size_t>(nv)), weights, x);
    };
    out.emplace(v, std::move(node));
  }
  return out;
}

/// The sliding entries of `boundary` (symmetry planes, their lines), as nodes of `mesh` the
/// untangling may slide in their plane or line through where they are.
template <int Dim>
void add_sliding_entries(const Mesh<Dim>& mesh, const ResolvedBoundary<Dim>& boundary, SlidingNodes<Dim>& out) {
  for (Index k = 0; k < boundary.size(); ++k) {
    if (boundary.kinds[static_cast<std::size_t>(k)] != BoundaryKind::sliding) continue;
    const typename ResolvedBoundary<Dim>::Basis basis = boundary.sliding_basis(k);
    SlidingNode<Dim> node;
    node.directions = tangent_directions<Dim>(basis);
    const Index v = boundary.nodes[static_cast<std::size_t>(k)];
    node.project = [basis, origin = Vec<Dim>(mesh.points.col(v))](const Vec<Dim>& x) {
      return Vec<Dim>(origin + basis * (basis.transpose() * (x - origin)));
    };
    out.emplace(v, std::move(node));
  }
}

}  // namespace detail

}  // namespace meshmotion
