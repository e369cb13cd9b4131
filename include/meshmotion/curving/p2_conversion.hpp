#pragma once
/// \file
/// P1 → P2 conversion (thesis section 3.1, the first step of the curving pipeline): one new
/// node at the straight midpoint of every unique edge, shared by all cells, facets and lines
/// using that edge; a node at the centre of every quadrilateral face for the complete types
/// (quad9, hex27, prism18, pyramid14) and at the centre of every hex27. The linear nodes
/// keep their numbering; the new ones are appended after them (edges, then quadrilateral
/// faces, then hexahedron centres), so a flow solver's node indices stay valid. In 2D the
/// quadrilateral face nodes follow cell order.

#include "meshmotion/core/element.hpp"
#include "meshmotion/core/error.hpp"
#include "meshmotion/core/mesh.hpp"
#include "meshmotion/core/topology.hpp"
#include "meshmotion/core/types.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace meshmotion {

/// Options of to_quadratic().
struct P2Options {
  /// true: quad9/hex27/prism18/pyramid14 (face and volume nodes); false: the serendipity
  /// quad8/hex20/prism15/pyramid13 (edge nodes only).
  bool complete = true;
};

/// Where a high-order node of a converted mesh comes from.
struct HighOrderNodeSource {
  enum class Kind : std::uint8_t { edge, face, volume };
  Kind kind = Kind::edge;
  /// The linear vertices it lies between: the edge's 2 ends (as the first element using the
  /// edge lists them) or the quadrilateral face's 4 corners; -1 where unused (volume nodes).
  std::array<Index, 4> vertices{-1, -1, -1, -1};
  Index cell = -1;  ///< for a volume node, its hexahedron (cell order)
  /// The first facet element (index of the block in mesh.facets, element in that block)
  /// holding this node, or {-1, -1} for nodes inside the domain.
  std::array<Index, 2> facet{-1, -1};
};

/// A converted mesh and the origin of each of its high-order nodes.
template <int Dim>
struct QuadraticConversion {
  Mesh<Dim> mesh;
  Index num_linear_nodes = 0;                ///< nodes 0 .. num_linear_nodes-1 are the input's
  std::vector<HighOrderNodeSource> sources;  ///< node num_linear_nodes + i comes from sources[i]
};

/// Converts a linear mesh (any mix of element types; cells, facets and lower-dimensional
/// blocks) into a P2 mesh, keeping block order, element order, tags, element ids and groups.
/// node_ids of new nodes continue after the largest input id; node_params of a new node are
/// the parameter midpoint when all its vertices lie on the same CAD entity (not valid across
/// the seam of a periodic curve), otherwise "unknown" (entity_dim = Dim, tag 0).
/// Throws InputError when the mesh already has quadratic elements or fails validate().
template <int Dim>
[[nodiscard]] QuadraticConversion<Dim> convert_to_quadratic(const Mesh<Dim>& linear, const P2Options& options = {}) {
  validate(linear);
  std::vector<const ElementBlock*> blocks;
  for (const auto* list : {&linear.cells, &linear.facets, &linear.lower})
    for (const auto& b : *list) {
      if (order(b.type) > 1)
        throw InputError("to_quadratic: the mesh already has " + std::string(name(b.type)) +
                         " elements (expected a linear mesh)");
      blocks.push_back(&b);
    }
  const Index n_linear = linear.num_nodes();
  const EdgeTopology edge_topo = unique_edges(blocks, n_linear);
  // In 2D the only faces are the cells themselves, one node each: no numbering needed.
  bool any_face_nodes = false;
  for (const auto* b : blocks) any_face_nodes |= has_face_nodes(quadratic_type(b->type, options.complete));
  const FacetTopology face_topo = Dim == 3 && any_face_nodes ? unique_faces(blocks, n_linear) : FacetTopology{};

  QuadraticConversion<Dim> out;
  out.num_linear_nodes = n_linear;
  auto& sources = out.sources;
  std::size_t num_cell_nodes = 0;  // hexahedron centres, 2D face nodes
  for (const auto& b : linear.cells) {
    const ElementType qt = quadratic_type(b.type, options.complete);
    if (qt == ElementType::hex27 || (Dim == 2 && has_face_nodes(qt))) num_cell_nodes += static_cast<std::size_t>(b.size());
  }
  sources.reserve(edge_topo.edges.size() + static_cast<std::size_t>(face_topo.size()) + num_cell_nodes);
  for (const auto& e : edge_topo.edges) sources.push_back({HighOrderNodeSource::Kind::edge, {e[0], e[1], -1, -1}, -1, {-1, -1}});
  std::vector<Index> face_node(static_cast<std::size_t>(face_topo.size()), -1);
  for (Index f = 0; f < face_topo.size(); ++f)
    if (face_topo.num_vertices[static_cast<std::size_t>(f)] == 4) {
      face_node[static_cast<std::size_t>(f)] = n_linear + static_cast<Index>(sources.size());
      sources.push_back({HighOrderNodeSource::Kind::face, face_topo.vertices[static_cast<std::size_t>(f)], -1, {-1, -1}});
    }

  Mesh<Dim>& mesh = out.mesh;
  mesh.groups = linear.groups;
  Index block_index = 0;  // position in `blocks`, the topologies' block order
  Index cell = 0;
  for (const auto* list : {&linear.cells, &linear.facets, &linear.lower}) {
    std::vector<ElementBlock>& out_list = list == &linear.cells    ? mesh.cells
                                          : list == &linear.facets ? mesh.facets
                                                                   : mesh.lower;
    for (const auto& b : *list) {
      const ElementType t = b.type;
      const ElementType qt = dimension(t) == 0 ? t : quadratic_type(t, options.complete);
      const int nv = num_vertices(t);
      ElementBlock q{qt, {}, b.tags, b.ids, b.entities};
      q.connectivity.reserve(static_cast<std::size_t>(b.size() * num_nodes(qt)));
      for (Index e = 0; e < b.size(); ++e) {
        const auto el = b.element(e);
        q.connectivity.insert(q.connectivity.end(), el.begin(), el.end());
        for (Index id : edge_topo.element_edges.of(block_index, e)) q.connectivity.push_back(n_linear + id);
        if (Dim == 2 && has_face_nodes(qt)) {
          q.connectivity.push_back(n_linear + static_cast<Index>(sources.size()));
          sources.push_back({HighOrderNodeSource::Kind::face, {el[0], el[1], el[2], el[3]}, -1, {-1, -1}});
        } else if (has_face_nodes(qt)) {
          const auto faces = face_topo.element_facets.of(block_index, e);
          for (std::size_t f = 0; f < faces.size(); ++f)
            if (face_node[static_cast<std::size_t>(faces[f])] >= 0) q.connectivity.push_back(face_node[static_cast<std::size_t>(faces[f])]);
        }
        if (qt == ElementType::hex27) {
          q.connectivity.push_back(n_linear + static_cast<Index>(sources.size()));
          sources.push_back({HighOrderNodeSource::Kind::volume, {-1, -1, -1, -1}, cell + e, {-1, -1}});
        }
      }
      if (list == &linear.facets)
        for (Index e = 0; e < q.size(); ++e)
          for (int k = nv; k < num_nodes(qt); ++k) {
            auto& facet = sources[static_cast<std::size_t>(q.element(e)[static_cast<std::size_t>(k)] - n_linear)].facet;
            if (facet[0] < 0) facet = {static_cast<Index>(&b - linear.facets.data()), e};
          }
      if (list == &linear.cells) cell += b.size();
      out_list.push_back(std::move(q));
      ++block_index;
    }
  }

  // Straight-sided positions: the mean of the vertices each node lies between.
  const Index n_total = n_linear + static_cast<Index>(sources.size());
  mesh.points.resize(Dim, n_total);
  mesh.points.leftCols(n_linear) = linear.points;
  for (std::size_t i = 0; i < sources.size(); ++i) {
    const auto& s = sources[i];
    Vec<Dim> p = Vec<Dim>::Zero();
    int n = 0;
    if (s.kind == HighOrderNodeSource::Kind::volume) {
      // Cell order index → hexahedron vertices (cells blocks come first in `blocks`).
      Index c = s.cell;
      for (const auto& b : linear.cells) {
        if (c < b.size()) {
          for (int k = 0; k < 8; ++k) p += linear.points.col(b.element(c)[static_cast<std::size_t>(k)]);
          n = 8;
          break;
        }
        c -= b.size();
      }
    } else {
      for (Index v : s.vertices)
        if (v >= 0) {
          p += linear.points.col(v);
          ++n;
        }
    }
    mesh.points.col(n_linear + static_cast<Index>(i)) = p / n;
  }

  mesh.first_node_id = linear.first_node_id;
  if (!linear.node_ids.empty()) {
    mesh.node_ids = linear.node_ids;
    std::int64_t next = *std::max_element(linear.node_ids.begin(), linear.node_ids.end()) + 1;
    for (std::size_t i = 0; i < sources.size(); ++i) mesh.node_ids.push_back(next++);
  }
  if (!linear.node_params.empty()) {
    mesh.node_params = linear.node_params;
    for (const auto& s : sources) {
      NodeParametrization param{Dim, 0, 0.0, 0.0};
      if (s.kind != HighOrderNodeSource::Kind::volume) {
        const NodeParametrization& first = linear.node_params[static_cast<std::size_t>(s.vertices[0])];
        bool same = true;
        double u = 0, v = 0;
        int n = 0;
        for (Index vert : s.vertices)
          if (vert >= 0) {
            const NodeParametrization& p = linear.node_params[static_cast<std::size_t>(vert)];
            same = same && p.entity_dim == first.entity_dim && p.entity_tag == first.entity_tag;
            u += p.u;
            v += p.v;
            ++n;
          }
        if (same) param = {first.entity_dim, first.entity_tag, u / n, v / n};
      }
      mesh.node_params.push_back(param);
    }
  }
  return out;
}

/// The P2 mesh of convert_to_quadratic() alone.
template <int Dim>
[[nodiscard]] Mesh<Dim> to_quadratic(const Mesh<Dim>& linear, const P2Options& options = {}) {
  return convert_to_quadratic(linear, options).mesh;
}

}  // namespace meshmotion

// The compiled library (target meshmotion::compiled, src/) holds these for Dim 2 and 3.
#ifdef MESHMOTION_COMPILED
namespace meshmotion {
extern template QuadraticConversion<2> convert_to_quadratic<2>(const Mesh<2>&, const P2Options&);
extern template QuadraticConversion<3> convert_to_quadratic<3>(const Mesh<3>&, const P2Options&);
}  // namespace meshmotion
#endif
