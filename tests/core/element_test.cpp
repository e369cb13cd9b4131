#include "meshmotion/core/element.hpp"
#include "meshmotion/core/shape_functions.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <set>

using namespace meshmotion;

namespace {
std::vector<ElementType> all_types() {
  std::vector<ElementType> t;
  for (int i = 0; i < num_element_types; ++i) t.push_back(static_cast<ElementType>(i));
  return t;
}
}  // namespace

TEST_CASE("element catalogue is consistent", "[core]") {
  for (ElementType t : all_types()) {
    INFO(name(t));
    const auto& info = element_info(t);
    CHECK(info.type == t);
    CHECK(element_type_from_gmsh(info.gmsh_id) == t);
    CHECK(element_type_from_name(info.name) == t);
    const int ne = static_cast<int>(edges(t).size());
    if (order(t) >= 2) {
      // Vertices + order - 1 nodes per edge (+ face and volume nodes for complete types).
      CHECK(num_nodes(t) >= num_vertices(t) + ne * (order(t) - 1));
      CHECK(linear_type(t) == element_type(shape(t), 1));
      CHECK(element_type(shape(t), order(t), info.complete) == t);
      CHECK(num_nodes(t) <= max_element_nodes);
    }
    if (const auto perm = vtk_order(t); !perm.empty()) {
      // A permutation of the nodes that VTK writes.
      std::set<int> seen(perm.begin(), perm.end());
      CHECK(static_cast<int>(seen.size()) == static_cast<int>(perm.size()));
      CHECK(*seen.rbegin() < num_nodes(t));
    }
  }
}

TEST_CASE("every edge lies on exactly two facets of a 3D shape, one of a 2D shape's", "[core]") {
  for (ElementType t : {ElementType::tri3, ElementType::quad4, ElementType::tet4, ElementType::hex8,
                        ElementType::prism6, ElementType::pyramid5}) {
    INFO(name(t));
    for (const auto& e : edges(t)) {
      int count = 0;
      for (const auto& f : facets(t))
        for (int k = 0; k < (f.shape == Shape::line ? 1 : f.num_vertices); ++k) {
          const int a = f.vertices[static_cast<std::size_t>(k)];
          const int b = f.vertices[static_cast<std::size_t>((k + 1) % f.num_vertices)];
          if ((a == e[0] && b == e[1]) || (a == e[1] && b == e[0])) ++count;
        }
      CHECK(count == (dimension(t) == 3 ? 2 : 1));
    }
  }
}

TEST_CASE("facet nodes of quadratic elements follow Gmsh's face node numbering", "[core]") {
  std::array<int, max_facet_nodes> nodes{};
  // hex27 face k carries node 20 + k; its edge nodes are the element's.
  for (int f = 0; f < 6; ++f) {
    REQUIRE(facet_nodes(ElementType::hex27, f, nodes) == 9);
    CHECK(nodes[8] == 20 + f);
  }
  REQUIRE(facet_nodes(ElementType::tet10, 0, nodes) == 6);  // facet (0,2,1)
  CHECK(std::vector<int>(nodes.begin(), nodes.begin() + 6) == std::vector<int>{0, 2, 1, 6, 5, 4});
  CHECK(facet_type(ElementType::prism18, 2) == ElementType::quad9);
  CHECK(facet_type(ElementType::prism15, 2) == ElementType::quad8);
  CHECK(facet_type(ElementType::prism18, 0) == ElementType::tri6);
  REQUIRE(facet_nodes(ElementType::pyramid14, 0, nodes) == 9);
  CHECK(nodes[8] == 13);
  REQUIRE(facet_nodes(ElementType::tri6, 2, nodes) == 3);
  CHECK(std::vector<int>(nodes.begin(), nodes.begin() + 3) == std::vector<int>{2, 0, 5});
}

TEST_CASE("orders the catalogue does not hold are refused by name", "[core]") {
  CHECK(element_type(Shape::tetrahedron, 4) == ElementType::tet35);
  CHECK(element_type(Shape::pyramid, 3) == ElementType::pyramid30);
  CHECK(element_type(Shape::triangle, 8) == ElementType::tri45);
  CHECK(element_type(Shape::quadrilateral, 8) == ElementType::quad81);
  CHECK(element_type(Shape::tetrahedron, 6) == ElementType::tet84);
  CHECK(element_type(Shape::tetrahedron, 7) == ElementType::tet120);
  CHECK(element_type(Shape::tetrahedron, 8) == ElementType::tet165);
  CHECK(element_type_from_gmsh(72) == ElementType::tet120);
  CHECK(element_type_from_gmsh(73) == ElementType::tet165);
  CHECK_THROWS_WITH(element_type(Shape::triangle, 9), Catch::Contains("no triangle of order 9"));
  CHECK_THROWS_WITH(element_type(Shape::tetrahedron, 9), Catch::Contains("no tetrahedron of order 9 (orders 1 to 8"));
  CHECK_THROWS_WITH(element_type(Shape::quadrilateral, 3, false), Catch::Contains("serendipity"));
  CHECK(element_type(Shape::hexahedron, 8) == ElementType::hex729);
  CHECK(element_type(Shape::prism, 4) == ElementType::prism75);
  CHECK(element_type(Shape::prism, 8) == ElementType::prism405);
  CHECK(element_type(Shape::pyramid, 5) == ElementType::pyramid91);
  CHECK(element_type(Shape::pyramid, 8) == ElementType::pyramid285);
  CHECK(element_type_from_gmsh(91) == ElementType::prism75);
  CHECK(element_type_from_gmsh(109) == ElementType::prism405);
  CHECK(element_type_from_gmsh(119) == ElementType::pyramid55);
  CHECK(element_type_from_gmsh(123) == ElementType::pyramid285);
  CHECK_THROWS_WITH(element_type(Shape::prism, 9), Catch::Contains("no prism of order 9 (orders 1 to 8"));
  CHECK_THROWS_WITH(element_type_from_gmsh(110), Catch::Contains("110"));  // prism550, order 9
}

TEST_CASE("unknown type numbers and names are errors", "[core]") {
  CHECK_THROWS_AS(element_type_from_gmsh(45), InputError);  // tri55, order 9
  CHECK_THROWS_WITH(element_type_from_gmsh(74), Catch::Contains("prism or pyramid of order 1 to 8"));  // tet220
  CHECK_THROWS_AS(element_type_from_vtk(99), InputError);
  CHECK_THROWS_WITH(element_type_from_name("tri7"), Catch::Contains("tri7"));
}
