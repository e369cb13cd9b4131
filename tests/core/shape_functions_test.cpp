#include "meshmotion/core/shape_functions.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <random>
#include <vector>

using namespace meshmotion;

namespace {

std::vector<ElementType> cell_like_types() {
  std::vector<ElementType> t;
  for (int i = 1; i < num_element_types; ++i) t.push_back(static_cast<ElementType>(i));
  return t;
}

// A random point strictly inside the reference element of t.
RefPoint random_inside(ElementType t, std::mt19937& rng) {
  std::uniform_real_distribution<double> u01(0.05, 0.95), u11(-0.9, 0.9);
  switch (shape(t)) {
    case Shape::line: return {u11(rng), 0, 0};
    case Shape::quadrilateral: return {u11(rng), u11(rng), 0};
    case Shape::hexahedron: return {u11(rng), u11(rng), u11(rng)};
    case Shape::triangle: {
      const double a = u01(rng), b = u01(rng) * (1 - a);
      return {a, b, 0};
    }
    case Shape::tetrahedron: {
      const double a = u01(rng) * 0.9, b = u01(rng) * (1 - a), c = u01(rng) * (1 - a - b);
      return {a, b, c};
    }
    case Shape::prism: {
      const double a = u01(rng), b = u01(rng) * (1 - a);
      return {a, b, u11(rng)};
    }
    case Shape::pyramid: {
      const double w = u01(rng) * 0.9;
      return {u11(rng) * (1 - w), u11(rng) * (1 - w), w};
    }
    case Shape::point: break;
  }
  return {0, 0, 0};
}

std::vector<double> values_at(ElementType t, const RefPoint& x) {
  std::vector<double> n(static_cast<std::size_t>(num_nodes(t)));
  shape_functions(t, x, n);
  return n;
}

}  // namespace

TEST_CASE("shape functions interpolate at the reference nodes", "[core]") {
  for (ElementType t : cell_like_types()) {
    INFO(name(t));
    const auto nodes = reference_nodes(t);
    REQUIRE(static_cast<int>(nodes.size()) == num_nodes(t));
    for (std::size_t j = 0; j < nodes.size(); ++j) {
      const auto n = values_at(t, nodes[j]);
      for (std::size_t i = 0; i < n.size(); ++i) CHECK(n[i] == Approx(i == j ? 1.0 : 0.0).margin(1e-12));
    }
  }
}

TEST_CASE("reference nodes follow Gmsh's layout", "[core]") {
  // Edge nodes evenly along each edge from its first vertex, the hex27 volume node at the
  // centre, pyramid apex on top. (python/tests/test_element_catalogue.py compares every
  // type's nodes with Gmsh's own.)
  for (ElementType t : cell_like_types()) {
    const int p = order(t);
    if (p < 2) continue;
    INFO(name(t));
    const auto x = reference_nodes(t);
    const auto e = edges(t);
    for (std::size_t k = 0; k < e.size(); ++k)
      for (int j = 1; j < p; ++j)
        for (std::size_t d = 0; d < 3; ++d) {
          const double r = static_cast<double>(j) / p;
          CHECK(x[static_cast<std::size_t>(num_vertices(t) + static_cast<int>(k) * (p - 1) + j - 1)][d] ==
                Approx((1 - r) * x[static_cast<std::size_t>(e[k][0])][d] + r * x[static_cast<std::size_t>(e[k][1])][d]));
        }
  }
  CHECK(reference_nodes(ElementType::hex27)[26] == RefPoint{0, 0, 0});
  CHECK(reference_nodes(ElementType::hex27)[20] == RefPoint{0, 0, -1});  // face (0,3,2,1)
  CHECK(reference_nodes(ElementType::prism18)[15] == RefPoint{0.5, 0, 0});
  CHECK(reference_nodes(ElementType::pyramid5)[4] == RefPoint{0, 0, 1});
  CHECK(reference_nodes(ElementType::pyramid14)[13] == RefPoint{0, 0, 0});
  CHECK(reference_nodes(ElementType::line3)[2] == RefPoint{0, 0, 0});
}

TEST_CASE("facet nodes at every order are the facet element's nodes, in its own order", "[core]") {
  // Local facet f's nodes, mapped back through the facet's vertices, must be the reference
  // nodes of facet_type(t, f): the rotation of the face's inside nodes included (a tet35's
  // last face starts at vertex 3 in Gmsh's numbering and at vertex 1 in facets()).
  std::array<int, max_facet_nodes> nodes{};
  for (ElementType t : cell_like_types()) {
    if (dimension(t) < 2) continue;
    const auto x = reference_nodes(t);
    for (int f = 0; f < static_cast<int>(facets(t).size()); ++f) {
      INFO(name(t) << " facet " << f);
      const ElementType ft = facet_type(t, f);
      const int n = facet_nodes(t, f, nodes);
      REQUIRE(n == num_nodes(ft));
      const auto fx = reference_nodes(ft);
      std::vector<double> w(static_cast<std::size_t>(num_vertices(ft)));
      for (int k = 0; k < n; ++k) {
        shape_functions(linear_type(ft), fx[static_cast<std::size_t>(k)], w);
        RefPoint expected{0, 0, 0};
        for (int v = 0; v < num_vertices(ft); ++v)
          for (std::size_t d = 0; d < 3; ++d)
            expected[d] += w[static_cast<std::size_t>(v)] * x[static_cast<std::size_t>(facets(t)[static_cast<std::size_t>(f)].vertices[static_cast<std::size_t>(v)])][d];
        for (std::size_t d = 0; d < 3; ++d) CHECK(x[static_cast<std::size_t>(nodes[static_cast<std::size_t>(k)])][d] == Approx(expected[d]).margin(1e-12));
      }
    }
  }
}

TEST_CASE("shape functions: partition of unity, derivatives, polynomial reproduction", "[core]") {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> coef(-1, 1);
  for (ElementType t : cell_like_types()) {
    INFO(name(t));
    const auto nodes = reference_nodes(t);
    const int n = num_nodes(t);
    // Random linear and quadratic functions of (u,v,w).
    const std::array<double, 4> lin{coef(rng), coef(rng), coef(rng), coef(rng)};
    const std::array<double, 6> quad{coef(rng), coef(rng), coef(rng), coef(rng), coef(rng), coef(rng)};
    const auto f_lin = [&](const RefPoint& x) { return lin[0] + lin[1] * x[0] + lin[2] * x[1] + lin[3] * x[2]; };
    const auto f_quad = [&](const RefPoint& x) {
      return f_lin(x) + quad[0] * x[0] * x[0] + quad[1] * x[0] * x[1] + quad[2] * x[1] * x[1] +
             quad[3] * x[0] * x[2] + quad[4] * x[1] * x[2] + quad[5] * x[2] * x[2];
    };
    // Pyramid spaces reproduce linear functions; complete P2 types also reproduce quadratics,
    // and every complete type of the other shapes a polynomial of its own degree (at P8 a test
    // of the basis's digits: the monomial one lost 1e-11 on a tri45, 1e-9 on a hex729).
    const bool reproduces_quadratics = order(t) == 2 && element_info(t).complete && shape(t) != Shape::pyramid;
    const bool reproduces_own_degree = element_info(t).complete && shape(t) != Shape::pyramid;
    const auto f_own = [&](const RefPoint& x) {
      return std::pow(0.3 + 0.5 * x[0] - 0.4 * x[1] + 0.2 * x[2], order(t)) + lin[1] * x[0];
    };
    for (int trial = 0; trial < 10; ++trial) {
      const RefPoint x = random_inside(t, rng);
      const auto v = values_at(t, x);
      double sum = 0, interp_lin = 0, interp_quad = 0, interp_own = 0;
      for (int i = 0; i < n; ++i) {
        const auto ii = static_cast<std::size_t>(i);
        sum += v[ii];
        interp_lin += v[ii] * f_lin(nodes[ii]);
        interp_quad += v[ii] * f_quad(nodes[ii]);
        interp_own += v[ii] * f_own(nodes[ii]);
      }
      CHECK(sum == Approx(1.0).margin(1e-12));
      CHECK(interp_lin == Approx(f_lin(x)).margin(1e-12));
      if (reproduces_quadratics) CHECK(interp_quad == Approx(f_quad(x)).margin(1e-12));
      if (reproduces_own_degree) CHECK(interp_own == Approx(f_own(x)).margin(1e-12));

      std::vector<std::array<double, 3>> g(static_cast<std::size_t>(n));
      shape_derivatives(t, x, g);
      const double h = 1e-6;
      for (int d = 0; d < dimension(t); ++d) {
        RefPoint xp = x, xm = x;
        xp[static_cast<std::size_t>(d)] += h;
        xm[static_cast<std::size_t>(d)] -= h;
        const auto vp = values_at(t, xp), vm = values_at(t, xm);
        for (int i = 0; i < n; ++i) {
          const auto ii = static_cast<std::size_t>(i);
          CHECK(g[ii][static_cast<std::size_t>(d)] == Approx((vp[ii] - vm[ii]) / (2 * h)).margin(1e-6));
        }
      }
    }
  }
}

TEST_CASE("jacobian of an affine map is its matrix", "[core]") {
  Eigen::Matrix3d a;
  a << 2, 0.3, -0.1, 0.2, 1.5, 0.4, -0.3, 0.1, 0.8;
  const Eigen::Vector3d b(1, -2, 0.5);
  for (ElementType t : {ElementType::tet10, ElementType::hex27, ElementType::prism15, ElementType::pyramid13}) {
    INFO(name(t));
    const auto x = reference_nodes(t);
    Eigen::Matrix<double, 3, Eigen::Dynamic> coords(3, num_nodes(t));
    for (int i = 0; i < num_nodes(t); ++i)
      coords.col(i) = a * Eigen::Vector3d(x[static_cast<std::size_t>(i)][0], x[static_cast<std::size_t>(i)][1],
                                          x[static_cast<std::size_t>(i)][2]) + b;
    const RefPoint xi = reference_centroid(t);
    CHECK((jacobian(t, coords, xi) - a).norm() < 1e-12);
    CHECK(jacobian_determinant(t, coords, xi) == Approx(a.determinant()));
    const Eigen::Vector3d p = map_to_physical(t, coords, xi);
    CHECK((p - (a * Eigen::Vector3d(xi[0], xi[1], xi[2]) + b)).norm() < 1e-12);
  }
  // A surface triangle in 3D: the measure is twice its area.
  Eigen::Matrix<double, 3, 3> tri;
  tri << 0, 2, 0, 0, 0, 3, 1, 1, 1;
  CHECK(jacobian_determinant(ElementType::tri3, tri, RefPoint{0.2, 0.2, 0}) == Approx(6.0));
}
