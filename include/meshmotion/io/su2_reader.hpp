#pragma once
/// \file
/// SU2 native mesh (.su2) reader: NDIME 2 or 3, mixed elements (VTK type numbers and node
/// order, 0-based node indices; high-order elements of SU2's DG-FEM format, type + 100 ×
/// (order - 1) with nodes on its lattice), NPOIN before or after NELEM, an optional trailing index on
/// point and element lines, and markers, each becoming a facet group (tag = position of the
/// marker, from 1). Sections that are not mesh data (NZONE/IZONE, the periodic
/// transformations of NPERIODIC/PERIODIC_INDEX, SU2_DEF's FFD boxes) are skipped.
/// Elements keep the file's orientation: check it with orientation_report() (core/orientation.hpp).

#include "meshmotion/core/element.hpp"
#include "meshmotion/core/error.hpp"
#include "meshmotion/core/mesh.hpp"
#include "meshmotion/core/shape_functions.hpp"
#include "meshmotion/io/any_mesh.hpp"
#include "meshmotion/io/detail/raw_mesh.hpp"
#include "meshmotion/io/detail/read_file.hpp"
#include "meshmotion/io/detail/text_cursor.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace meshmotion {
namespace detail {

class Su2Parser {
 public:
  Su2Parser(std::string_view data, std::filesystem::path file) : text_(data, std::move(file)) { block_of_type_.fill(-1); }

  [[nodiscard]] RawMesh parse() {
    std::vector<PendingElement> pending;  // NELEM may come before NPOIN: indices checked at the end
    while (!text_.at_end()) {
      if (text_.remaining().front() == '%') {
        text_.next_line();
        continue;
      }
      const std::string_view key = keyword();
      if (key == "NDIME") {
        dim_ = text_.integer<int>("NDIME", 2, 3);
        text_.next_line();
      } else if (key == "NPOIN") {
        require_dim();
        read_points();
      } else if (key == "NELEM") {
        require_dim();
        read_elements(pending);
      } else if (key == "NMARK") {
        require_dim();
        read_markers(pending);
      } else if (marker_tag(key) || marker_elems(key)) {
        text_.fail(std::string(key) + "= of a marker beyond NMARK= (the file lists more markers than NMARK= counts)");
      } else if (key == "NZONE") {
        const auto zones = text_.integer<int>("NZONE", 1);
        if (zones > 1)
          text_.fail("NZONE= " + std::to_string(zones) + ": a multi-zone SU2 file (its zones are not read; give each zone "
                     "as a file of its own)");
        text_.next_line();
      } else {
        skip_section();  // IZONE, NPERIODIC/PERIODIC_INDEX, FFD_* boxes: not mesh data
      }
    }
    if (dim_ < 0) text_.fail("no NDIME keyword (expected NDIME= 2 or 3)");
    if (!have_points_) text_.fail("no NPOIN section (expected the points)");
    if (!have_elements_) text_.fail("no NELEM section (expected the elements)");
    const auto n = raw_.num_nodes();
    for (const auto& p : pending) {
      const auto& block = raw_.blocks[static_cast<std::size_t>(p.block)];
      for (int k = 0; k < block.nodes_per_element(); ++k) {
        const Index v = block.connectivity[static_cast<std::size_t>(p.first + k)];
        if (v >= n)
          throw ParseError(text_.file(), p.line, "node index " + std::to_string(v) + " out of range (expected 0 to " +
                                                     std::to_string(n - 1) + ")");
      }
    }
    raw_.dim = dim_;
    return std::move(raw_);
  }

 private:
  struct PendingElement {
    int block;
    std::size_t first;
    std::uint64_t line;
  };

  // SU2's own reader takes the line after NMARK= as a marker's tag and the next as its element
  // count whatever their keywords say; files from SU2's repository write MARKERTAG= (and
  // MARKERELEMS=). Both spellings are read, any other keyword there is refused.
  [[nodiscard]] static bool marker_tag(std::string_view key) { return key == "MARKER_TAG" || key == "MARKERTAG"; }
  [[nodiscard]] static bool marker_elems(std::string_view key) { return key == "MARKER_ELEMS" || key == "MARKERELEMS"; }

  // "KEY=" possibly with spaces around '='; the cursor stops after '='.
  [[nodiscard]] std::string_view keyword() {
    const std::string_view rest = text_.remaining();
    std::size_t k = 0;
    while (k < rest.size() && rest[k] != '=' && rest[k] != '\n' && rest[k] != ' ' && rest[k] != '\t') ++k;
    std::size_t eq = k;
    while (eq < rest.size() && (rest[eq] == ' ' || rest[eq] == '\t')) ++eq;
    if (eq >= rest.size() || rest[eq] != '=')
      text_.fail("expected a keyword such as NDIME=, NPOIN=, NELEM= or NMARK= (got '" +
                 TextCursor::shorten(rest.substr(0, rest.find('\n'))) + "')");
    text_.seek(text_.offset() + eq + 1);
    return rest.substr(0, k);
  }

  // True when the current line starts with a keyword ("KEY=" or "KEY ="), not data.
  [[nodiscard]] bool at_keyword_line() const {
    const std::string_view rest = text_.remaining();
    std::size_t k = 0;
    while (k < rest.size() && rest[k] != '=' && rest[k] != '\n' && rest[k] != ' ' && rest[k] != '\t') ++k;
    while (k < rest.size() && (rest[k] == ' ' || rest[k] == '\t')) ++k;
    return k < rest.size() && rest[k] == '=';
  }

  // Skips the line of a keyword the reader does not use and the data lines under it (SU2's
  // periodic transformations, the FFD boxes' corner, control and surface points), up to the
  // next keyword line.
  void skip_section() {
    text_.next_line();
    while (!text_.at_end() && !at_keyword_line()) text_.next_line();
  }

  void require_dim() {
    if (dim_ < 0) text_.fail("NDIME must come first (expected NDIME= 2 or 3)");
  }

  void read_points() {
    if (have_points_) text_.fail("a second NPOIN section");
    have_points_ = true;
    const auto count = text_.integer<std::int64_t>("number of points", 0);
    text_.next_line();  // SU2 may add the number of domain points after the total
    const auto capped = static_cast<std::size_t>(std::min<std::int64_t>(count, static_cast<std::int64_t>(text_.remaining().size())));
    raw_.coords.reserve(3 * capped);
    for (std::int64_t i = 0; i < count; ++i) {
      skip_comments();
      for (int d = 0; d < 3; ++d) {
        if (d < dim_ && text_.at_line_end())
          text_.fail("point " + std::to_string(i) + " has " + std::to_string(d) + " coordinates (expected " + std::to_string(dim_) + ")");
        raw_.coords.push_back(d < dim_ ? text_.real("point coordinate") : 0.0);
      }
      text_.next_line();  // optional index (and, in some 2D files, a zero z) after the coordinates
    }
    raw_.first_node_id = 0;  // SU2's point index, which element lines and markers use
  }

  void skip_comments() {
    while (!text_.at_end() && text_.remaining().front() == '%') text_.next_line();
  }

  ElementBlock& block_for(int su2_type, int expected_dim, std::uint64_t line, int& index_out) {
    ElementType type{};
    try {
      type = element_type_from_su2(su2_type);
    } catch (const InputError& e) {
      throw ParseError(text_.file(), line, e.what());
    }
    if (dimension(type) != expected_dim)
      throw ParseError(text_.file(), line, std::string(name(type)) + " element of dimension " + std::to_string(dimension(type)) +
                                               " (expected dimension " + std::to_string(expected_dim) + " here)");
    int& index = block_of_type_[static_cast<std::size_t>(type)];
    if (index < 0) {
      index = static_cast<int>(raw_.blocks.size());
      raw_.blocks.push_back(ElementBlock{type, {}, {}, {}, {}});
    }
    index_out = index;
    return raw_.blocks[static_cast<std::size_t>(index)];
  }

  // Reads `count` element lines (after the count keyword) of dimension `element_dim` with `tag`.
  void read_element_lines(std::int64_t count, std::vector<PendingElement>& pending, int tag, int element_dim) {
    for (std::int64_t e = 0; e < count; ++e) {
      skip_comments();
      const std::uint64_t line = text_.line();
      int index = 0;
      ElementBlock& block = block_for(text_.integer<int>("element type"), element_dim, line, index);
      const std::size_t first = block.connectivity.size();
      const int nodes = block.nodes_per_element();
      block.connectivity.resize(first + static_cast<std::size_t>(nodes));
      // The file lists nodes in VTK's order (SU2's lattice past order 1): its node k is our
      // local node order[k].
      const auto order = su2_node_order(block.type);
      for (int k = 0; k < nodes; ++k) {
        if (text_.at_line_end())
          text_.fail(std::string(name(block.type)) + " element with " + std::to_string(k) + " nodes (expected " +
                     std::to_string(nodes) + ")");
        const int local = order.empty() ? k : order[static_cast<std::size_t>(k)];
        block.connectivity[first + static_cast<std::size_t>(local)] = text_.integer<Index>("node index", 0);
      }
      if (const auto twice = repeated_node(block.connectivity.data() + first, nodes))
        text_.fail(std::string(name(block.type)) + " element lists node " + std::to_string(*twice) + " twice");
      // SU2 lists the element's index after its nodes; more numbers mean that the type code
      // and the nodes disagree (a prism listed as a tetrahedron), which must not pass as a
      // smaller element.
      if (!text_.at_line_end()) {
        (void)text_.integer<std::int64_t>("element index");
        if (!text_.at_line_end())
          text_.fail(std::string(name(block.type)) + " element with more numbers than its " + std::to_string(nodes) +
                     " nodes and an index (does its type code match its nodes?)");
      }
      block.tags.push_back(tag);
      pending.push_back({index, first, line});
      text_.next_line();
    }
  }

  void read_elements(std::vector<PendingElement>& pending) {
    if (have_elements_) text_.fail("a second NELEM section");
    have_elements_ = true;
    const auto count = text_.integer<std::int64_t>("number of elements", 0);
    text_.next_line();
    read_element_lines(count, pending, 0, dim_);
  }

  void read_markers(std::vector<PendingElement>& pending) {
    const auto count = text_.integer<int>("number of markers", 0);
    text_.next_line();
    for (int m = 0; m < count; ++m) {
      skip_comments();
      if (!marker_tag(keyword())) text_.fail("expected MARKER_TAG= for marker " + std::to_string(m + 1));
      PhysicalGroup g;
      g.dim = dim_ - 1;
      g.tag = m + 1;
      g.name = std::string(text_.rest_of_line());
      if (g.name.empty()) text_.fail("empty marker name (expected MARKER_TAG= name)");
      skip_comments();
      if (!marker_elems(keyword())) text_.fail("expected MARKER_ELEMS= for marker '" + g.name + "'");
      const auto n = text_.integer<std::int64_t>("number of marker elements", 0);
      text_.next_line();
      read_element_lines(n, pending, g.tag, dim_ - 1);
      raw_.groups.push_back(std::move(g));
    }
  }

  TextCursor text_;
  RawMesh raw_;
  int dim_ = -1;
  bool have_points_ = false;
  bool have_elements_ = false;
  std::array<int, num_element_types> block_of_type_{};
};

}  // namespace detail

/// Parses SU2 mesh content held in memory; `file` names it in error messages.
/// Throws ParseError for malformed content, InputError for an invalid mesh.
[[nodiscard]] inline AnyMesh parse_su2(std::string_view data, const std::filesystem::path& file) {
  return detail::to_any_mesh(detail::Su2Parser(data, file).parse(), file);
}

/// Reads an SU2 .su2 mesh file. Throws IoError when unreadable and as parse_su2() otherwise.
[[nodiscard]] inline AnyMesh read_su2(const std::filesystem::path& file) {
  const std::string data = detail::read_whole_file(file);
  return parse_su2(data, file);
}

}  // namespace meshmotion
