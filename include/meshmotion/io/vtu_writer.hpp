#pragma once
/// \file
/// VTK XML unstructured grid (.vtu) writer, inline base64 binary (default) or ASCII. Quadratic elements that VTK has as
/// Lagrange cells (line3, tri6, quad9, tet10, hex27, prism18) are written as such so ParaView
/// draws them curved; serendipity types use the classic quadratic cells (pyramid14 is written
/// as the 13-node quadratic pyramid). Point data and cell data are named arrays.

#include "meshmotion/core/element.hpp"
#include "meshmotion/core/error.hpp"
#include "meshmotion/core/mesh.hpp"
#include "meshmotion/core/shape_functions.hpp"
#include "meshmotion/core/detail/atomic_file.hpp"
#include "meshmotion/io/detail/number_format.hpp"

#include <Eigen/Core>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
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
  const bool lagrange = (info.order == 2 || info.vtk_id < 0) && info.vtk_lagrange_id >= 0;
  const auto order = vtk_order(t, lagrange);
  return {lagrange ? info.vtk_lagrange_id : info.vtk_id, order,
          order.empty() ? info.num_nodes : static_cast<int>(order.size())};
}

inline void encode_base64(std::string& out, const unsigned char* bytes, std::size_t n) {
  static constexpr char alphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  // Sized once and written through a pointer: character appends kept the encoder at ~100 MB/s.
  const std::size_t start = out.size();
  out.resize(start + (n + 2) / 3 * 4);
  char* o = out.data() + start;
  std::size_t i = 0;
  // Two characters per lookup of 12 bits: half the lookups of one per 6 bits (the .vtu of the
  // 30P30N's P2 mesh encodes 11 MB).
  static const std::array<std::array<char, 2>, 4096> pairs = [] {
    std::array<std::array<char, 2>, 4096> table{};
    for (unsigned k = 0; k < 4096; ++k) table[k] = {alphabet[k >> 6], alphabet[k & 63u]};
    return table;
  }();
  for (; i + 3 <= n; i += 3, o += 4) {
    const unsigned v = (unsigned{bytes[i]} << 16) | (unsigned{bytes[i + 1]} << 8) | bytes[i + 2];
    std::memcpy(o, pairs[v >> 12].data(), 2);
    std::memcpy(o + 2, pairs[v & 4095u].data(), 2);
  }
  if (i == n) return;
  const unsigned v = (unsigned{bytes[i]} << 16) | (i + 1 < n ? unsigned{bytes[i + 1]} << 8 : 0u);
  o[0] = alphabet[(v >> 18) & 63u];
  o[1] = alphabet[(v >> 12) & 63u];
  o[2] = i + 1 < n ? alphabet[(v >> 6) & 63u] : '=';
  o[3] = '=';
}

/// One <DataArray> element of `count` values, the i-th being `value(i)`; `attributes` holds its
/// type, name and component count. In binary, the UInt64 byte count and the data are
/// base64-encoded separately, as VTK's reader expects. The values are made and encoded a slice
/// at a time (a whole number of 3-byte groups, so the slices' encodings join into the array's),
/// with no copy of the array.
template <class T, class Value>
void append_data_array(TextOutput& output, const std::string& attributes, std::size_t count, Value&& value,
                       std::size_t per_line, VtuEncoding encoding) {
  std::string& out = output.text;
  const bool binary = encoding == VtuEncoding::binary;
  out += "        <DataArray " + attributes + " format=\"" + (binary ? "binary" : "ascii") + "\">\n";
  if (binary) {
    const std::uint64_t num_bytes = count * sizeof(T);
    out += "          ";
    encode_base64(out, reinterpret_cast<const unsigned char*>(&num_bytes), sizeof(num_bytes));
    constexpr std::size_t slice = 3 * 8192;
    std::vector<T> values(std::min(slice, count));
    for (std::size_t first = 0; first < count; first += slice) {
      const std::size_t n = std::min(slice, count - first);
      for (std::size_t i = 0; i < n; ++i) values[i] = value(first + i);
      encode_base64(out, reinterpret_cast<const unsigned char*>(values.data()), n * sizeof(T));
      output.spill();
    }
    out.push_back('\n');
  } else {
    for (std::size_t i = 0; i < count; ++i) {
      const T v = value(i);
      if constexpr (std::is_floating_point_v<T>) {
        if (std::isnan(v))
          out += "nan";
        else
          append_number(out, v);
      } else {
        append_number(out, static_cast<std::int64_t>(v));
      }
      out.push_back((i + 1) % per_line == 0 || i + 1 == count ? '\n' : ' ');
      output.spill();
    }
  }
  out += "        </DataArray>\n";
}

/// A named Float64 array from a field matrix (a column per entity), padded with NaN entities.
inline void append_field(TextOutput& output, const std::string& name, const Eigen::MatrixXd& values, Index num_padding,
                         VtuEncoding encoding) {
  const auto size = static_cast<std::size_t>(values.size());
  append_data_array<double>(
      output, "type=\"Float64\" Name=\"" + name + "\" NumberOfComponents=\"" + std::to_string(values.rows()) + "\"",
      size + static_cast<std::size_t>(num_padding * values.rows()),
      [&](std::size_t i) { return i < size ? values.data()[i] : std::nan(""); }, static_cast<std::size_t>(values.rows()),
      encoding);
}

/// The written elements (cells, then facets when asked) as one sequence of VTK cells: the
/// k-th node of the e-th element, offsets and types by position.
class VtkCellSequence {
 public:
  explicit VtkCellSequence(std::vector<const ElementBlock*> blocks) : blocks_(std::move(blocks)) {
    for (const auto* b : blocks_) {
      cells_.push_back(vtk_cell(b->type));
      first_element_.push_back(num_elements_);
      first_node_.push_back(num_nodes_);
      num_elements_ += static_cast<std::size_t>(b->size());
      num_nodes_ += static_cast<std::size_t>(b->size()) * static_cast<std::size_t>(cells_.back().num_nodes);
    }
  }
  [[nodiscard]] std::size_t num_elements() const { return num_elements_; }
  [[nodiscard]] std::size_t num_nodes() const { return num_nodes_; }

  [[nodiscard]] std::int64_t node(std::size_t i) const {
    const std::size_t b = block_of(first_node_, i);
    const auto& cell = cells_[b];
    const std::size_t local = i - first_node_[b], per = static_cast<std::size_t>(cell.num_nodes);
    const std::size_t k = local % per;
    return blocks_[b]->element(static_cast<Index>(local / per))[cell.order.empty() ? k : static_cast<std::size_t>(cell.order[k])];
  }
  [[nodiscard]] std::int64_t offset(std::size_t e) const {
    const std::size_t b = block_of(first_element_, e);
    return static_cast<std::int64_t>(first_node_[b] + (e - first_element_[b] + 1) * static_cast<std::size_t>(cells_[b].num_nodes));
  }
  [[nodiscard]] std::uint8_t type(std::size_t e) const {
    return static_cast<std::uint8_t>(cells_[block_of(first_element_, e)].type);
  }

 private:
  // The block holding position i of a sequence whose blocks start at `firsts` (the last of
  // equal starts: empty blocks hold nothing).
  [[nodiscard]] static std::size_t block_of(const std::vector<std::size_t>& firsts, std::size_t i) {
    return static_cast<std::size_t>(std::upper_bound(firsts.begin(), firsts.end(), i) - firsts.begin()) - 1;
  }

  std::vector<const ElementBlock*> blocks_;
  std::vector<VtkCell> cells_;
  std::vector<std::size_t> first_element_, first_node_;
  std::size_t num_elements_ = 0, num_nodes_ = 0;
};

template <int Dim>
void check_vtu_writable(const Mesh<Dim>& mesh, const VtuFields& fields) {
  validate(mesh);
  for (const auto* list : {&mesh.cells, &mesh.facets})
    for (const auto& b : *list)
      if (vtk_cell(b.type).type < 0)
        throw InputError("write_vtu: VTK has no cell for " + std::string(name(b.type)) +
                         " elements (its Lagrange pyramids are not in VTK 9.1; write .msh instead)");
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
}

template <int Dim>
void format_vtu(TextOutput& output, const Mesh<Dim>& mesh, const VtuFields& fields, const VtuOptions& options) {
  std::vector<const ElementBlock*> blocks;
  for (const auto& b : mesh.cells) blocks.push_back(&b);
  if (options.include_facets)
    for (const auto& b : mesh.facets) blocks.push_back(&b);
  const VtkCellSequence cells(std::move(blocks));
  const auto num_written = static_cast<Index>(cells.num_elements());

  const auto encoding = options.encoding;
  std::string& out = output.text;
  out += std::string("<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"") +
         (std::endian::native == std::endian::little ? "LittleEndian" : "BigEndian") + "\" header_type=\"UInt64\">\n";
  out += "  <UnstructuredGrid>\n    <Piece NumberOfPoints=\"" + std::to_string(mesh.num_nodes()) + "\" NumberOfCells=\"" +
         std::to_string(num_written) + "\">\n";
  out += "      <Points>\n";
  append_data_array<double>(
      output, "type=\"Float64\" NumberOfComponents=\"3\"", static_cast<std::size_t>(3 * mesh.num_nodes()),
      [&](std::size_t i) {
        const auto d = static_cast<int>(i % 3);
        return d < Dim ? mesh.points(d, static_cast<Index>(i / 3)) : 0.0;
      },
      3, encoding);
  out += "      </Points>\n      <Cells>\n";
  append_data_array<std::int64_t>(output, "type=\"Int64\" Name=\"connectivity\"", cells.num_nodes(),
                                  [&](std::size_t i) { return cells.node(i); }, 1, encoding);
  append_data_array<std::int64_t>(output, "type=\"Int64\" Name=\"offsets\"", cells.num_elements(),
                                  [&](std::size_t e) { return cells.offset(e); }, 1, encoding);
  append_data_array<std::uint8_t>(output, "type=\"UInt8\" Name=\"types\"", cells.num_elements(),
                                  [&](std::size_t e) { return cells.type(e); }, 1, encoding);
  out += "      </Cells>\n";
  if (!fields.point_data.empty()) {
    out += "      <PointData>\n";
    for (const auto& [array_name, values] : fields.point_data) append_field(output, array_name, values, 0, encoding);
    out += "      </PointData>\n";
  }
  if (!fields.cell_data.empty() || options.include_facets) {
    out += "      <CellData>\n";
    for (const auto& [array_name, values] : fields.cell_data)
      append_field(output, array_name, values, num_written - mesh.num_cells(), encoding);
    if (options.include_facets) {
      Eigen::MatrixXd facet_tag = Eigen::MatrixXd::Zero(1, num_written);
      Index j = mesh.num_cells();
      for (const auto& b : mesh.facets)
        for (const int tag : b.tags) facet_tag(0, j++) = tag;
      append_field(output, "facet_tag", facet_tag, 0, encoding);
    }
    out += "      </CellData>\n";
  }
  out += "    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n";
}

}  // namespace detail

/// The content of a .vtu file for `mesh` and `fields`. Throws InputError for an invalid mesh,
/// an array name with a quote, or an array whose column count is not n_nodes (point data) or
/// num_cells() (cell data).
template <int Dim>
[[nodiscard]] std::string format_vtu(const Mesh<Dim>& mesh, const VtuFields& fields = {}, const VtuOptions& options = {}) {
  detail::check_vtu_writable(mesh, fields);
  detail::TextOutput output;
  Index connectivity = 0;
  for (const auto& b : mesh.cells) connectivity += static_cast<Index>(b.connectivity.size());
  output.text.reserve(static_cast<std::size_t>(mesh.num_nodes() * 40 + connectivity * 12));
  detail::format_vtu(output, mesh, fields, options);
  return std::move(output.text);
}

/// Writes `mesh` and `fields` to a .vtu file, streamed through a temporary file and a rename.
/// Throws as format_vtu() (before anything is written), and IoError when the file cannot be
/// written.
template <int Dim>
void write_vtu(const std::filesystem::path& file, const Mesh<Dim>& mesh, const VtuFields& fields = {},
               const VtuOptions& options = {}) {
  detail::check_vtu_writable(mesh, fields);
  detail::write_streamed(file, [&](detail::TextOutput& output) { detail::format_vtu(output, mesh, fields, options); });
}

}  // namespace meshmotion
