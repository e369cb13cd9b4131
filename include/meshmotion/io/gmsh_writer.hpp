#pragma once
/// \file
/// Gmsh .msh writer: version 2.2 or 4.1, ASCII or binary. Node and element ids of the mesh are
/// written as they are (1, 2, ... where the mesh has none), so numbering survives round trips;
/// element tags become physical tags (4.1: one entity per dimension and tag), groups become
/// $PhysicalNames, node parametrizations become 2.2 ASCII $ParametricNodes. Elements are
/// written by increasing dimension (lower, facets, cells), each block in its order.

#include "meshmotion/core/element.hpp"
#include "meshmotion/core/error.hpp"
#include "meshmotion/core/mesh.hpp"
#include "meshmotion/core/detail/atomic_file.hpp"
#include "meshmotion/io/detail/number_format.hpp"

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

namespace meshmotion {

/// The two Gmsh file format versions the library writes.
enum class MshVersion { v2_2, v4_1 };

/// Options of write_gmsh().
struct GmshWriteOptions {
  MshVersion version = MshVersion::v4_1;
  bool binary = false;  ///< binary data in native byte order (the file says which)
};

namespace detail {

class GmshFormatter {
 public:
  GmshFormatter(TextOutput& output, bool binary) : out(output.text), output_(output), binary_(binary) {}
  std::string& out;

  void text(std::string_view s) { out.append(s); }
  template <class T>
  void ascii(T value) { append_number(out, value); }
  template <class T>
  void bin(T value) { append_bytes(out, value); }
  // A value as ASCII followed by `sep`, or as raw bytes of type B.
  template <class B, class T>
  void value(T v, char sep = ' ') {
    if (binary_) {
      bin(static_cast<B>(v));
    } else {
      ascii(v);
      out.push_back(sep);
    }
  }
  // Ends a node or element line; the output may be written out after it, not within.
  void end_of_record() {
    if (!binary_) out.back() = '\n';
    output_.spill();
  }

 private:
  TextOutput& output_;
  bool binary_;
};

template <int Dim>
void check_int32_ids(const Mesh<Dim>& mesh, const std::vector<const ElementBlock*>& blocks) {
  const auto too_big = [](std::int64_t id) { return id < 0 || id > std::numeric_limits<std::int32_t>::max(); };
  for (Index i = 0; i < mesh.num_nodes(); ++i)
    if (too_big(msh_node_id(mesh, i)))
      throw InputError("write_gmsh: node id " + std::to_string(msh_node_id(mesh, i)) + " does not fit msh 2.2 binary (expected 0 to 2^31-1)");
  for (const auto* b : blocks)
    for (const auto id : b->ids)
      if (too_big(id)) throw InputError("write_gmsh: element id " + std::to_string(id) + " does not fit msh 2.2 binary");
}

template <int Dim>
void format_gmsh_v2(GmshFormatter& f, const Mesh<Dim>& mesh, bool binary) {
  const auto blocks = blocks_in_file_order(mesh);
  const bool parametric = !mesh.node_params.empty() && !binary;
  f.text(parametric ? "$ParametricNodes\n" : "$Nodes\n");
  f.ascii(mesh.num_nodes());
  f.text("\n");
  for (Index i = 0; i < mesh.num_nodes(); ++i) {
    f.value<std::int32_t>(msh_node_id(mesh, i));
    for (int d = 0; d < 3; ++d) f.value<double>(d < Dim ? mesh.points(d, i) : 0.0);
    if (parametric) {
      const auto& p = mesh.node_params[static_cast<std::size_t>(i)];
      f.value<int>(p.entity_dim);
      f.value<int>(p.entity_tag);
      if (p.entity_dim >= 1 && p.entity_dim <= 2) f.value<double>(p.u);
      if (p.entity_dim == 2) f.value<double>(p.v);
    }
    f.end_of_record();
  }
  f.text(binary ? "\n" : "");
  f.text(parametric ? "$EndParametricNodes\n" : "$EndNodes\n");
  Index total = 0;
  for (const auto* b : blocks) total += b->size();
  f.text("$Elements\n");
  f.ascii(total);
  f.text("\n");
  std::int64_t position = 0;
  for (const auto* b : blocks) {
    const int gmsh = element_info(b->type).gmsh_id;
    if (binary) {
      f.bin(static_cast<std::int32_t>(gmsh));
      f.bin(static_cast<std::int32_t>(b->size()));
      f.bin(std::int32_t{2});
    }
    for (Index e = 0; e < b->size(); ++e, ++position) {
      const int tag = b->tags[static_cast<std::size_t>(e)];
      f.value<std::int32_t>(element_id(*b, e, position));
      if (!binary) {
        f.value<int>(gmsh);
        f.value<int>(2);
      }
      f.value<std::int32_t>(tag);
      f.value<std::int32_t>(tag);  // elementary entity: the mesh keeps none, the physical tag stands in
      for (const Index v : b->element(e)) f.value<std::int32_t>(msh_node_id(mesh, v));
      f.end_of_record();
    }
  }
  f.text(binary ? "\n" : "");
  f.text("$EndElements\n");
}

template <int Dim>
void format_gmsh_v4(GmshFormatter& f, const Mesh<Dim>& mesh, bool binary) {
  const auto blocks = blocks_in_file_order(mesh);
  // One entity per (dimension, physical tag); entity tags are positions from 1.
  std::vector<std::vector<int>> entity_tags(4);
  entity_tags[Dim].push_back(0);  // the entity that holds the nodes, without a physical tag
  const auto entity_of = [&](int dim, int tag) {
    auto& list = entity_tags[static_cast<std::size_t>(dim)];
    const auto it = std::find(list.begin(), list.end(), tag);
    if (it != list.end()) return static_cast<int>(it - list.begin()) + 1;
    list.push_back(tag);
    return static_cast<int>(list.size());
  };
  for (const auto* b : blocks)
    for (const int tag : b->tags) entity_of(dimension(b->type), tag);

  const auto size = [&](std::uint64_t v, char sep = ' ') { f.value<std::uint64_t>(v, sep); };
  f.text("$Entities\n");
  for (int d = 0; d < 4; ++d) size(entity_tags[static_cast<std::size_t>(d)].size(), d == 3 ? '\n' : ' ');
  for (int d = 0; d < 4; ++d)
    for (std::size_t k = 0; k < entity_tags[static_cast<std::size_t>(d)].size(); ++k) {
      const int physical = entity_tags[static_cast<std::size_t>(d)][k];
      f.value<std::int32_t>(static_cast<int>(k) + 1);
      for (int c = 0; c < (d == 0 ? 3 : 6); ++c) f.value<double>(0.0);
      size(physical != 0 ? 1 : 0);
      if (physical != 0) f.value<std::int32_t>(physical);
      if (d > 0) size(0);
      f.end_of_record();
    }
  f.text(binary ? "\n" : "");
  f.text("$EndEntities\n");

  std::int64_t min_id = std::numeric_limits<std::int64_t>::max(), max_id = 0;
  for (Index i = 0; i < mesh.num_nodes(); ++i) {
    min_id = std::min(min_id, msh_node_id(mesh, i));
    max_id = std::max(max_id, msh_node_id(mesh, i));
  }
  if (mesh.num_nodes() == 0) min_id = 0;
  f.text("$Nodes\n");
  const Index n = mesh.num_nodes();
  size(n > 0 ? 1 : 0);
  size(static_cast<std::uint64_t>(n));
  size(static_cast<std::uint64_t>(min_id));
  size(static_cast<std::uint64_t>(max_id), '\n');
  if (n > 0) {
    f.value<std::int32_t>(Dim);
    f.value<std::int32_t>(1);
    f.value<std::int32_t>(0);
    size(static_cast<std::uint64_t>(n), '\n');
    for (Index i = 0; i < n; ++i) {
      size(static_cast<std::uint64_t>(msh_node_id(mesh, i)), '\n');
      f.end_of_record();
    }
    for (Index i = 0; i < n; ++i) {
      for (int d = 0; d < 3; ++d) f.value<double>(d < Dim ? mesh.points(d, i) : 0.0);
      f.end_of_record();
    }
  }
  f.text(binary ? "\n" : "");
  f.text("$EndNodes\n");

  // Element blocks: runs of consecutive elements with the same tag, so block order is kept.
  struct Run {
    const ElementBlock* block;
    Index first, last;
  };
  std::vector<Run> runs;
  std::int64_t min_el = std::numeric_limits<std::int64_t>::max(), max_el = 0, position = 0;
  for (const auto* b : blocks)
    for (Index e = 0; e < b->size(); ++e, ++position) {
      if (runs.empty() || runs.back().block != b || b->tags[static_cast<std::size_t>(e)] != b->tags[static_cast<std::size_t>(e - 1)])
        runs.push_back({b, e, e + 1});
      else
        runs.back().last = e + 1;
      const auto id = element_id(*b, e, position);
      min_el = std::min(min_el, id);
      max_el = std::max(max_el, id);
    }
  if (position == 0) min_el = 0;
  f.text("$Elements\n");
  size(runs.size());
  size(static_cast<std::uint64_t>(position));
  size(static_cast<std::uint64_t>(min_el));
  size(static_cast<std::uint64_t>(max_el), '\n');
  position = 0;
  const ElementBlock* previous = nullptr;
  std::int64_t block_start = 0;
  for (const auto& run : runs) {
    if (run.block != previous) {
      block_start = position - run.first;
      previous = run.block;
    }
    const int dim = dimension(run.block->type);
    f.value<std::int32_t>(dim);
    f.value<std::int32_t>(entity_of(dim, run.block->tags[static_cast<std::size_t>(run.first)]));
    f.value<std::int32_t>(element_info(run.block->type).gmsh_id);
    size(static_cast<std::uint64_t>(run.last - run.first), '\n');
    for (Index e = run.first; e < run.last; ++e) {
      size(static_cast<std::uint64_t>(element_id(*run.block, e, block_start + e)));
      for (const Index v : run.block->element(e)) size(static_cast<std::uint64_t>(msh_node_id(mesh, v)));
      f.end_of_record();
    }
    position = block_start + run.last;
  }
  f.text(binary ? "\n" : "");
  f.text("$EndElements\n");
}

}  // namespace detail

namespace detail {

template <int Dim>
void format_gmsh(TextOutput& output, const Mesh<Dim>& mesh, const GmshWriteOptions& options) {
  GmshFormatter f(output, options.binary);
  f.text(options.version == MshVersion::v2_2 ? "$MeshFormat\n2.2 " : "$MeshFormat\n4.1 ");
  f.text(options.binary ? "1 8\n" : "0 8\n");
  if (options.binary) {
    f.bin(std::int32_t{1});
    f.text("\n");
  }
  f.text("$EndMeshFormat\n");
  if (!mesh.groups.empty()) {
    f.text("$PhysicalNames\n");
    f.ascii(mesh.groups.size());
    f.text("\n");
    for (const auto& g : mesh.groups) {
      f.ascii(g.dim);
      f.text(" ");
      f.ascii(g.tag);
      f.text(" \"" + g.name + "\"\n");
    }
    f.text("$EndPhysicalNames\n");
  }
  if (options.version == MshVersion::v2_2) format_gmsh_v2(f, mesh, options.binary);
  else format_gmsh_v4(f, mesh, options.binary);
}

// What the file cannot hold, refused before anything is written.
template <int Dim>
void check_gmsh_writable(const Mesh<Dim>& mesh, const GmshWriteOptions& options) {
  validate(mesh);
  for (const auto& g : mesh.groups)
    if (g.name.find('"') != std::string::npos || g.name.find('\n') != std::string::npos)
      throw InputError("write_gmsh: group name '" + g.name + "' contains a quote or a line break");
  if (options.version == MshVersion::v2_2 && options.binary) check_int32_ids(mesh, blocks_in_file_order(mesh));
}

}  // namespace detail

/// The content of a .msh file for `mesh`. Throws InputError for an invalid mesh.
template <int Dim>
[[nodiscard]] std::string format_gmsh(const Mesh<Dim>& mesh, const GmshWriteOptions& options = {}) {
  detail::check_gmsh_writable(mesh, options);
  detail::TextOutput output;
  // One allocation for the whole file: appending into a growing string copied it log n times.
  // Binary values are 8 bytes at most; ASCII ones are bounded by the shortest round-trip form.
  std::size_t values = static_cast<std::size_t>(mesh.num_nodes()) * 5;
  for (const auto* list : {&mesh.cells, &mesh.facets, &mesh.lower})
    for (const auto& b : *list) values += b.connectivity.size() + 5 * static_cast<std::size_t>(b.size());
  output.text.reserve(4096 + values * (options.binary ? 8 : 12) +
                      (options.binary ? 0 : static_cast<std::size_t>(mesh.num_nodes()) * 3 * 14));
  detail::format_gmsh(output, mesh, options);
  return std::move(output.text);
}

/// Writes `mesh` to a Gmsh .msh file, streamed through a temporary file and a rename.
/// Throws InputError for an invalid mesh (nothing written), IoError when the file cannot be written.
template <int Dim>
void write_gmsh(const std::filesystem::path& file, const Mesh<Dim>& mesh, const GmshWriteOptions& options = {}) {
  detail::check_gmsh_writable(mesh, options);
  detail::write_streamed(file, [&](detail::TextOutput& output) { detail::format_gmsh(output, mesh, options); });
}

}  // namespace meshmotion
