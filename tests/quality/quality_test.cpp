#include "meshmotion/core/generators.hpp"
#include "meshmotion/core/shape_functions.hpp"
#include "meshmotion/curving/p2_conversion.hpp"
#include "meshmotion/io.hpp"
#include "meshmotion/quality.hpp"

#include "test_data.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <numbers>
#include <random>
#include <sstream>
#include <string>

using namespace meshmotion;

namespace {

const double sqrt3 = std::sqrt(3.0);

template <int D>
Eigen::Matrix<double, D, Eigen::Dynamic> columns(std::initializer_list<std::array<double, D>> pts) {
  Eigen::Matrix<double, D, Eigen::Dynamic> x(D, static_cast<Index>(pts.size()));
  Index i = 0;
  for (const auto& p : pts) {
    for (int d = 0; d < D; ++d) x(d, i) = p[static_cast<std::size_t>(d)];
    ++i;
  }
  return x;
}

// The nodes of `type` mapped by x -> a x + b from the reference element.
template <int D>
Eigen::Matrix<double, D, Eigen::Dynamic> affine_element(ElementType type, const Eigen::Matrix<double, D, D>& a,
                                                       const Eigen::Matrix<double, D, 1>& b) {
  const auto ref = reference_nodes(type);
  Eigen::Matrix<double, D, Eigen::Dynamic> x(D, num_nodes(type));
  for (int i = 0; i < num_nodes(type); ++i) {
    Eigen::Matrix<double, D, 1> r;
    for (int d = 0; d < D; ++d) r(d) = ref[static_cast<std::size_t>(i)][static_cast<std::size_t>(d)];
    x.col(i) = a * r + b;
  }
  return x;
}

template <int D>
double dense_min(ElementType type, const Eigen::Matrix<double, D, Eigen::Dynamic>& x, double linear_det, int n) {
  double m = std::numeric_limits<double>::infinity();
  const Shape s = shape(type);
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j)
      for (int k = 0; k <= (D == 3 ? n : 0); ++k) {
        const double a = static_cast<double>(i) / n, b = static_cast<double>(j) / n, c = static_cast<double>(k) / n;
        RefPoint p{};
        if (s == Shape::triangle || s == Shape::tetrahedron) {
          if (a + b + c > 1 + 1e-12) continue;
          p = {a, b, c};
        } else if (s == Shape::prism) {
          if (a + b > 1 + 1e-12) continue;
          p = {a, b, 2 * c - 1};
        } else {
          p = {2 * a - 1, 2 * b - 1, D == 3 ? 2 * c - 1 : 0.0};
        }
        m = std::min(m, jacobian_determinant(type, x, p) / linear_det);
      }
  return m;
}

}  // namespace

TEST_CASE("Knupp metrics: known values", "[quality]") {
  const auto equilateral = columns<2>({{0, 0}, {1, 0}, {0.5, sqrt3 / 2}});
  const auto q_eq = knupp_quality(ElementType::tri3, equilateral, sqrt3 / 4);
  CHECK(q_eq.valid);
  CHECK(q_eq.shape == Approx(1.0));
  CHECK(q_eq.relative_size == Approx(1.0));
  CHECK(q_eq.measure == Approx(sqrt3 / 4));

  const auto regular_tet = columns<3>({{0, 0, 0}, {1, 0, 0}, {0.5, sqrt3 / 2, 0}, {0.5, sqrt3 / 6, std::sqrt(2.0 / 3.0)}});
  CHECK(knupp_quality(ElementType::tet4, regular_tet, 1.0).shape == Approx(1.0));

  // Right isosceles triangle: eq. 2.19 with r = 1, θ = 90°: √3 / 2.
  const auto right = columns<2>({{0, 0}, {1, 0}, {0, 1}});
  CHECK(knupp_quality(ElementType::tri3, right, 1.0).shape == Approx(sqrt3 / 2));
  // Its relative size against twice its area is 1/2.
  CHECK(knupp_quality(ElementType::tri3, right, 1.0).relative_size == Approx(0.5));

  // 2:1 rectangle: right angles (skew 1) but unequal sides: 8 / (4 × 2.5) = 0.8.
  const auto rect = columns<2>({{0, 0}, {2, 0}, {2, 1}, {0, 1}});
  const auto q_rect = knupp_quality(ElementType::quad4, rect, 2.0);
  CHECK(q_rect.skew == Approx(1.0));
  CHECK(q_rect.shape == Approx(0.8));
  CHECK(q_rect.size_skew == Approx(1.0));
  CHECK(q_rect.size_shape == Approx(0.8));
  CHECK(knupp_quality(ElementType::hex8, affine_element<3>(ElementType::hex8, Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero()), 8.0).shape ==
        Approx(1.0));

  // Prism on an equilateral triangle with unit height, pyramid with equilateral sides.
  const auto prism = columns<3>({{0, 0, 0}, {1, 0, 0}, {0.5, sqrt3 / 2, 0}, {0, 0, 1}, {1, 0, 1}, {0.5, sqrt3 / 2, 1}});
  CHECK(knupp_quality(ElementType::prism6, prism, 1.0).shape == Approx(1.0));
  const auto pyramid = columns<3>({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0.5, 0.5, 1 / std::sqrt(2.0)}});
  CHECK(knupp_quality(ElementType::pyramid5, pyramid, 1.0).shape == Approx(1.0));
  const auto flat_pyramid = columns<3>({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0.5, 0.5, 0.1}});
  CHECK(knupp_quality(ElementType::pyramid5, flat_pyramid, 1.0).shape < 0.5);
}

TEST_CASE("Knupp metrics: degenerate and inverted elements are 0 and invalid", "[quality]") {
  const auto collapsed = columns<2>({{0, 0}, {1, 1}, {2, 2}});
  const auto q = knupp_quality(ElementType::tri3, collapsed, 1.0);
  CHECK_FALSE(q.valid);
  CHECK(q.shape == 0.0);
  CHECK(q.relative_size == 0.0);
  const auto repeated = columns<2>({{0, 0}, {1, 0}, {1, 0}, {0, 1}});
  CHECK_FALSE(knupp_quality(ElementType::quad4, repeated, 1.0).valid);
  const auto inverted = columns<2>({{0, 0}, {0, 1}, {1, 0}});  // clockwise
  const auto qi = knupp_quality(ElementType::tri3, inverted, 1.0);
  CHECK_FALSE(qi.valid);
  CHECK(qi.shape == 0.0);
  CHECK(qi.skew == 0.0);
  const auto bowtie = columns<2>({{0, 0}, {1, 0}, {0, 1}, {1, 1}});
  CHECK_FALSE(knupp_quality(ElementType::quad4, bowtie, 1.0).valid);
  const auto nan = columns<2>({{0, 0}, {1, 0}, {std::nan(""), 1}});
  const auto qn = knupp_quality(ElementType::tri3, nan, 1.0);
  CHECK_FALSE(qn.valid);
  CHECK(qn.shape == 0.0);
  CHECK(qn.measure == 0.0);
}

TEST_CASE("Knupp metrics: thesis eqs. 2.19-2.21 equal the matrix form", "[quality]") {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-0.3, 0.3);
  const auto angle = [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return std::atan2(a.x() * b.y() - a.y() * b.x(), a.dot(b));
  };
  for (int trial = 0; trial < 50; ++trial) {
    auto tri = columns<2>({{0, 0}, {1, 0}, {0.5, 0.9}});
    for (int i = 0; i < 3; ++i) tri.col(i) += Eigen::Vector2d(u(rng), u(rng));
    const Eigen::Vector2d e1 = tri.col(1) - tri.col(0), e2 = tri.col(2) - tri.col(0);
    const double r = e2.norm() / e1.norm(), th = angle(e1, e2);
    const double eq219 = sqrt3 * r * std::sin(th) / (1 - r * std::cos(th) + r * r);
    CHECK(knupp_quality(ElementType::tri3, tri, 1.0).shape == Approx(eq219).epsilon(1e-12));

    auto quad = columns<2>({{0, 0}, {1, 0}, {1, 1}, {0, 1}});
    for (int i = 0; i < 4; ++i) quad.col(i) += Eigen::Vector2d(u(rng), u(rng));
    double sum_shape = 0, sum_skew = 0;
    for (int k = 0; k < 4; ++k) {
      const Eigen::Vector2d a = quad.col((k + 1) % 4) - quad.col(k), b = quad.col((k + 3) % 4) - quad.col(k);
      const double rk = b.norm() / a.norm(), tk = angle(a, b);
      sum_shape += (1 + rk * rk) / (rk * std::sin(tk));
      sum_skew += 1 / std::sin(tk);
    }
    const auto q = knupp_quality(ElementType::quad4, quad, 1.0);
    CHECK(q.shape == Approx(8 / sum_shape).epsilon(1e-12));
    CHECK(q.skew == Approx(4 / sum_skew).epsilon(1e-12));
  }
}

TEST_CASE("Knupp metrics: invariant under translation, rotation and uniform scaling", "[quality]") {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-0.25, 0.25);
  Eigen::Matrix3d rot = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const double scale = 3.7;
  for (ElementType t : {ElementType::tet4, ElementType::hex8, ElementType::prism6, ElementType::pyramid5}) {
    INFO(name(t));
    Eigen::Matrix<double, 3, Eigen::Dynamic> x = affine_element<3>(t, Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero());
    for (Index i = 0; i < x.cols(); ++i) x.col(i) += Eigen::Vector3d(u(rng), u(rng), u(rng));
    const Eigen::Matrix<double, 3, Eigen::Dynamic> y = ((scale * rot) * x).colwise() + Eigen::Vector3d(5, -3, 2);
    const auto qx = knupp_quality(t, x, 1.0), qy = knupp_quality(t, y, scale * scale * scale);
    CHECK(qx.valid);
    CHECK(qy.shape == Approx(qx.shape).epsilon(1e-12));
    CHECK(qy.skew == Approx(qx.skew).epsilon(1e-12));
    CHECK(qy.relative_size == Approx(qx.relative_size).epsilon(1e-12));  // reference scaled alike
  }
  Eigen::Matrix2d rot2 = Eigen::Rotation2Dd(1.1).toRotationMatrix();
  for (ElementType t : {ElementType::tri3, ElementType::quad4}) {
    Eigen::Matrix<double, 2, Eigen::Dynamic> x = affine_element<2>(t, Eigen::Matrix2d::Identity(), Eigen::Vector2d::Zero());
    for (Index i = 0; i < x.cols(); ++i) x.col(i) += Eigen::Vector2d(u(rng), u(rng));
    const Eigen::Matrix<double, 2, Eigen::Dynamic> y = ((scale * rot2) * x).colwise() + Eigen::Vector2d(-1, 4);
    CHECK(knupp_quality(t, y, 1.0).shape == Approx(knupp_quality(t, x, 1.0).shape).epsilon(1e-12));
    CHECK(knupp_quality(t, y, 1.0).skew == Approx(knupp_quality(t, x, 1.0).skew).epsilon(1e-12));
  }
}

TEST_CASE("scaled Jacobian is 1 on straight-sided elements of every type", "[quality]") {
  Eigen::Matrix3d a3;
  a3 << 1.3, 0.2, -0.1, 0.1, 0.9, 0.3, 0.0, -0.2, 1.1;
  Eigen::Matrix2d a2;
  a2 << 1.5, 0.4, -0.2, 0.7;
  for (int i = 0; i < num_element_types; ++i) {
    const auto t = static_cast<ElementType>(i);
    if (dimension(t) < 2) continue;
    INFO(name(t));
    const auto s = dimension(t) == 2 ? scaled_jacobian(t, affine_element<2>(t, a2, Eigen::Vector2d(1, 2)))
                                     : scaled_jacobian(t, affine_element<3>(t, a3, Eigen::Vector3d(1, 2, 3)));
    CHECK(s.valid);
    CHECK(s.certified);
    CHECK(s.certified_min == Approx(1.0).epsilon(1e-10));
    CHECK(s.certified_max == Approx(1.0).epsilon(1e-10));
    CHECK(s.sampled_min == Approx(1.0).epsilon(1e-10));
    CHECK(s.leaves == 1);
  }
  // A mirrored (negatively oriented) straight element is inverted: -1.
  Eigen::Matrix2d mirror;
  mirror << -1, 0, 0, 1;
  const auto m = scaled_jacobian(ElementType::tri6, affine_element<2>(ElementType::tri6, mirror, Eigen::Vector2d::Zero()));
  CHECK(m.certified_min == Approx(-1.0));
  CHECK_FALSE(m.valid);
}

/// det J of a pyramid at reference point (u, v, w) below its apex, from its shape functions'
/// derivatives (the rational map's own), over |det J_lin|.
double pyramid_det(ElementType t, const Eigen::Matrix<double, 3, Eigen::Dynamic>& x, const RefPoint& xi, double linear) {
  std::vector<std::array<double, 3>> g(static_cast<std::size_t>(num_nodes(t)));
  shape_derivatives(t, xi, g);
  Eigen::Matrix3d j = Eigen::Matrix3d::Zero();
  for (Index i = 0; i < x.cols(); ++i)
    for (int d = 0; d < 3; ++d) j.col(d) += x.col(i) * g[static_cast<std::size_t>(i)][static_cast<std::size_t>(d)];
  return j.determinant() / std::abs(linear);
}

TEST_CASE("pyramids of every order are certified: det J on the collapsed cube is the map's, its bounds hold it", "[quality]") {
  // A pyramid's det J is rational in (u, v, w) but a polynomial of û = u/(1−w), v̂ = v/(1−w), w;
  // its lattice values there must be the map's det J (shape_derivatives at (û(1−w), v̂(1−w), w)),
  // and the certified bounds must hold det J at every point of the cell, within the tolerance of
  // the best value found.
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (const ElementType t : {ElementType::pyramid5, ElementType::pyramid13, ElementType::pyramid14, ElementType::pyramid30,
                              ElementType::pyramid55, ElementType::pyramid91, ElementType::pyramid140, ElementType::pyramid204,
                              ElementType::pyramid285}) {
    INFO(name(t));
    const auto reference = reference_nodes(t);
    for (const bool fold : {false, true}) {  // curved and valid; a base edge's inner nodes pushed across (P2 on)
      if (fold && order(t) == 1) continue;
      Eigen::Matrix<double, 3, Eigen::Dynamic> x(3, num_nodes(t));
      for (Index i = 0; i < x.cols(); ++i) {
        const Vec<3> r(reference[static_cast<std::size_t>(i)][0], reference[static_cast<std::size_t>(i)][1], reference[static_cast<std::size_t>(i)][2]);
        x.col(i) = Vec<3>(1.2 * r.x() + 0.2 * r.z(), 0.9 * r.y(), 1.1 * r.z()) +
                   0.1 * Vec<3>(std::sin(2.0 * r.y()), std::cos(2.0 * r.x()) * r.z(), r.x() * r.y() - 2.0 * r.x() * r.x() * r.z());
        if (i >= 5) x.col(i) += 0.02 * (1.0 - r.z()) / order(t) * Vec<3>(u(rng), u(rng), u(rng));  // a share of the nodes' spacing
        if (fold && i >= 5 && r.z() == 0.0 && r.y() == -1.0) x(1, i) += 2.0;
      }
      const ScaledJacobian m = scaled_jacobian(t, x);
      CHECK(m.certified);
      const auto& space = detail::jacobian_space(t);
      Eigen::VectorXd lattice;
      detail::lattice_dets<3>(space, detail::ElementCoords<3>(x), 1.0 / std::abs(m.linear_det), lattice);
      for (int k = 0; k < space.num_points; ++k) {
        const RefPoint& c = space.points[static_cast<std::size_t>(k)];
        const double w = 0.5 * (c[2] + 1.0);
        if (w > 1.0 - 1e-9) continue;  // the apex: a limit, direction by direction
        CHECK(lattice(k) == Approx(pyramid_det(t, x, {c[0] * (1.0 - w), c[1] * (1.0 - w), w}, m.linear_det)).margin(1e-9));
      }
      double lowest = std::numeric_limits<double>::infinity();
      for (int k = 0; k < 3000; ++k) {
        const double w = 0.5 * (u(rng) + 1.0);
        const double value = pyramid_det(t, x, {u(rng) * (1.0 - w), u(rng) * (1.0 - w), w}, m.linear_det);
        CHECK(value >= m.certified_min - 1e-12);
        CHECK(value <= m.certified_max + 1e-12);
        lowest = std::min(lowest, value);
      }
      CHECK(m.valid == !fold);
      if (!fold) CHECK(m.certified_min >= std::min(lowest, m.sampled_min) - 1e-4 - 1e-12);  // sharp
    }
  }
}

TEST_CASE("scaled Jacobian of a non-parallelogram quad is below 1", "[quality]") {
  // Trapezoid: det J at the top corners is 1/4, at the centre 3/8.
  const auto trapezoid = columns<2>({{0, 0}, {2, 0}, {1.5, 1}, {0.5, 1}});
  const auto s = scaled_jacobian(ElementType::quad4, trapezoid);
  CHECK(s.linear_det == Approx(0.375));
  CHECK(s.certified_min == Approx(2.0 / 3.0));
  CHECK(s.certified_max == Approx(4.0 / 3.0));
  CHECK(s.valid);
}

TEST_CASE("certified bound is below the sampled minimum and sharp on curved elements", "[quality]") {
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> u(-0.12, 0.12);
  // Vertices move too (by half as much): bilinear and trilinear cells are not parallelograms
  // and the tensor-product path (quad4/9, hex8/27) sees general coordinates.
  for (ElementType t : {ElementType::tri6, ElementType::quad4, ElementType::quad8, ElementType::quad9, ElementType::tet10,
                        ElementType::hex8, ElementType::hex20, ElementType::hex27, ElementType::prism15, ElementType::prism18,
                        ElementType::tri10, ElementType::tri15, ElementType::quad16, ElementType::quad25, ElementType::tet20,
                        ElementType::tet35, ElementType::hex64, ElementType::prism40}) {
    INFO(name(t));
    for (int trial = 0; trial < 3; ++trial) {
      if (dimension(t) == 2) {
        auto x = affine_element<2>(t, Eigen::Matrix2d::Identity(), Eigen::Vector2d::Zero());
        for (Index i = 0; i < x.cols(); ++i) x.col(i) += (i < num_vertices(t) ? 0.5 : 1.0) * Eigen::Vector2d(u(rng), u(rng));
        const auto s = scaled_jacobian(t, x);
        CHECK(s.certified_min <= s.sampled_min);
        // Sharp: within the margin of the smallest value of det J found, on a fine lattice or
        // at the certification's own sampling points (both are values of the function).
        CHECK(s.certified_min == Approx(std::min(s.sampled_min, dense_min<2>(t, x, s.linear_det, 120))).margin(2e-3));
      } else {
        auto x = affine_element<3>(t, Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero());
        for (Index i = 0; i < x.cols(); ++i) x.col(i) += (i < num_vertices(t) ? 0.5 : 1.0) * Eigen::Vector3d(u(rng), u(rng), u(rng));
        const auto s = scaled_jacobian(t, x);
        INFO("certified " << s.certified_min << ", sampled " << s.sampled_min << ", " << s.leaves << " leaves");
        CHECK(s.certified_min <= s.sampled_min);
        CHECK(s.certified_min == Approx(std::min(s.sampled_min, dense_min<3>(t, x, s.linear_det, 24))).margin(5e-3));
      }
    }
  }
}

TEST_CASE("high-order hexahedra, prisms and tetrahedra: certified below their det J and sharp, valid and folded", "[quality]") {
  // Hexahedra of orders 4 to 8, prisms of orders 2 to 8, tetrahedra of orders 7 and 8. Their
  // det J (792 to 13,824 lattice points) is held on the heap, the complete prisms'
  // Jacobians come by sum factorization (triangle times line; the serendipity prism15 by its
  // gradient table) and the tetrahedra's children by de Casteljau's
  // algorithm (no tables); det J on the dense lattice comes from the shape functions themselves.
  // The nodes of the reference cell bent
  // by x -> x + a sin(2 y) e_x + a sin(2 z) e_y + a x y e_z: valid for a small bend, folded for a
  // large one, a polynomial of the full degree either way.
  for (const ElementType t : {ElementType::hex125, ElementType::hex343, ElementType::hex729, ElementType::tet120, ElementType::tet165,
                              ElementType::prism15, ElementType::prism18, ElementType::prism40, ElementType::prism75,
                              ElementType::prism196, ElementType::prism405}) {
    // A quadratic cell interpolates the bend too mildly to fold at 0.9 (min 0.26): twice that.
    const double fold = order(t) == 2 ? 1.8 : 0.9;
    for (const double a : {0.15, fold}) {
      INFO(name(t) << ", bend " << a);
      auto x = affine_element<3>(t, Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero());
      for (Index i = 0; i < x.cols(); ++i) {
        const Eigen::Vector3d r = x.col(i);
        x.col(i) += a * Eigen::Vector3d(std::sin(2 * r.y()), std::sin(2 * r.z()), r.x() * r.y());
      }
      const ScaledJacobian s = scaled_jacobian(t, x);
      const double dense = dense_min<3>(t, x, s.linear_det, 8);
      INFO("certified " << s.certified_min << ", sampled " << s.sampled_min << ", dense " << dense << ", " << s.leaves << " leaves");
      CHECK(s.certified);
      // A lower bound (to rounding: where the minimum sits at a corner both are the same value,
      // which the prism405's det J, by sum factorization and by its shape functions, gives to
      // within 1e-11).
      CHECK(s.certified_min <= s.sampled_min + 1e-12);
      CHECK(s.certified_min <= dense + 1e-10);
      CHECK(s.certified_min == Approx(std::min(s.sampled_min, dense)).margin(5e-3));
      CHECK(s.valid == (a < 0.5));
      CHECK(s.valid == (dense > 0));
    }
  }
}

TEST_CASE("a tetrahedron's children by de Casteljau's algorithm are its children's Bezier coefficients", "[quality]") {
  // Against the subdivision tables where they are kept (tet35: degree 9, the tables' rounding
  // 2e-12; at a tet84's degree 15 the tables themselves carry 1e-7 of the Bernstein inversion's
  // rounding) and, at the degree of a tet165's det J, against the definition: a child's
  // coefficients, evaluated as a Bernstein polynomial at its own points, give the parent's at
  // the same places.
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<std::array<std::array<double, 4>, 4>> children;
  for (const auto& vertices : detail::simplex_children(3)) {
    auto& bary = children.emplace_back();
    for (std::size_t i = 0; i < 4; ++i)
      bary[i] = {1.0 - vertices[i][0] - vertices[i][1] - vertices[i][2], vertices[i][0], vertices[i][1], vertices[i][2]};
  }
  const detail::JacobianSpace& tables = detail::jacobian_space(ElementType::tet35);
  REQUIRE(tables.simplex.child_bezier.size() == 8);
  Eigen::VectorXd parent(tables.num_points), child(tables.num_points);
  for (Index k = 0; k < parent.size(); ++k) parent(k) = u(rng);
  for (std::size_t c = 0; c < 8; ++c) {
    detail::tet_child_coefficients(tables.simplex_degree, children[c], parent.data(), child.data());
    CHECK((child - tables.simplex.child_bezier[c] * parent).cwiseAbs().maxCoeff() < 1e-10);
  }
  const detail::JacobianSpace& s = detail::jacobian_space(ElementType::tet165);
  CHECK(s.simplex.child_bezier.empty());
  REQUIRE(s.num_children() == 8);
  const auto at = [&](const Eigen::VectorXd& coefficients, const RefPoint& x) {
    double sum = 0.0;
    for (std::size_t k = 0; k < s.points.size(); ++k) sum += coefficients(static_cast<Index>(k)) * detail::bernstein(s, k, x);
    return sum;
  };
  parent.resize(s.num_points);
  child.resize(s.num_points);
  for (Index k = 0; k < parent.size(); ++k) parent(k) = u(rng);
  for (const std::size_t c : {std::size_t{1}, std::size_t{6}}) {  // a corner child and one of the octahedron's
    detail::tet_child_coefficients(s.simplex_degree, children[c], parent.data(), child.data());
    for (const RefPoint& x : {RefPoint{0.2, 0.3, 0.1}, RefPoint{0.0, 0.0, 1.0}, RefPoint{0.25, 0.25, 0.25}}) {
      RefPoint y{0, 0, 0};  // x mapped into the child, in the parent's reference coordinates
      const std::array<double, 4> lambda{1.0 - x[0] - x[1] - x[2], x[0], x[1], x[2]};
      for (std::size_t i = 0; i < 4; ++i)
        for (std::size_t d = 0; d < 3; ++d) y[d] += lambda[i] * children[c][i][d + 1];
      CHECK(at(child, x) == Approx(at(parent, y)).margin(1e-9));
    }
  }
}

TEST_CASE("straight-sided high-order cells certify as their linear cell, with the same values", "[quality]") {
  // Vertices of a non-parallelepiped cell; higher-order nodes where the linear cell's map puts
  // them (the shortcut), or 1e-9 off (the full high-order path): the bounds agree.
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-0.2, 0.2);
  for (ElementType t : {ElementType::tri6, ElementType::quad8, ElementType::quad9, ElementType::tet10, ElementType::hex20,
                        ElementType::hex27, ElementType::prism15, ElementType::prism18, ElementType::tri10, ElementType::tri15,
                        ElementType::quad16, ElementType::quad25, ElementType::tet20, ElementType::tet35, ElementType::hex64,
                        ElementType::prism40}) {
    INFO(name(t));
    const ElementType lin = linear_type(t);
    const int d = dimension(t), nv = num_vertices(t);
    Eigen::MatrixXd vertices(d, nv);
    const auto ref = reference_nodes(lin);
    for (int v = 0; v < nv; ++v)
      for (int k = 0; k < d; ++k) vertices(k, v) = ref[static_cast<std::size_t>(v)][static_cast<std::size_t>(k)] + u(rng);
    Eigen::MatrixXd x(d, num_nodes(t));
    std::vector<double> n(static_cast<std::size_t>(nv));
    for (int i = 0; i < num_nodes(t); ++i) {
      shape_functions(lin, reference_nodes(t)[static_cast<std::size_t>(i)], n);
      x.col(i) = vertices * Eigen::Map<const Eigen::VectorXd>(n.data(), nv);
    }
    const ScaledJacobian straight = scaled_jacobian(t, x);
    const ScaledJacobian linear = scaled_jacobian(lin, vertices);
    CHECK(straight.certified_min == linear.certified_min);
    CHECK(straight.leaves == linear.leaves);
    x(0, nv) += 1e-9;
    const ScaledJacobian full = scaled_jacobian(t, x);
    CHECK(full.certified_min == Approx(straight.certified_min).margin(2e-4));
    CHECK(full.sampled_min == Approx(straight.sampled_min).margin(1e-6));
    CHECK(full.valid == straight.valid);
  }
}

TEST_CASE("scaled Jacobian flags tangled curved elements", "[quality]") {
  // Midpoint of edge (1,2) pushed across vertex 0.
  auto tri = columns<2>({{0, 0}, {1, 0}, {0, 1}, {0.5, 0}, {-0.3, -0.3}, {0, 0.5}});
  const auto s = scaled_jacobian(ElementType::tri6, tri);
  CHECK(s.certified_min < 0);
  CHECK_FALSE(s.valid);
  CHECK(s.certified_max > 0);

  // A quad9 whose det J is positive at all nine nodes but negative inside: sampling at the
  // nodes misses it, the Bézier bound does not.
  const auto quad = columns<2>({{-1, -1}, {1, -1}, {1, 1}, {-1, 1}, {0.3, -1.1}, {0.9, 0.4}, {-0.3, 1.4}, {-0.4, 0.5}, {0.3, -0.2}});
  const auto q = scaled_jacobian(ElementType::quad9, quad);
  double at_nodes = std::numeric_limits<double>::infinity();
  for (const auto& p : reference_nodes(ElementType::quad9))
    at_nodes = std::min(at_nodes, jacobian_determinant(ElementType::quad9, quad, p) / q.linear_det);
  CHECK(at_nodes > 0.4);
  CHECK(q.certified_min < -0.15);
  CHECK(dense_min<2>(ElementType::quad9, quad, q.linear_det, 100) < -0.15);
  CHECK_FALSE(q.valid);
  // Validity-only mode decides the same without sharpening.
  ScaledJacobianOptions fast;
  fast.sharp = false;
  CHECK_FALSE(scaled_jacobian(ElementType::quad9, quad, fast).valid);
}

TEST_CASE("a Knupp metric takes the certificate's verdict on a high-order cell", "[quality]") {
  // A P2 triangle whose mid-edge node (1,2) lies beyond vertex 0: its straight corners are a
  // fine triangle, the curved cell is folded. Beside it a sound P2 triangle.
  Mesh<2> mesh;
  mesh.points = columns<2>({{0, 0}, {1, 0}, {0, 1}, {0.5, 0}, {-0.3, -0.3}, {0, 0.5}, {1, 1}, {1, 0.5}, {0.5, 1}, {0.5, 0.5}});
  mesh.block(ElementType::tri6).add({0, 1, 2, 3, 4, 5});
  mesh.cells[0].add({1, 6, 2, 7, 8, 9});
  for (const Metric m : {Metric::skew, Metric::shape, Metric::size_shape, Metric::scaled_jacobian}) {
    INFO(metric_name(m));
    const QualityReport r = quality_report(mesh, m);
    CHECK(r.num_invalid == 1);
    CHECK(r.min <= 0.0);
    const std::vector<CellQuality> cells = evaluate_cells(mesh, m);
    CHECK_FALSE(cells[0].valid);
    CHECK(cells[1].valid);
    CHECK(cells[1].value > 0.5);
  }
}

TEST_CASE("a Knupp metric calls valid a curved cell the certificate finds valid, however folded its corners", "[quality]") {
  // The converse: a P2 and a P3 quadrilateral covering 200 degrees of a ring (radii 1 to 2).
  // Their four corners make a quadrilateral that folds over itself (its area is negative),
  // so a verdict from the corners called them invalid; the curved cells are sound.
  for (const ElementType type : {ElementType::quad9, ElementType::quad16}) {
    INFO(name(type));
    Mesh<2> mesh;
    const auto reference = reference_nodes(type);
    mesh.points.resize(2, static_cast<Index>(reference.size()));
    std::vector<Index> nodes;
    for (std::size_t k = 0; k < reference.size(); ++k) {
      const double r = 1.5 + 0.5 * reference[k][0], angle = (reference[k][1] + 1.0) * std::numbers::pi * 200.0 / 360.0;
      mesh.points.col(static_cast<Index>(k)) = Vec<2>(r * std::cos(angle), r * std::sin(angle));
      nodes.push_back(static_cast<Index>(k));
    }
    mesh.block(type).add(nodes);
    Eigen::Matrix<double, 2, 4> corners = mesh.points.leftCols(4);
    double twice_area = 0.0;
    for (int c = 0; c < 4; ++c) twice_area += corners(0, c) * corners(1, (c + 1) % 4) - corners(0, (c + 1) % 4) * corners(1, c);
    REQUIRE(twice_area < 0.0);  // the straight corners fold
    REQUIRE(scaled_jacobian(type, mesh.points).valid);
    for (const Metric m : {Metric::skew, Metric::shape, Metric::size_shape, Metric::scaled_jacobian}) {
      INFO(metric_name(m));
      CHECK(quality_report(mesh, m).num_invalid == 0);
      CHECK(evaluate_cells(mesh, m)[0].valid);
    }
  }
}

TEST_CASE("bad input gives defined results, never NaN", "[quality]") {
  auto tri = columns<2>({{0, 0}, {1, 0}, {0, 1}, {0.5, 0}, {0.5, 0.5}, {0, 0.5}});
  tri(0, 4) = std::nan("");
  const auto s = scaled_jacobian(ElementType::tri6, tri);
  CHECK(s.degenerate);
  CHECK_FALSE(s.valid);
  CHECK(s.certified_min == 0.0);
  const auto repeated = columns<2>({{0, 0}, {1, 0}, {1, 0}, {0.5, 0}, {1, 0}, {0.5, 0}});
  CHECK(scaled_jacobian(ElementType::tri6, repeated).degenerate);
  CHECK_THROWS_AS(scaled_jacobian(ElementType::tri6, columns<3>({{0, 0, 0}})), InputError);

  Mesh<2> mesh;
  mesh.points = columns<2>({{0, 0}, {1, 0}, {0, 1}, {2, 2}, {std::nan(""), 0}});
  mesh.block(ElementType::tri3).add({0, 1, 2});
  mesh.cells[0].add({0, 0, 1});  // repeated node
  mesh.cells[0].add({0, 1, 4});  // NaN coordinate
  mesh.cells[0].add({0, 2, 1});  // inverted
  for (Metric m : all_metrics) {
    INFO(metric_name(m));
    const auto r = quality_report(mesh, m);
    CHECK(r.num_elements == 4);
    CHECK(r.num_invalid == 3);
    CHECK(std::isfinite(r.min));
    CHECK(std::isfinite(r.mean));
    CHECK(std::isfinite(r.max));
    CHECK(to_json(r).find("nan") == std::string::npos);
  }
  CHECK_THROWS_AS(metric_from_name("beauty"), InputError);
}

TEST_CASE("quality report: values, histogram, worst elements, JSON", "[quality]") {
  Mesh<2> mesh;
  mesh.points = columns<2>({{0, 0}, {1, 0}, {0.5, sqrt3 / 2}, {2, 0}, {2, 1}, {0, 1}});
  mesh.block(ElementType::tri3).add({0, 1, 2});
  mesh.block(ElementType::quad4).add({1, 3, 4, 5});
  const auto shape_values = cell_quality(mesh, Metric::shape);
  REQUIRE(shape_values.size() == 2);
  CHECK(shape_values[0] == Approx(1.0));
  ReportOptions opt;
  opt.num_worst = 1;
  const auto r = quality_report(mesh, Metric::shape, opt);
  CHECK(r.num_invalid == 0);
  CHECK(r.max == Approx(1.0));
  CHECK(r.min == shape_values[1]);
  CHECK(r.mean == Approx((shape_values[0] + shape_values[1]) / 2));
  CHECK(r.histogram.back() == 1);
  REQUIRE(r.worst.size() == 1);
  CHECK(r.worst[0].id == 1);
  CHECK(r.worst[0].type == ElementType::quad4);
  CHECK(r.worst[0].centroid[0] == Approx(1.25));
  REQUIRE(r.per_type.size() == 2);
  CHECK(r.per_type[1].type == ElementType::quad4);
  const std::string json = to_json(r);
  CHECK(json.find("\"metric\":\"shape\"") != std::string::npos);
  CHECK(json.find("\"elements\":2") != std::string::npos);
  // Default reference size is the mean cell measure: (√3/4 + 1.5) / 2.
  CHECK(mean_cell_measure(mesh) == Approx((sqrt3 / 4 + 1.5) / 2));
}

// ---- Agreement with Gmsh's AnalyseMeshQuality plugin --------------------------------------
// tests/quality/data/boundary_layer_{tri6,quad9}.msh were made by Gmsh 4.8.4 from the .geo
// files beside them (`gmsh X.geo -2 -order 2`), and the plugin (JacobianDeterminant = 1,
// CreateView = 1) gave, per element, minJ/maxJ; straight elements have 1 and are not listed.

namespace {

struct GmshRatio {
  std::int64_t id;
  double min_over_max;
};

struct GmshCase {
  const char* file;
  Index invalid;
  std::array<double, 3> min_j;  // plugin's "minJ (min, avg, max)" log line, 3 digits
  std::vector<GmshRatio> curved;
};

std::filesystem::path quality_data(const std::string& name) {
  return std::filesystem::path(__FILE__).parent_path() / "data" / name;
}

// Per-element min/max ratio and invalid count of ours, by element id.
template <int Dim>
std::map<std::int64_t, ScaledJacobian> ours_by_id(const Mesh<Dim>& mesh) {
  const auto sj = scaled_jacobians(mesh);
  std::map<std::int64_t, ScaledJacobian> out;
  std::size_t k = 0;
  for (const auto& b : mesh.cells)
    for (Index e = 0; e < b.size(); ++e, ++k) out[b.ids.empty() ? static_cast<std::int64_t>(k) + 1 : b.ids[static_cast<std::size_t>(e)]] = sj[k];
  return out;
}

// Past order 2 Gmsh's plugin stops subdividing earlier than our certification: its bounds
// are looser, by up to 1.3% on these meshes (a tet35 of sphere_box at order 4: 0.36426 from
// Gmsh, 0.36506 certified here, 0.36519 sampled on a 60-point lattice; a tangled tri15 of the
// boundary layer: -17.515 from Gmsh, -17.7347 here, -17.7351 sampled on a 400-point lattice),
// so the ratios agree to 2% there and to 0.1% at order 2, and a valid cell's ratio is never
// below Gmsh's up to order 4. Past it Gmsh's bound is now and then the tighter one, by less
// than the certificate's tolerance (4e-8 on a quad81 of the boundary layer).
template <int Dim>
void check_against(const Mesh<Dim>& mesh, const std::map<std::int64_t, double>& gmsh_ratio_by_id, Index gmsh_invalid) {
  const auto ours = ours_by_id(mesh);
  Index invalid = 0;
  for (const auto& [id, s] : ours) invalid += s.valid ? 0 : 1;
  CHECK(invalid == gmsh_invalid);
  const bool past_p2 = order(mesh.cells.front().type) > 2;
  for (const auto& [id, s] : ours) {
    INFO("element " << id);
    const auto it = gmsh_ratio_by_id.find(id);
    const double expected = it == gmsh_ratio_by_id.end() ? 1.0 : it->second;
    const double ratio = s.certified_min / s.certified_max;
    CHECK(ratio == Approx(expected).epsilon(past_p2 ? 2e-2 : 1e-3).margin(1e-9));
    if (past_p2 && expected > 0) CHECK(ratio >= expected - (order(mesh.cells.front().type) > 4 ? 1e-4 : 1e-9));
  }
}

bool have_gmsh() { return std::system("gmsh --version > /dev/null 2>&1") == 0; }

// Runs `gmsh` on a script with the given arguments (-0: parse it and exit), which must succeed.
void run_gmsh(const std::string& name, const std::string& script_text, const std::string& arguments = "-0") {
  const auto script = test::scratch_path(name + ".geo");
  {
    std::ofstream geo(script);
    geo << script_text;
  }
  REQUIRE(std::system(("gmsh \"" + script.string() + "\" " + arguments + " -nopopup > /dev/null 2>&1").c_str()) == 0);
}

// Gmsh's AnalyseMeshQuality plugin on a mesh file: min J / max J of every element it lists
// (straight elements are left out), and how many are invalid.
std::pair<std::map<std::int64_t, double>, Index> gmsh_plugin_ratios(const std::filesystem::path& mesh, int dim) {
  const auto view = test::scratch_path("view_" + mesh.filename().string());
  std::filesystem::remove(view);
  run_gmsh("analyse_" + mesh.filename().string(),
           "Merge \"" + mesh.string() + "\";\n"
           "Plugin(AnalyseMeshQuality).JacobianDeterminant = 1;\n"
           "Plugin(AnalyseMeshQuality).CreateView = 1;\n"
           "Plugin(AnalyseMeshQuality).DimensionOfElements = " + std::to_string(dim) + ";\n"
           "Plugin(AnalyseMeshQuality).Run;\n"
           "Save View[0] \"" + view.string() + "\";\n");
  std::ifstream in(view);
  std::string line;
  while (std::getline(in, line) && line != "$ElementData") {}
  for (int k = 0; k < 9; ++k) std::getline(in, line);  // tags: names, time, step, components, count
  std::map<std::int64_t, double> ratio;
  Index invalid = 0;
  while (std::getline(in, line) && line != "$EndElementData") {
    std::istringstream s(line);
    std::int64_t id = 0;
    double v = 0;
    s >> id >> v;
    ratio[id] = v;
    invalid += v <= 0 ? 1 : 0;
  }
  REQUIRE(!ratio.empty());
  return {ratio, invalid};
}

#include "data/gmsh_reference.inc"

}  // namespace

TEST_CASE("scaled Jacobian agrees with Gmsh's AnalyseMeshQuality on its own P2 meshes", "[quality]") {
  for (const GmshCase& c : gmsh_cases) {
    INFO(c.file);
    const auto mesh = read_mesh_as<2>(quality_data(c.file));
    std::map<std::int64_t, double> ratio;
    for (const auto& r : c.curved) ratio[r.id] = r.min_over_max;
    check_against(mesh, ratio, c.invalid);
    // The plugin's summary of raw min det J over the elements.
    const auto ours = ours_by_id(mesh);
    double lo = std::numeric_limits<double>::infinity(), hi = -lo, sum = 0;
    for (const auto& [id, s] : ours) {
      lo = std::min(lo, s.min_det());
      hi = std::max(hi, s.min_det());
      sum += s.min_det();
    }
    CHECK(lo == Approx(c.min_j[0]).epsilon(5e-3));
    CHECK(sum / static_cast<double>(ours.size()) == Approx(c.min_j[1]).epsilon(5e-3));
    CHECK(hi == Approx(c.min_j[2]).epsilon(5e-3));
  }
}

TEST_CASE("scaled Jacobian agrees with a live gmsh run", "[quality]") {
  if (!have_gmsh()) {
    WARN("skipped: gmsh is not on PATH");
    return;
  }
  for (const GmshCase& c : gmsh_cases) {
    INFO(c.file);
    const auto [ratio, invalid] = gmsh_plugin_ratios(quality_data(c.file), 2);
    check_against(read_mesh_as<2>(quality_data(c.file)), ratio, invalid);
  }
}

TEST_CASE("scaled Jacobian agrees with Gmsh's AnalyseMeshQuality at orders 3 to 8", "[quality]") {
  // Gmsh meshes the .geo files of tests/quality/data at each order (its plain snapping of
  // thin boundary layers and of the sphere leaves invalid cells: the count must agree too).
  if (!have_gmsh()) {
    WARN("skipped: gmsh is not on PATH (apt-get install gmsh)");
    return;
  }
  struct Case {
    const char* geo;
    int dim;
    int order;
  };
  for (const Case& c : {Case{"boundary_layer_tri6.geo", 2, 3}, Case{"boundary_layer_tri6.geo", 2, 4},
                        Case{"boundary_layer_tri6.geo", 2, 5}, Case{"boundary_layer_tri6.geo", 2, 8},
                        Case{"boundary_layer_quad9.geo", 2, 3}, Case{"boundary_layer_quad9.geo", 2, 4},
                        Case{"boundary_layer_quad9.geo", 2, 6}, Case{"boundary_layer_quad9.geo", 2, 8},
                        Case{"sphere_box.geo", 3, 3}, Case{"sphere_box.geo", 3, 4}, Case{"sphere_box.geo", 3, 5},
                        Case{"sphere_box.geo", 3, 6}}) {
    const std::string stem = std::filesystem::path(c.geo).stem().string() + "_p" + std::to_string(c.order);
    INFO(stem);
    const auto mesh_file = test::scratch_path(stem + ".msh");
    std::filesystem::remove(mesh_file);
    // The order is set after the .geo, which sets its own.
    // Appends, not one concatenation: GCC 12 misreads the latter (-Wrestrict).
    std::string script = "Merge \"";
    script += quality_data(c.geo).string();
    script += "\";\nMesh.ElementOrder = ";
    script += std::to_string(c.order);
    script += ";\n";
    std::string arguments = "-";
    arguments += std::to_string(c.dim);
    arguments += " -o \"";
    arguments += mesh_file.string();
    arguments += "\"";
    run_gmsh("make_" + stem, script, arguments);
    const auto [ratio, invalid] = gmsh_plugin_ratios(mesh_file, c.dim);
    if (c.dim == 2) {
      const auto mesh = read_mesh_as<2>(mesh_file);
      CHECK(order(mesh.cells.front().type) == c.order);
      check_against(mesh, ratio, invalid);
    } else {
      const auto mesh = read_mesh_as<3>(mesh_file);
      CHECK(order(mesh.cells.front().type) == c.order);
      check_against(mesh, ratio, invalid);
    }
  }
}

namespace {
// Counts the occurrences of `needle` in `text`.
std::size_t occurrences(const std::string& text, const std::string& needle) {
  std::size_t n = 0;
  for (auto at = text.find(needle); at != std::string::npos; at = text.find(needle, at + needle.size())) ++n;
  return n;
}
}  // namespace

TEST_CASE("SVG picture: well-formed, one path per cell in the zoom box, curved P2 edges", "[quality]") {
  Mesh<2> mesh = rectangle_mesh({.nx = 4, .ny = 2, .x_min = 0.0, .x_max = 4.0, .y_min = 0.0, .y_max = 2.0});
  const std::vector<double> values(static_cast<std::size_t>(mesh.num_cells()), 0.5);
  SvgOptions options;
  options.title = "a <long> title & more, so the header is longer than any fixed buffer";

  const std::string whole = svg_picture(mesh, values, options);
  CHECK(whole.rfind("<svg xmlns=\"http://www.w3.org/2000/svg\"", 0) == 0);
  CHECK(whole.find("stroke-width=\"0.4\">\n") != std::string::npos);  // header complete
  CHECK(whole.size() > 6);
  CHECK(whole.substr(whole.size() - 7) == "</svg>\n");
  CHECK(occurrences(whole, "<path ") == static_cast<std::size_t>(mesh.num_cells()));
  CHECK(occurrences(whole, "&lt;long>") == 1);
  CHECK(occurrences(whole, "&amp;") == 1);
  CHECK(occurrences(whole, "<") == occurrences(whole, ">") - 1);  // the escaped title keeps one '>'
  // The title has a band above the picture (4000 × 2000 box at width 1000: 500 px high).
  CHECK(whole.find("height=\"522\"") != std::string::npos);
  CHECK(whole.find("<g transform=\"translate(0 22)\">") < whole.find("<path "));
  CHECK(whole.find("<text x=\"5\" y=\"15\"") > whole.rfind("</g>"));
  options.title.clear();
  CHECK(svg_picture(mesh, values, options).find("height=\"500\"") != std::string::npos);
  options.title = "restored";

  // Zoom on the left square column: the other cells are not drawn.
  options.zoom = std::array<double, 4>{0.1, 0.9, 0.1, 1.9};
  CHECK(occurrences(svg_picture(mesh, values, options), "<path ") == 2);

  // Quadratic cells are drawn with quadratic Bézier edges, straight cells with lines.
  CHECK(occurrences(whole, " Q") == 0);
  options.zoom.reset();
  const std::string curved = svg_picture(to_quadratic(mesh), values, options);
  CHECK(occurrences(curved, " Q") == 4 * static_cast<std::size_t>(mesh.num_cells()));

  options.zoom = std::array<double, 4>{1.0, 1.0, 0.0, 1.0};
  CHECK_THROWS_AS(svg_picture(mesh, values, options), InputError);
}

TEST_CASE("SVG picture: a ring and a count for exactly the invalid cells drawn", "[quality]") {
  // 4 × 2 unit squares; cell order is row by row from the bottom left.
  const Mesh<2> mesh = rectangle_mesh({.nx = 4, .ny = 2, .x_min = 0.0, .x_max = 4.0, .y_min = 0.0, .y_max = 2.0});
  std::vector<double> values(static_cast<std::size_t>(mesh.num_cells()), 0.5);
  SvgOptions options;
  const std::string valid = svg_picture(mesh, values, options);
  CHECK(occurrences(valid, "class=\"invalid\"") == 0);
  CHECK(occurrences(valid, ">0 invalid<") == 1);

  // ≤ 0 and NaN are invalid; a value just above 0 is not.
  values[1] = -3.0, values[2] = 0.0, values[5] = std::nan(""), values[6] = 1e-12;
  const std::string marked = svg_picture(mesh, values, options);
  CHECK(occurrences(marked, "<circle class=\"invalid\"") == 3);
  CHECK(occurrences(marked, ">3 invalid<") == 1);
  CHECK(occurrences(marked, "fill=\"#ff00ff\" d=") == 3);
  // Invalid cells are drawn over the valid ones (value 0.5, 1e-12).
  CHECK(marked.find("fill=\"#ff00ff\" d=") > marked.rfind("<path fill=\"" + detail::colour(0.5) + "\""));
  CHECK(marked.find("fill=\"#ff00ff\" d=") > marked.rfind("<path fill=\"" + detail::colour(1e-12) + "\""));
  // Rings are drawn after every cell, at the centroids (1000 px for 4 units: cell 1 is
  // centred at x = 1.5, y = 0.5 → 375, 375 px).
  CHECK(marked.find("<circle class=\"invalid\"") > marked.rfind("<path "));
  CHECK(marked.find("cx=\"375.00\" cy=\"375.00\" r=\"5.0\"") != std::string::npos);
  CHECK(marked.size() > 7);
  CHECK(marked.substr(marked.size() - 7) == "</svg>\n");

  // Zoom on the right half: only cells 2, 3, 6, 7 are drawn, and of the invalid ones only 2.
  options.zoom = std::array<double, 4>{2.1, 3.9, 0.1, 1.9};
  const std::string zoomed = svg_picture(mesh, values, options);
  CHECK(occurrences(zoomed, "<path ") == 4);
  CHECK(occurrences(zoomed, "<circle class=\"invalid\"") == 1);
  CHECK(occurrences(zoomed, ">1 invalid<") == 1);

  options.mark_invalid = false;
  const std::string plain = svg_picture(mesh, values, options);
  CHECK(occurrences(plain, "<circle") == 0);
  CHECK(plain.find(" invalid<") == std::string::npos);
}
