#pragma once
/// \file
/// VTK XML unstructured grid (.vtu) writer, ASCII. Quadratic elements that VTK has as
/// Lagrange cells (line3, tri6, quad9, tet10, hex27, prism18) are written as such so ParaView
/// draws them curved; serendipity types use the classic quadratic cells (pyramid14 is written
/// as the 13-node quadratic pyramid). Point data and cell data are named arrays.

#include "meshmotion/core/element.hpp"
#include "meshmotion/core/error.hpp"
#include "meshmotion/core/mesh.hpp"
#include "meshmotion/io/detail/atomic_file.hpp"
#include "meshmotion/io/detail/number_format.hpp"

#include <Eigen/Core>

#include <cmath>
#include <filesystem>
#include <span>
#include <string>
#include <utility>
#include <vector>

namespace meshmotion {

/// Named arrays to write: each a matrix with one column per node (point data) or per cell in
/// cell order (cell data); the rows are the components (1 for a scalar, Dim for a vector).
struct VtuFields {
  std::vector<std::pair<std::string, Eigen::MatrixXd>> point_data;
  std::vector<std::pair<std::string, Eigen::MatrixXd>> cell_data;
};

/// Options of write_vtu().
struct VtuOptions {
  /// Also write the facets (after the cells); their cell data values are NaN, and a cell array
  /// "facet_tag" (0 on cells) tells them apart.
  bool include_facets = false;
};

namespace detail {

/// VTK cell type and node order used for an element type.
struct VtkCell {
  int type;
  std::span<const int> order;  ///< empty: identity
  int num_nodes;
};

[[nodiscard]] inline VtkCell vtk_cell(ElementType t) {
  const ElementInfo& info = element_info(t);
  const bool lagrange = info.order == 2 && info.vtk_lagrange_id >= 0;
  const auto order = vtk_order(t, lagrange);
  return {lagrange ? info.vtk_lagrange_id : info.vtk_id, order,
          order.empty() ? info.num_nodes : static_cast<int>(order.size())};
}

inline void append_data_array(std::string& out, const std::string& name, const Eigen::MatrixXd& values,
                              Index num_padding) {
  out += "        <DataArray type=\"Float64\" Name=\"" + name + "\" NumberOfComponents=\"" +
         std::to_string(values.rows()) + "\" format=\"ascii\">\n";
  for (Index j = 0; j < values.cols(); ++j) {
    for (Index r = 0; r < values.rows(); ++r) {
      append_number(out, values(r, j));
      out.push_back(' ');
    }
    out.back() = '\n';
  }
  for (Index j = 0; j < num_padding * values.rows(); ++j) out += "nan\n";
  out += "        </DataArray>\n";
}

}  // namespace detail

/// The content of a .vtu file for `mesh` and `fields`. Throws InputError for an invalid mesh,
/// an array name with a quote, or an array whose column count is not n_nodes (point data) or
/// num_cells() (cell data).
template <int Dim>
[[nodiscard]] std::string format_vtu(const Mesh<Dim>& mesh, const VtuFields& fields = {}, const VtuOptions& options = {}) {
  validate(mesh);
  for (const auto& [array_name, values] : fields.point_data)
    if (values.cols() != mesh.num_nodes())
      throw InputError("write_vtu: point data '" + array_name + "' has " + std::to_string(values.cols()) +
                       " columns (expected one per node: " + std::to_string(mesh.num_nodes()) + ")");
  for (const auto& [array_name, values] : fields.cell_data)
    if (values.cols() != mesh.num_cells())
      throw InputError("write_vtu: cell data '" + array_name + "' has " + std::to_string(values.cols()) +
                       " columns (expected one per cell: " + std::to_string(mesh.num_cells()) + ")");
  for (const auto* list : {&fields.point_data, &fields.cell_data})
    for (const auto& entry : *list)
      if (entry.first.find_first_of("\"<>&") != std::string::npos)
        throw InputError("write_vtu: array name '" + entry.first + "' contains a character XML needs escaped");

  std::vector<const ElementBlock*> blocks;
  for (const auto& b : mesh.cells) blocks.push_back(&b);
  if (options.include_facets)
    for (const auto& b : mesh.facets) blocks.push_back(&b);
  Index num_written = 0;
  for (const auto* b : blocks) num_written += b->size();

  std::string out;
  out.reserve(static_cast<std::size_t>(mesh.num_nodes() * 60 + num_written * 40));
  out += "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n";
  out += "  <UnstructuredGrid>\n    <Piece NumberOfPoints=\"" + std::to_string(mesh.num_nodes()) + "\" NumberOfCells=\"" +
         std::to_string(num_written) + "\">\n";
  out += "      <Points>\n        <DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n";
  for (Index i = 0; i < mesh.num_nodes(); ++i) {
    for (int d = 0; d < 3; ++d) {
      detail::append_number(out, d < Dim ? mesh.points(d, i) : 0.0);
      out.push_back(d == 2 ? '\n' : ' ');
    }
  }
  out += "        </DataArray>\n      </Points>\n      <Cells>\n";
  out += "        <DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n";
  for (const auto* b : blocks) {
    const auto cell = detail::vtk_cell(b->type);
    for (Index e = 0; e < b->size(); ++e) {
      const auto nodes = b->element(e);
      for (int k = 0; k < cell.num_nodes; ++k) {
        detail::append_number(out, nodes[static_cast<std::size_t>(cell.order.empty() ? k : cell.order[static_cast<std::size_t>(k)])]);
        out.push_back(' ');
      }
      out.back() = '\n';
    }
  }
  out += "        </DataArray>\n        <DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
  Index offset = 0;
  for (const auto* b : blocks) {
    const auto cell = detail::vtk_cell(b->type);
    for (Index e = 0; e < b->size(); ++e) {
      offset += cell.num_nodes;
      detail::append_number(out, offset);
      out.push_back('\n');
    }
  }
  out += "        </DataArray>\n        <DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n";
  for (const auto* b : blocks) {
    const auto cell = detail::vtk_cell(b->type);
    for (Index e = 0; e < b->size(); ++e) {
      detail::append_number(out, cell.type);
      out.push_back('\n');
    }
  }
  out += "        </DataArray>\n      </Cells>\n";
  if (!fields.point_data.empty()) {
    out += "      <PointData>\n";
    for (const auto& [array_name, values] : fields.point_data) detail::append_data_array(out, array_name, values, 0);
    out += "      </PointData>\n";
  }
  if (!fields.cell_data.empty() || options.include_facets) {
    out += "      <CellData>\n";
    for (const auto& [array_name, values] : fields.cell_data)
      detail::append_data_array(out, array_name, values, num_written - mesh.num_cells());
    if (options.include_facets) {
      Eigen::MatrixXd facet_tag = Eigen::MatrixXd::Zero(1, num_written);
      Index j = mesh.num_cells();
      for (const auto& b : mesh.facets)
        for (const int tag : b.tags) facet_tag(0, j++) = tag;
      detail::append_data_array(out, "facet_tag", facet_tag, 0);
    }
    out += "      </CellData>\n";
  }
  out += "    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n";
  return out;
}

/// Writes `mesh` and `fields` to a .vtu file (through a temporary file and a rename).
/// Throws as format_vtu(), and IoError when the file cannot be written.
template <int Dim>
void write_vtu(const std::filesystem::path& file, const Mesh<Dim>& mesh, const VtuFields& fields = {},
               const VtuOptions& options = {}) {
  const std::string content = format_vtu(mesh, fields, options);
  detail::write_file_atomically(file, content);
}

}  // namespace meshmotion
