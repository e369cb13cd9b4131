#pragma once
/// \file
/// What CGNS reading and writing share: whether the build has CGNS, the element types and
/// node orders of CGNS against the catalogue's, and an open file whose failures name the node
/// path (io/cgns_reader.hpp, io/cgns_writer.hpp).

#include "meshmotion/core/element.hpp"
#include "meshmotion/core/detail/per_type_cache.hpp"
#include "meshmotion/core/error.hpp"
#include "meshmotion/io/detail/cgns_library.hpp"

#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <iterator>
#include <map>
#include <string>
#include <tuple>
#include <unordered_map>
#include <utility>
#include <vector>

namespace meshmotion {

/// Whether this build reads and writes CGNS files.
#ifdef MESHMOTION_HAVE_CGNS
inline constexpr bool have_cgns = true;
#else
inline constexpr bool have_cgns = false;
#endif

namespace detail {

/// CGNS's local node order of a type: CGNS node i is our (Gmsh's) local node cgns_order[i].
/// CGNS numbers edges and quadrilateral faces differently from Gmsh for tetrahedra,
/// pyramids, prisms and hexahedra; both put vertices first, then one node per edge, per
/// quadrilateral face and the centre. Built from CGNS's edge and face lists (SIDS, element
/// numbering conventions) matched against the catalogue's.
[[nodiscard]] inline std::vector<int> cgns_order(ElementType type) {
  using Pair = std::array<int, 2>;
  using Quad = std::array<int, 4>;
  static constexpr Pair cgns_tet_edges[] = {{0, 1}, {1, 2}, {2, 0}, {0, 3}, {1, 3}, {2, 3}};
  static constexpr Pair cgns_pyramid_edges[] = {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {0, 4}, {1, 4}, {2, 4}, {3, 4}};
  static constexpr Pair cgns_prism_edges[] = {{0, 1}, {1, 2}, {2, 0}, {0, 3}, {1, 4}, {2, 5}, {3, 4}, {4, 5}, {5, 3}};
  static constexpr Pair cgns_hex_edges[] = {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {0, 4}, {1, 5},
                                       {2, 6}, {3, 7}, {4, 5}, {5, 6}, {6, 7}, {7, 4}};
  static constexpr Quad cgns_pyramid_faces[] = {{0, 1, 2, 3}};
  static constexpr Quad cgns_prism_faces[] = {{0, 1, 4, 3}, {1, 2, 5, 4}, {2, 0, 3, 5}};
  static constexpr Quad cgns_hex_faces[] = {{0, 1, 2, 3}, {0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {0, 3, 7, 4}, {4, 5, 6, 7}};
  std::span<const Pair> cgns_edges;
  std::span<const Quad> cgns_faces;
  switch (shape(type)) {
    case Shape::tetrahedron: cgns_edges = cgns_tet_edges; break;
    case Shape::pyramid: cgns_edges = cgns_pyramid_edges; cgns_faces = cgns_pyramid_faces; break;
    case Shape::prism: cgns_edges = cgns_prism_edges; cgns_faces = cgns_prism_faces; break;
    case Shape::hexahedron: cgns_edges = cgns_hex_edges; cgns_faces = cgns_hex_faces; break;
    default: break;  // points, lines, triangles and quadrilaterals: Gmsh's order
  }
  std::vector<int> order(static_cast<std::size_t>(num_nodes(type)));
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
  if (cgns_edges.empty() || ::meshmotion::order(type) < 2) return order;
  const int nv = num_vertices(type);
  std::size_t next = static_cast<std::size_t>(nv);
  for (const Pair& e : cgns_edges) order[next++] = nv + local_edge(type, e[0], e[1]);
  if (!has_face_nodes(type)) return order;
  const int first_face_node = nv + static_cast<int>(edges(type).size());
  for (const Quad& face : cgns_faces) {
    Quad key = face;
    std::sort(key.begin(), key.end());
    int quad_index = 0;
    for (const LocalFacet& f : facets(type)) {
      if (f.shape != Shape::quadrilateral) continue;
      Quad ours{f.vertices[0], f.vertices[1], f.vertices[2], f.vertices[3]};
      std::sort(ours.begin(), ours.end());
      if (ours == key) break;
      ++quad_index;
    }
    order[next++] = first_face_node + quad_index;
  }
  // The hexahedron's centre stays last.
  return order;
}

}  // namespace detail

#ifdef MESHMOTION_HAVE_CGNS

namespace detail {

/// CGNS element type of each catalogue type, in ElementType order (ElementTypeNull past order 2).
inline constexpr CGNS_ENUMT(ElementType_t) cgns_types[num_element_types] = {
    CGNS_ENUMV(NODE),     CGNS_ENUMV(BAR_2),    CGNS_ENUMV(BAR_3),    CGNS_ENUMV(TRI_3),    CGNS_ENUMV(TRI_6),
    CGNS_ENUMV(QUAD_4),   CGNS_ENUMV(QUAD_8),   CGNS_ENUMV(QUAD_9),   CGNS_ENUMV(TETRA_4),  CGNS_ENUMV(TETRA_10),
    CGNS_ENUMV(HEXA_8),   CGNS_ENUMV(HEXA_20),  CGNS_ENUMV(HEXA_27),  CGNS_ENUMV(PENTA_6),  CGNS_ENUMV(PENTA_15),
    CGNS_ENUMV(PENTA_18), CGNS_ENUMV(PYRA_5),   CGNS_ENUMV(PYRA_13),  CGNS_ENUMV(PYRA_14)};

[[nodiscard]] inline CGNS_ENUMT(ElementType_t) cgns_type(ElementType t) { return cgns_types[static_cast<std::size_t>(t)]; }

[[nodiscard]] inline std::string cgns_type_name(CGNS_ENUMT(ElementType_t) t) {
  const int k = static_cast<int>(t);
  return k >= 0 && k < NofValidElementTypes ? std::string(cgns_api().cg_ElementTypeName(t)) : "element type " + std::to_string(k);
}

/// Our type of a CGNS type, or nullopt-like -1 when the catalogue has none (past order 2:
/// CGNS orders their nodes unlike Gmsh, and the table holds no CGNS type for them).
[[nodiscard]] inline int element_type_of_cgns(CGNS_ENUMT(ElementType_t) t) {
  for (int k = 0; k < num_element_types; ++k)
    if (order(static_cast<ElementType>(k)) <= 2 && cgns_types[k] == t) return k;
  return -1;
}

/// The permutation of a type, computed on its first use.
[[nodiscard]] inline const std::vector<int>& cgns_order_of(ElementType t) {
  static PerTypeCache<std::vector<int>> orders;
  return orders.get(t, cgns_order);
}

/// An open CGNS file, closed on scope exit; check() turns a library status into an exception
/// naming the file, the node path and the library's message.
/// Why a file cannot be created at `file`, in the user's terms (the CGNS library reports HDF5's):
/// its folder missing, not a folder or not writable, or else the library's own words.
[[nodiscard]] inline std::string creation_obstacle(const std::filesystem::path& file) {
  const std::filesystem::path folder = file.has_parent_path() ? file.parent_path() : std::filesystem::path(".");
  std::error_code ec;
  const auto status = std::filesystem::status(folder, ec);
  if (!std::filesystem::exists(status)) return "its folder " + folder.string() + " does not exist";
  if (!std::filesystem::is_directory(status)) return folder.string() + " is not a folder";
  if (::access(folder.c_str(), W_OK) != 0) return "its folder " + folder.string() + " is not writable (" + std::strerror(errno) + ")";
  return std::string("the CGNS library cannot create it (") + cgns_api().cg_get_error() + ")";
}

class CgnsFile {
 public:
  /// `file` opened in `mode`; errors name `shown` when given (the user's path, where `file` is
  /// its temporary), and a file that cannot be created says why in the user's terms.
  CgnsFile(const std::filesystem::path& file, int mode, const std::filesystem::path& shown = {})
      : file_(shown.empty() ? file : shown) {
    if (cgns_api().cg_open(file.c_str(), mode, &fn_) != CG_OK) {
      fn_ = -1;
      if (mode == CG_MODE_WRITE) throw IoError(file_.string() + ": cannot write: " + creation_obstacle(file));
      throw IoError(file_.string() + ": cannot open as a CGNS file (" + cgns_api().cg_get_error() + ")");
    }
  }
  CgnsFile(const CgnsFile&) = delete;
  CgnsFile& operator=(const CgnsFile&) = delete;
  ~CgnsFile() { close_quietly(); }

  [[nodiscard]] int id() const noexcept { return fn_; }

  void check(int status, const std::string& path) const {
    if (status != CG_OK) throw IoError(file_.string() + ": " + path + ": " + cgns_api().cg_get_error());
  }
  [[noreturn]] void fail(const std::string& path, const std::string& what) const {
    throw InputError(file_.string() + ": " + path + ": " + what);
  }
  /// Closes, reporting a failure (the last write happens here).
  void close() {
    const int fn = fn_;
    fn_ = -1;
    if (fn >= 0 && cgns_api().cg_close(fn) != CG_OK) throw IoError(file_.string() + ": closing failed (" + cgns_api().cg_get_error() + ")");
  }

 private:
  void close_quietly() noexcept {
    if (fn_ >= 0) cgns_api().cg_close(fn_);
    fn_ = -1;
  }
  std::filesystem::path file_;
  int fn_ = -1;
};

}  // namespace detail

#endif  // MESHMOTION_HAVE_CGNS

}  // namespace meshmotion
