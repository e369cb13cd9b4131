#pragma once
/// \file
/// SU2 native mesh (.su2) writer. Writes NDIME, NELEM (the cells, in cell order), NPOIN (with
/// the point index) and one marker per facet tag (named after its group, "tag_<n>" without
/// one). Linear elements in VTK's node order; high-order (complete) elements as SU2's DG-FEM
/// solver reads them: type number + 100 × (order - 1), nodes on its lattice
/// (su2_node_order()). Orientation is written as it is.

#include "meshmotion/core/element.hpp"
#include "meshmotion/core/error.hpp"
#include "meshmotion/core/mesh.hpp"
#include "meshmotion/core/shape_functions.hpp"
#include "meshmotion/core/detail/atomic_file.hpp"
#include "meshmotion/io/detail/number_format.hpp"

#include <algorithm>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace meshmotion {

namespace detail {

template <int Dim>
void check_su2_writable(const Mesh<Dim>& mesh) {
  validate(mesh);
  for (const auto* list : {&mesh.cells, &mesh.facets})
    for (const auto& b : *list)
      if (su2_id(b.type) < 0)
        throw InputError("write_su2: SU2 has no serendipity elements (got " + std::string(name(b.type)) +
                         "; convert to the complete element of that order)");
}

template <int Dim>
void format_su2(TextOutput& output, const Mesh<Dim>& mesh) {
  std::string& out = output.text;
  const auto element_line = [&](const ElementBlock& b, Index e) {
    append_number(out, su2_id(b.type));
    const auto nodes = b.element(e);
    const auto order = su2_node_order(b.type);
    for (std::size_t k = 0; k < nodes.size(); ++k) {
      out.push_back('\t');
      append_number(out, nodes[order.empty() ? k : static_cast<std::size_t>(order[k])]);
    }
  };
  out += "NDIME= " + std::to_string(Dim) + "\nNELEM= " + std::to_string(mesh.num_cells()) + "\n";
  Index position = 0;
  for (const auto& b : mesh.cells)
    for (Index e = 0; e < b.size(); ++e, ++position) {
      element_line(b, e);
      out.push_back('\t');
      append_number(out, position);
      out.push_back('\n');
      output.spill();
    }
  out += "NPOIN= " + std::to_string(mesh.num_nodes()) + "\n";
  for (Index i = 0; i < mesh.num_nodes(); ++i) {
    for (int d = 0; d < Dim; ++d) {
      append_number(out, mesh.points(d, i));
      out.push_back('\t');
    }
    append_number(out, i);
    out.push_back('\n');
    output.spill();
  }
  // Markers in the order of the named groups, then the unnamed tags in order of appearance;
  // tags without facets are left out.
  std::vector<int> tags;
  for (const auto& g : mesh.groups)
    if (g.dim == Dim - 1 && std::find(tags.begin(), tags.end(), g.tag) == tags.end()) tags.push_back(g.tag);
  for (const auto& b : mesh.facets)
    for (const int t : b.tags)
      if (std::find(tags.begin(), tags.end(), t) == tags.end()) tags.push_back(t);
  std::vector<std::pair<int, Index>> markers;
  for (const int tag : tags) {
    Index count = 0;
    for (const auto& b : mesh.facets) count += std::count(b.tags.begin(), b.tags.end(), tag);
    if (count > 0) markers.emplace_back(tag, count);
  }
  out += "NMARK= " + std::to_string(markers.size()) + "\n";
  for (const auto& [tag, count] : markers) {
    std::string marker_name = tag == 0 ? "untagged" : "tag_" + std::to_string(tag);
    for (const auto& g : mesh.groups)
      if (g.dim == Dim - 1 && g.tag == tag) {
        marker_name = g.name;
        break;
      }
    out += "MARKER_TAG= " + marker_name + "\nMARKER_ELEMS= " + std::to_string(count) + "\n";
    for (const auto& b : mesh.facets)
      for (Index e = 0; e < b.size(); ++e)
        if (b.tags[static_cast<std::size_t>(e)] == tag) {
          element_line(b, e);
          out.push_back('\n');
          output.spill();
        }
  }
}

}  // namespace detail

/// The content of a .su2 file for `mesh`. Throws InputError for an invalid mesh or one with
/// quadratic elements (SU2 stores none). Lower-dimensional elements are not written.
template <int Dim>
[[nodiscard]] std::string format_su2(const Mesh<Dim>& mesh) {
  detail::check_su2_writable(mesh);
  detail::TextOutput output;
  detail::format_su2(output, mesh);
  return std::move(output.text);
}

/// Writes `mesh` to an SU2 file, streamed through a temporary file and a rename.
/// Throws as format_su2() (before anything is written), and IoError when the file cannot be
/// written.
template <int Dim>
void write_su2(const std::filesystem::path& file, const Mesh<Dim>& mesh) {
  detail::check_su2_writable(mesh);
  detail::write_streamed(file, [&](detail::TextOutput& output) { detail::format_su2(output, mesh); });
}

}  // namespace meshmotion
