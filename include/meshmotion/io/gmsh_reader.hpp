#pragma once
/// \file
/// Gmsh .msh reader: versions 2.2 and 4.1, ASCII and binary (detected from $MeshFormat, with
/// the endianness check word honoured), P1 and P2 elements of every catalogue type (Gmsh ids
/// 1-19 and 15 for points), $PhysicalNames, 4.1 $Entities (physical tags of entities become
/// element tags), the elements' entities (2.2's elementary tag, 4.1's block entity: kept in
/// ElementBlock::entities), 2.2 $ParametricNodes and 4.1 parametric node blocks (kept in
/// Mesh::node_params), arbitrary node and element ids (kept in node_ids / ElementBlock::ids).
/// Unknown sections are skipped. The whole file is parsed from one buffer with from_chars.

#include "meshmotion/core/element.hpp"
#include "meshmotion/core/error.hpp"
#include "meshmotion/core/mesh.hpp"
#include "meshmotion/io/any_mesh.hpp"
#include "meshmotion/io/detail/binary_cursor.hpp"
#include "meshmotion/io/detail/raw_mesh.hpp"
#include "meshmotion/io/detail/read_file.hpp"
#include "meshmotion/io/detail/text_cursor.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace meshmotion {
namespace detail {

class GmshParser {
 public:
  GmshParser(std::string_view data, std::filesystem::path file) : data_(data), text_(data, file), file_(std::move(file)) {
    block_of_type_.fill(-1);
  }

  [[nodiscard]] RawMesh parse() {
    if (text_.at_end()) text_.fail("empty file (expected $MeshFormat)");
    text_.expect("$MeshFormat");
    read_format();
    while (!text_.at_end()) {
      const std::string_view section = text_.word("a section name");
      if (section == "$PhysicalNames") read_physical_names();
      else if (section == "$Entities") read_entities();
      else if (section == "$Nodes") version_ >= 4 ? read_nodes_v4() : read_nodes_v2(false);
      else if (section == "$ParametricNodes" && version_ < 4) read_nodes_v2(true);
      else if (section == "$Elements") version_ >= 4 ? read_elements_v4() : read_elements_v2();
      else if (section.size() > 1 && section[0] == '$' && !section.starts_with("$End")) skip_section(section.substr(1));
      else text_.fail("expected a section such as $Nodes or $Elements (got '" + TextCursor::shorten(section) + "')");
    }
    if (!have_nodes_) text_.fail("no $Nodes section (expected one)");
    int cell_dim = 2;
    for (const auto& b : raw_.blocks)
      if (dimension(b.type) == 3 && !b.empty()) cell_dim = 3;
    for (const int d : {cell_dim - 1, cell_dim})
      if (const auto& first = repeated_[static_cast<std::size_t>(d)]) throw *first;
    if (!node_entity_.empty() && parametric_) raw_.node_params = std::move(node_entity_);
    return std::move(raw_);
  }

 private:
  void read_format() {
    const std::string_view version = text_.word("the format version");
    if (version.starts_with("2.")) version_ = 2.2;
    else if (version == "4.1") version_ = 4.1;
    else text_.fail("unsupported msh version " + TextCursor::shorten(version) + " (expected 2.2 or 4.1)");
    const int file_type = text_.integer<int>("file type (0 ASCII, 1 binary)", 0, 1);
    binary_ = file_type == 1;
    const int data_size = text_.integer<int>("data size", 4, 8);
    if (version_ >= 4 && data_size != 4 && data_size != 8) text_.fail("data size must be 4 or 8 (got " + std::to_string(data_size) + ")");
    if (version_ < 4 && data_size != 8) text_.fail("data size must be 8 for msh 2.2 (got " + std::to_string(data_size) + ")");
    size_bytes_ = static_cast<std::size_t>(data_size);
    if (binary_) {
      text_.next_line();
      BinaryCursor bin(data_, text_.offset(), file_, false);
      const auto one = bin.read<std::int32_t>("endianness check word");
      if (one == 1) swap_ = false;
      else if (byte_swapped(one) == 1) swap_ = true;
      else bin.fail("bad endianness check word (got " + std::to_string(one) + ", expected 1)");
      text_.seek(bin.offset());
      text_.use_byte_offsets();
    }
    text_.expect("$EndMeshFormat");
  }

  void end_section(std::string_view name) {
    const std::string end = "$End" + std::string(name);
    const std::string_view token = text_.word(end);
    if (token != end)
      text_.fail("expected '" + end + "' (got '" + TextCursor::shorten(token) +
                 "': the section holds more or fewer entries than its count says)");
  }

  void skip_section(std::string_view name) {
    const std::string end = "$End" + std::string(name);
    const std::size_t at = text_.remaining().find(end);
    if (at == std::string_view::npos) text_.fail("unterminated section $" + std::string(name) + " (expected " + end + ")");
    const std::string_view skipped = text_.remaining().substr(0, at + end.size());
    text_.seek(text_.offset() + skipped.size(), static_cast<std::uint64_t>(std::count(skipped.begin(), skipped.end(), '\n')));
  }

  void read_physical_names() {
    const auto count = text_.integer<std::int64_t>("number of physical names", 0);
    for (std::int64_t i = 0; i < count; ++i) {
      PhysicalGroup g;
      g.dim = text_.integer<int>("physical group dimension", 0, 3);
      g.tag = text_.integer<int>("physical tag");
      const std::string_view rest = text_.rest_of_line();
      if (rest.size() < 2 || rest.front() != '"' || rest.back() != '"')
        text_.fail("expected a quoted physical name (got '" + TextCursor::shorten(rest) + "')");
      g.name = std::string(rest.substr(1, rest.size() - 2));
      raw_.groups.push_back(std::move(g));
    }
    end_section("PhysicalNames");
  }

  // ---- $Entities (4.1): only the physical tags of each entity matter here.
  void read_entities() {
    if (version_ < 4) return skip_section("Entities");
    if (have_entities_) text_.fail("a second $Entities section (expected one)");
    have_entities_ = true;
    if (binary_) {
      BinaryCursor bin = binary_at_line_start();
      std::array<std::uint64_t, 4> counts{};
      for (auto& c : counts) c = bin.read_size(size_bytes_, "entity count");
      for (int dim = 0; dim < 4; ++dim)
        for (std::uint64_t e = 0; e < counts[static_cast<std::size_t>(dim)]; ++e) {
          const int tag = bin.read<std::int32_t>("entity tag");
          bin.require(dim == 0 ? 3 : 6, sizeof(double), "entity coordinates");
          for (int k = 0; k < (dim == 0 ? 3 : 6); ++k) (void)bin.read<double>("entity coordinate");
          const std::uint64_t num_physical = bin.read_size(size_bytes_, "number of physical tags");
          bin.require(num_physical, 4, "physical tags");
          for (std::uint64_t p = 0; p < num_physical; ++p) {
            const int physical = bin.read<std::int32_t>("physical tag");
            if (p == 0) entity_physical_[{dim, tag}] = physical;
          }
          declare_entity(dim, tag, bin);
          if (dim > 0) {
            const std::uint64_t num_bounding = bin.read_size(size_bytes_, "number of bounding entities");
            bin.require(num_bounding, 4, "bounding entity tags");
            for (std::uint64_t b = 0; b < num_bounding; ++b) (void)bin.read<std::int32_t>("bounding entity tag");
          }
        }
      text_.seek(bin.offset());
    } else {
      std::array<std::int64_t, 4> counts{};
      for (auto& c : counts) c = text_.integer<std::int64_t>("entity count", 0);
      for (int dim = 0; dim < 4; ++dim)
        for (std::int64_t e = 0; e < counts[static_cast<std::size_t>(dim)]; ++e) {
          const int tag = text_.integer<int>("entity tag");
          for (int k = 0; k < (dim == 0 ? 3 : 6); ++k) (void)text_.real("entity coordinate");
          const auto num_physical = text_.integer<std::int64_t>("number of physical tags", 0);
          for (std::int64_t p = 0; p < num_physical; ++p) {
            const int physical = text_.integer<int>("physical tag");
            if (p == 0) entity_physical_[{dim, tag}] = physical;
          }
          declare_entity(dim, tag, text_);
          if (dim > 0) {
            const auto num_bounding = text_.integer<std::int64_t>("number of bounding entities", 0);
            for (std::int64_t b = 0; b < num_bounding; ++b) (void)text_.integer<int>("bounding entity tag");
          }
        }
    }
    end_section("Entities");
  }

  template <class Cursor>
  void declare_entity(int dim, int tag, const Cursor& cursor) {
    if (!entities_.insert({dim, tag}).second)
      cursor.fail("entity " + std::to_string(tag) + " of dimension " + std::to_string(dim) + " declared twice in $Entities");
  }

  // Binary data starts after the line end that follows the section keyword or count line.
  [[nodiscard]] BinaryCursor binary_at_line_start() {
    text_.next_line();
    return BinaryCursor(data_, text_.offset(), file_, swap_);
  }

  void begin_nodes(std::uint64_t count) {
    if (have_nodes_) text_.fail("a second node section (expected one $Nodes or $ParametricNodes)");
    have_nodes_ = true;
    const auto capped = static_cast<std::size_t>(std::min<std::uint64_t>(count, data_.size()));
    raw_.coords.reserve(3 * capped);
    raw_.node_ids.reserve(capped);
    node_entity_.reserve(capped);
  }
  void finish_nodes() {
    std::int64_t max_id = -1;
    for (const auto id : raw_.node_ids) max_id = std::max(max_id, id);
    node_map_.build(raw_.node_ids, max_id);
    for (std::size_t i = 0; i < raw_.node_ids.size(); ++i)
      if (node_map_(raw_.node_ids[i]) != static_cast<Index>(i)) text_.fail("duplicate node id " + std::to_string(raw_.node_ids[i]));
  }

  // ---- $Nodes / $ParametricNodes of msh 2.2
  void read_nodes_v2(bool parametric) {
    const char* section = parametric ? "ParametricNodes" : "Nodes";
    const auto count = text_.integer<std::int64_t>("number of nodes", 0);
    begin_nodes(static_cast<std::uint64_t>(count));
    if (binary_ && !parametric) {
      BinaryCursor bin = binary_at_line_start();
      bin.require(static_cast<std::uint64_t>(count), 4 + 3 * sizeof(double), "nodes (id x y z)");
      for (std::int64_t i = 0; i < count; ++i) {
        const std::int64_t id = bin.read<std::int32_t>("node id");
        if (id < 0) bin.fail("negative node id " + std::to_string(id));
        raw_.node_ids.push_back(id);
        for (int d = 0; d < 3; ++d) {
          const double x = bin.read<double>("node coordinate");
          if (!std::isfinite(x)) bin.fail("node " + std::to_string(id) + " has a non-finite coordinate");
          raw_.coords.push_back(x);
        }
      }
      text_.seek(bin.offset());
    } else {
      if (binary_) text_.fail("binary $ParametricNodes are not supported (expected ASCII)");
      if (parametric) parametric_ = true;
      for (std::int64_t i = 0; i < count; ++i) {
        raw_.node_ids.push_back(text_.integer<std::int64_t>("node id", 0));
        for (int d = 0; d < 3; ++d) raw_.coords.push_back(text_.real("node coordinate"));
        if (parametric) {
          NodeParametrization p;
          p.entity_dim = text_.integer<int>("entity dimension", 0, 3);
          p.entity_tag = text_.integer<int>("entity tag");
          if (p.entity_dim >= 1 && p.entity_dim <= 2) p.u = text_.real("parametric coordinate u");
          if (p.entity_dim == 2) p.v = text_.real("parametric coordinate v");
          node_entity_.push_back(p);
        }
      }
    }
    end_section(section);
    finish_nodes();
  }

  // ---- $Nodes of msh 4.1
  void read_nodes_v4() {
    if (binary_) {
      BinaryCursor bin = binary_at_line_start();
      const std::uint64_t num_blocks = bin.read_size(size_bytes_, "number of node blocks");
      const std::uint64_t num_nodes = bin.read_size(size_bytes_, "number of nodes");
      (void)bin.read_size(size_bytes_, "min node tag");
      (void)bin.read_size(size_bytes_, "max node tag");
      begin_nodes(num_nodes);
      // Tags and coordinates go straight into the node arrays: no staging copy of the section.
      std::vector<double> values;  // parametric blocks only
      for (std::uint64_t b = 0; b < num_blocks; ++b) {
        const int dim = bin.read<std::int32_t>("entity dimension");
        const int tag = bin.read<std::int32_t>("entity tag");
        const int parametric = bin.read<std::int32_t>("parametric flag");
        const std::uint64_t n = bin.read_size(size_bytes_, "number of nodes in block");
        if (dim < 0 || dim > 3) bin.fail("entity dimension " + std::to_string(dim) + " (expected 0 to 3)");
        if (parametric != 0 && parametric != 1) bin.fail("parametric flag " + std::to_string(parametric) + " (expected 0 or 1)");
        bin.require(n, size_bytes_, "node tags");
        const std::size_t first = raw_.node_ids.size();
        raw_.node_ids.resize(first + n);
        for (std::uint64_t i = 0; i < n; ++i) {
          const std::uint64_t t = bin.read_size(size_bytes_, "node tag");
          if (t > static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max())) bin.fail("node tag out of range");
          raw_.node_ids[first + i] = static_cast<std::int64_t>(t);
        }
        const int per_node = 3 + (parametric ? dim : 0);
        bin.require(n, static_cast<std::size_t>(per_node) * sizeof(double), "node coordinates");
        const std::size_t first_coord = raw_.coords.size();
        raw_.coords.resize(first_coord + 3 * n);
        double* coords = raw_.coords.data() + first_coord;
        if (per_node == 3) {
          bin.read_array(coords, 3 * n, "node coordinates");
        } else {
          values.resize(n * static_cast<std::size_t>(per_node));
          bin.read_array(values.data(), values.size(), "node coordinates");
          for (std::uint64_t i = 0; i < n; ++i)
            std::copy_n(values.data() + i * static_cast<std::size_t>(per_node), 3, coords + 3 * i);
        }
        for (std::uint64_t i = 0; i < n; ++i) {
          for (int d = 0; d < 3; ++d)
            if (!std::isfinite(coords[3 * i + static_cast<std::size_t>(d)]))
              bin.fail("node " + std::to_string(raw_.node_ids[first + i]) + " has a non-finite coordinate");
          add_node_entity(dim, tag, parametric != 0, per_node == 3 ? nullptr : values.data() + i * static_cast<std::size_t>(per_node) + 3);
        }
      }
      if (raw_.node_ids.size() != num_nodes)
        bin.fail("node blocks hold " + std::to_string(raw_.node_ids.size()) + " nodes (expected " + std::to_string(num_nodes) + ")");
      text_.seek(bin.offset());
    } else {
      const auto num_blocks = text_.integer<std::int64_t>("number of node blocks", 0);
      const auto num_nodes = text_.integer<std::int64_t>("number of nodes", 0);
      (void)text_.integer<std::int64_t>("min node tag");
      (void)text_.integer<std::int64_t>("max node tag");
      begin_nodes(static_cast<std::uint64_t>(num_nodes));
      for (std::int64_t b = 0; b < num_blocks; ++b) {
        const int dim = text_.integer<int>("entity dimension", 0, 3);
        const int tag = text_.integer<int>("entity tag");
        const int parametric = text_.integer<int>("parametric flag", 0, 1);
        const auto n = text_.integer<std::int64_t>("number of nodes in block", 0);
        for (std::int64_t i = 0; i < n; ++i) raw_.node_ids.push_back(text_.integer<std::int64_t>("node tag", 0));
        for (std::int64_t i = 0; i < n; ++i) {
          for (int d = 0; d < 3; ++d) raw_.coords.push_back(text_.real("node coordinate"));
          std::array<double, 3> uvw{};
          for (int k = 0; k < (parametric ? dim : 0); ++k) uvw[static_cast<std::size_t>(k)] = text_.real("parametric coordinate");
          add_node_entity(dim, tag, parametric != 0, uvw.data());
        }
      }
      if (static_cast<std::int64_t>(raw_.node_ids.size()) != num_nodes)
        text_.fail("node blocks hold " + std::to_string(raw_.node_ids.size()) + " nodes (expected " + std::to_string(num_nodes) + ")");
    }
    end_section("Nodes");
    finish_nodes();
  }

  void add_node_entity(int dim, int tag, bool parametric, const double* uvw) {
    NodeParametrization p;
    p.entity_dim = dim;
    p.entity_tag = tag;
    if (parametric && dim >= 1) p.u = uvw[0];
    if (parametric && dim >= 2) p.v = uvw[1];
    parametric_ = parametric_ || parametric;
    node_entity_.push_back(p);
  }

  // The type of a Gmsh element number; `cursor` reports unknown numbers where they were read.
  template <class Cursor>
  [[nodiscard]] static ElementType checked_type(int gmsh_type, const Cursor& cursor) {
    try {
      return element_type_from_gmsh(gmsh_type);
    } catch (const InputError& e) {
      const std::string_view what = e.what();
      cursor.fail(std::string(what.substr(what.find("unsupported"))));
    }
  }

  ElementBlock& block_for(int gmsh_type) {
    const ElementType type = checked_type(gmsh_type, text_);
    int& index = block_of_type_[static_cast<std::size_t>(type)];
    if (index < 0) {
      index = static_cast<int>(raw_.blocks.size());
      raw_.blocks.push_back(ElementBlock{type, {}, {}, {}, {}});
    }
    return raw_.blocks[static_cast<std::size_t>(index)];
  }

  [[nodiscard]] Index node_index(std::int64_t id, std::int64_t element_id) const {
    const Index i = node_map_(id);
    if (i < 0)
      text_.fail("element " + std::to_string(element_id) + " refers to node " + std::to_string(id) +
                 (id < 0 ? " (expected a non-negative node id)" : ", which is not in the node section"));
    return i;
  }
  [[nodiscard]] Index node_index(std::int64_t id, std::int64_t element_id, const BinaryCursor& bin) const {
    const Index i = node_map_(id);
    if (i < 0) bin.fail("element " + std::to_string(element_id) + " refers to node " + std::to_string(id) + ", which is not in the node section");
    return i;
  }

  void begin_elements() {
    if (!have_nodes_) text_.fail("$Elements before $Nodes (expected the nodes first)");
    if (have_elements_) text_.fail("a second $Elements section (expected one: its cells would be read twice)");
    have_elements_ = true;
  }

  /// A 4.1 element block's entity: declared in $Entities, of the elements' dimension. Without
  /// $Entities no element can be in a physical group, so named groups are refused.
  template <class Cursor>
  void check_block_entity(int dim, int entity, ElementType type, const Cursor& cursor) const {
    if (dimension(type) != dim)
      cursor.fail("element block of " + std::string(name(type)) + " (dimension " + std::to_string(dimension(type)) +
                  ") on an entity of dimension " + std::to_string(dim));
    if (have_entities_) {
      if (!entities_.contains({dim, entity}))
        cursor.fail("element block on entity " + std::to_string(entity) + " of dimension " + std::to_string(dim) +
                    ", which $Entities does not declare");
    } else if (!raw_.groups.empty()) {
      cursor.fail("physical groups are named but there is no $Entities section before $Elements (msh 4.1 puts "
                  "elements in groups through their entities)");
    }
  }

  /// Notes element `id` (its nodes end at `end`) when it lists one node twice, naming the node
  /// by its id in the file: the first of each dimension, refused by parse() when the
  /// dimension is the mesh's cells' or facets'. Gmsh writes lines through one node twice on a
  /// degenerate curve (a sphere's pole), which a volume mesh does not keep.
  template <class Cursor>
  void check_distinct_nodes(ElementType type, const Index* end, std::int64_t id, const Cursor& cursor) {
    const int per = num_nodes(type);
    auto& first = repeated_[static_cast<std::size_t>(dimension(type))];
    if (first) return;
    if (const auto twice = repeated_node(end - per, per)) {
      try {
        cursor.fail("element " + std::to_string(id) + " (" + std::string(name(type)) + ") lists node " +
                    std::to_string(raw_.node_ids.empty() ? raw_.first_node_id + *twice : raw_.node_ids[static_cast<std::size_t>(*twice)]) +
                    " twice");
      } catch (const ParseError& e) {
        first = e;
      }
    }
  }
  template <class Cursor>
  void check_distinct_nodes(const ElementBlock& block, std::int64_t id, const Cursor& cursor) {
    check_distinct_nodes(block.type, block.connectivity.data() + block.connectivity.size(), id, cursor);
  }

  // ---- $Elements of msh 2.2: id type ntags tags... nodes...
  void read_elements_v2() {
    begin_elements();
    const auto count = text_.integer<std::int64_t>("number of elements", 0);
    if (binary_) {
      BinaryCursor bin = binary_at_line_start();
      std::vector<std::int32_t> buffer;
      std::int64_t done = 0;
      while (done < count) {
        const int gmsh_type = bin.read<std::int32_t>("element type");
        const std::int64_t n = bin.read<std::int32_t>("number of elements following");
        const std::int64_t num_tags = bin.read<std::int32_t>("number of tags");
        if (n <= 0 || n > count - done) bin.fail("element header announces " + std::to_string(n) + " elements (expected 1 to " + std::to_string(count - done) + ")");
        if (num_tags < 0 || num_tags > 64) bin.fail("element header has " + std::to_string(num_tags) + " tags (expected 0 to 64)");
        const ElementType type = checked_type(gmsh_type, bin);
        ElementBlock& block = block_for(gmsh_type);
        const std::int64_t per = 1 + num_tags + num_nodes(type);
        bin.require(static_cast<std::uint64_t>(n) * static_cast<std::uint64_t>(per), 4, "element data");
        buffer.resize(static_cast<std::size_t>(n * per));
        bin.read_array(buffer.data(), buffer.size(), "element data");
        block.reserve(block.size() + n);
        for (std::int64_t e = 0; e < n; ++e) {
          const std::int32_t* rec = buffer.data() + e * per;
          block.ids.push_back(rec[0]);
          block.tags.push_back(num_tags > 0 ? rec[1] : 0);
          block.entities.push_back(num_tags > 1 ? rec[2] : 0);
          for (int k = 0; k < num_nodes(type); ++k) block.connectivity.push_back(node_index(rec[1 + num_tags + k], rec[0], bin));
          check_distinct_nodes(block, rec[0], bin);
        }
        done += n;
      }
      text_.seek(bin.offset());
    } else {
      for (std::int64_t e = 0; e < count; ++e) {
        const auto id = text_.integer<std::int64_t>("element id");
        ElementBlock& block = block_for(text_.integer<int>("element type"));
        const auto num_tags = text_.integer<int>("number of tags", 0, 64);
        int physical = 0, entity = 0;
        for (int t = 0; t < num_tags; ++t) {
          const int tag = text_.integer<int>("element tag");
          if (t == 0) physical = tag;
          if (t == 1) entity = tag;
        }
        block.ids.push_back(id);
        block.tags.push_back(physical);
        block.entities.push_back(entity);
        for (int k = 0; k < block.nodes_per_element(); ++k)
          block.connectivity.push_back(node_index(text_.integer<std::int64_t>("element node"), id));
        check_distinct_nodes(block, id, text_);
        if (!text_.at_line_end())
          text_.fail("element " + std::to_string(id) + " has more nodes than its type " + std::string(name(block.type)) +
                     " (expected " + std::to_string(block.nodes_per_element()) + ")");
      }
    }
    end_section("Elements");
  }

  [[nodiscard]] int physical_tag_of(int dim, int entity) const {
    const auto it = entity_physical_.find({dim, entity});
    return it == entity_physical_.end() ? 0 : it->second;
  }

  // ---- $Elements of msh 4.1
  void read_elements_v4() {
    begin_elements();
    if (binary_) {
      BinaryCursor bin = binary_at_line_start();
      const std::uint64_t num_blocks = bin.read_size(size_bytes_, "number of element blocks");
      const std::uint64_t num_elements = bin.read_size(size_bytes_, "number of elements");
      (void)bin.read_size(size_bytes_, "min element tag");
      (void)bin.read_size(size_bytes_, "max element tag");
      std::uint64_t total = 0;
      for (std::uint64_t b = 0; b < num_blocks; ++b) {
        const int dim = bin.read<std::int32_t>("entity dimension");
        const int entity = bin.read<std::int32_t>("entity tag");
        const int gmsh_type = bin.read<std::int32_t>("element type");
        const std::uint64_t n = bin.read_size(size_bytes_, "number of elements in block");
        const ElementType type = checked_type(gmsh_type, bin);
        check_block_entity(dim, entity, type, bin);
        ElementBlock& block = block_for(gmsh_type);
        const int physical = physical_tag_of(dim, entity);
        const auto per = static_cast<std::size_t>(num_nodes(type));
        bin.require(n, (1 + per) * size_bytes_, "element data");
        // Records are decoded in place into the block's arrays, sized once.
        const auto first = static_cast<std::size_t>(block.size());
        block.ids.resize(first + n);
        block.tags.resize(first + n, physical);
        block.entities.resize(first + n, entity);
        block.connectivity.resize((first + n) * per);
        Index* nodes = block.connectivity.data() + first * per;
        constexpr auto largest = static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max());
        for (std::uint64_t e = 0; e < n; ++e) {
          const std::uint64_t raw_id = bin.read_size(size_bytes_, "element tag");
          const auto id = static_cast<std::int64_t>(std::min(raw_id, largest));
          block.ids[first + e] = id;
          for (std::size_t k = 0; k < per; ++k) {
            const std::uint64_t node = bin.read_size(size_bytes_, "element node");
            *nodes++ = node_index(node > largest ? -1 : static_cast<std::int64_t>(node), id, bin);
          }
          check_distinct_nodes(type, nodes, id, bin);
        }
        total += n;
      }
      if (total != num_elements)
        bin.fail("element blocks hold " + std::to_string(total) + " elements (expected " + std::to_string(num_elements) + ")");
      text_.seek(bin.offset());
    } else {
      const auto num_blocks = text_.integer<std::int64_t>("number of element blocks", 0);
      const auto num_elements = text_.integer<std::int64_t>("number of elements", 0);
      (void)text_.integer<std::int64_t>("min element tag");
      (void)text_.integer<std::int64_t>("max element tag");
      std::int64_t total = 0;
      for (std::int64_t b = 0; b < num_blocks; ++b) {
        const int dim = text_.integer<int>("entity dimension", 0, 3);
        const int entity = text_.integer<int>("entity tag");
        ElementBlock& block = block_for(text_.integer<int>("element type"));
        check_block_entity(dim, entity, block.type, text_);
        const auto n = text_.integer<std::int64_t>("number of elements in block", 0);
        const int physical = physical_tag_of(dim, entity);
        for (std::int64_t e = 0; e < n; ++e) {
          const auto id = text_.integer<std::int64_t>("element tag");
          block.ids.push_back(id);
          block.tags.push_back(physical);
          block.entities.push_back(entity);
          for (int k = 0; k < block.nodes_per_element(); ++k)
            block.connectivity.push_back(node_index(text_.integer<std::int64_t>("element node"), id));
          check_distinct_nodes(block, id, text_);
          if (!text_.at_line_end())
            text_.fail("element " + std::to_string(id) + " has more nodes than its type " + std::string(name(block.type)) +
                       " (expected " + std::to_string(block.nodes_per_element()) + ")");
        }
        total += n;
      }
      if (total != num_elements)
        text_.fail("element blocks hold " + std::to_string(total) + " elements (expected " + std::to_string(num_elements) + ")");
    }
    end_section("Elements");
  }

  std::string_view data_;
  TextCursor text_;
  std::filesystem::path file_;
  double version_ = 0;
  bool binary_ = false;
  bool swap_ = false;
  std::size_t size_bytes_ = 8;
  bool have_nodes_ = false;
  bool have_entities_ = false;
  bool have_elements_ = false;
  bool parametric_ = false;
  RawMesh raw_;
  NodeIdMap node_map_;
  std::vector<NodeParametrization> node_entity_;
  std::map<std::pair<int, int>, int> entity_physical_;
  std::set<std::pair<int, int>> entities_;  ///< every (dimension, tag) $Entities declares
  std::array<std::optional<ParseError>, 4> repeated_{};  ///< per dimension, the first element through a node twice
  std::array<int, num_element_types> block_of_type_{};
};

}  // namespace detail

/// Parses Gmsh .msh content held in memory; `file` names it in error messages.
/// Throws ParseError (file, line or byte offset, what was expected) for malformed content and
/// InputError when the mesh read is invalid (e.g. nonzero z in a mesh without 3D elements).
[[nodiscard]] inline AnyMesh parse_gmsh(std::string_view data, const std::filesystem::path& file) {
  return detail::to_any_mesh(detail::GmshParser(data, file).parse(), file);
}

/// Reads a Gmsh .msh file (2.2 or 4.1, ASCII or binary). Throws IoError when unreadable and
/// as parse_gmsh() otherwise.
[[nodiscard]] inline AnyMesh read_gmsh(const std::filesystem::path& file) {
  const std::string data = detail::read_whole_file(file);
  return parse_gmsh(data, file);
}

}  // namespace meshmotion
