#pragma once
/// \file
/// VTK XML unstructured grid (.vtu) reader: what write_vtu() writes and what ParaView and VTK
/// write uncompressed — ASCII or inline base64 binary arrays (UInt32 or UInt64 headers, either
/// byte order), classic linear and quadratic cells and Lagrange cells up to order 4, in the
/// library's node order (Lagrange hexahedra in the legacy edge order of files before version
/// 2.2, which write_vtu() declares, or in the order of later ones). Cells of the mesh's dimension are its cells; cells one dimension
/// lower its facets, tagged by a "facet_tag" cell array when there is one (write_vtu with
/// include_facets), else 0; lower ones go to `lower`. Compressed and appended data are refused
/// by name.

#include "meshmotion/core/element.hpp"
#include "meshmotion/core/error.hpp"
#include "meshmotion/core/mesh.hpp"
#include "meshmotion/io/any_mesh.hpp"
#include "meshmotion/io/detail/raw_mesh.hpp"
#include "meshmotion/io/detail/read_file.hpp"
#include "meshmotion/io/vtu_writer.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

namespace meshmotion {

namespace detail {

// The file's text with positions turned into line numbers for errors.
class VtuText {
 public:
  VtuText(std::filesystem::path file, std::string text) : file_(std::move(file)), text_(std::move(text)) {}
  [[nodiscard]] const std::string& text() const noexcept { return text_; }
  [[noreturn]] void fail(std::size_t at, const std::string& what) const {
    const auto line = 1 + std::count(text_.begin(), text_.begin() + static_cast<std::ptrdiff_t>(std::min(at, text_.size())), '\n');
    throw ParseError(file_, static_cast<std::uint64_t>(line), what);
  }

 private:
  std::filesystem::path file_;
  std::string text_;
};

// One XML start tag: where it is and its attributes.
struct VtuTag {
  std::size_t at = std::string::npos;  // position of '<'
  std::size_t end = 0;                 // one past '>'
  std::string text;                    // between '<' and '>'
  [[nodiscard]] bool found() const noexcept { return at != std::string::npos; }
  [[nodiscard]] std::optional<std::string> attribute(std::string_view key) const {
    for (std::size_t p = text.find(key); p != std::string::npos; p = text.find(key, p + 1)) {
      const bool starts = p > 0 && (text[p - 1] == ' ' || text[p - 1] == '\n' || text[p - 1] == '\t' || text[p - 1] == '\r');
      std::size_t q = p + key.size();
      if (!starts || q >= text.size() || text[q] != '=') continue;
      const char quote = text[q + 1];
      const std::size_t close = text.find(quote, q + 2);
      if ((quote != '"' && quote != '\'') || close == std::string::npos) return std::nullopt;
      return text.substr(q + 2, close - q - 2);
    }
    return std::nullopt;
  }
};

// The first start tag <name ...> from `from` (before `limit`).
inline VtuTag find_tag(const VtuText& t, std::string_view name, std::size_t from, std::size_t limit = std::string::npos) {
  const std::string& s = t.text();
  const std::string open = "<" + std::string(name);
  for (std::size_t p = s.find(open, from); p != std::string::npos && p < limit; p = s.find(open, p + 1)) {
    const char next = p + open.size() < s.size() ? s[p + open.size()] : '>';
    if (next != ' ' && next != '>' && next != '/' && next != '\n' && next != '\t' && next != '\r') continue;
    const std::size_t close = s.find('>', p);
    if (close == std::string::npos) t.fail(p, "<" + std::string(name) + " is not closed");
    return {p, close + 1, s.substr(p + 1, close - p - 1)};
  }
  return {};
}

inline std::size_t find_end_tag(const VtuText& t, std::string_view name, std::size_t from) {
  const std::size_t p = t.text().find("</" + std::string(name), from);
  if (p == std::string::npos) t.fail(from, "no </" + std::string(name) + "> closes the element");
  return p;
}

inline int base64_value(char c) {
  if (c >= 'A' && c <= 'Z') return c - 'A';
  if (c >= 'a' && c <= 'z') return c - 'a' + 26;
  if (c >= '0' && c <= '9') return c - '0' + 52;
  if (c == '+') return 62;
  if (c == '/') return 63;
  return -1;
}

// Decodes the base64 characters [from, to) of the text, skipping white space. A padded group
// ends a block and the next block starts after it: VTK's writer encodes an array's header and
// data as one block, write_vtu() as two.
inline std::vector<unsigned char> decode_base64(const VtuText& t, std::size_t from, std::size_t to) {
  const std::string& s = t.text();
  std::vector<unsigned char> out;
  out.reserve((to - from) / 4 * 3);
  std::array<int, 4> group{};
  int filled = 0, padding = 0;
  for (std::size_t p = from; p < to; ++p) {
    const char c = s[p];
    if (c == ' ' || c == '\n' || c == '\r' || c == '\t') continue;
    const int v = c == '=' ? 0 : base64_value(c);
    if (v < 0 || (padding > 0 && c != '=')) t.fail(p, std::string("'") + c + "' is not a base64 character here");
    padding += c == '=';
    group[static_cast<std::size_t>(filled++)] = v;
    if (filled < 4) continue;
    const unsigned bits = (unsigned(group[0]) << 18) | (unsigned(group[1]) << 12) | (unsigned(group[2]) << 6) | unsigned(group[3]);
    out.push_back(static_cast<unsigned char>(bits >> 16));
    if (padding < 2) out.push_back(static_cast<unsigned char>((bits >> 8) & 255u));
    if (padding < 1) out.push_back(static_cast<unsigned char>(bits & 255u));
    filled = 0;
    padding = 0;
  }
  if (filled != 0) t.fail(to, "base64 data ends inside a group of four characters");
  return out;
}

// One <DataArray>: its attributes and where its content is.
struct VtuArray {
  VtuTag tag;
  std::size_t begin = 0, end = 0;
  [[nodiscard]] std::string name() const { return tag.attribute("Name").value_or(""); }
  [[nodiscard]] int components() const { return std::atoi(tag.attribute("NumberOfComponents").value_or("1").c_str()); }
};

inline std::vector<VtuArray> data_arrays(const VtuText& t, std::size_t from, std::size_t to) {
  std::vector<VtuArray> out;
  for (VtuTag tag = find_tag(t, "DataArray", from, to); tag.found(); tag = find_tag(t, "DataArray", tag.end, to)) {
    VtuArray a;
    a.tag = tag;
    a.begin = tag.end;
    a.end = tag.text.ends_with("/") ? tag.end : find_end_tag(t, "DataArray", tag.end);
    // The values stop at the first child element (VTK's writer adds <InformationKey> ones).
    a.end = std::min(a.end, t.text().find('<', a.begin));
    out.push_back(a);
  }
  return out;
}

// The byte size of a VTK scalar type, 0 when unknown.
inline int vtk_type_size(std::string_view type) {
  static const std::map<std::string_view, int> sizes{{"Int8", 1},  {"UInt8", 1},   {"Int16", 2},   {"UInt16", 2},
                                                     {"Int32", 4}, {"UInt32", 4},  {"Int64", 8},   {"UInt64", 8},
                                                     {"Float32", 4}, {"Float64", 8}};
  const auto it = sizes.find(type);
  return it == sizes.end() ? 0 : it->second;
}

template <class T>
T load(const unsigned char* bytes, bool swap) {
  std::array<unsigned char, sizeof(T)> b;
  std::memcpy(b.data(), bytes, sizeof(T));
  if (swap) std::reverse(b.begin(), b.end());
  return std::bit_cast<T>(b);
}

// The values of an array as doubles (exact for every integer a mesh holds).
struct VtuFormat {
  bool swap = false;        // the file's byte order is not this machine's
  int header_bytes = 4;     // UInt32 (VTK's default) or UInt64
};

inline std::vector<double> array_values(const VtuText& t, const VtuArray& a, const VtuFormat& f, std::size_t expected) {
  const std::string type = a.tag.attribute("type").value_or("");
  const int size = vtk_type_size(type);
  if (size == 0) t.fail(a.tag.at, "DataArray '" + a.name() + "' has type '" + type + "' (expected a VTK scalar type: Int8 .. Float64)");
  const std::string format = a.tag.attribute("format").value_or("ascii");
  std::vector<double> out;
  // `expected` comes from the file's counts: reserve no more than the array's text can hold.
  out.reserve(std::min(expected, a.end - a.begin));
  if (format == "ascii") {
    // Values in the notation of their type: an integer array holds integers only (not 1.5,
    // 1e1 or 0x10), a real array decimal numbers (not hexadecimal ones).
    const bool integers = type.find("Int") != std::string::npos;
    const std::string& s = t.text();
    const auto blank = [&](std::size_t k) { return s[k] == ' ' || s[k] == '\n' || s[k] == '\r' || s[k] == '\t'; };
    std::size_t p = a.begin;
    while (true) {
      while (p < a.end && blank(p)) ++p;
      if (p >= a.end) break;
      std::size_t q = p;
      while (q < a.end && !blank(q)) ++q;
      const char* first = s.data() + p;
      const char* last = s.data() + q;
      double v = 0.0;
      std::from_chars_result r{};
      if (integers) {
        long long i = 0;
        r = std::from_chars(first, last, i);
        v = static_cast<double>(i);
      } else {
        r = std::from_chars(first + (*first == '+' ? 1 : 0), last, v);
      }
      if (r.ec != std::errc() || r.ptr != last)
        t.fail(p, "DataArray '" + a.name() + "': '" + s.substr(p, std::min<std::size_t>(16, q - p)) + "' is not " +
                      (integers ? "an integer (its type is " + type + ")" : std::string("a decimal number")));
      out.push_back(v);
      p = q;
    }
  } else if (format == "binary") {
    const auto decoded = decode_base64(t, a.begin, a.end);
    const auto header = static_cast<std::size_t>(f.header_bytes);
    if (decoded.size() < header) t.fail(a.tag.at, "DataArray '" + a.name() + "' has no byte count");
    const std::uint64_t bytes = header == 8 ? load<std::uint64_t>(decoded.data(), f.swap) : load<std::uint32_t>(decoded.data(), f.swap);
    if (bytes % static_cast<std::uint64_t>(size) != 0 || bytes > decoded.size() - header)
      t.fail(a.tag.at, "DataArray '" + a.name() + "' declares " + std::to_string(bytes) + " bytes (it holds " +
                           std::to_string(decoded.size() - header) + ", in " + type + " values)");
    for (std::size_t i = header; i < header + bytes; i += static_cast<std::size_t>(size)) {
      const unsigned char* b = decoded.data() + i;
      double v = 0.0;
      if (type == "Float64") v = load<double>(b, f.swap);
      else if (type == "Float32") v = load<float>(b, f.swap);
      else if (type == "Int64") v = static_cast<double>(load<std::int64_t>(b, f.swap));
      else if (type == "UInt64") v = static_cast<double>(load<std::uint64_t>(b, f.swap));
      else if (type == "Int32") v = load<std::int32_t>(b, f.swap);
      else if (type == "UInt32") v = load<std::uint32_t>(b, f.swap);
      else if (type == "Int16") v = load<std::int16_t>(b, f.swap);
      else if (type == "UInt16") v = load<std::uint16_t>(b, f.swap);
      else if (type == "Int8") v = load<std::int8_t>(b, f.swap);
      else v = load<std::uint8_t>(b, f.swap);
      out.push_back(v);
    }
  } else {
    t.fail(a.tag.at, "DataArray '" + a.name() + "' has format '" + format + "' (expected ascii or binary; appended data is not read)");
  }
  if (out.size() != expected)
    t.fail(a.tag.at, "DataArray '" + a.name() + "' has " + std::to_string(out.size()) + " values (expected " + std::to_string(expected) + ")");
  return out;
}

// The element type of a VTK cell type with `n` nodes, and the VTK order of its nodes.
struct VtkReadCell {
  ElementType type;
  std::span<const int> order;  // our local node order[k] is the VTK cell's k-th node; empty: identity
};

inline std::optional<VtkReadCell> element_of_vtk(int vtk_type, int n) {
  for (int i = 0; i < num_element_types; ++i) {
    const auto t = static_cast<ElementType>(i);
    const ElementInfo& info = element_info(t);
    for (const bool lagrange : {false, true}) {
      const int id = lagrange ? info.vtk_lagrange_id : info.vtk_id;
      if (id != vtk_type || id < 0) continue;
      const auto order = vtk_order(t, lagrange);
      const int count = order.empty() ? info.num_nodes : static_cast<int>(order.size());
      if (count == n) return VtkReadCell{t, order};
    }
  }
  return std::nullopt;
}

}  // namespace detail

/// Parses VTK XML content held in memory (see the file comment); `file` names it in messages.
/// A 3D mesh when it holds a 3D cell, else a 2D mesh, whose points must then lie in z = 0.
/// Node numbering is the file's; element ids follow the file's order. Throws ParseError (file
/// and line) for malformed content: a missing section or array, an array of the wrong length,
/// a node index out of range, a cell type the library lacks (naming it and its node count),
/// compressed or appended data, a 2D mesh off z = 0.
[[nodiscard]] inline AnyMesh parse_vtu(std::string_view data, const std::filesystem::path& file) {
  const detail::VtuText t(file, std::string(data));
  const detail::VtuTag root = detail::find_tag(t, "VTKFile", 0);
  if (!root.found()) t.fail(0, "no <VTKFile> element (expected a VTK XML file)");
  if (root.attribute("type").value_or("") != "UnstructuredGrid")
    t.fail(root.at, "VTKFile type '" + root.attribute("type").value_or("") + "' (expected UnstructuredGrid)");
  if (root.attribute("compressor"))
    t.fail(root.at, "compressed data (" + *root.attribute("compressor") + ") is not read (write the file uncompressed)");
  detail::VtuFormat format;
  const std::string order = root.attribute("byte_order").value_or("LittleEndian");
  format.swap = (order == "BigEndian") != (std::endian::native == std::endian::big);
  const std::string header = root.attribute("header_type").value_or("UInt32");
  if (header != "UInt32" && header != "UInt64") t.fail(root.at, "header_type '" + header + "' (expected UInt32 or UInt64)");
  format.header_bytes = header == "UInt64" ? 8 : 4;
  const double version = std::atof(root.attribute("version").value_or("0.1").c_str());
  const bool new_hexahedra = version >= 2.2 - 1e-9;

  const detail::VtuTag piece = detail::find_tag(t, "Piece", root.end);
  if (!piece.found()) t.fail(root.end, "no <Piece> element");
  if (detail::find_tag(t, "Piece", piece.end).found()) t.fail(piece.end, "several <Piece> elements (expected one)");
  // A count is refused beyond what the file's bytes can hold (each value takes one at least),
  // before it sizes anything.
  const auto count = [&](const char* key) {
    const std::optional<std::string> text = piece.attribute(key);
    if (!text) t.fail(piece.at, std::string("<Piece> without ") + key);
    long long n = -1;
    const auto [ptr, ec] = std::from_chars(text->data(), text->data() + text->size(), n);
    if (ec != std::errc() || ptr != text->data() + text->size() || n < 0 || static_cast<unsigned long long>(n) > t.text().size())
      t.fail(piece.at, std::string(key) + " '" + text->substr(0, 32) + "' (expected a count the file's " +
                           std::to_string(t.text().size()) + " bytes can hold)");
    return n;
  };
  const long long num_points = count("NumberOfPoints");
  const long long num_cells = count("NumberOfCells");
  const std::size_t piece_end = detail::find_end_tag(t, "Piece", piece.end);

  const auto section = [&](std::string_view name) -> std::pair<std::size_t, std::size_t> {
    const detail::VtuTag tag = detail::find_tag(t, name, piece.end, piece_end);
    if (!tag.found()) return {0, 0};
    return {tag.end, detail::find_end_tag(t, name, tag.end)};
  };
  const auto [points_begin, points_end] = section("Points");
  const std::size_t points_at = points_begin;  // for the lambda below (clang 14 captures no bindings)
  if (points_end == 0) t.fail(piece.end, "no <Points> section");
  const auto point_arrays = detail::data_arrays(t, points_begin, points_end);
  if (point_arrays.empty()) t.fail(points_begin, "<Points> holds no DataArray");
  const int point_components = point_arrays.front().components();
  if (point_components != 3) t.fail(point_arrays.front().tag.at, "points have " + std::to_string(point_components) + " components (expected 3)");
  const std::vector<double> xyz = detail::array_values(t, point_arrays.front(), format, static_cast<std::size_t>(3 * num_points));

  const auto [cells_begin, cells_end] = section("Cells");
  if (cells_end == 0) t.fail(piece.end, "no <Cells> section");
  std::optional<detail::VtuArray> connectivity, offsets, types;
  for (const auto& a : detail::data_arrays(t, cells_begin, cells_end)) {
    if (a.name() == "connectivity") connectivity = a;
    if (a.name() == "offsets") offsets = a;
    if (a.name() == "types") types = a;
  }
  for (const auto& [array, name] : {std::pair{&offsets, "offsets"}, std::pair{&types, "types"}, std::pair{&connectivity, "connectivity"}})
    if (!*array) t.fail(cells_begin, std::string("<Cells> has no '") + name + "' array");
  const std::vector<double> offset = detail::array_values(t, *offsets, format, static_cast<std::size_t>(num_cells));
  const std::vector<double> type = detail::array_values(t, *types, format, static_cast<std::size_t>(num_cells));
  // Each value checked before it is converted: a binary array may hold any double (a NaN, a
  // negative or huge value), whose conversion to an index would be undefined.
  const auto check_integers = [&](const std::vector<double>& values, const detail::VtuArray& a, double lo, double hi) {
    for (std::size_t k = 0; k < values.size(); ++k)
      if (!(values[k] >= lo && values[k] <= hi && values[k] == std::floor(values[k])))
        t.fail(a.tag.at, "DataArray '" + a.name() + "': value " + std::to_string(values[k]) + " of cell " + std::to_string(k) +
                             " (expected an integer from " + std::to_string(static_cast<long long>(lo)) + " to " +
                             std::to_string(static_cast<long long>(hi)) + ")");
  };
  check_integers(offset, *offsets, 0.0, static_cast<double>(t.text().size()));
  check_integers(type, *types, 0.0, 255.0);  // VTK's cell types are UInt8
  const std::size_t num_entries = offset.empty() ? 0 : static_cast<std::size_t>(offset.back());
  const std::vector<double> nodes = detail::array_values(t, *connectivity, format, num_entries);

  std::vector<double> facet_tag;
  if (const auto [data_begin, data_end] = section("CellData"); data_end != 0)
    for (const auto& a : detail::data_arrays(t, data_begin, data_end))
      if (a.name() == "facet_tag") {
        facet_tag = detail::array_values(t, a, format, static_cast<std::size_t>(num_cells));
        check_integers(facet_tag, a, -2147483647.0, 2147483647.0);
      }

  // The elements, in file order, with our node order.
  struct Element {
    detail::VtkReadCell cell;
    std::size_t first;
  };
  std::vector<Element> elements;
  elements.reserve(static_cast<std::size_t>(num_cells));
  int dim = 0;
  std::size_t previous = 0;
  for (std::size_t e = 0; e < offset.size(); ++e) {
    const auto end = static_cast<std::size_t>(offset[e]);
    if (end < previous || end > num_entries) t.fail(offsets->tag.at, "offset " + std::to_string(end) + " of cell " + std::to_string(e) + " is out of order");
    const int n = static_cast<int>(end - previous);
    const auto cell = detail::element_of_vtk(static_cast<int>(type[e]), n);
    if (!cell)
      t.fail(types->tag.at, "cell " + std::to_string(e) + " has VTK type " + std::to_string(static_cast<int>(type[e])) + " with " +
                                std::to_string(n) + " nodes, which the library has no element for");
    elements.push_back({*cell, previous});
    dim = std::max(dim, dimension(cell->type));
    previous = end;
  }
  if (dim < 2) t.fail(cells_begin, "no 2D or 3D cell (expected a surface or volume mesh)");

  const auto build = [&]<int Dim>(Mesh<Dim>& mesh) {
    mesh.points.resize(Dim, static_cast<Index>(num_points));
    mesh.first_node_id = 0;  // the file's point index, which its connectivity uses
    for (Index v = 0; v < static_cast<Index>(num_points); ++v) {
      for (int d = 0; d < Dim; ++d) mesh.points(d, v) = xyz[static_cast<std::size_t>(3 * v + d)];
      if (Dim == 2 && xyz[static_cast<std::size_t>(3 * v + 2)] != 0.0)
        t.fail(points_at, "point " + std::to_string(v) + " has z = " + std::to_string(xyz[static_cast<std::size_t>(3 * v + 2)]) +
                                 " in a mesh of 2D cells (expected z = 0)");
    }
    std::array<Index, max_element_nodes> local{};
    std::array<double, max_element_nodes> listed{};
    for (std::size_t e = 0; e < elements.size(); ++e) {
      const detail::VtkReadCell& cell = elements[e].cell;
      const ElementType et = cell.type;
      auto& blocks = mesh.blocks_of_dim(dimension(et));
      if (blocks.empty() || blocks.back().type != et) blocks.push_back(ElementBlock{et, {}, {}, {}, {}});
      std::copy_n(nodes.begin() + static_cast<std::ptrdiff_t>(elements[e].first), num_nodes(et), listed.begin());
      if (new_hexahedra && static_cast<int>(type[e]) == element_info(et).vtk_lagrange_id && shape(et) == Shape::hexahedron) {
        // From file version 2.2 VTK lists the nodes of the hexahedron's edges 10 and 11 the
        // other way round than the legacy order the library's table holds (vtu_writer.hpp).
        const auto p = static_cast<std::size_t>(meshmotion::order(et));
        const auto first = listed.begin() + static_cast<std::ptrdiff_t>(8 + 10 * (p - 1));
        std::swap_ranges(first, first + static_cast<std::ptrdiff_t>(p - 1), first + static_cast<std::ptrdiff_t>(p - 1));
      }
      for (int k = 0; k < num_nodes(et); ++k) {
        const double id = listed[static_cast<std::size_t>(k)];
        if (!(id >= 0.0 && id < static_cast<double>(num_points)))
          t.fail(connectivity->tag.at, "cell " + std::to_string(e) + " names node " + std::to_string(static_cast<long long>(id)) +
                                           " (expected 0 to " + std::to_string(num_points - 1) + ")");
        local[static_cast<std::size_t>(cell.order.empty() ? k : cell.order[static_cast<std::size_t>(k)])] = static_cast<Index>(id);
      }
      const int tag = facet_tag.empty() ? 0 : static_cast<int>(facet_tag[e]);
      blocks.back().add(std::span<const Index>(local.data(), static_cast<std::size_t>(num_nodes(et))), tag);
      blocks.back().ids.push_back(static_cast<std::int64_t>(e) + 1);
    }
    detail::validate_read(mesh, file);
  };
  if (dim == 3) {
    Mesh<3> mesh;
    build(mesh);
    return mesh;
  }
  Mesh<2> mesh;
  build(mesh);
  return mesh;
}

/// Reads a .vtu file: as parse_vtu() on its content; IoError when it cannot be read.
[[nodiscard]] inline AnyMesh read_vtu(const std::filesystem::path& file) { return parse_vtu(detail::read_whole_file(file), file); }

}  // namespace meshmotion
