#pragma once
/// \file
/// SU2 native mesh (.su2) writer. Writes NDIME, NELEM (the cells, in cell order), NPOIN (with
/// the point index) and one marker per facet tag (named after its group, "tag_<n>" without
/// one). SU2 holds linear elements only; node order and orientation are written as they are.

#include "meshmotion/core/element.hpp"
#include "meshmotion/core/error.hpp"
#include "meshmotion/core/mesh.hpp"
#include "meshmotion/io/detail/atomic_file.hpp"
#include "meshmotion/io/detail/number_format.hpp"

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

namespace meshmotion {

/// The content of a .su2 file for `mesh`. Throws InputError for an invalid mesh or one with
/// quadratic elements (SU2 stores none). Lower-dimensional elements are not written.
template <int Dim>
[[nodiscard]] std::string format_su2(const Mesh<Dim>& mesh) {
  validate(mesh);
  for (const auto* list : {&mesh.cells, &mesh.facets})
    for (const auto& b : *list)
      if (su2_id(b.type) < 0)
        throw InputError("write_su2: SU2 stores linear elements only (got " + std::string(name(b.type)) + ")");
  std::string out;
  const auto element_line = [&](const ElementBlock& b, Index e) {
    detail::append_number(out, su2_id(b.type));
    const auto nodes = b.element(e);
    const auto order = vtk_order(b.type);  // SU2 lists nodes in VTK's order
    for (std::size_t k = 0; k < nodes.size(); ++k) {
      out.push_back('\t');
      detail::append_number(out, nodes[order.empty() ? k : static_cast<std::size_t>(order[k])]);
    }
  };
  out += "NDIME= " + std::to_string(Dim) + "\nNELEM= " + std::to_string(mesh.num_cells()) + "\n";
  Index position = 0;
  for (const auto& b : mesh.cells)
    for (Index e = 0; e < b.size(); ++e, ++position) {
      element_line(b, e);
      out.push_back('\t');
      detail::append_number(out, position);
      out.push_back('\n');
    }
  out += "NPOIN= " + std::to_string(mesh.num_nodes()) + "\n";
  for (Index i = 0; i < mesh.num_nodes(); ++i) {
    for (int d = 0; d < Dim; ++d) {
      detail::append_number(out, mesh.points(d, i));
      out.push_back('\t');
    }
    detail::append_number(out, i);
    out.push_back('\n');
  }
  // Markers in the order of the named groups, then the unnamed tags in order of appearance.
  std::vector<int> tags;
  for (const auto& g : mesh.groups)
    if (g.dim == Dim - 1 && std::find(tags.begin(), tags.end(), g.tag) == tags.end()) tags.push_back(g.tag);
  for (const auto& b : mesh.facets)
    for (const int t : b.tags)
      if (std::find(tags.begin(), tags.end(), t) == tags.end()) tags.push_back(t);
  std::string markers;
  int num_markers = 0;
  for (const int tag : tags) {
    Index count = 0;
    for (const auto& b : mesh.facets) count += std::count(b.tags.begin(), b.tags.end(), tag);
    if (count == 0) continue;
    ++num_markers;
    std::string marker_name = tag == 0 ? "untagged" : "tag_" + std::to_string(tag);
    for (const auto& g : mesh.groups)
      if (g.dim == Dim - 1 && g.tag == tag) {
        marker_name = g.name;
        break;
      }
    std::swap(out, markers);
    out += "MARKER_TAG= " + marker_name + "\nMARKER_ELEMS= " + std::to_string(count) + "\n";
    for (const auto& b : mesh.facets)
      for (Index e = 0; e < b.size(); ++e)
        if (b.tags[static_cast<std::size_t>(e)] == tag) {
          element_line(b, e);
          out.push_back('\n');
        }
    std::swap(out, markers);
  }
  out += "NMARK= " + std::to_string(num_markers) + "\n" + markers;
  return out;
}

/// Writes `mesh` to an SU2 file (through a temporary file and a rename).
/// Throws as format_su2(), and IoError when the file cannot be written.
template <int Dim>
void write_su2(const std::filesystem::path& file, const Mesh<Dim>& mesh) {
  const std::string content = format_su2(mesh);
  detail::write_file_atomically(file, content);
}

}  // namespace meshmotion
