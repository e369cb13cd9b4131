#pragma once
/// \file
/// MeshSummary: what mesh_info prints about a mesh (element counts per type, boundary groups,
/// bounding box, edge lengths, orientation), as text or as one JSON object. Any program that
/// holds a Mesh in memory can print it.

#include "meshmotion/core/element.hpp"
#include "meshmotion/core/mesh.hpp"
#include "meshmotion/core/orientation.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
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

/// Summary of a mesh (see summarize()).
struct MeshSummary {
  int dim = 0;
  Index num_nodes = 0;
  std::vector<std::pair<std::string, Index>> cells, facets, lower;  ///< type name, count
  std::vector<GroupSummary> groups;
  std::array<double, 3> bbox_min{}, bbox_max{};   ///< z is 0 in 2D
  double min_edge = 0, max_edge = 0;               ///< over the straight vertex edges of the cells
  OrientationReport orientation;
};

/// Computes the summary: groups are the named groups plus any other tag found on facets or
/// lower elements; edge lengths are those of the cells' vertex-to-vertex edges.
template <int Dim>
[[nodiscard]] MeshSummary summarize(const Mesh<Dim>& mesh) {
  MeshSummary s;
  s.dim = Dim;
  s.num_nodes = mesh.num_nodes();
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

namespace detail {
[[nodiscard]] inline std::string format_real(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.10g", v);
  return buffer;
}
[[nodiscard]] inline std::string json_string(const std::string& s) {
  std::string out = "\"";
  for (const char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    if (static_cast<unsigned char>(c) < 0x20) {
      char buffer[8];
      std::snprintf(buffer, sizeof buffer, "\\u%04x", c);
      out += buffer;
    } else {
      out += c;
    }
  }
  return out + "\"";
}
}  // namespace detail

/// The summary as readable lines.
[[nodiscard]] inline std::string to_text(const MeshSummary& s) {
  std::string out = std::to_string(s.dim) + "D mesh, " + std::to_string(s.num_nodes) + " nodes\n";
  const auto list = [&](const char* title, const std::vector<std::pair<std::string, Index>>& counts) {
    out += title;
    if (counts.empty()) out += " none";
    for (const auto& [type, n] : counts) out += " " + type + " " + std::to_string(n);
    out += "\n";
  };
  list("cells:", s.cells);
  list("facets:", s.facets);
  list("lower:", s.lower);
  out += "groups:" + std::string(s.groups.empty() ? " none" : "") + "\n";
  for (const auto& g : s.groups)
    out += "  " + (g.name.empty() ? "(unnamed)" : g.name) + " (dim " + std::to_string(g.dim) + ", tag " + std::to_string(g.tag) +
           "): " + std::to_string(g.num_elements) + " elements, " + std::to_string(g.num_nodes) + " nodes\n";
  out += "bounding box: [";
  for (int d = 0; d < s.dim; ++d) (out += d ? ", " : "") += detail::format_real(s.bbox_min[static_cast<std::size_t>(d)]);
  out += "] to [";
  for (int d = 0; d < s.dim; ++d) (out += d ? ", " : "") += detail::format_real(s.bbox_max[static_cast<std::size_t>(d)]);
  out += "]\nedge length: min " + detail::format_real(s.min_edge) + ", max " + detail::format_real(s.max_edge) + "\n";
  out += "orientation: " + std::to_string(s.orientation.num_negative) + " of " + std::to_string(s.orientation.num_cells) +
         " cells negative, " + std::to_string(s.orientation.num_degenerate) + " degenerate\n";
  return out;
}

/// The summary as one JSON object (one line).
[[nodiscard]] inline std::string to_json(const MeshSummary& s) {
  const auto counts = [](const std::vector<std::pair<std::string, Index>>& list) {
    std::string out = "{";
    for (const auto& [type, n] : list) {
      if (out.size() > 1) out += ',';
      out += detail::json_string(type);
      out += ':';
      out += std::to_string(n);
    }
    out += '}';
    return out;
  };
  const auto point = [&](const std::array<double, 3>& p) {
    std::string out = "[";
    for (int d = 0; d < s.dim; ++d) {
      if (d) out += ',';
      out += detail::format_real(p[static_cast<std::size_t>(d)]);
    }
    out += ']';
    return out;
  };
  std::string out = "{\"dim\":" + std::to_string(s.dim) + ",\"nodes\":" + std::to_string(s.num_nodes) + ",\"cells\":" +
                    counts(s.cells) + ",\"facets\":" + counts(s.facets) + ",\"lower\":" + counts(s.lower) + ",\"groups\":[";
  for (std::size_t k = 0; k < s.groups.size(); ++k) {
    const auto& g = s.groups[k];
    if (k) out += ',';
    out += "{\"name\":" + detail::json_string(g.name) + ",\"dim\":" + std::to_string(g.dim) +
           ",\"tag\":" + std::to_string(g.tag) + ",\"elements\":" + std::to_string(g.num_elements) +
           ",\"nodes\":" + std::to_string(g.num_nodes) + "}";
  }
  out += "],\"bbox_min\":" + point(s.bbox_min) + ",\"bbox_max\":" + point(s.bbox_max) +
         ",\"min_edge\":" + detail::format_real(s.min_edge) + ",\"max_edge\":" + detail::format_real(s.max_edge) +
         ",\"negative_cells\":" + std::to_string(s.orientation.num_negative) +
         ",\"degenerate_cells\":" + std::to_string(s.orientation.num_degenerate) + "}";
  return out;
}

}  // namespace meshmotion
