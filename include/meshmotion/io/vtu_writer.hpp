#pragma once
/// \file
/// VTK XML unstructured grid (.vtu) writer, inline base64 binary (default) or ASCII. Quadratic elements that VTK has as
/// Lagrange cells (line3, tri6, quad9, tet10, hex27, prism18) are written as such so ParaView
/// draws them curved; serendipity types use the classic quadratic cells (pyramid14 is written
/// as the 13-node quadratic pyramid). Point data and cell data are named arrays.

#include "meshmotion/core/element.hpp"
#include "meshmotion/core/error.hpp"
#include "meshmotion/core/mesh.hpp"
#include "meshmotion/io/detail/atomic_file.hpp"
#include "meshmotion/io/detail/number_format.hpp"

#include <Eigen/Core>

#include <bit>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace meshmotion {

/// Named arrays to write: each a matrix with one column per node (point data) or per cell in
/// cell order (cell data); the rows are the components (1 for a scalar, Dim for a vector).
struct VtuFields {
  std::vector<std::pair<std::string, Eigen::MatrixXd>> point_data;
  std::vector<std::pair<std::string, Eigen::MatrixXd>> cell_data;
};

/// How a .vtu file stores its arrays.
enum class VtuEncoding {
  ascii,   ///< numbers as text (shortest round-trip form): readable, ~3× larger, slower
  binary,  ///< base64 of the little/big-endian bytes (VTK's inline "binary" format): exact, compact
};

/// Options of write_vtu().
struct VtuOptions {
  /// Also write the facets (after the cells); their cell data values are NaN, and a cell array
  /// "facet_tag" (0 on cells) tells them apart.
  bool include_facets = false;
  /// Binary by default: a curved mesh of a few million nodes is several hundred MB as text.
  VtuEncoding encoding = VtuEncoding::binary;
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

inline void append_base64(std::string& out, const unsigned char* bytes, std::size_t n) {
  static constexpr char alphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  // Sized once and written through a pointer: character appends kept the encoder at ~100 MB/s.
  const std::size_t start = out.size();
  out.resize(start + (n + 2) / 3 * 4);
  char* o = out.data() + start;
  std::size_t i = 0;
  for (; i + 3 <= n; i += 3, o += 4) {
    const unsigned v = (unsigned{bytes[i]} << 16) | (unsigned{bytes[i + 1]} << 8) | bytes[i + 2];
    o[0] = alphabet[(v >> 18) & 63u];
    o[1] = alphabet[(v >> 12) & 63u];
    o[2] = alphabet[(v >> 6) & 63u];
    o[3] = alphabet[v & 63u];
  }
  if (i == n) return;
  const unsigned v = (unsigned{bytes[i]} << 16) | (i + 1 < n ? unsigned{bytes[i + 1]} << 8 : 0u);
  o[0] = alphabet[(v >> 18) & 63u];
  o[1] = alphabet[(v >> 12) & 63u];
  o[2] = i + 1 < n ? alphabet[(v >> 6) & 63u] : '=';
  o[3] = '=';
}

/// One <DataArray> element; `attributes` holds its type, name and component count. In binary,
/// the UInt64 byte count and the data are base64-encoded separately, as VTK's reader expects.
template <class T>
void append_data_array(std::string& out, const std::string& attributes, const std::vector<T>& values,
                       std::size_t per_line, VtuEncoding encoding) {
  const bool binary = encoding == VtuEncoding::binary;
  out += "        <DataArray " + attributes + " format=\"" + (binary ? "binary" : "ascii") + "\">\n";
  if (binary) {
    const std::uint64_t num_bytes = values.size() * sizeof(T);
    out += "          ";
    append_base64(out, reinterpret_cast<const unsigned char*>(&num_bytes), sizeof(num_bytes));
    append_base64(out, reinterpret_cast<const unsigned char*>(values.data()), num_bytes);
    out.push_back('\n');
  } else {
    for (std::size_t i = 0; i < values.size(); ++i) {
      if constexpr (std::is_floating_point_v<T>) {
        if (std::isnan(values[i]))
          out += "nan";
        else
          append_number(out, values[i]);
      } else {
        append_number(out, static_cast<std::int64_t>(values[i]));
      }
      out.push_back((i + 1) % per_line == 0 || i + 1 == values.size() ? '\n' : ' ');
    }
  }
  out += "        </DataArray>\n";
}

/// A named Float64 array from a field matrix (a column per entity), padded with NaN entities.
inline void append_field(std::string& out, const std::string& name, const Eigen::MatrixXd& values, Index num_padding,
                         VtuEncoding encoding) {
  std::vector<double> flat(values.data(), values.data() + values.size());
  flat.resize(flat.size() + static_cast<std::size_t>(num_padding * values.rows()), std::nan(""));
  append_data_array(out, "type=\"Float64\" Name=\"" + name + "\" NumberOfComponents=\"" + std::to_string(values.rows()) + "\"",
                    flat, static_cast<std::size_t>(values.rows()), encoding);
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

  std::vector<double> points(static_cast<std::size_t>(3 * mesh.num_nodes()), 0.0);
  for (Index i = 0; i < mesh.num_nodes(); ++i)
    for (int d = 0; d < Dim; ++d) points[static_cast<std::size_t>(3 * i + d)] = mesh.points(d, i);
  std::vector<std::int64_t> connectivity;
  std::vector<std::int64_t> offsets;
  std::vector<std::uint8_t> types;
  offsets.reserve(static_cast<std::size_t>(num_written));
  types.reserve(static_cast<std::size_t>(num_written));
  for (const auto* b : blocks) {
    const auto cell = detail::vtk_cell(b->type);
    for (Index e = 0; e < b->size(); ++e) {
      const auto nodes = b->element(e);
      for (int k = 0; k < cell.num_nodes; ++k)
        connectivity.push_back(nodes[static_cast<std::size_t>(cell.order.empty() ? k : cell.order[static_cast<std::size_t>(k)])]);
      offsets.push_back(static_cast<std::int64_t>(connectivity.size()));
      types.push_back(static_cast<std::uint8_t>(cell.type));
    }
  }

  const auto encoding = options.encoding;
  std::string out;
  out.reserve(static_cast<std::size_t>(mesh.num_nodes() * 40 + static_cast<Index>(connectivity.size()) * 12));
  out += std::string("<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"") +
         (std::endian::native == std::endian::little ? "LittleEndian" : "BigEndian") + "\" header_type=\"UInt64\">\n";
  out += "  <UnstructuredGrid>\n    <Piece NumberOfPoints=\"" + std::to_string(mesh.num_nodes()) + "\" NumberOfCells=\"" +
         std::to_string(num_written) + "\">\n";
  out += "      <Points>\n";
  detail::append_data_array(out, "type=\"Float64\" NumberOfComponents=\"3\"", points, 3, encoding);
  out += "      </Points>\n      <Cells>\n";
  detail::append_data_array(out, "type=\"Int64\" Name=\"connectivity\"", connectivity, 1, encoding);
  detail::append_data_array(out, "type=\"Int64\" Name=\"offsets\"", offsets, 1, encoding);
  detail::append_data_array(out, "type=\"UInt8\" Name=\"types\"", types, 1, encoding);
  out += "      </Cells>\n";
  if (!fields.point_data.empty()) {
    out += "      <PointData>\n";
    for (const auto& [array_name, values] : fields.point_data) detail::append_field(out, array_name, values, 0, encoding);
    out += "      </PointData>\n";
  }
  if (!fields.cell_data.empty() || options.include_facets) {
    out += "      <CellData>\n";
    for (const auto& [array_name, values] : fields.cell_data)
      detail::append_field(out, array_name, values, num_written - mesh.num_cells(), encoding);
    if (options.include_facets) {
      Eigen::MatrixXd facet_tag = Eigen::MatrixXd::Zero(1, num_written);
      Index j = mesh.num_cells();
      for (const auto& b : mesh.facets)
        for (const int tag : b.tags) facet_tag(0, j++) = tag;
      detail::append_field(out, "facet_tag", facet_tag, 0, encoding);
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
