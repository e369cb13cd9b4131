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
  // Order 3 and 4 (complete Lagrange elements): appended so that the numbers above stay.
  line4, tri10, quad16, tet20, hex64, prism40, pyramid30,
  line5, tri15, quad25, tet35,
  // Orders 5 to 8 (lines, triangles and quadrilaterals; tetrahedra to 6), then hexahedra of
  // orders 4 to 8, then tetrahedra of orders 7 and 8 (appended when the certificate could hold them).
  line6, tri21, quad36, tet56,
  line7, tri28, quad49, tet84,
  line8, tri36, quad64,
  line9, tri45, quad81,
  hex125, hex216, hex343, hex512, hex729,
  tet120, tet165,
  // Prisms and pyramids of orders 4 to 8 (appended when the catalogue's lattice reproduced Gmsh's).
  prism75, prism126, prism196, prism288, prism405,
  pyramid55, pyramid91, pyramid140, pyramid204, pyramid285,
};

inline constexpr int num_element_types = 61;

/// Most nodes of any element type (hex729).
inline constexpr int max_element_nodes = 729;

/// Most nodes of any element facet (the quad81 face of a hex729).
inline constexpr int max_facet_nodes = 81;

/// Highest element order of the catalogue; max_order() gives it per shape.
inline constexpr int max_element_order = 8;

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
  int order;                ///< 1 to max_element_order (0 for a point)
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
    // VTK has no classic cells past order 2, only Lagrange cells (pyramids: none in VTK 9.1).
    {ElementType::line4, "line4", Shape::line, 1, 3, 4, 2, true, 26, -1, 68},
    {ElementType::tri10, "tri10", Shape::triangle, 2, 3, 10, 3, true, 21, -1, 69},
    {ElementType::quad16, "quad16", Shape::quadrilateral, 2, 3, 16, 4, true, 36, -1, 70},
    {ElementType::tet20, "tet20", Shape::tetrahedron, 3, 3, 20, 4, true, 29, -1, 71},
    {ElementType::hex64, "hex64", Shape::hexahedron, 3, 3, 64, 8, true, 92, -1, 72},
    {ElementType::prism40, "prism40", Shape::prism, 3, 3, 40, 6, true, 90, -1, 73},
    {ElementType::pyramid30, "pyramid30", Shape::pyramid, 3, 3, 30, 5, true, 118, -1, -1},
    {ElementType::line5, "line5", Shape::line, 1, 4, 5, 2, true, 27, -1, 68},
    {ElementType::tri15, "tri15", Shape::triangle, 2, 4, 15, 3, true, 23, -1, 69},
    {ElementType::quad25, "quad25", Shape::quadrilateral, 2, 4, 25, 4, true, 37, -1, 70},
    {ElementType::tet35, "tet35", Shape::tetrahedron, 3, 4, 35, 4, true, 30, -1, 71},
    {ElementType::line6, "line6", Shape::line, 1, 5, 6, 2, true, 28, -1, 68},
    {ElementType::tri21, "tri21", Shape::triangle, 2, 5, 21, 3, true, 25, -1, 69},
    {ElementType::quad36, "quad36", Shape::quadrilateral, 2, 5, 36, 4, true, 38, -1, 70},
    {ElementType::tet56, "tet56", Shape::tetrahedron, 3, 5, 56, 4, true, 31, -1, 71},
    {ElementType::line7, "line7", Shape::line, 1, 6, 7, 2, true, 62, -1, 68},
    {ElementType::tri28, "tri28", Shape::triangle, 2, 6, 28, 3, true, 42, -1, 69},
    {ElementType::quad49, "quad49", Shape::quadrilateral, 2, 6, 49, 4, true, 47, -1, 70},
    {ElementType::tet84, "tet84", Shape::tetrahedron, 3, 6, 84, 4, true, 71, -1, 71},
    {ElementType::line8, "line8", Shape::line, 1, 7, 8, 2, true, 63, -1, 68},
    {ElementType::tri36, "tri36", Shape::triangle, 2, 7, 36, 3, true, 43, -1, 69},
    {ElementType::quad64, "quad64", Shape::quadrilateral, 2, 7, 64, 4, true, 48, -1, 70},
    {ElementType::line9, "line9", Shape::line, 1, 8, 9, 2, true, 64, -1, 68},
    {ElementType::tri45, "tri45", Shape::triangle, 2, 8, 45, 3, true, 44, -1, 69},
    {ElementType::quad81, "quad81", Shape::quadrilateral, 2, 8, 81, 4, true, 49, -1, 70},
    {ElementType::hex125, "hex125", Shape::hexahedron, 3, 4, 125, 8, true, 93, -1, 72},
    {ElementType::hex216, "hex216", Shape::hexahedron, 3, 5, 216, 8, true, 94, -1, 72},
    {ElementType::hex343, "hex343", Shape::hexahedron, 3, 6, 343, 8, true, 95, -1, 72},
    {ElementType::hex512, "hex512", Shape::hexahedron, 3, 7, 512, 8, true, 96, -1, 72},
    {ElementType::hex729, "hex729", Shape::hexahedron, 3, 8, 729, 8, true, 97, -1, 72},
    {ElementType::tet120, "tet120", Shape::tetrahedron, 3, 7, 120, 4, true, 72, -1, 71},
    {ElementType::tet165, "tet165", Shape::tetrahedron, 3, 8, 165, 4, true, 73, -1, 71},
    {ElementType::prism75, "prism75", Shape::prism, 3, 4, 75, 6, true, 91, -1, 73},
    {ElementType::prism126, "prism126", Shape::prism, 3, 5, 126, 6, true, 106, -1, 73},
    {ElementType::prism196, "prism196", Shape::prism, 3, 6, 196, 6, true, 107, -1, 73},
    {ElementType::prism288, "prism288", Shape::prism, 3, 7, 288, 6, true, 108, -1, 73},
    {ElementType::prism405, "prism405", Shape::prism, 3, 8, 405, 6, true, 109, -1, 73},
    {ElementType::pyramid55, "pyramid55", Shape::pyramid, 3, 4, 55, 5, true, 119, -1, -1},
    {ElementType::pyramid91, "pyramid91", Shape::pyramid, 3, 5, 91, 5, true, 120, -1, -1},
    {ElementType::pyramid140, "pyramid140", Shape::pyramid, 3, 6, 140, 5, true, 121, -1, -1},
    {ElementType::pyramid204, "pyramid204", Shape::pyramid, 3, 7, 204, 5, true, 122, -1, -1},
    {ElementType::pyramid285, "pyramid285", Shape::pyramid, 3, 8, 285, 5, true, 123, -1, -1},
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

// Gmsh's order of the faces whose inside nodes a 3D element lists (see face_order()).
inline constexpr std::array<LocalFacet, 4> tetrahedron_face_order{{
    {Shape::triangle, 3, {0, 2, 1, 0}}, {Shape::triangle, 3, {0, 1, 3, 0}},
    {Shape::triangle, 3, {0, 3, 2, 0}}, {Shape::triangle, 3, {3, 1, 2, 0}}}};
inline constexpr std::array<LocalFacet, 5> pyramid_face_order{{
    {Shape::triangle, 3, {0, 1, 4, 0}}, {Shape::triangle, 3, {3, 0, 4, 0}},
    {Shape::triangle, 3, {1, 2, 4, 0}}, {Shape::triangle, 3, {2, 3, 4, 0}},
    {Shape::quadrilateral, 4, {0, 3, 2, 1}}}};

// VTK node i is our node vtk_order[i] (classic VTK quadratic cells).
inline constexpr std::array<int, 10> tet10_vtk{0, 1, 2, 3, 4, 5, 6, 7, 9, 8};
inline constexpr std::array<int, 20> hex20_vtk{0, 1, 2, 3, 4, 5, 6, 7, 8, 11, 13, 9, 16, 18, 19, 17, 10, 12, 14, 15};
inline constexpr std::array<int, 27> hex27_vtk{0,  1,  2,  3,  4,  5,  6,  7,  8,  11, 13, 9,  16, 18,
                                               19, 17, 10, 12, 14, 15, 22, 23, 21, 24, 20, 25, 26};
// VTK's classic wedges (linear, quadratic, biquadratic) turn their base (0,1,2) the other way:
// by the right-hand rule its normal points away from (3,4,5), Gmsh's towards it. VTK vertex i
// is our vertex {0,2,1,3,5,4}[i]; its edges (0,1) (1,2) (2,0) (3,4) (4,5) (5,3) (0,3) (1,4)
// (2,5) and quadrilateral faces (0,1,4,3) (1,2,5,4) (2,0,3,5) are ours through that
// relabelling. VTK's Lagrange wedge turns its base as Gmsh does (checked against VTK's signed
// cell sizes in python/tests/test_vtk_orientation.py).
inline constexpr std::array<int, 6> prism6_vtk{0, 2, 1, 3, 5, 4};
inline constexpr std::array<int, 15> prism15_vtk{0, 2, 1, 3, 5, 4, 7, 9, 6, 13, 14, 12, 8, 11, 10};
inline constexpr std::array<int, 18> prism18_vtk{0, 2, 1, 3, 5, 4, 7, 9, 6, 13, 14, 12, 8, 11, 10, 16, 17, 15};
// VTK's Lagrange tetrahedra past order 2, tabulated from VTK 9.1's own parametric coordinates
// (python/tests/test_element_catalogue.py checks them against VTK). Lines and triangles list
// their nodes as Gmsh does; quadrilaterals, hexahedra and Lagrange wedges follow a rule
// (vtk_order() in core/shape_functions.hpp).
inline constexpr std::array<int, 20> tet20_vtk{0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 11, 10, 15, 14, 13, 12, 17, 19, 18, 16};
inline constexpr std::array<int, 35> tet35_vtk{0,  1,  2,  3,  4,  5,  6,  7,  8,  9,  10, 11, 12, 15, 14, 13, 21, 20,
                                               19, 18, 17, 16, 25, 26, 27, 33, 31, 32, 28, 29, 30, 22, 23, 24, 34};
inline constexpr std::array<int, 56> tet56_vtk{
    0,  1,  2,  3,  4,  5,  6,  7,  8,  9,  10, 11, 12, 13, 14, 15, 19, 18, 17, 16, 27, 26, 25, 24, 23, 22, 21, 20,
    34, 35, 36, 37, 38, 39, 48, 46, 47, 51, 49, 50, 40, 41, 42, 43, 44, 45, 28, 29, 30, 31, 32, 33, 52, 53, 54, 55};
inline constexpr std::array<int, 84> tet84_vtk{
    0,  1,  2,  3,  4,  5,  6,  7,  8,  9,  10, 11, 12, 13, 14, 15, 16, 17, 18, 23, 22, 21, 20, 19, 33, 32, 31, 30,
    29, 28, 27, 26, 25, 24, 44, 45, 46, 47, 48, 49, 50, 51, 52, 53, 66, 64, 65, 71, 72, 67, 68, 69, 70, 73, 54, 55,
    56, 57, 58, 59, 60, 61, 62, 63, 34, 35, 36, 37, 38, 39, 40, 41, 42, 43, 74, 75, 76, 77, 78, 79, 80, 81, 83, 82};
inline constexpr std::array<int, 120> tet120_vtk{
      0,   1,   2,   3,   4,   5,   6,   7,   8,   9,  10,  11,  12,  13,  14,  15,  16,  17,  18,  19,  20,  21,  27,
     26,  25,  24,  23,  22,  39,  38,  37,  36,  35,  34,  33,  32,  31,  30,  29,  28,  55,  56,  57,  58,  59,  60,
     61,  62,  63,  64,  65,  66,  67,  68,  69,  87,  85,  86,  94,  95,  96,  88,  89,  90,  91,  92,  93,  99,  97,
     98,  70,  71,  72,  73,  74,  75,  76,  77,  78,  79,  80,  81,  82,  83,  84,  40,  41,  42,  43,  44,  45,  46,
     47,  48,  49,  50,  51,  52,  53,  54, 100, 101, 102, 103, 104, 105, 106, 107, 108, 109, 111, 110, 115, 114, 113,
    112, 117, 119, 118, 116};
inline constexpr std::array<int, 165> tet165_vtk{
      0,   1,   2,   3,   4,   5,   6,   7,   8,   9,  10,  11,  12,  13,  14,  15,  16,  17,  18,  19,  20,  21,  22,
     23,  24,  31,  30,  29,  28,  27,  26,  25,  45,  44,  43,  42,  41,  40,  39,  38,  37,  36,  35,  34,  33,  32,
     67,  68,  69,  70,  71,  72,  73,  74,  75,  76,  77,  78,  79,  80,  81,  82,  83,  84,  85,  86,  87, 111, 109,
    110, 120, 121, 122, 123, 112, 113, 114, 115, 116, 117, 118, 119, 126, 124, 125, 129, 127, 128,  88,  89,  90,  91,
     92,  93,  94,  95,  96,  97,  98,  99, 100, 101, 102, 103, 104, 105, 106, 107, 108,  46,  47,  48,  49,  50,  51,
     52,  53,  54,  55,  56,  57,  58,  59,  60,  61,  62,  63,  64,  65,  66, 130, 131, 132, 133, 134, 135, 136, 137,
    138, 139, 140, 141, 142, 145, 144, 143, 151, 150, 149, 148, 147, 146, 155, 156, 157, 163, 161, 162, 158, 159, 160,
    152, 153, 154, 164};
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

/// "triangle", "hexahedron", ...
[[nodiscard]] constexpr std::string_view shape_name(Shape s) {
  switch (s) {
    case Shape::point: return "point";
    case Shape::line: return "line";
    case Shape::triangle: return "triangle";
    case Shape::quadrilateral: return "quadrilateral";
    case Shape::tetrahedron: return "tetrahedron";
    case Shape::hexahedron: return "hexahedron";
    case Shape::prism: return "prism";
    case Shape::pyramid: return "pyramid";
  }
  return "?";
}

/// Highest order of the catalogue's elements of a shape: 8 for every shape but the point.
[[nodiscard]] constexpr int max_order(Shape s) { return s == Shape::point ? 0 : max_element_order; }

/// The element type of a given shape and order; `complete` picks quad9/hex27/prism18/pyramid14
/// over the serendipity quad8/hex20/prism15/pyramid13. Orders past 2 are complete Lagrange
/// elements up to max_order(s); throws InputError for an order the catalogue does not hold.
[[nodiscard]] constexpr ElementType element_type(Shape s, int element_order, bool complete = true) {
  if (s == Shape::point) return ElementType::point1;
  if (element_order > 2 && !complete)
    throw InputError("element_type: serendipity elements stop at order 2 (asked for order " + std::to_string(element_order) + ")");
  // The table lists each serendipity type before its complete sibling, and shapes without
  // one (triangles, tetrahedra) answer both requests.
  for (const ElementInfo& e : detail::element_table)
    if (e.shape == s && e.order == element_order && (e.complete || !complete)) return e.type;
  throw InputError("element_type: no " + std::string(shape_name(s)) + " of order " + std::to_string(element_order) +
                   " (orders 1 to " + std::to_string(max_order(s)) + " for " + std::string(shape_name(s)) +
                   "s)");
}

/// The linear element of the same shape.
[[nodiscard]] constexpr ElementType linear_type(ElementType t) { return element_type(shape(t), 1); }

/// The quadratic element of the same shape; `complete` as in element_type().
[[nodiscard]] constexpr ElementType quadratic_type(ElementType t, bool complete = true) {
  return element_type(shape(t), 2, complete);
}

/// Whether a quadratic element of this type carries a node at the centre of quadrilateral
/// facet f (quad9 as a 2D element has its one "face" node at index 8). False past order 2:
/// there, face_nodes_per_face() counts the nodes inside each face.
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

// ---- Node layout of every order ----------------------------------------------------------
// Gmsh's: the vertices; order - 1 nodes per edge, from edges()[k][0] to edges()[k][1]; the
// nodes inside each face of a 3D element, face by face in Gmsh's face order (face_order()),
// each face's own nodes laid out as an element of the face's shape and order (order - 3
// for triangles, order - 2 for quadrilaterals) on the face's inner corners, starting at its
// first vertex; then the nodes inside the element, laid out the same way recursively.

/// The faces of a 3D shape in the order Gmsh lists their inside nodes, each as a vertex
/// cycle starting where its nodes start. The same faces as facets(), the same orientation;
/// tetrahedra start their last face at vertex 3 and pyramids list the base last.
[[nodiscard]] constexpr std::span<const LocalFacet> face_order(Shape s) {
  switch (s) {
    case Shape::tetrahedron: return detail::as_span(detail::tetrahedron_face_order);
    case Shape::pyramid: return detail::as_span(detail::pyramid_face_order);
    case Shape::hexahedron:
    case Shape::prism: return facets(s);
    default: return {};
  }
}

/// Nodes strictly inside one face of the given shape for an element of order p (complete types).
[[nodiscard]] constexpr int face_nodes_per_face(Shape face, int p) {
  if (face == Shape::triangle) return p < 3 ? 0 : (p - 1) * (p - 2) / 2;
  if (face == Shape::quadrilateral) return p < 2 ? 0 : (p - 1) * (p - 1);
  return 0;
}

/// Local index of the first node inside face g of face_order() (3D types; complete types only
/// have them).
[[nodiscard]] constexpr int first_face_node(ElementType t, int g) {
  int n = num_vertices(t) + static_cast<int>(edges(t).size()) * (order(t) - 1);
  if (!element_info(t).complete) return n;
  const auto faces = face_order(shape(t));
  for (int k = 0; k < g; ++k) n += face_nodes_per_face(faces[static_cast<std::size_t>(k)].shape, order(t));
  return n;
}

namespace detail {

// The inside nodes of a face, numbered from `first` in Gmsh's layout (an element of the face's
// shape and order q on its inner corners, recursively; q = 0 is one centre node), appended as
// seen from the face's vertex `shift`: corners and edges rotate by `shift`, edges keep their
// direction (a rotation keeps the cycle's sense), and every inner ring does the same.
constexpr void append_rotated_face(Shape face, int q, int shift, int first, std::array<int, max_facet_nodes>& out, int& n) {
  if (q < 0) return;
  if (q == 0) {
    out[static_cast<std::size_t>(n++)] = first;
    return;
  }
  const int nv = face == Shape::triangle ? 3 : 4;
  for (int k = 0; k < nv; ++k) out[static_cast<std::size_t>(n++)] = first + (k + shift) % nv;
  for (int k = 0; k < nv; ++k)
    for (int j = 0; j < q - 1; ++j) out[static_cast<std::size_t>(n++)] = first + nv + ((k + shift) % nv) * (q - 1) + j;
  append_rotated_face(face, q - (face == Shape::triangle ? 3 : 2), shift, first + nv * q, out, n);
}

}  // namespace detail

/// All local nodes of local facet f of an element of type t, in the facet type's own order
/// (vertices from facets(t)[f].vertices[0], edges, inside nodes). Returns the number written.
constexpr int facet_nodes(ElementType t, int f, std::array<int, max_facet_nodes>& out) {
  const LocalFacet& facet = facets(t)[static_cast<std::size_t>(f)];
  int n = 0;
  for (int k = 0; k < facet.num_vertices; ++k) out[static_cast<std::size_t>(n++)] = facet.vertices[static_cast<std::size_t>(k)];
  const int p = order(t);
  if (p < 2 || facet.shape == Shape::point) return n;
  const int nv = num_vertices(t);
  const int num_facet_edges = facet.shape == Shape::line ? 1 : facet.num_vertices;
  for (int k = 0; k < num_facet_edges; ++k) {
    const int a = facet.vertices[static_cast<std::size_t>(k)];
    const int b = facet.vertices[static_cast<std::size_t>((k + 1) % facet.num_vertices)];
    const int e = local_edge(t, a, b);
    const bool forward = edges(t)[static_cast<std::size_t>(e)][0] == a;
    for (int j = 0; j < p - 1; ++j) out[static_cast<std::size_t>(n++)] = nv + e * (p - 1) + (forward ? j : p - 2 - j);
  }
  if (facet.shape == Shape::line || !element_info(t).complete) return n;
  // The face's inside nodes, rotated from face_order()'s start to the facet's.
  const auto faces = face_order(shape(t));
  for (std::size_t g = 0; g < faces.size(); ++g) {
    const LocalFacet& face = faces[g];
    int shift = -1;
    for (int r = 0; r < face.num_vertices && shift < 0; ++r) {
      bool same = true;
      for (int k = 0; k < face.num_vertices; ++k)
        same = same && face.vertices[static_cast<std::size_t>((r + k) % face.num_vertices)] == facet.vertices[static_cast<std::size_t>(k)];
      if (same) shift = r;
    }
    if (shift < 0) continue;
    detail::append_rotated_face(face.shape, p - (face.shape == Shape::triangle ? 3 : 2), shift,
                                first_face_node(t, static_cast<int>(g)), out, n);
    return n;
  }
  return n;
}

namespace detail {

// The tabulated part of vtk_order() (core/shape_functions.hpp): every classic cell, and the
// Lagrange tetrahedra.
[[nodiscard]] constexpr std::span<const int> tabulated_vtk_order(ElementType t) {
  switch (t) {
    case ElementType::tet10: return detail::as_span(detail::tet10_vtk);
    case ElementType::hex20: return detail::as_span(detail::hex20_vtk);
    case ElementType::hex27: return detail::as_span(detail::hex27_vtk);
    case ElementType::prism6: return detail::as_span(detail::prism6_vtk);
    case ElementType::prism15: return detail::as_span(detail::prism15_vtk);
    case ElementType::prism18: return detail::as_span(detail::prism18_vtk);
    case ElementType::pyramid13:
    case ElementType::pyramid14: return detail::as_span(detail::pyramid13_vtk);
    case ElementType::tet20: return detail::as_span(detail::tet20_vtk);
    case ElementType::tet35: return detail::as_span(detail::tet35_vtk);
    case ElementType::tet56: return detail::as_span(detail::tet56_vtk);
    case ElementType::tet84: return detail::as_span(detail::tet84_vtk);
    case ElementType::tet120: return detail::as_span(detail::tet120_vtk);
    case ElementType::tet165: return detail::as_span(detail::tet165_vtk);
    default: return {};
  }
}

}  // namespace detail

/// SU2's element number: VTK's type number for linear elements (nodes in VTK's order), and
/// for the high-order elements of SU2's DG-FEM solver the linear element's number plus
/// 100 × (order - 1) (nodes on the lattice, su2_node_order() in core/shape_functions.hpp);
/// -1 for the serendipity types, which SU2 does not have.
[[nodiscard]] constexpr int su2_id(ElementType t) {
  const ElementInfo& info = element_info(t);
  if (info.order <= 1) return info.vtk_id;
  if (!info.complete) return -1;
  return element_info(linear_type(t)).vtk_id + 100 * (info.order - 1);
}

/// The type with the given Gmsh number; throws InputError for unknown numbers.
[[nodiscard]] inline ElementType element_type_from_gmsh(int gmsh_id) {
  for (const auto& e : detail::element_table)
    if (e.gmsh_id == gmsh_id) return e.type;
  throw InputError("element_type_from_gmsh: unsupported Gmsh element type " + std::to_string(gmsh_id) +
                   " (expected a point, or a line, triangle, quadrilateral, tetrahedron, hexahedron, prism or pyramid " +
                   "of order 1 to 8; the serendipity elements stop at order 2)");
}

/// The linear type with the given VTK/SU2 number; throws InputError for unknown numbers.
[[nodiscard]] inline ElementType element_type_from_vtk(int vtk_id) {
  for (const auto& e : detail::element_table)
    if (e.vtk_id == vtk_id && e.type != ElementType::pyramid14) return e.type;
  throw InputError("element_type_from_vtk: unsupported VTK cell type " + std::to_string(vtk_id));
}

/// The type with the given SU2 number (su2_id(); a leading solution degree, 10000 × (degree + 1),
/// is ignored); throws InputError for unknown numbers.
[[nodiscard]] inline ElementType element_type_from_su2(int su2_number) {
  const int id = su2_number % 10000;
  ElementType lin{};
  try {
    lin = element_type_from_vtk(id % 100);
    if (order(lin) > 1 || su2_number < 0) throw InputError("");
  } catch (const InputError&) {
    throw InputError("unknown SU2 element type " + std::to_string(su2_number) +
                     " (expected 3 line, 5 tri, 9 quad, 10 tet, 12 hex, 13 prism or 14 pyramid, plus 100 per order past 1)");
  }
  return element_type(shape(lin), id / 100 + 1);
}

/// The type named "tri6", "hex27", ...; throws InputError for unknown names.
[[nodiscard]] inline ElementType element_type_from_name(std::string_view element_name) {
  for (const auto& e : detail::element_table)
    if (e.name == element_name) return e.type;
  throw InputError("element_type_from_name: unknown element type '" + std::string(element_name) + "'");
}

}  // namespace meshmotion
