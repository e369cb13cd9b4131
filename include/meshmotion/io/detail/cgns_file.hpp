#pragma once
/// \file
/// What CGNS reading and writing share: whether the build has CGNS, the element types and
/// node orders of CGNS against the catalogue's, and an open file whose failures name the node
/// path (io/cgns_reader.hpp, io/cgns_writer.hpp).

#include "meshmotion/core/element.hpp"
#include "meshmotion/core/shape_functions.hpp"
#include "meshmotion/core/detail/per_type_cache.hpp"
#include "meshmotion/core/error.hpp"
#include "meshmotion/io/detail/cgns_library.hpp"

#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
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

#ifdef MESHMOTION_HAVE_CGNS

namespace detail {

/// CGNS element type of each catalogue type, in ElementType order: ElementTypeNull for the
/// cubic prisms and pyramids (the readers at hand disagree on the PENTA_40's faces) and past
/// order 3 (the quartic simplices' face and inside nodes lie off the equispaced lattice).
inline constexpr CGNS_ENUMT(ElementType_t) cgns_types[num_element_types] = {
    CGNS_ENUMV(NODE),     CGNS_ENUMV(BAR_2),    CGNS_ENUMV(BAR_3),    CGNS_ENUMV(TRI_3),    CGNS_ENUMV(TRI_6),
    CGNS_ENUMV(QUAD_4),   CGNS_ENUMV(QUAD_8),   CGNS_ENUMV(QUAD_9),   CGNS_ENUMV(TETRA_4),  CGNS_ENUMV(TETRA_10),
    CGNS_ENUMV(HEXA_8),   CGNS_ENUMV(HEXA_20),  CGNS_ENUMV(HEXA_27),  CGNS_ENUMV(PENTA_6),  CGNS_ENUMV(PENTA_15),
    CGNS_ENUMV(PENTA_18), CGNS_ENUMV(PYRA_5),   CGNS_ENUMV(PYRA_13),  CGNS_ENUMV(PYRA_14),  CGNS_ENUMV(BAR_4),
    CGNS_ENUMV(TRI_10),   CGNS_ENUMV(QUAD_16),  CGNS_ENUMV(TETRA_20), CGNS_ENUMV(HEXA_64)};

[[nodiscard]] inline CGNS_ENUMT(ElementType_t) cgns_type(ElementType t) { return cgns_types[static_cast<std::size_t>(t)]; }

[[nodiscard]] inline std::string cgns_type_name(CGNS_ENUMT(ElementType_t) t) {
  const int k = static_cast<int>(t);
  return k >= 0 && k < NofValidElementTypes ? std::string(cgns_api().cg_ElementTypeName(t)) : "element type " + std::to_string(k);
}

/// Our type of a CGNS type, or -1 when cgns_types holds none.
[[nodiscard]] inline int element_type_of_cgns(CGNS_ENUMT(ElementType_t) t) {
  if (t == CGNS_ENUMV(ElementTypeNull)) return -1;
  for (int k = 0; k < num_element_types; ++k)
    if (cgns_types[k] == t) return k;
  return -1;
}

/// Whether CGNS files hold elements of type t (cgns_types names a CGNS type for it).
[[nodiscard]] inline bool cgns_writes(ElementType t) {
  return cgns_types[static_cast<std::size_t>(t)] != CGNS_ENUMV(ElementTypeNull);
}

/// CGNS's local node order of a type: CGNS node i is our (Gmsh's) local node cgns_order[i].
/// Both put the vertices first, then the nodes of each edge from its first vertex, the nodes
/// inside each face and the inside; CGNS lists and orients the edges of tetrahedra, pyramids,
/// prisms and hexahedra and the faces of the 3D shapes differently from Gmsh (SIDS, element
/// numbering conventions: edges below; a face's inside nodes start at its first vertex, a
/// hexahedron's side faces at the bottom edge's first vertex, (3, 0, 4, 7) included). CGNS's
/// nodes are built as reference points from those lists and matched against the catalogue's.
/// Orders to 3 (cgns_types holds no type past them: the quartic simplices place their face
/// and inside nodes off the equispaced lattice).
[[nodiscard]] inline std::vector<int> cgns_order(ElementType type) {
  if (!cgns_writes(type)) throw InputError("CGNS node order: no CGNS type holds a " + std::string(name(type)));
  using Pair = std::array<int, 2>;
  struct Face {
    int size;
    std::array<int, 4> vertices;
  };
  static constexpr Pair cgns_tet_edges[] = {{0, 1}, {1, 2}, {2, 0}, {0, 3}, {1, 3}, {2, 3}};
  static constexpr Pair cgns_pyramid_edges[] = {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {0, 4}, {1, 4}, {2, 4}, {3, 4}};
  static constexpr Pair cgns_prism_edges[] = {{0, 1}, {1, 2}, {2, 0}, {0, 3}, {1, 4}, {2, 5}, {3, 4}, {4, 5}, {5, 3}};
  static constexpr Pair cgns_hex_edges[] = {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {0, 4}, {1, 5},
                                       {2, 6}, {3, 7}, {4, 5}, {5, 6}, {6, 7}, {7, 4}};
  static constexpr Face cgns_tet_faces[] = {{3, {0, 1, 2}}, {3, {0, 1, 3}}, {3, {1, 2, 3}}, {3, {2, 0, 3}}};
  // Order 2 at most: the faces with a node there (the quadrilaterals).
  static constexpr Face cgns_pyramid_faces[] = {{4, {0, 1, 2, 3}}};
  static constexpr Face cgns_prism_faces[] = {{4, {0, 1, 4, 3}}, {4, {1, 2, 5, 4}}, {4, {2, 0, 3, 5}}};
  static constexpr Face cgns_hex_faces[] = {{4, {0, 1, 2, 3}}, {4, {0, 1, 5, 4}}, {4, {1, 2, 6, 5}},
                                       {4, {2, 3, 7, 6}}, {4, {3, 0, 4, 7}}, {4, {4, 5, 6, 7}}};
  std::span<const Pair> cgns_edges;
  std::span<const Face> cgns_faces;
  switch (shape(type)) {
    case Shape::tetrahedron: cgns_edges = cgns_tet_edges; cgns_faces = cgns_tet_faces; break;
    case Shape::pyramid: cgns_edges = cgns_pyramid_edges; cgns_faces = cgns_pyramid_faces; break;
    case Shape::prism: cgns_edges = cgns_prism_edges; cgns_faces = cgns_prism_faces; break;
    case Shape::hexahedron: cgns_edges = cgns_hex_edges; cgns_faces = cgns_hex_faces; break;
    default: break;  // points, lines, triangles and quadrilaterals: Gmsh's order
  }
  std::vector<int> order(static_cast<std::size_t>(num_nodes(type)));
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
  const int p = ::meshmotion::order(type);
  if (cgns_edges.empty() || p < 2) return order;
  const auto ours = reference_nodes(type);
  const auto corners = ours.first(static_cast<std::size_t>(num_vertices(type)));
  std::vector<RefPoint> points(corners.begin(), corners.end());
  for (const Pair& e : cgns_edges)
    for (int j = 1; j < p; ++j) {
      const double r = static_cast<double>(j) / p;
      points.push_back(combine(std::array<RefPoint, 2>{corners[static_cast<std::size_t>(e[0])], corners[static_cast<std::size_t>(e[1])]},
                               {1 - r, r}));
    }
  if (element_info(type).complete) {
    for (const Face& f : cgns_faces) {
      std::array<RefPoint, 4> face{};
      for (int k = 0; k < f.size; ++k) face[static_cast<std::size_t>(k)] = corners[static_cast<std::size_t>(f.vertices[static_cast<std::size_t>(k)])];
      append_inside(f.size == 3 ? Shape::triangle : Shape::quadrilateral, p, std::span<const RefPoint>(face.data(), static_cast<std::size_t>(f.size)), points);
    }
    append_inside(shape(type), p, corners, points);
  }
  for (std::size_t i = 0; i < order.size(); ++i) {
    const auto at = std::find_if(ours.begin(), ours.end(), [&](const RefPoint& x) {
      return std::abs(x[0] - points[i][0]) + std::abs(x[1] - points[i][1]) + std::abs(x[2] - points[i][2]) < 1e-9;
    });
    if (at == ours.end()) throw InputError("CGNS node order: no " + std::string(name(type)) + " node at CGNS node " + std::to_string(i));
    order[i] = static_cast<int>(at - ours.begin());
  }
  return order;
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
