#pragma once
/// \file
/// partition_mesh(): a Mesh<Dim> held by one rank split into DistributedMesh parts, one per
/// rank of the communicator — by METIS (the dual graph of the cells, neighbours sharing a
/// facet) or by a cell → rank array the caller gives (a solver's own partition).
///
/// - Cells go to their rank; a node is owned by the lowest rank among the cells that hold it
///   (the root for a node in no cell), and is a ghost on the other ranks whose cells hold it.
/// - Facets go to every rank that holds all their nodes; groups (names and tags) to all.
/// - The root packs each part and sends it; memory on the root is the whole mesh plus one part.

#include "meshmotion/core/error.hpp"
#include "meshmotion/core/mesh.hpp"
#include "meshmotion/parallel/communicator.hpp"
#include "meshmotion/parallel/distributed_mesh.hpp"

#include <metis.h>

#include <algorithm>
#include <climits>
#include <cstdint>
#include <cstring>
#include <span>
#include <string>
#include <vector>

namespace meshmotion::parallel {

/// A rank (0..parts-1) per cell of `mesh` (cells in block order) from METIS's partition of
/// the cells' dual graph, balanced by cell count. Throws InputError when METIS fails.
template <int Dim>
[[nodiscard]] std::vector<int> metis_cell_ranks(const Mesh<Dim>& mesh, int parts) {
  const Index cells = mesh.num_cells();
  std::vector<int> out(static_cast<std::size_t>(cells), 0);
  if (parts <= 1 || cells == 0) return out;
  // METIS refuses more parts than cells: the extra ranks stay empty.
  if (cells < parts) {
    for (Index c = 0; c < cells; ++c) out[static_cast<std::size_t>(c)] = static_cast<int>(c);
    return out;
  }
  if (cells > INT32_MAX || mesh.num_nodes() > INT32_MAX)
    throw InputError("parallel::metis_cell_ranks: the mesh exceeds METIS's 32-bit indices");
  std::vector<idx_t> eptr{0}, eind;
  eptr.reserve(static_cast<std::size_t>(cells) + 1);
  for (const auto& block : mesh.cells) {
    const int nv = num_vertices(block.type);
    for (Index e = 0; e < block.size(); ++e) {
      const auto nodes = block.element(e);
      for (int k = 0; k < nv; ++k) eind.push_back(static_cast<idx_t>(nodes[static_cast<std::size_t>(k)]));
      eptr.push_back(static_cast<idx_t>(eind.size()));
    }
  }
  idx_t ne = static_cast<idx_t>(cells), nn = static_cast<idx_t>(mesh.num_nodes()), ncommon = Dim, nparts = parts, cut = 0;
  idx_t options[METIS_NOPTIONS];
  METIS_SetDefaultOptions(options);
  options[METIS_OPTION_NUMBERING] = 0;
  std::vector<idx_t> epart(static_cast<std::size_t>(ne)), npart(static_cast<std::size_t>(nn));
  const int status = METIS_PartMeshDual(&ne, &nn, eptr.data(), eind.data(), nullptr, nullptr, &ncommon, &nparts, nullptr,
                                        options, &cut, epart.data(), npart.data());
  if (status != METIS_OK)
    throw InputError("parallel::metis_cell_ranks: METIS_PartMeshDual failed (status " + std::to_string(status) + ") on " +
                     std::to_string(cells) + " cells into " + std::to_string(parts) + " parts");
  for (Index c = 0; c < cells; ++c) out[static_cast<std::size_t>(c)] = static_cast<int>(epart[static_cast<std::size_t>(c)]);
  return out;
}

namespace detail {

// A part travels as one byte buffer: arrays prefixed by their length.
struct Packer {
  std::vector<char> bytes;
  template <class T>
  void put(std::span<const T> values) {
    const auto n = static_cast<std::uint64_t>(values.size());
    append(&n, sizeof n);
    append(values.data(), values.size() * sizeof(T));
  }
  template <class T>
  void put(const std::vector<T>& values) { put(std::span<const T>(values)); }
  template <class T>
  void put_value(T value) { append(&value, sizeof value); }

 private:
  void append(const void* p, std::size_t n) {
    const auto* c = static_cast<const char*>(p);
    bytes.insert(bytes.end(), c, c + n);
  }
};

struct Unpacker {
  const std::vector<char>& bytes;
  std::size_t at = 0;
  template <class T>
  std::vector<T> get() {
    const auto n = get_value<std::uint64_t>();
    std::vector<T> out(static_cast<std::size_t>(n));
    take(out.data(), out.size() * sizeof(T));
    return out;
  }
  template <class T>
  T get_value() {
    T value{};
    take(&value, sizeof value);
    return value;
  }

 private:
  void take(void* p, std::size_t n) {
    if (at + n > bytes.size()) throw InputError("parallel::partition_mesh: a received part is truncated");
    std::memcpy(p, bytes.data() + at, n);
    at += n;
  }
};

template <int Dim>
void pack_blocks(Packer& out, const std::vector<ElementBlock>& blocks) {
  out.put_value<std::uint64_t>(blocks.size());
  for (const auto& b : blocks) {
    out.put_value<int>(static_cast<int>(b.type));
    out.put(b.connectivity);
    out.put(b.tags);
    out.put(b.ids);
    out.put(b.entities);
  }
}

inline std::vector<ElementBlock> unpack_blocks(Unpacker& in) {
  std::vector<ElementBlock> blocks(static_cast<std::size_t>(in.get_value<std::uint64_t>()));
  for (auto& b : blocks) {
    b.type = static_cast<ElementType>(in.get_value<int>());
    b.connectivity = in.get<Index>();
    b.tags = in.get<int>();
    b.ids = in.get<std::int64_t>();
    b.entities = in.get<int>();
  }
  return blocks;
}

template <int Dim>
[[nodiscard]] std::vector<char> pack_part(const DistributedMesh<Dim>& part) {
  Packer out;
  out.put(std::span<const double>(part.local.points.data(), static_cast<std::size_t>(part.local.points.size())));
  out.put(part.global_ids);
  out.put(part.owner);
  out.put_value<Index>(part.num_owned);
  out.put_value<Index>(part.num_global_nodes);
  pack_blocks<Dim>(out, part.local.cells);
  pack_blocks<Dim>(out, part.local.facets);
  out.put_value<std::uint64_t>(part.local.groups.size());
  for (const auto& g : part.local.groups) {
    out.put_value<int>(g.dim);
    out.put_value<int>(g.tag);
    out.put(std::span<const char>(g.name.data(), g.name.size()));
  }
  out.put(part.local.node_ids);
  return std::move(out.bytes);
}

template <int Dim>
[[nodiscard]] DistributedMesh<Dim> unpack_part(const std::vector<char>& bytes, MPI_Comm comm) {
  Unpacker in{bytes};
  DistributedMesh<Dim> part;
  part.comm = comm;
  const std::vector<double> xyz = in.get<double>();
  part.local.points = Eigen::Map<const Points<Dim>>(xyz.data(), Dim, static_cast<Index>(xyz.size() / Dim));
  part.global_ids = in.get<std::int64_t>();
  part.owner = in.get<int>();
  part.num_owned = in.get_value<Index>();
  part.num_global_nodes = in.get_value<Index>();
  part.local.cells = unpack_blocks(in);
  part.local.facets = unpack_blocks(in);
  part.local.groups.resize(static_cast<std::size_t>(in.get_value<std::uint64_t>()));
  for (auto& g : part.local.groups) {
    g.dim = in.get_value<int>();
    g.tag = in.get_value<int>();
    const std::vector<char> name = in.get<char>();
    g.name.assign(name.begin(), name.end());
  }
  part.local.node_ids = in.get<std::int64_t>();
  return part;
}

/// Sends `bytes` to `to` in pieces MPI's int count can describe.
inline void send_bytes(const std::vector<char>& bytes, int to, MPI_Comm comm) {
  const auto n = static_cast<std::uint64_t>(bytes.size());
  MPI_Send(&n, 1, MPI_UINT64_T, to, 0, comm);
  for (std::uint64_t at = 0; at < n; at += INT_MAX)
    MPI_Send(bytes.data() + at, static_cast<int>(std::min<std::uint64_t>(INT_MAX, n - at)), MPI_CHAR, to, 1, comm);
}
inline std::vector<char> receive_bytes(int from, MPI_Comm comm) {
  std::uint64_t n = 0;
  MPI_Recv(&n, 1, MPI_UINT64_T, from, 0, comm, MPI_STATUS_IGNORE);
  std::vector<char> bytes(static_cast<std::size_t>(n));
  for (std::uint64_t at = 0; at < n; at += INT_MAX)
    MPI_Recv(bytes.data() + at, static_cast<int>(std::min<std::uint64_t>(INT_MAX, n - at)), MPI_CHAR, from, 1, comm,
             MPI_STATUS_IGNORE);
  return bytes;
}

}  // namespace detail

/// Splits `whole` (significant on `root` only) into one part per rank of `comm`: by
/// `cell_ranks` when given on the root (one rank per cell, cells in block order), otherwise by
/// METIS. Collective. Throws InputError on every rank for a mesh without cells, a cell node
/// out of range, or a cell rank list of the wrong length or with a rank outside the
/// communicator (naming the cell).
template <int Dim>
[[nodiscard]] DistributedMesh<Dim> partition_mesh(MPI_Comm comm, const Mesh<Dim>& whole, std::span<const int> cell_ranks = {},
                                                  int root = 0) {
  const int p = size_of(comm);
  const bool at_root = rank_of(comm) == root;
  std::vector<int> ranks;
  collective(comm, [&] {
    if (!at_root) return;
    const Index n = whole.num_nodes();
    if (whole.num_cells() == 0) throw InputError("parallel::partition_mesh: the mesh has no cells");
    for (const auto* list : {&whole.cells, &whole.facets})
      for (const auto& block : *list)
        for (const Index v : block.connectivity)
          if (v < 0 || v >= n)
            throw InputError("parallel::partition_mesh: a " + std::string(name(block.type)) + " refers to node " +
                             std::to_string(v) + " (expected 0 to " + std::to_string(n - 1) + ")");
    if (cell_ranks.empty()) {
      ranks = metis_cell_ranks(whole, p);
    } else {
      if (static_cast<Index>(cell_ranks.size()) != whole.num_cells())
        throw InputError("parallel::partition_mesh: " + std::to_string(cell_ranks.size()) + " cell ranks for " +
                         std::to_string(whole.num_cells()) + " cells (expected one per cell)");
      for (std::size_t c = 0; c < cell_ranks.size(); ++c)
        if (cell_ranks[c] < 0 || cell_ranks[c] >= p)
          throw InputError("parallel::partition_mesh: cell " + std::to_string(c) + " goes to rank " +
                           std::to_string(cell_ranks[c]) + " (expected 0.." + std::to_string(p - 1) + ")");
      ranks.assign(cell_ranks.begin(), cell_ranks.end());
    }
  });
  if (!at_root) return detail::unpack_part<Dim>(detail::receive_bytes(root, comm), comm);

  const Index n = whole.num_nodes();
  std::vector<int> owner(static_cast<std::size_t>(n), p);
  {
    std::size_t c = 0;
    for (const auto& block : whole.cells)
      for (Index e = 0; e < block.size(); ++e, ++c)
        for (const Index v : block.element(e)) owner[static_cast<std::size_t>(v)] = std::min(owner[static_cast<std::size_t>(v)], ranks[c]);
  }
  for (int& o : owner)
    if (o == p) o = root;
  std::vector<std::vector<Index>> owned(static_cast<std::size_t>(p));
  for (Index v = 0; v < n; ++v) owned[static_cast<std::size_t>(owner[static_cast<std::size_t>(v)])].push_back(v);

  std::vector<Index> local_of(static_cast<std::size_t>(n), -1);
  DistributedMesh<Dim> mine;
  for (int r = 0; r < p; ++r) {
    DistributedMesh<Dim> part;
    part.comm = comm;
    part.num_global_nodes = n;
    std::vector<Index> nodes = owned[static_cast<std::size_t>(r)];
    part.num_owned = static_cast<Index>(nodes.size());
    std::vector<Index> ghosts;
    std::size_t c = 0;
    for (const auto& block : whole.cells)
      for (Index e = 0; e < block.size(); ++e, ++c)
        if (ranks[c] == r)
          for (const Index v : block.element(e))
            if (owner[static_cast<std::size_t>(v)] != r) ghosts.push_back(v);
    std::sort(ghosts.begin(), ghosts.end());
    ghosts.erase(std::unique(ghosts.begin(), ghosts.end()), ghosts.end());
    nodes.insert(nodes.end(), ghosts.begin(), ghosts.end());
    part.local.points.resize(Dim, static_cast<Index>(nodes.size()));
    for (std::size_t i = 0; i < nodes.size(); ++i) {
      local_of[static_cast<std::size_t>(nodes[i])] = static_cast<Index>(i);
      part.local.points.col(static_cast<Index>(i)) = whole.points.col(nodes[i]);
      part.global_ids.push_back(nodes[i]);
      part.owner.push_back(owner[static_cast<std::size_t>(nodes[i])]);
      // A part's nodes are not a run of the file's numbering: each keeps its own id.
      part.local.node_ids.push_back(whole.node_id(nodes[i]));
    }
    const auto copy_element = [&](const ElementBlock& block, Index e, ElementBlock& local) {
      for (const Index v : block.element(e)) local.connectivity.push_back(local_of[static_cast<std::size_t>(v)]);
      const auto k = static_cast<std::size_t>(e);
      local.tags.push_back(block.tags[k]);
      if (!block.ids.empty()) local.ids.push_back(block.ids[k]);
      if (!block.entities.empty()) local.entities.push_back(block.entities[k]);
    };
    c = 0;
    for (const auto& block : whole.cells) {
      ElementBlock local{block.type, {}, {}, {}, {}};
      for (Index e = 0; e < block.size(); ++e, ++c)
        if (ranks[c] == r) copy_element(block, e, local);
      if (!local.empty()) part.local.cells.push_back(std::move(local));
    }
    for (const auto& block : whole.facets) {
      ElementBlock local{block.type, {}, {}, {}, {}};
      for (Index e = 0; e < block.size(); ++e) {
        const auto el = block.element(e);
        if (std::all_of(el.begin(), el.end(), [&](Index v) { return local_of[static_cast<std::size_t>(v)] >= 0; }))
          copy_element(block, e, local);
      }
      if (!local.empty()) part.local.facets.push_back(std::move(local));
    }
    part.local.groups = whole.groups;
    for (const Index v : nodes) local_of[static_cast<std::size_t>(v)] = -1;
    if (r == root)
      mine = std::move(part);
    else
      detail::send_bytes(detail::pack_part<Dim>(part), r, comm);
  }
  return mine;
}

}  // namespace meshmotion::parallel

// The compiled parallel library (target meshmotion::parallel, src/parallel.cpp) holds these.
#ifdef MESHMOTION_PARALLEL_COMPILED
namespace meshmotion::parallel {
extern template DistributedMesh<2> partition_mesh<2>(MPI_Comm, const Mesh<2>&, std::span<const int>, int);
extern template DistributedMesh<3> partition_mesh<3>(MPI_Comm, const Mesh<3>&, std::span<const int>, int);
}  // namespace meshmotion::parallel
#endif
