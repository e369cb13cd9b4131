#pragma once
/// \file
/// The element catalogue: types, node counts, local edges and facets, and node orderings.
///
/// The library's own local node order is Gmsh's (vertices first, then one node per edge in
/// the order of edges(), then one node per quadrilateral facet in the order of facets(),
/// then the volume node). VTK and SU2 orders are reached through the permutations below.
/// Reference coordinates and shape functions live in core/shape_functions.hpp.

#include "meshmotion/core/error.hpp"

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

namespace meshmotion {

/// Every element type the library reads, writes, moves and curves.
enum class ElementType : std::uint8_t {
  point1,
  line2, line3,
  tri3, tri6,
  quad4, quad8, quad9,
  tet4, tet10,
  hex8, hex20, hex27,
  prism6, prism15, prism18,
  pyramid5, pyramid13, pyramid14,
};

inline constexpr int num_element_types = 19;

/// Geometric shape of an element, independent of its order.
enum class Shape : std::uint8_t { point, line, triangle, quadrilateral, tetrahedron, hexahedron, prism, pyramid };

/// A local facet (an element face in 3D, an edge in 2D, a vertex in 1D): its vertices, in
/// the order that makes its normal point out of a positively oriented element.
struct LocalFacet {
  Shape shape;
  int num_vertices;
  std::array<int, 4> vertices;
};

/// Static description of one element type.
struct ElementInfo {
  ElementType type;
  std::string_view name;    ///< "tri6", "hex27", ...
  Shape shape;
  int dim;                  ///< topological dimension
  int order;                ///< 1 or 2 (0 for a point)
  int num_nodes;
  int num_vertices;
  bool complete;            ///< all Lagrange nodes present (quad9, hex27, ...), not serendipity
  int gmsh_id;              ///< Gmsh element type number
  int vtk_id;               ///< classic VTK cell type (VTK_QUADRATIC_TETRA = 24, ...)
  int vtk_lagrange_id;      ///< VTK Lagrange cell type, -1 where VTK has none for this node set
};

namespace detail {

inline constexpr std::array<ElementInfo, num_element_types> element_table{{
    {ElementType::point1, "point1", Shape::point, 0, 0, 1, 1, true, 15, 1, -1},
    {ElementType::line2, "line2", Shape::line, 1, 1, 2, 2, true, 1, 3, -1},
    {ElementType::line3, "line3", Shape::line, 1, 2, 3, 2, true, 8, 21, 68},
    {ElementType::tri3, "tri3", Shape::triangle, 2, 1, 3, 3, true, 2, 5, -1},
    {ElementType::tri6, "tri6", Shape::triangle, 2, 2, 6, 3, true, 9, 22, 69},
    {ElementType::quad4, "quad4", Shape::quadrilateral, 2, 1, 4, 4, true, 3, 9, -1},
    {ElementType::quad8, "quad8", Shape::quadrilateral, 2, 2, 8, 4, false, 16, 23, -1},
    {ElementType::quad9, "quad9", Shape::quadrilateral, 2, 2, 9, 4, true, 10, 28, 70},
    {ElementType::tet4, "tet4", Shape::tetrahedron, 3, 1, 4, 4, true, 4, 10, -1},
    {ElementType::tet10, "tet10", Shape::tetrahedron, 3, 2, 10, 4, true, 11, 24, 71},
    {ElementType::hex8, "hex8", Shape::hexahedron, 3, 1, 8, 8, true, 5, 12, -1},
    {ElementType::hex20, "hex20", Shape::hexahedron, 3, 2, 20, 8, false, 17, 25, -1},
    {ElementType::hex27, "hex27", Shape::hexahedron, 3, 2, 27, 8, true, 12, 29, 72},
    {ElementType::prism6, "prism6", Shape::prism, 3, 1, 6, 6, true, 6, 13, -1},
    {ElementType::prism15, "prism15", Shape::prism, 3, 2, 15, 6, false, 18, 26, -1},
    {ElementType::prism18, "prism18", Shape::prism, 3, 2, 18, 6, true, 13, 32, 73},
    {ElementType::pyramid5, "pyramid5", Shape::pyramid, 3, 1, 5, 5, true, 7, 14, -1},
    {ElementType::pyramid13, "pyramid13", Shape::pyramid, 3, 2, 13, 5, false, 19, 27, -1},
    {ElementType::pyramid14, "pyramid14", Shape::pyramid, 3, 2, 14, 5, true, 14, 27, -1},
}};

using Edge = std::array<int, 2>;

// Gmsh's local edge order: edge k of a quadratic element carries node num_vertices + k.
inline constexpr std::array<Edge, 1> line_edges{{{0, 1}}};
inline constexpr std::array<Edge, 3> triangle_edges{{{0, 1}, {1, 2}, {2, 0}}};
inline constexpr std::array<Edge, 4> quadrilateral_edges{{{0, 1}, {1, 2}, {2, 3}, {3, 0}}};
inline constexpr std::array<Edge, 6> tetrahedron_edges{{{0, 1}, {1, 2}, {2, 0}, {3, 0}, {3, 2}, {3, 1}}};
inline constexpr std::array<Edge, 12> hexahedron_edges{{{0, 1}, {0, 3}, {0, 4}, {1, 2}, {1, 5}, {2, 3},
                                                        {2, 6}, {3, 7}, {4, 5}, {4, 7}, {5, 6}, {6, 7}}};
inline constexpr std::array<Edge, 9> prism_edges{{{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 4}, {2, 5},
                                                  {3, 4}, {3, 5}, {4, 5}}};
inline constexpr std::array<Edge, 8> pyramid_edges{{{0, 1}, {0, 3}, {0, 4}, {1, 2}, {1, 4}, {2, 3},
                                                    {2, 4}, {3, 4}}};

// Outward facets of positively oriented elements. Quadrilateral facets are listed in
// Gmsh's order of face nodes (hex27 nodes 20..25, prism18 nodes 15..17, pyramid14 node 13).
inline constexpr std::array<LocalFacet, 2> line_facets{{
    {Shape::point, 1, {0, 0, 0, 0}}, {Shape::point, 1, {1, 0, 0, 0}}}};
inline constexpr std::array<LocalFacet, 3> triangle_facets{{
    {Shape::line, 2, {0, 1, 0, 0}}, {Shape::line, 2, {1, 2, 0, 0}}, {Shape::line, 2, {2, 0, 0, 0}}}};
inline constexpr std::array<LocalFacet, 4> quadrilateral_facets{{
    {Shape::line, 2, {0, 1, 0, 0}}, {Shape::line, 2, {1, 2, 0, 0}},
    {Shape::line, 2, {2, 3, 0, 0}}, {Shape::line, 2, {3, 0, 0, 0}}}};
inline constexpr std::array<LocalFacet, 4> tetrahedron_facets{{
    {Shape::triangle, 3, {0, 2, 1, 0}}, {Shape::triangle, 3, {0, 1, 3, 0}},
    {Shape::triangle, 3, {0, 3, 2, 0}}, {Shape::triangle, 3, {1, 2, 3, 0}}}};
inline constexpr std::array<LocalFacet, 6> hexahedron_facets{{
    {Shape::quadrilateral, 4, {0, 3, 2, 1}}, {Shape::quadrilateral, 4, {0, 1, 5, 4}},
    {Shape::quadrilateral, 4, {0, 4, 7, 3}}, {Shape::quadrilateral, 4, {1, 2, 6, 5}},
    {Shape::quadrilateral, 4, {2, 3, 7, 6}}, {Shape::quadrilateral, 4, {4, 5, 6, 7}}}};
inline constexpr std::array<LocalFacet, 5> prism_facets{{
    {Shape::triangle, 3, {0, 2, 1, 0}}, {Shape::triangle, 3, {3, 4, 5, 0}},
    {Shape::quadrilateral, 4, {0, 1, 4, 3}}, {Shape::quadrilateral, 4, {0, 3, 5, 2}},
    {Shape::quadrilateral, 4, {1, 2, 5, 4}}}};
inline constexpr std::array<LocalFacet, 5> pyramid_facets{{
    {Shape::quadrilateral, 4, {0, 3, 2, 1}}, {Shape::triangle, 3, {0, 1, 4, 0}},
    {Shape::triangle, 3, {1, 2, 4, 0}}, {Shape::triangle, 3, {2, 3, 4, 0}},
    {Shape::triangle, 3, {3, 0, 4, 0}}}};

// VTK node i is our node vtk_order[i] (classic VTK quadratic cells).
inline constexpr std::array<int, 10> tet10_vtk{0, 1, 2, 3, 4, 5, 6, 7, 9, 8};
inline constexpr std::array<int, 20> hex20_vtk{0, 1, 2, 3, 4, 5, 6, 7, 8, 11, 13, 9, 16, 18, 19, 17, 10, 12, 14, 15};
inline constexpr std::array<int, 27> hex27_vtk{0,  1,  2,  3,  4,  5,  6,  7,  8,  11, 13, 9,  16, 18,
                                               19, 17, 10, 12, 14, 15, 22, 23, 21, 24, 20, 25, 26};
// VTK_LAGRANGE_HEXAHEDRON lists the vertical edges as (0,4) (1,5) (3,7) (2,6).
inline constexpr std::array<int, 27> hex27_vtk_lagrange{0,  1,  2,  3,  4,  5,  6,  7,  8,  11, 13, 9,  16, 18,
                                                        19, 17, 10, 12, 15, 14, 22, 23, 21, 24, 20, 25, 26};
// VTK's classic wedges (linear, quadratic, biquadratic) turn their base (0,1,2) the other way:
// by the right-hand rule its normal points away from (3,4,5), Gmsh's towards it. VTK vertex i
// is our vertex {0,2,1,3,5,4}[i]; its edges (0,1) (1,2) (2,0) (3,4) (4,5) (5,3) (0,3) (1,4)
// (2,5) and quadrilateral faces (0,1,4,3) (1,2,5,4) (2,0,3,5) are ours through that
// relabelling. VTK's Lagrange wedge turns its base as Gmsh does (checked against VTK's signed
// cell sizes in python/tests/test_vtk_orientation.py).
inline constexpr std::array<int, 6> prism6_vtk{0, 2, 1, 3, 5, 4};
inline constexpr std::array<int, 15> prism15_vtk{0, 2, 1, 3, 5, 4, 7, 9, 6, 13, 14, 12, 8, 11, 10};
inline constexpr std::array<int, 18> prism18_vtk{0, 2, 1, 3, 5, 4, 7, 9, 6, 13, 14, 12, 8, 11, 10, 16, 17, 15};
inline constexpr std::array<int, 18> prism18_vtk_lagrange{0, 1, 2, 3, 4, 5, 6, 9, 7, 12, 14, 13, 8, 10, 11, 15, 17, 16};
inline constexpr std::array<int, 13> pyramid13_vtk{0, 1, 2, 3, 4, 5, 8, 10, 6, 7, 9, 11, 12};

template <class T, std::size_t N>
constexpr std::span<const T> as_span(const std::array<T, N>& a) {
  return std::span<const T>(a.data(), N);
}

}  // namespace detail

/// Catalogue entry of a type.
[[nodiscard]] constexpr const ElementInfo& element_info(ElementType type) {
  return detail::element_table[static_cast<std::size_t>(type)];
}
[[nodiscard]] constexpr int num_nodes(ElementType type) { return element_info(type).num_nodes; }
[[nodiscard]] constexpr int num_vertices(ElementType type) { return element_info(type).num_vertices; }
[[nodiscard]] constexpr int dimension(ElementType type) { return element_info(type).dim; }
[[nodiscard]] constexpr int order(ElementType type) { return element_info(type).order; }
[[nodiscard]] constexpr Shape shape(ElementType type) { return element_info(type).shape; }
[[nodiscard]] constexpr std::string_view name(ElementType type) { return element_info(type).name; }

/// Local edges of a shape as vertex pairs, in Gmsh order (edge k carries node num_vertices + k).
[[nodiscard]] constexpr std::span<const std::array<int, 2>> edges(Shape s) {
  switch (s) {
    case Shape::point: return {};
    case Shape::line: return detail::as_span(detail::line_edges);
    case Shape::triangle: return detail::as_span(detail::triangle_edges);
    case Shape::quadrilateral: return detail::as_span(detail::quadrilateral_edges);
    case Shape::tetrahedron: return detail::as_span(detail::tetrahedron_edges);
    case Shape::hexahedron: return detail::as_span(detail::hexahedron_edges);
    case Shape::prism: return detail::as_span(detail::prism_edges);
    case Shape::pyramid: return detail::as_span(detail::pyramid_edges);
  }
  return {};
}
[[nodiscard]] constexpr std::span<const std::array<int, 2>> edges(ElementType t) { return edges(shape(t)); }

/// Local facets (dimension dim - 1) of a shape, outward oriented.
[[nodiscard]] constexpr std::span<const LocalFacet> facets(Shape s) {
  switch (s) {
    case Shape::point: return {};
    case Shape::line: return detail::as_span(detail::line_facets);
    case Shape::triangle: return detail::as_span(detail::triangle_facets);
    case Shape::quadrilateral: return detail::as_span(detail::quadrilateral_facets);
    case Shape::tetrahedron: return detail::as_span(detail::tetrahedron_facets);
    case Shape::hexahedron: return detail::as_span(detail::hexahedron_facets);
    case Shape::prism: return detail::as_span(detail::prism_facets);
    case Shape::pyramid: return detail::as_span(detail::pyramid_facets);
  }
  return {};
}
[[nodiscard]] constexpr std::span<const LocalFacet> facets(ElementType t) { return facets(shape(t)); }

/// The element type of a given shape and order; `complete` picks quad9/hex27/prism18/pyramid14
/// over the serendipity quad8/hex20/prism15/pyramid13.
[[nodiscard]] constexpr ElementType element_type(Shape s, int element_order, bool complete = true) {
  const bool p2 = element_order == 2;
  switch (s) {
    case Shape::point: return ElementType::point1;
    case Shape::line: return p2 ? ElementType::line3 : ElementType::line2;
    case Shape::triangle: return p2 ? ElementType::tri6 : ElementType::tri3;
    case Shape::quadrilateral: return p2 ? (complete ? ElementType::quad9 : ElementType::quad8) : ElementType::quad4;
    case Shape::tetrahedron: return p2 ? ElementType::tet10 : ElementType::tet4;
    case Shape::hexahedron: return p2 ? (complete ? ElementType::hex27 : ElementType::hex20) : ElementType::hex8;
    case Shape::prism: return p2 ? (complete ? ElementType::prism18 : ElementType::prism15) : ElementType::prism6;
    case Shape::pyramid: return p2 ? (complete ? ElementType::pyramid14 : ElementType::pyramid13) : ElementType::pyramid5;
  }
  return ElementType::point1;
}

/// The linear element of the same shape.
[[nodiscard]] constexpr ElementType linear_type(ElementType t) { return element_type(shape(t), 1); }

/// The quadratic element of the same shape; `complete` as in element_type().
[[nodiscard]] constexpr ElementType quadratic_type(ElementType t, bool complete = true) {
  return element_type(shape(t), 2, complete);
}

/// Whether a quadratic element of this type carries a node at the centre of quadrilateral
/// facet f (quad9 as a 2D element has its one "face" node at index 8).
[[nodiscard]] constexpr bool has_face_nodes(ElementType t) {
  return t == ElementType::quad9 || t == ElementType::hex27 || t == ElementType::prism18 ||
         t == ElementType::pyramid14;
}

/// The facet element type of local facet f of an element of type t (same order, and complete
/// quadrilateral facets for complete elements).
[[nodiscard]] constexpr ElementType facet_type(ElementType t, int f) {
  return element_type(facets(t)[static_cast<std::size_t>(f)].shape, order(t), element_info(t).complete);
}

/// Local index of the edge joining vertices a and b, or -1.
[[nodiscard]] constexpr int local_edge(ElementType t, int a, int b) {
  const auto e = edges(t);
  for (std::size_t k = 0; k < e.size(); ++k)
    if ((e[k][0] == a && e[k][1] == b) || (e[k][0] == b && e[k][1] == a)) return static_cast<int>(k);
  return -1;
}

/// All local nodes (vertices, then edge nodes, then the centre node where the facet type has
/// one) of local facet f of an element of type t, in the facet type's own Gmsh order.
/// Returns the number of nodes written to `out`.
constexpr int facet_nodes(ElementType t, int f, std::array<int, 9>& out) {
  const LocalFacet& facet = facets(t)[static_cast<std::size_t>(f)];
  int n = 0;
  for (int k = 0; k < facet.num_vertices; ++k) out[static_cast<std::size_t>(n++)] = facet.vertices[static_cast<std::size_t>(k)];
  if (order(t) < 2) return n;
  if (facet.shape == Shape::point) return n;
  const int nv = num_vertices(t);
  const int num_facet_edges = facet.shape == Shape::line ? 1 : facet.num_vertices;
  for (int k = 0; k < num_facet_edges; ++k) {
    const int a = facet.vertices[static_cast<std::size_t>(k)];
    const int b = facet.vertices[static_cast<std::size_t>((k + 1) % facet.num_vertices)];
    out[static_cast<std::size_t>(n++)] = nv + local_edge(t, a, b);
  }
  if (facet.shape == Shape::quadrilateral && has_face_nodes(t)) {
    int quad_index = 0;
    for (int g = 0; g < f; ++g)
      if (facets(t)[static_cast<std::size_t>(g)].shape == Shape::quadrilateral) ++quad_index;
    out[static_cast<std::size_t>(n++)] = nv + static_cast<int>(edges(t).size()) + quad_index;
  }
  return n;
}

/// VTK node order: VTK's node i is our local node vtk_order(t)[i]. Empty span means identity.
/// `lagrange` selects the order of the VTK Lagrange cell where it differs from the classic one.
[[nodiscard]] constexpr std::span<const int> vtk_order(ElementType t, bool lagrange = false) {
  switch (t) {
    case ElementType::tet10: return detail::as_span(detail::tet10_vtk);
    case ElementType::hex20: return detail::as_span(detail::hex20_vtk);
    case ElementType::hex27: return lagrange ? detail::as_span(detail::hex27_vtk_lagrange) : detail::as_span(detail::hex27_vtk);
    case ElementType::prism6: return detail::as_span(detail::prism6_vtk);
    case ElementType::prism15: return detail::as_span(detail::prism15_vtk);
    case ElementType::prism18: return lagrange ? detail::as_span(detail::prism18_vtk_lagrange) : detail::as_span(detail::prism18_vtk);
    case ElementType::pyramid13:
    case ElementType::pyramid14: return detail::as_span(detail::pyramid13_vtk);
    default: return {};
  }
}

/// SU2 uses VTK type numbers and VTK's node order (vtk_order()) for its linear elements.
[[nodiscard]] constexpr int su2_id(ElementType t) { return element_info(t).order <= 1 ? element_info(t).vtk_id : -1; }

/// The type with the given Gmsh number; throws InputError for unknown numbers.
[[nodiscard]] inline ElementType element_type_from_gmsh(int gmsh_id) {
  for (const auto& e : detail::element_table)
    if (e.gmsh_id == gmsh_id) return e.type;
  throw InputError("element_type_from_gmsh: unsupported Gmsh element type " + std::to_string(gmsh_id) +
                   " (expected a point, linear or quadratic element: 1 to 19)");
}

/// The linear type with the given VTK/SU2 number; throws InputError for unknown numbers.
[[nodiscard]] inline ElementType element_type_from_vtk(int vtk_id) {
  for (const auto& e : detail::element_table)
    if (e.vtk_id == vtk_id && e.type != ElementType::pyramid14) return e.type;
  throw InputError("element_type_from_vtk: unsupported VTK cell type " + std::to_string(vtk_id));
}

/// The type named "tri6", "hex27", ...; throws InputError for unknown names.
[[nodiscard]] inline ElementType element_type_from_name(std::string_view element_name) {
  for (const auto& e : detail::element_table)
    if (e.name == element_name) return e.type;
  throw InputError("element_type_from_name: unknown element type '" + std::string(element_name) + "'");
}

}  // namespace meshmotion
