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

/// CGNS element type of each catalogue type (ElementTypeNull for none): CGNS names the complete
/// Lagrange elements to order 4. Its quartic triangles, tetrahedra, prisms and pyramids place
/// their triangle-face and inside nodes off the equispaced lattice; they are read and written
/// as equispaced, as Gmsh's and SU2's CGNS readers take them (docs/formats.md).
inline constexpr auto cgns_types = [] {
  std::array<CGNS_ENUMT(ElementType_t), num_element_types> types{};
  types.fill(CGNS_ENUMV(ElementTypeNull));
  using E = ElementType;
  const std::pair<E, CGNS_ENUMT(ElementType_t)> named[] = {
      {E::point1, CGNS_ENUMV(NODE)},       {E::line2, CGNS_ENUMV(BAR_2)},       {E::line3, CGNS_ENUMV(BAR_3)},
      {E::line4, CGNS_ENUMV(BAR_4)},       {E::line5, CGNS_ENUMV(BAR_5)},       {E::tri3, CGNS_ENUMV(TRI_3)},
      {E::tri6, CGNS_ENUMV(TRI_6)},        {E::tri10, CGNS_ENUMV(TRI_10)},      {E::tri15, CGNS_ENUMV(TRI_15)},
      {E::quad4, CGNS_ENUMV(QUAD_4)},      {E::quad8, CGNS_ENUMV(QUAD_8)},      {E::quad9, CGNS_ENUMV(QUAD_9)},
      {E::quad16, CGNS_ENUMV(QUAD_16)},    {E::quad25, CGNS_ENUMV(QUAD_25)},    {E::tet4, CGNS_ENUMV(TETRA_4)},
      {E::tet10, CGNS_ENUMV(TETRA_10)},    {E::tet20, CGNS_ENUMV(TETRA_20)},    {E::tet35, CGNS_ENUMV(TETRA_35)},
      {E::hex8, CGNS_ENUMV(HEXA_8)},       {E::hex20, CGNS_ENUMV(HEXA_20)},     {E::hex27, CGNS_ENUMV(HEXA_27)},
      {E::hex64, CGNS_ENUMV(HEXA_64)},     {E::hex125, CGNS_ENUMV(HEXA_125)},   {E::prism6, CGNS_ENUMV(PENTA_6)},
      {E::prism15, CGNS_ENUMV(PENTA_15)},  {E::prism18, CGNS_ENUMV(PENTA_18)},  {E::prism40, CGNS_ENUMV(PENTA_40)},
      {E::prism75, CGNS_ENUMV(PENTA_75)},  {E::pyramid5, CGNS_ENUMV(PYRA_5)},   {E::pyramid13, CGNS_ENUMV(PYRA_13)},
      {E::pyramid14, CGNS_ENUMV(PYRA_14)}, {E::pyramid30, CGNS_ENUMV(PYRA_30)}, {E::pyramid55, CGNS_ENUMV(PYRA_55)}};
  for (const auto& [ours, theirs] : named) types[static_cast<std::size_t>(ours)] = theirs;
  return types;
}();

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

inline void append_cgns_inside(Shape s, int p, std::span<const RefPoint> c, std::vector<RefPoint>& out);

/// CGNS's nodes of an element of shape s and order p on corners c (SIDS, element numbering
/// conventions, with its cubic and quartic extensions): the vertices, the nodes of each edge
/// from its first vertex, then (complete elements) the inside nodes of each face, then the
/// inside. CGNS lists and orients the edges of tetrahedra, pyramids, prisms and hexahedra and
/// the faces of the 3D shapes differently from Gmsh; a face's inside starts at its first
/// vertex. Order 0: one node at the centre (the bottom of the recursion).
inline void append_cgns_nodes(Shape s, int p, bool complete, std::span<const RefPoint> c, std::vector<RefPoint>& out) {
  if (p == 0) {
    out.push_back(mean_point(c));
    return;
  }
  using Pair = std::array<int, 2>;
  struct Face {
    int size;
    std::array<int, 4> vertices;
  };
  static constexpr Pair cgns_line_edges[] = {{0, 1}};
  static constexpr Pair cgns_tri_edges[] = {{0, 1}, {1, 2}, {2, 0}};
  static constexpr Pair cgns_quad_edges[] = {{0, 1}, {1, 2}, {2, 3}, {3, 0}};
  static constexpr Pair cgns_tet_edges[] = {{0, 1}, {1, 2}, {2, 0}, {0, 3}, {1, 3}, {2, 3}};
  static constexpr Pair cgns_pyramid_edges[] = {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {0, 4}, {1, 4}, {2, 4}, {3, 4}};
  static constexpr Pair cgns_prism_edges[] = {{0, 1}, {1, 2}, {2, 0}, {0, 3}, {1, 4}, {2, 5}, {3, 4}, {4, 5}, {5, 3}};
  static constexpr Pair cgns_hex_edges[] = {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {0, 4}, {1, 5},
                                       {2, 6}, {3, 7}, {4, 5}, {5, 6}, {6, 7}, {7, 4}};
  static constexpr Face cgns_tet_faces[] = {{3, {0, 1, 2}}, {3, {0, 1, 3}}, {3, {1, 2, 3}}, {3, {2, 0, 3}}};
  static constexpr Face cgns_pyramid_faces[] = {{4, {0, 1, 2, 3}}, {3, {0, 1, 4}}, {3, {1, 2, 4}}, {3, {2, 3, 4}}, {3, {3, 0, 4}}};
  static constexpr Face cgns_prism_faces[] = {{3, {0, 1, 2}}, {4, {0, 1, 4, 3}}, {4, {1, 2, 5, 4}}, {4, {2, 0, 3, 5}}, {3, {3, 4, 5}}};
  static constexpr Face cgns_hex_faces[] = {{4, {0, 1, 2, 3}}, {4, {0, 1, 5, 4}}, {4, {1, 2, 6, 5}},
                                       {4, {2, 3, 7, 6}}, {4, {3, 0, 4, 7}}, {4, {4, 5, 6, 7}}};
  std::span<const Pair> edges;
  std::span<const Face> faces;
  switch (s) {
    case Shape::point: break;
    case Shape::line: edges = cgns_line_edges; break;
    case Shape::triangle: edges = cgns_tri_edges; break;
    case Shape::quadrilateral: edges = cgns_quad_edges; break;
    case Shape::tetrahedron: edges = cgns_tet_edges; faces = cgns_tet_faces; break;
    case Shape::pyramid: edges = cgns_pyramid_edges; faces = cgns_pyramid_faces; break;
    case Shape::prism: edges = cgns_prism_edges; faces = cgns_prism_faces; break;
    case Shape::hexahedron: edges = cgns_hex_edges; faces = cgns_hex_faces; break;
  }
  out.insert(out.end(), c.begin(), c.end());
  for (const Pair& e : edges)
    for (int j = 1; j < p; ++j) {
      const double r = static_cast<double>(j) / p;
      out.push_back(combine(std::array<RefPoint, 2>{c[static_cast<std::size_t>(e[0])], c[static_cast<std::size_t>(e[1])]}, {1 - r, r}));
    }
  if (!complete) return;
  for (const Face& f : faces) {
    std::array<RefPoint, 4> face{};
    for (int k = 0; k < f.size; ++k) face[static_cast<std::size_t>(k)] = c[static_cast<std::size_t>(f.vertices[static_cast<std::size_t>(k)])];
    append_cgns_inside(f.size == 3 ? Shape::triangle : Shape::quadrilateral, p, std::span<const RefPoint>(face.data(), static_cast<std::size_t>(f.size)), out);
  }
  append_cgns_inside(s, p, c, out);
}

/// CGNS's inside nodes of an element of shape s and order p on corners c: a triangle's,
/// tetrahedron's and pyramid's are CGNS's element of order p - 3, p - 4, p - 3 on the inner
/// corners; a quadrilateral's go round in rings from the node nearest its first vertex toward its
/// second, then the centre; a prism's and a hexahedron's are the insides of their triangle or
/// quadrilateral layers from the bottom up.
inline void append_cgns_inside(Shape s, int p, std::span<const RefPoint> c, std::vector<RefPoint>& out) {
  switch (s) {
    case Shape::triangle:
    case Shape::pyramid:
    case Shape::tetrahedron:
      if (const int q = inner_order(s, p); q >= 0) append_cgns_nodes(s, q, true, inner_corners(s, p, c), out);
      break;
    case Shape::quadrilateral: {
      const auto at = [&](int i, int j) { return multilinear(c, static_cast<double>(i) / p, static_cast<double>(j) / p); };
      for (int low = 1, high = p - 1; low <= high; ++low, --high) {
        if (low == high) {
          out.push_back(at(low, low));
          break;
        }
        for (int t = low; t < high; ++t) out.push_back(at(t, low));
        for (int t = low; t < high; ++t) out.push_back(at(high, t));
        for (int t = high; t > low; --t) out.push_back(at(t, high));
        for (int t = high; t > low; --t) out.push_back(at(low, t));
      }
      break;
    }
    case Shape::prism:
    case Shape::hexahedron: {
      const std::size_t n = c.size() / 2;
      for (int k = 1; k < p; ++k) {
        const double r = static_cast<double>(k) / p;
        std::vector<RefPoint> layer;
        for (std::size_t i = 0; i < n; ++i) layer.push_back(combine(std::array<RefPoint, 2>{c[i], c[i + n]}, {1 - r, r}));
        append_cgns_inside(s == Shape::prism ? Shape::triangle : Shape::quadrilateral, p, layer, out);
      }
      break;
    }
    case Shape::point:
    case Shape::line: break;
  }
}

/// CGNS's local node order of a type: CGNS node i is our (Gmsh's) local node cgns_order[i].
/// CGNS's nodes are built as reference points (append_cgns_nodes) and matched against the
/// catalogue's. They agree node by node with SU2's CGNS reader for every complete type to
/// order 4, and with Gmsh's rules for building CGNS's nodes.
[[nodiscard]] inline std::vector<int> cgns_order(ElementType type) {
  if (!cgns_writes(type)) throw InputError("CGNS node order: no CGNS type holds a " + std::string(name(type)));
  const auto ours = reference_nodes(type);
  std::vector<RefPoint> points;
  append_cgns_nodes(shape(type), std::max(::meshmotion::order(type), 1), element_info(type).complete,
                    ours.first(static_cast<std::size_t>(num_vertices(type))), points);
  std::vector<int> order(points.size());
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
