#pragma once
/// \file
/// MeshSummary: what mesh_info prints about a mesh (element counts per type, boundary groups,
/// bounding box, edge lengths, orientation), as text or as one JSON object. Any program that
/// holds a Mesh in memory can print it.

#include "meshmotion/core/element.hpp"
#include "meshmotion/core/mesh.hpp"
#include "meshmotion/core/fields.hpp"
#include "meshmotion/core/json.hpp"
#include "meshmotion/core/orientation.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace meshmotion {

/// Summary of one boundary group.
struct GroupSummary {
  std::string name;  ///< empty for a tag without a name
  int dim = 0;
  int tag = 0;
  Index num_elements = 0;
  Index num_nodes = 0;
};

template <class F>
void visit_fields(const GroupSummary& g, F&& f) {
  f("name", g.name, "the group's name (empty for a tag without a name)");
  f("dim", g.dim, "dimension of its elements");
  f("tag", g.tag, "its tag");
  f("elements", g.num_elements, "elements of the group");
  f("nodes", g.num_nodes, "distinct nodes of its elements");
}

/// Summary of a mesh (see summarize()).
struct MeshSummary {
  int dim = 0;
  Index num_nodes = 0;
  Index num_auxiliary_nodes = 0;  ///< of num_nodes: centres of polyhedra cut into tetrahedra
  Index num_on_model = 0;         ///< of num_nodes: placed on a model curve or surface (Mesh::node_params)
  std::vector<std::pair<std::string, Index>> cells, facets, lower;  ///< type name, count
  std::vector<GroupSummary> groups;
  std::array<double, 3> bbox_min{}, bbox_max{};   ///< z is 0 in 2D
  double min_edge = 0, max_edge = 0;               ///< over the straight vertex edges of the cells
  OrientationReport orientation;
};

template <class F>
void visit_fields(const MeshSummary& s, F&& f) {
  const auto corner = [&](const std::array<double, 3>& p) {
    return std::vector<double>(p.begin(), p.begin() + std::clamp(s.dim, 0, 3));
  };
  f("dim", s.dim, "dimension of the mesh");
  f("nodes", s.num_nodes, "nodes");
  f("auxiliary_nodes", s.num_auxiliary_nodes, "of the nodes: centres of polyhedra cut into tetrahedra");
  f("nodes_on_model", s.num_on_model, "of the nodes: those the file places on a model curve or surface, with their parameters there");
  f("cells", s.cells, "cells per element type");
  f("facets", s.facets, "boundary facets per element type");
  f("lower", s.lower, "lower-dimensional elements per type (edges, points)");
  f("groups", s.groups, "named groups and tags found on facets or lower elements");
  f("bbox_min", corner(s.bbox_min), "lowest coordinates");
  f("bbox_max", corner(s.bbox_max), "highest coordinates");
  f("min_edge", s.min_edge, "shortest straight vertex edge of a cell");
  f("max_edge", s.max_edge, "longest straight vertex edge of a cell");
  f("negative_cells", s.orientation.num_negative, "cells of negative signed measure");
  f("degenerate_cells", s.orientation.num_degenerate, "cells of zero signed measure");
  f("orientation", s.orientation.orientation(), "positive, reversed (every cell negative) or mixed");
}

/// Computes the summary: groups are the named groups plus any other tag found on facets or
/// lower elements; edge lengths are those of the cells' vertex-to-vertex edges.
template <int Dim>
[[nodiscard]] MeshSummary summarize(const Mesh<Dim>& mesh) {
  MeshSummary s;
  s.dim = Dim;
  s.num_nodes = mesh.num_nodes();
  s.num_auxiliary_nodes = mesh.num_auxiliary_nodes;
  s.num_on_model = std::count_if(mesh.node_params.begin(), mesh.node_params.end(),
                                 [](const NodeParametrization& p) { return p.entity_dim == 1 || p.entity_dim == 2; });
  const auto counts = [](const std::vector<ElementBlock>& list) {
    std::vector<std::pair<std::string, Index>> out;
    for (const auto& b : list) out.emplace_back(std::string(name(b.type)), b.size());
    return out;
  };
  s.cells = counts(mesh.cells);
  s.facets = counts(mesh.facets);
  s.lower = counts(mesh.lower);
  for (const auto& g : mesh.groups) s.groups.push_back({g.name, g.dim, g.tag, 0, 0});
  for (int d = 0; d < Dim; ++d)
    for (const auto& b : mesh.blocks_of_dim(d))
      if (dimension(b.type) == d)
        for (const int tag : b.tags)
          if (tag != 0 && std::none_of(s.groups.begin(), s.groups.end(), [&](const GroupSummary& g) { return g.dim == d && g.tag == tag; }))
            s.groups.push_back({"", d, tag, 0, 0});
  for (auto& g : s.groups) {
    for (const auto& b : mesh.blocks_of_dim(g.dim))
      if (dimension(b.type) == g.dim) g.num_elements += std::count(b.tags.begin(), b.tags.end(), g.tag);
    std::vector<Index> nodes;
    for (const auto& b : mesh.blocks_of_dim(g.dim))
      if (dimension(b.type) == g.dim)
        for (Index e = 0; e < b.size(); ++e)
          if (b.tags[static_cast<std::size_t>(e)] == g.tag) nodes.insert(nodes.end(), b.element(e).begin(), b.element(e).end());
    std::sort(nodes.begin(), nodes.end());
    g.num_nodes = std::unique(nodes.begin(), nodes.end()) - nodes.begin();
  }
  if (mesh.num_nodes() > 0)
    for (int d = 0; d < Dim; ++d) {
      s.bbox_min[static_cast<std::size_t>(d)] = mesh.points.row(d).minCoeff();
      s.bbox_max[static_cast<std::size_t>(d)] = mesh.points.row(d).maxCoeff();
    }
  double lo = std::numeric_limits<double>::infinity(), hi = 0;
  for (const auto& b : mesh.cells)
    for (Index e = 0; e < b.size(); ++e) {
      const auto nodes = b.element(e);
      for (const auto& edge : edges(b.type)) {
        const double len = (mesh.points.col(nodes[static_cast<std::size_t>(edge[0])]) -
                            mesh.points.col(nodes[static_cast<std::size_t>(edge[1])])).norm();
        lo = std::min(lo, len);
        hi = std::max(hi, len);
      }
    }
  s.min_edge = std::isfinite(lo) ? lo : 0.0;
  s.max_edge = hi;
  s.orientation = orientation_report(mesh);
  return s;
}

/// The summary as readable lines "key: value", from its description (write_text).
[[nodiscard]] inline std::string to_text(const MeshSummary& s) {
  std::ostringstream out;
  write_text(out, s);
  return out.str();
}

/// The summary as one JSON object (one line).
[[nodiscard]] inline std::string to_json(const MeshSummary& s) {
  std::ostringstream out;
  JsonWriter w(out);
  write_json(w, s);
  return out.str();
}

}  // namespace meshmotion
