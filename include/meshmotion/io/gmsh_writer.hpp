#pragma once
/// \file
/// Gmsh .msh writer: version 2.2 or 4.1, ASCII or binary. Node and element ids of the mesh are
/// written as they are (1, 2, ... where the mesh has none), so numbering survives round trips;
/// element tags become physical tags and element entities elementary tags (4.1: the entities
/// in $Entities, with an entity made for each dimension and physical tag of elements without
/// one), groups become $PhysicalNames, node parametrizations become 2.2 ASCII $ParametricNodes
/// or 4.1 parametric node blocks. Elements are written by increasing dimension (lower,
/// facets, cells), each block in its order; nodes in their order.

#include "meshmotion/core/element.hpp"
#include "meshmotion/core/error.hpp"
#include "meshmotion/core/mesh.hpp"
#include "meshmotion/core/threads.hpp"
#include "meshmotion/core/detail/atomic_file.hpp"
#include "meshmotion/io/detail/number_format.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <map>
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

  // record(formatter, i) for i in [first, last), each ended as a line. ASCII records are
  // formatted by the threads in blocks, each into its own reused buffer, and written in order:
  // number formatting was the larger part of writing a curved mesh's file (the 30P30N's 257k P2
  // nodes and 64k cells, 17 MB, 47 ms on one thread).
  template <class Record>
  void records(Index first, Index last, const Record& record) {
    constexpr Index block = 4096;  // a P2 mesh's lines: about 200 kB of text per block
    const int threads = binary_ ? 1 : static_cast<int>(std::min<Index>(num_threads(), (last - first) / block));
    if (threads <= 1) {
      for (Index i = first; i < last; ++i) {
        record(*this, i);
        end_of_record();
      }
      return;
    }
    // A cache line each: the threads update their buffer's size at every number.
    struct alignas(64) Piece {
      TextOutput output;
    };
    std::vector<Piece> pieces(static_cast<std::size_t>(threads));
    RegionErrors errors;
    for (Index start = first; start < last; start += threads * block) {
#pragma omp parallel for num_threads(threads) schedule(static, 1)
      for (int t = 0; t < threads; ++t)
        errors.run([&] {
          TextOutput& piece = pieces[static_cast<std::size_t>(t)].output;
          piece.text.clear();
          GmshFormatter local(piece, false);
          for (Index i = start + t * block; i < std::min(last, start + (t + 1) * block); ++i) {
            record(local, i);
            local.end_of_record();
          }
        });
      errors.rethrow();
      for (const Piece& piece : pieces) {
        const std::string& text = piece.output.text;
        for (std::size_t at = 0; at < text.size(); at += TextOutput::chunk / 2) {
          out.append(text, at, TextOutput::chunk / 2);
          output_.spill();
        }
      }
    }
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
  f.records(0, mesh.num_nodes(), [&](GmshFormatter& g, Index i) {
    g.value<std::int32_t>(msh_node_id(mesh, i));
    for (int d = 0; d < 3; ++d) g.value<double>(d < Dim ? mesh.points(d, i) : 0.0);
    if (parametric) {
      const auto& p = mesh.node_params[static_cast<std::size_t>(i)];
      g.value<int>(p.entity_dim);
      g.value<int>(p.entity_tag);
      if (p.entity_dim >= 1 && p.entity_dim <= 2) g.value<double>(p.u);
      if (p.entity_dim == 2) g.value<double>(p.v);
    }
  });
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
      // The elementary entity: the element's own, else its physical tag stands in.
      f.value<std::int32_t>(b->entities.empty() || b->entities[static_cast<std::size_t>(e)] == 0 ? tag : b->entities[static_cast<std::size_t>(e)]);
      for (const Index v : b->element(e)) f.value<std::int32_t>(msh_node_id(mesh, v));
      f.end_of_record();
    }
  }
  f.text(binary ? "\n" : "");
  f.text("$EndElements\n");
}

// The model entities a 4.1 file declares: the elements' own (ElementBlock::entities) and the
// nodes' (Mesh::node_params), each with at most one physical tag. An element without an entity,
// or whose entity already carries another physical tag, goes to an entity made for its
// (dimension, physical tag), numbered after the largest tag of that dimension in use.
class GmshEntities {
 public:
  template <int Dim>
  GmshEntities(const Mesh<Dim>& mesh, const std::vector<const ElementBlock*>& blocks) {
    for (const auto* b : blocks) {
      const int dim = dimension(b->type);
      for (Index e = 0; e < b->size(); ++e) {
        const int given = given_entity(*b, e);
        if (given != 0) physical_.emplace(std::pair{dim, given}, b->tags[static_cast<std::size_t>(e)]);
      }
    }
    for (const auto& p : mesh.node_params) physical_.emplace(std::pair{p.entity_dim, p.entity_tag}, 0);
    for (const auto& [key, physical] : physical_) largest_[static_cast<std::size_t>(key.first)] = std::max(largest_[static_cast<std::size_t>(key.first)], key.second);
    for (const auto* b : blocks)
      for (Index e = 0; e < b->size(); ++e) (void)of(*b, e);
    // Nodes without a parametrization lie in the mesh's own domain: the first cell's entity.
    volume_ = mesh.cells.empty() || mesh.cells.front().empty() ? made(Dim, 0) : of(mesh.cells.front(), 0);
  }

  /// The entity element e of block b is written in.
  [[nodiscard]] int of(const ElementBlock& b, Index e) {
    const std::array<int, 3> key{dimension(b.type), b.tags[static_cast<std::size_t>(e)], given_entity(b, e)};
    if (key != last_key_) {  // elements come in long runs of one entity: one lookup per run
      const auto [dim, physical, given] = key;
      const auto it = given != 0 ? physical_.find({dim, given}) : physical_.end();
      last_entity_ = it != physical_.end() && it->second == physical ? given : made(dim, physical);
      last_key_ = key;
    }
    return last_entity_;
  }
  [[nodiscard]] int volume() const noexcept { return volume_; }
  /// (dimension, tag) -> physical tag, 0 for none; in file order.
  [[nodiscard]] const std::map<std::pair<int, int>, int>& all() const noexcept { return physical_; }

 private:
  [[nodiscard]] static int given_entity(const ElementBlock& b, Index e) {
    return b.entities.empty() ? 0 : b.entities[static_cast<std::size_t>(e)];
  }
  int made(int dim, int physical) {
    const auto it = made_.find({dim, physical});
    if (it != made_.end()) return it->second;
    const int tag = ++largest_[static_cast<std::size_t>(dim)];
    made_.emplace(std::pair{dim, physical}, tag);
    physical_.emplace(std::pair{dim, tag}, physical);
    return tag;
  }

  std::map<std::pair<int, int>, int> physical_;
  std::map<std::pair<int, int>, int> made_;
  std::array<int, 4> largest_{};
  std::array<int, 3> last_key_{-1, 0, 0};
  int last_entity_ = 0;
  int volume_ = 0;
};

template <int Dim>
void format_gmsh_v4(GmshFormatter& f, const Mesh<Dim>& mesh, bool binary) {
  const auto blocks = blocks_in_file_order(mesh);
  GmshEntities entities(mesh, blocks);

  const auto size = [&](std::uint64_t v, char sep = ' ') { f.value<std::uint64_t>(v, sep); };
  f.text("$Entities\n");
  std::array<std::uint64_t, 4> count{};
  for (const auto& [key, physical] : entities.all()) ++count[static_cast<std::size_t>(key.first)];
  for (int d = 0; d < 4; ++d) size(count[static_cast<std::size_t>(d)], d == 3 ? '\n' : ' ');
  for (const auto& [key, physical] : entities.all()) {
    f.value<std::int32_t>(key.second);
    for (int c = 0; c < (key.first == 0 ? 3 : 6); ++c) f.value<double>(0.0);
    size(physical != 0 ? 1 : 0);
    if (physical != 0) f.value<std::int32_t>(physical);
    if (key.first > 0) size(0);
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
  // Node blocks: runs of consecutive nodes in one entity, so the nodes keep their order.
  const bool parametric = !mesh.node_params.empty();
  const auto entity_of_node = [&](Index i) {
    if (!parametric) return std::pair{Dim, entities.volume()};
    const auto& p = mesh.node_params[static_cast<std::size_t>(i)];
    return std::pair{p.entity_dim, p.entity_tag};
  };
  std::vector<Index> run_starts;
  for (Index i = 0; i < n; ++i)
    if (i == 0 || entity_of_node(i) != entity_of_node(i - 1)) run_starts.push_back(i);
  run_starts.push_back(n);
  size(run_starts.size() - 1);
  size(static_cast<std::uint64_t>(n));
  size(static_cast<std::uint64_t>(min_id));
  size(static_cast<std::uint64_t>(max_id), '\n');
  for (std::size_t r = 0; r + 1 < run_starts.size(); ++r) {
    const Index first = run_starts[r], last = run_starts[r + 1];
    const auto [dim, tag] = entity_of_node(first);
    const int num_params = parametric && dim >= 1 && dim <= 2 ? dim : 0;
    f.value<std::int32_t>(dim);
    f.value<std::int32_t>(tag);
    f.value<std::int32_t>(num_params > 0 ? 1 : 0);
    size(static_cast<std::uint64_t>(last - first), '\n');
    f.records(first, last, [&](GmshFormatter& g, Index i) { g.value<std::uint64_t>(static_cast<std::uint64_t>(msh_node_id(mesh, i)), '\n'); });
    f.records(first, last, [&](GmshFormatter& g, Index i) {
      for (int d = 0; d < 3; ++d) g.value<double>(d < Dim ? mesh.points(d, i) : 0.0);
      if (num_params > 0) g.value<double>(mesh.node_params[static_cast<std::size_t>(i)].u);
      if (num_params > 1) g.value<double>(mesh.node_params[static_cast<std::size_t>(i)].v);
    });
  }
  f.text(binary ? "\n" : "");
  f.text("$EndNodes\n");

  // Element blocks: runs of consecutive elements in one entity, so block order is kept.
  struct Run {
    const ElementBlock* block;
    int entity;
    Index first, last;
  };
  std::vector<Run> runs;
  std::int64_t min_el = std::numeric_limits<std::int64_t>::max(), max_el = 0, position = 0;
  for (const auto* b : blocks)
    for (Index e = 0; e < b->size(); ++e, ++position) {
      const int entity = entities.of(*b, e);
      if (runs.empty() || runs.back().block != b || runs.back().entity != entity)
        runs.push_back({b, entity, e, e + 1});
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
    f.value<std::int32_t>(run.entity);
    f.value<std::int32_t>(element_info(run.block->type).gmsh_id);
    size(static_cast<std::uint64_t>(run.last - run.first), '\n');
    f.records(run.first, run.last, [&](GmshFormatter& g, Index e) {
      g.value<std::uint64_t>(static_cast<std::uint64_t>(element_id(*run.block, e, block_start + e)));
      for (const Index v : run.block->element(e)) g.value<std::uint64_t>(static_cast<std::uint64_t>(msh_node_id(mesh, v)));
    });
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
