#pragma once
/// \file
/// Reference elements, Lagrange shape functions and their derivatives for every ElementType,
/// and the Jacobian of the reference-to-physical map.
///
/// Reference elements are Gmsh's: line [-1,1]; triangle (0,0),(1,0),(0,1); quadrilateral
/// [-1,1]^2; tetrahedron the unit simplex; hexahedron [-1,1]^3; prism = unit triangle × [-1,1];
/// pyramid with base [-1,1]^2 at w = 0 and apex (0,0,1). Node order is the library's (Gmsh's):
/// vertices, one node per edge in the order of edges(type), one node per quadrilateral facet
/// in the order of facets(type), then the volume node.
///
/// Every type's functions are the nodal basis of a fixed function space, obtained once by
/// inverting the generalized Vandermonde matrix at the reference nodes:
/// - complete types: P_p on simplices, Q_p on quads/hexes, P_p(u,v) ⊗ P_p(w) on prisms;
/// - serendipity quad8/hex20: the monomials of Q2 with at most one exponent equal to 2;
///   prism15: P2(u,v) ⊗ {1,w} plus P1(u,v) w^2;
/// - pyramids: Gmsh's (Bergot's) rational space û^i v̂^j (1-w)^max(i,j) w^k with
///   û = u/(1-w), v̂ = v/(1-w), k ≤ p - max(i,j); pyramid13 drops (i,j) = (2,2); complete
///   pyramids span it with Legendre polynomials of û, v̂ and 2w - 1 in place of the powers.
/// Since the interpolant in a space is unique, these are the functions Gmsh uses.

#include "meshmotion/core/detail/per_type_cache.hpp"
#include "meshmotion/core/detail/table_kernels.hpp"
#include "meshmotion/core/element.hpp"
#include "meshmotion/core/types.hpp"

#include <Eigen/Core>
#include <Eigen/LU>

#include <algorithm>
#include <array>
#include <cmath>
#include <initializer_list>
#include <span>
#include <vector>

namespace meshmotion {

/// A point of a reference element: (u, v, w); unused coordinates are 0.
using RefPoint = std::array<double, 3>;

namespace detail {

// One term of a function space: u^a v^b w^c (1-w)^e (e < 0 only for the rational pyramid
// terms), or, on lines, quadrilaterals and hexahedra, the product of Legendre polynomials
// P_a(u) P_b(v) P_c(w). Both span the same spaces, but past order 4 the monomials' nodal
// systems lose digits on [-1, 1]^3: the hex729's Vandermonde matrix has a condition number of
// 4e9 in monomials, 4e3 in Legendre products, and its shape functions summed to 1 only within
// 1e-9 (now 3e-14). On simplices, whose coordinates lie in [0, 1], Legendre products of 2x - 1
// gained nothing (tri45 2e-11 either way, tet84 worse), so they keep the monomials. Complete
// pyramids take P_a(û) P_b(v̂) (1-w)^max(a,b) P_c(2w - 1) (`pyramid`; the same space, each
// Legendre polynomial a triangular combination of the powers it replaces): with the powers a
// pyramid285's functions were 2e-11 off at its own nodes.
struct Monomial {
  int a = 0, b = 0, c = 0, e = 0;
  bool legendre = false;
  bool pyramid = false;
};

inline double int_pow(double x, int n) {
  if (n < 0) return 1.0 / int_pow(x, -n);
  double r = 1.0;
  for (int k = 0; k < n; ++k) r *= x;
  return r;
}

// Coefficients of s^j in the Legendre polynomial P_n(s), n ≤ max_element_order.
inline const std::array<std::array<double, max_element_order + 1>, max_element_order + 1>& legendre_coefficients() {
  static const auto table = [] {
    std::array<std::array<double, max_element_order + 1>, max_element_order + 1> c{};
    c[0][0] = 1.0;
    c[1][1] = 1.0;
    for (std::size_t n = 1; n < max_element_order; ++n)
      for (std::size_t j = 0; j <= n + 1; ++j)
        c[n + 1][j] = ((j > 0 ? static_cast<double>(2 * n + 1) * c[n][j - 1] : 0.0) - static_cast<double>(n) * c[n - 1][j]) /
                      static_cast<double>(n + 1);
    return c;
  }();
  return table;
}

// The k-th derivative of P_n at s.
inline double legendre_derivative(int n, int k, double s) {
  if (k > n) return 0.0;
  const auto& c = legendre_coefficients()[static_cast<std::size_t>(n)];
  double r = 0.0;
  for (int j = n; j >= k; --j) {
    double f = c[static_cast<std::size_t>(j)];
    for (int i = 0; i < k; ++i) f *= j - i;
    r = r * s + f;
  }
  return r;
}

// ∂^(du,dv,dw) of a term at x (not for pyramids: their terms are rational).
inline double term_derivative(const Monomial& m, const RefPoint& x, int du, int dv, int dw) {
  const std::array<int, 3> degree{m.a, m.b, m.c}, times{du, dv, dw};
  double r = 1.0;
  for (std::size_t d = 0; d < 3 && r != 0.0; ++d) {
    const int n = degree[d], k = times[d];
    if (k > n) return 0.0;
    if (m.legendre) {
      r *= legendre_derivative(n, k, x[d]);
    } else {
      double f = 1.0;
      for (int j = 0; j < k; ++j) f *= n - j;
      r *= f * int_pow(x[d], n - k);
    }
  }
  return r;
}

// At the pyramid apex (1-w = 0) the rational terms are direction dependent; like Gmsh we
// take û = v̂ = 0 there, which makes them (and their derivatives) vanish.
inline bool at_apex_singularity(const Monomial& m, double s) { return m.e < 0 && std::abs(s) < 1e-14; }

// A complete pyramid's term P_a(û) P_b(v̂) (1-w)^e P_c(2w - 1), e = max(a, b), and its
// gradient in (u, v, w): {value, ∂u, ∂v, ∂w}. At the apex û = v̂ = 0, as for the powers.
inline std::array<double, 4> pyramid_term(const Monomial& m, const RefPoint& x) {
  const double s = 1.0 - x[2];
  const bool apex = std::abs(s) < 1e-14;
  const double uh = apex ? 0.0 : x[0] / s, vh = apex ? 0.0 : x[1] / s, t = 2.0 * x[2] - 1.0;
  const int e = std::max(m.a, m.b);
  const double pa = legendre_derivative(m.a, 0, uh), da = legendre_derivative(m.a, 1, uh);
  const double pb = legendre_derivative(m.b, 0, vh), db = legendre_derivative(m.b, 1, vh);
  const double pc = legendre_derivative(m.c, 0, t), dc = 2.0 * legendre_derivative(m.c, 1, t);
  const double power = int_pow(s, e), lower = e == 0 ? 0.0 : int_pow(s, e - 1);  // (1-w)^e, (1-w)^(e-1)
  return {pa * pb * power * pc, da * pb * lower * pc, pa * db * lower * pc,
          (da * pb * uh + pa * db * vh - e * pa * pb) * lower * pc + pa * pb * power * dc};
}

inline double monomial_value(const Monomial& m, const RefPoint& x) {
  if (m.pyramid) return pyramid_term(m, x)[0];
  if (m.legendre) return term_derivative(m, x, 0, 0, 0);
  const double s = 1.0 - x[2];
  if (at_apex_singularity(m, s)) return 0.0;
  return int_pow(x[0], m.a) * int_pow(x[1], m.b) * int_pow(x[2], m.c) * int_pow(s, m.e);
}

inline std::array<double, 3> monomial_gradient(const Monomial& m, const RefPoint& x) {
  if (m.pyramid) {
    const auto v = pyramid_term(m, x);
    return {v[1], v[2], v[3]};
  }
  if (m.legendre) return {term_derivative(m, x, 1, 0, 0), term_derivative(m, x, 0, 1, 0), term_derivative(m, x, 0, 0, 1)};
  const double s = 1.0 - x[2];
  if (at_apex_singularity(m, s)) return {0.0, 0.0, 0.0};
  const double pu = int_pow(x[0], m.a), pv = int_pow(x[1], m.b), pw = int_pow(x[2], m.c), ps = int_pow(s, m.e);
  const double du = m.a == 0 ? 0.0 : m.a * int_pow(x[0], m.a - 1);
  const double dv = m.b == 0 ? 0.0 : m.b * int_pow(x[1], m.b - 1);
  const double dw = m.c == 0 ? 0.0 : m.c * int_pow(x[2], m.c - 1);
  const double ds = m.e == 0 ? 0.0 : -m.e * int_pow(s, m.e - 1);  // d/dw of (1-w)^e
  return {du * pv * pw * ps, pu * dv * pw * ps, pu * pv * (dw * ps + pw * ds)};
}

inline std::vector<Monomial> function_space(ElementType t) {
  const int p = order(t);
  const bool complete = element_info(t).complete;
  std::vector<Monomial> m;
  const auto twos = [](int a, int b, int c) { return (a == 2) + (b == 2) + (c == 2); };
  switch (shape(t)) {
    case Shape::point: m.push_back({}); break;
    case Shape::line:
      for (int a = 0; a <= p; ++a) m.push_back({a, 0, 0, 0});
      break;
    case Shape::triangle:
      for (int a = 0; a <= p; ++a)
        for (int b = 0; a + b <= p; ++b) m.push_back({a, b, 0, 0});
      break;
    case Shape::quadrilateral:
      for (int a = 0; a <= p; ++a)
        for (int b = 0; b <= p; ++b)
          if (complete || twos(a, b, 0) <= 1) m.push_back({a, b, 0, 0});
      break;
    case Shape::tetrahedron:
      for (int a = 0; a <= p; ++a)
        for (int b = 0; a + b <= p; ++b)
          for (int c = 0; a + b + c <= p; ++c) m.push_back({a, b, c, 0});
      break;
    case Shape::hexahedron:
      for (int a = 0; a <= p; ++a)
        for (int b = 0; b <= p; ++b)
          for (int c = 0; c <= p; ++c)
            if (complete || twos(a, b, c) <= 1) m.push_back({a, b, c, 0});
      break;
    case Shape::prism:
      for (int a = 0; a <= p; ++a)
        for (int b = 0; a + b <= p; ++b)
          for (int c = 0; c <= p; ++c)
            if (complete || !(a + b == 2 && c == 2)) m.push_back({a, b, c, 0});
      break;
    case Shape::pyramid:
      for (int i = 0; i <= p; ++i)
        for (int j = 0; j <= p; ++j) {
          if (!complete && i + j > p && !(i + j == p + 1 && (i == 1 || j == 1))) continue;
          const int mij = std::max(i, j);
          for (int k = 0; k <= p - mij; ++k) m.push_back({i, j, k, mij - i - j});
        }
      break;
  }
  const bool tensor = shape(t) == Shape::line || shape(t) == Shape::quadrilateral || shape(t) == Shape::hexahedron;
  for (Monomial& term : m) {
    term.legendre = tensor;
    term.pyramid = shape(t) == Shape::pyramid && complete;
  }
  return m;
}

inline std::vector<RefPoint> vertex_coordinates(Shape s) {
  switch (s) {
    case Shape::point: return {{0, 0, 0}};
    case Shape::line: return {{-1, 0, 0}, {1, 0, 0}};
    case Shape::triangle: return {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    case Shape::quadrilateral: return {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
    case Shape::tetrahedron: return {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    case Shape::hexahedron:
      return {{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1}, {-1, -1, 1}, {1, -1, 1}, {1, 1, 1}, {-1, 1, 1}};
    case Shape::prism: return {{0, 0, -1}, {1, 0, -1}, {0, 1, -1}, {0, 0, 1}, {1, 0, 1}, {0, 1, 1}};
    case Shape::pyramid: return {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}, {0, 0, 1}};
  }
  return {};
}

inline RefPoint mean_point(std::span<const RefPoint> corners) {
  RefPoint c{0, 0, 0};
  for (const auto& x : corners)
    for (std::size_t d = 0; d < 3; ++d) c[d] += x[d] / static_cast<double>(corners.size());
  return c;
}

// Σ_k weights[k] · corners[k].
inline RefPoint combine(std::span<const RefPoint> corners, std::initializer_list<double> weights) {
  RefPoint c{0, 0, 0};
  std::size_t k = 0;
  for (double w : weights) {
    for (std::size_t d = 0; d < 3; ++d) c[d] += w * corners[k][d];
    ++k;
  }
  return c;
}

// Multilinear map of a quadrilateral or hexahedron's corners at (s, t, r) in [0, 1]^dim.
inline RefPoint multilinear(std::span<const RefPoint> corners, double s, double t, double r = 0.0) {
  if (corners.size() == 4) return combine(corners, {(1 - s) * (1 - t), s * (1 - t), s * t, (1 - s) * t});
  return combine(corners, {(1 - s) * (1 - t) * (1 - r), s * (1 - t) * (1 - r), s * t * (1 - r), (1 - s) * t * (1 - r),
                           (1 - s) * (1 - t) * r, s * (1 - t) * r, s * t * r, (1 - s) * t * r});
}

inline void append_lattice(Shape s, int p, bool complete, std::span<const RefPoint> corners, std::vector<RefPoint>& out);

// The corners of the element inside one of shape s and order p on corners c whose outermost
// inside nodes they are: a triangle's and a tetrahedron's 1/p in from each side, a
// quadrilateral's and a hexahedron's 1/p in from each face, a pyramid's homothetic one (its base
// at height 1/p, its base corners 1 - 3/p of the way from the axis, its apex 2/p below this apex).
// The element inside is of order p - 3 (triangles, pyramids), p - 4 (tetrahedra) or p - 2.
inline std::vector<RefPoint> inner_corners(Shape s, int p, std::span<const RefPoint> c) {
  const double h = 1.0 / p;
  switch (s) {
    case Shape::triangle: return {combine(c, {1 - 2 * h, h, h}), combine(c, {h, 1 - 2 * h, h}), combine(c, {h, h, 1 - 2 * h})};
    case Shape::quadrilateral:
      return {multilinear(c, h, h), multilinear(c, 1 - h, h), multilinear(c, 1 - h, 1 - h), multilinear(c, h, 1 - h)};
    case Shape::tetrahedron:
      return {combine(c, {1 - 3 * h, h, h, h}), combine(c, {h, 1 - 3 * h, h, h}), combine(c, {h, h, 1 - 3 * h, h}),
              combine(c, {h, h, h, 1 - 3 * h})};
    case Shape::hexahedron: {
      std::vector<RefPoint> inner;
      for (const RefPoint& v : vertex_coordinates(Shape::hexahedron))
        inner.push_back(multilinear(c, v[0] < 0 ? h : 1 - h, v[1] < 0 ? h : 1 - h, v[2] < 0 ? h : 1 - h));
      return inner;
    }
    case Shape::pyramid: {
      const RefPoint base = mean_point(c.first(4));
      std::vector<RefPoint> inner;
      for (std::size_t k = 0; k < 4; ++k) inner.push_back(combine(std::array<RefPoint, 3>{c[k], c[4], base}, {1 - 3 * h, h, 2 * h}));
      inner.push_back(combine(std::array<RefPoint, 2>{c[4], base}, {1 - 2 * h, 2 * h}));
      return inner;
    }
    case Shape::point:
    case Shape::line:
    case Shape::prism: break;
  }
  return {};
}

// The order of the element on inner_corners(s, p, ...); negative: there are no inside nodes
// (and for points, lines and prisms, whose insides are not one such element).
inline int inner_order(Shape s, int p) {
  switch (s) {
    case Shape::triangle:
    case Shape::pyramid: return p - 3;
    case Shape::tetrahedron: return p - 4;
    case Shape::quadrilateral:
    case Shape::hexahedron: return p - 2;
    case Shape::point:
    case Shape::line:
    case Shape::prism: break;
  }
  return -1;
}

// The nodes strictly inside an element of shape s and order p on the given corners: a
// smaller element of the same shape on its inner corners, laid out recursively (Gmsh's order).
inline void append_inside(Shape s, int p, std::span<const RefPoint> c, std::vector<RefPoint>& out) {
  if (const int q = inner_order(s, p); q >= 0) {
    append_lattice(s, q, true, inner_corners(s, p, c), out);
    return;
  }
  if (s != Shape::prism) return;  // points and lines, or an element too low in order for inside nodes
  // The product of the triangle's inside and a line of order p - 2 on the inner levels, the
  // triangle's node outermost and the line in its own order (both ends first): at order 4,
  // each inside triangle node at the levels 1/4, 3/4, then 1/2 of the way up.
  const double h = 1.0 / p;
  std::vector<RefPoint> triangle;  // on the reference triangle: (u, v) are barycentric weights
  append_inside(Shape::triangle, p, vertex_coordinates(Shape::triangle), triangle);
  std::vector<RefPoint> levels;
  if (p >= 2) {
    const std::array<RefPoint, 2> ends{RefPoint{h, 0, 0}, RefPoint{1 - h, 0, 0}};
    append_lattice(Shape::line, p - 2, true, ends, levels);
  }
  for (const RefPoint& x : triangle)
    for (const RefPoint& level : levels) {
      const double r = level[0], u = x[0], v = x[1];
      out.push_back(combine(c, {(1 - u - v) * (1 - r), u * (1 - r), v * (1 - r), (1 - u - v) * r, u * r, v * r}));
    }
}

// An element of shape s and order p on the given corners, in Gmsh's node order; order 0 is
// one node at the centre (the inside of a tri10, a tet35 or a quad9 at the bottom of the
// recursion).
inline void append_lattice(Shape s, int p, bool complete, std::span<const RefPoint> corners, std::vector<RefPoint>& out) {
  if (p == 0) {
    out.push_back(mean_point(corners));
    return;
  }
  out.insert(out.end(), corners.begin(), corners.end());
  if (p < 2) return;
  for (const auto& e : edges(s))
    for (int j = 1; j < p; ++j) {
      const double r = static_cast<double>(j) / p;
      out.push_back(combine(std::array<RefPoint, 2>{corners[static_cast<std::size_t>(e[0])], corners[static_cast<std::size_t>(e[1])]},
                            {1 - r, r}));
    }
  if (!complete) return;
  for (const auto& f : face_order(s)) {
    std::array<RefPoint, 4> face{};
    for (int k = 0; k < f.num_vertices; ++k) face[static_cast<std::size_t>(k)] = corners[static_cast<std::size_t>(f.vertices[static_cast<std::size_t>(k)])];
    append_inside(f.shape, p, std::span<const RefPoint>(face.data(), static_cast<std::size_t>(f.num_vertices)), out);
  }
  append_inside(s, p, corners, out);
}

inline std::vector<RefPoint> make_reference_nodes(ElementType t) {
  std::vector<RefPoint> x;
  const auto corners = vertex_coordinates(shape(t));
  append_lattice(shape(t), std::max(order(t), 1), element_info(t).complete, corners, x);
  return x;
}

/// The nodal basis of one element type: N_i(x) = Σ_k coefficients(k, i) m_k(x).
/// Simplices and prisms also keep each node's lattice index in Silvester's coordinates
/// (silvester_coordinates(): a simplex's barycentric α_0 .. α_d summing to the order; a prism's
/// triangle index, then its line index (p − k, k)), which shape_functions() and
/// shape_derivatives() evaluate in Silvester's form.
struct ShapeBasis {
  std::vector<RefPoint> nodes;
  std::vector<Monomial> monomials;
  Eigen::MatrixXd coefficients;
  std::vector<std::array<int, 5>> silvester_index;
};

inline ShapeBasis make_shape_basis(ElementType t) {
  ShapeBasis basis{make_reference_nodes(t), function_space(t), {}, {}};
  const auto n = static_cast<Index>(basis.nodes.size());
  Eigen::MatrixXd vandermonde(n, n);
  for (Index i = 0; i < n; ++i)
    for (Index k = 0; k < n; ++k)
      vandermonde(i, k) = monomial_value(basis.monomials[static_cast<std::size_t>(k)], basis.nodes[static_cast<std::size_t>(i)]);
  basis.coefficients = table_inverse(vandermonde);
  const int p = order(t);
  const bool simplex = shape(t) == Shape::triangle || shape(t) == Shape::tetrahedron;
  if (simplex || (shape(t) == Shape::prism && element_info(t).complete)) {
    const int d = simplex ? dimension(t) : 2;
    for (const RefPoint& x : basis.nodes) {
      std::array<int, 5> alpha{p, 0, 0, 0, 0};
      for (int k = 0; k < d; ++k) {
        alpha[static_cast<std::size_t>(k + 1)] = static_cast<int>(std::lround(p * x[static_cast<std::size_t>(k)]));
        alpha[0] -= alpha[static_cast<std::size_t>(k + 1)];
      }
      if (!simplex) {
        alpha[4] = static_cast<int>(std::lround(p * (x[2] + 1.0) / 2.0));
        alpha[3] = p - alpha[4];
      }
      basis.silvester_index.push_back(alpha);
    }
  }
  return basis;
}

// Silvester's Lagrange functions of a complete simplex of order p on its equispaced lattice:
// node α has N_α = Π_j ℓ(α_j, λ_j) with ℓ(a, t) = Π_{k<a} (p t − k) / (k + 1), λ the
// barycentric coordinates (λ_0 = 1 − Σ ξ, λ_j = ξ_{j−1}). Exact and stable at every order,
// where the monomials' Vandermonde inverse lost digits with it (a tri45's functions were 3e-11
// off at its own nodes, a prism126's 1e-11). A complete prism's functions are the products
// of its triangle's and its line's, the line a 1D simplex in ((1 − w)/2, (1 + w)/2).
// `value(a, t)` and `slope(a, t)`, for every α_j, by one recurrence.
struct SilvesterFactor {
  double value = 1.0, slope = 0.0;
};

inline SilvesterFactor silvester_factor(int a, int p, double t) {
  SilvesterFactor f;
  for (int k = 0; k < a; ++k) {
    const double term = (p * t - k) / (k + 1);
    f.slope = f.slope * term + f.value * p / (k + 1);
    f.value *= term;
  }
  return f;
}

// The Silvester coordinates of xi (the simplex's barycentric ones, then a prism's line's) and
// how many there are; ∂λ_j/∂ξ_k is silvester_slope(j, k).
struct SilvesterCoordinates {
  std::array<double, 5> lambda{1.0, 0.0, 0.0, 0.0, 0.0};
  int count = 0;
  bool prism = false;
};

inline SilvesterCoordinates silvester_coordinates(ElementType t, const RefPoint& xi) {
  SilvesterCoordinates c;
  c.prism = shape(t) == Shape::prism;
  const int d = c.prism ? 2 : dimension(t);
  for (int k = 0; k < d; ++k) {
    c.lambda[static_cast<std::size_t>(k + 1)] = xi[static_cast<std::size_t>(k)];
    c.lambda[0] -= xi[static_cast<std::size_t>(k)];
  }
  c.count = d + 1;
  if (c.prism) {
    c.lambda[3] = 0.5 * (1.0 - xi[2]);
    c.lambda[4] = 0.5 * (1.0 + xi[2]);
    c.count = 5;
  }
  return c;
}

inline double silvester_slope(const SilvesterCoordinates& c, int j, int k) {
  if (c.prism && k == 2) return j == 3 ? -0.5 : (j == 4 ? 0.5 : 0.0);
  if (c.prism && j >= 3) return 0.0;
  return j == 0 ? -1.0 : (j == k + 1 ? 1.0 : 0.0);
}

inline const ShapeBasis& shape_basis(ElementType t) {
  static PerTypeCache<ShapeBasis> bases;
  return bases.get(t, make_shape_basis);
}

}  // namespace detail

/// Reference coordinates of the nodes of `type`, in local node order (num_nodes(type) points).
[[nodiscard]] inline std::span<const RefPoint> reference_nodes(ElementType type) {
  return detail::shape_basis(type).nodes;
}

/// The reference element's centroid (barycentre of its vertices; the pyramid's is (0,0,1/5)).
[[nodiscard]] inline RefPoint reference_centroid(ElementType type) {
  const auto x = reference_nodes(type);
  const int nv = num_vertices(type);
  RefPoint c{0, 0, 0};
  for (int i = 0; i < nv; ++i)
    for (std::size_t d = 0; d < 3; ++d) c[d] += x[static_cast<std::size_t>(i)][d] / nv;
  return c;
}

namespace detail {

// The lattice (integer coordinates, 0 to p per axis) of VTK's Lagrange quadrilateral or
// hexahedron of order p: vertices; edge nodes in the direction of increasing coordinate, edges
// (0,1) (1,2) (3,2) (0,3), then for hexahedra (4,5) (5,6) (7,6) (4,7) (0,4) (1,5) (3,7) (2,6)
// (the vertical edges (3,7) and (2,6) in the order of .vtu files before version 2.2, which is
// what the writer declares); the hexahedron's faces x = 0, x = p, y = 0, y = p, z = 0, z = p,
// each first free axis fastest; then the inside, x fastest.
inline std::vector<std::array<int, 3>> vtk_tensor_lattice(int dim, int p) {
  static constexpr std::array<std::array<int, 3>, 8> corner{{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                                                             {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}}};
  static constexpr std::array<std::array<int, 2>, 12> edge{
      {{0, 1}, {1, 2}, {3, 2}, {0, 3}, {4, 5}, {5, 6}, {7, 6}, {4, 7}, {0, 4}, {1, 5}, {3, 7}, {2, 6}}};
  std::vector<std::array<int, 3>> out;
  const std::size_t nv = dim == 2 ? 4 : 8, ne = dim == 2 ? 4 : 12;
  for (std::size_t v = 0; v < nv; ++v) out.push_back({corner[v][0] * p, corner[v][1] * p, corner[v][2] * p});
  for (std::size_t e = 0; e < ne; ++e)
    for (int j = 1; j < p; ++j) {
      const auto& a = corner[static_cast<std::size_t>(edge[e][0])];
      const auto& b = corner[static_cast<std::size_t>(edge[e][1])];
      out.push_back({a[0] * p + (b[0] - a[0]) * j, a[1] * p + (b[1] - a[1]) * j, a[2] * p + (b[2] - a[2]) * j});
    }
  if (dim == 3)
    for (int axis = 0; axis < 3; ++axis)
      for (const int side : {0, p}) {
        const int first = axis == 0 ? 1 : 0, second = axis == 2 ? 1 : 2;
        for (int t = 1; t < p; ++t)
          for (int s = 1; s < p; ++s) {
            std::array<int, 3> q{};
            q[static_cast<std::size_t>(axis)] = side;
            q[static_cast<std::size_t>(first)] = s;
            q[static_cast<std::size_t>(second)] = t;
            out.push_back(q);
          }
      }
  for (int k = dim == 3 ? 1 : 0; k < (dim == 3 ? p : 1); ++k)
    for (int j = 1; j < p; ++j)
      for (int i = 1; i < p; ++i) out.push_back({i, j, k});
  return out;
}

// The lattice (integer coordinates: i, j on the triangle, i + j ≤ p; k from 0 to p along the
// axis) of VTK's Lagrange wedge of order p: vertices; edge nodes from the first vertex, edges
// (0,1) (1,2) (2,0) (3,4) (4,5) (5,3) (0,3) (1,4) (2,5); the insides of the bottom and top
// triangles; of the quadrilaterals (0,1,4,3) (1,2,5,4) (2,0,3,5), along the triangle's edge
// fastest; then of the wedge, level by level. Every triangle inside is listed row by row, i
// fastest: VTK 9.1's wedge does so, although its triangle cell lists its inside recursively.
inline std::vector<std::array<int, 3>> vtk_wedge_lattice(int p) {
  const std::array<std::array<int, 3>, 6> corner{{{0, 0, 0}, {p, 0, 0}, {0, p, 0}, {0, 0, p}, {p, 0, p}, {0, p, p}}};
  static constexpr std::array<std::array<int, 2>, 9> edge{{{0, 1}, {1, 2}, {2, 0}, {3, 4}, {4, 5}, {5, 3}, {0, 3}, {1, 4}, {2, 5}}};
  std::vector<std::array<int, 3>> out(corner.begin(), corner.end());
  for (const auto& e : edge)
    for (int j = 1; j < p; ++j) {
      const auto& a = corner[static_cast<std::size_t>(e[0])];
      const auto& b = corner[static_cast<std::size_t>(e[1])];
      out.push_back({a[0] + (b[0] - a[0]) * j / p, a[1] + (b[1] - a[1]) * j / p, a[2] + (b[2] - a[2]) * j / p});
    }
  const auto triangle_inside = [&](int k) {
    for (int j = 1; j < p; ++j)
      for (int i = 1; i + j < p; ++i) out.push_back({i, j, k});
  };
  triangle_inside(0);
  triangle_inside(p);
  // The triangle's edges (0,1), (1,2), (2,0) as a point m steps along them.
  const std::array<std::array<int, 4>, 3> side{{{0, 0, 1, 0}, {p, 0, -1, 1}, {0, p, 0, -1}}};
  for (const auto& e : side)
    for (int k = 1; k < p; ++k)
      for (int m = 1; m < p; ++m) out.push_back({e[0] + e[2] * m, e[1] + e[3] * m, k});
  for (int k = 1; k < p; ++k) triangle_inside(k);
  return out;
}

// Our local node at each point of VTK's lattice of a complete quadrilateral, hexahedron or
// (Lagrange) wedge.
inline std::vector<int> make_vtk_lattice_order(ElementType t) {
  const auto ours = reference_nodes(t);
  const int p = order(t);
  const bool wedge = shape(t) == Shape::prism;
  // Our reference coordinates of a lattice point: [0, 1] on the wedge's triangle, [-1, 1] elsewhere.
  const auto coordinate = [&](const std::array<int, 3>& q, std::size_t d) {
    return wedge && d < 2 ? static_cast<double>(q[d]) / p : 2.0 * q[d] / p - 1.0;
  };
  std::vector<int> out;
  for (const auto& q : wedge ? vtk_wedge_lattice(p) : vtk_tensor_lattice(dimension(t), p)) {
    const auto at = std::find_if(ours.begin(), ours.end(), [&](const RefPoint& x) {
      double gap = 0.0;
      for (std::size_t d = 0; d < static_cast<std::size_t>(dimension(t)); ++d) gap += std::abs(x[d] - coordinate(q, d));
      return gap < 1e-9;
    });
    out.push_back(static_cast<int>(at - ours.begin()));
  }
  return out;
}

}  // namespace detail

/// VTK node order: VTK's node i is our local node vtk_order(t)[i]. Empty span means identity.
/// `lagrange` selects the order of the VTK Lagrange cell where it differs from the classic one
/// (types past order 2 exist only as Lagrange cells).
[[nodiscard]] inline std::span<const int> vtk_order(ElementType t, bool lagrange = false) {
  const bool lattice = shape(t) == Shape::quadrilateral || shape(t) == Shape::hexahedron || shape(t) == Shape::prism;
  const bool lagrange_cell = order(t) > 2 || (lagrange && order(t) == 2);
  if (!lattice || !element_info(t).complete || !lagrange_cell) return detail::tabulated_vtk_order(t);
  static detail::PerTypeCache<std::vector<int>> orders;
  return orders.get(t, detail::make_vtk_lattice_order);
}

namespace detail {

// The lattice SU2's DG-FEM solver lists a high-order element's nodes on: i along the edge from
// vertex 0 to vertex 1, j towards the vertex across the first face (2 for simplices and
// prisms, 3 for quadrilaterals, hexahedra and pyramid bases), k towards the next layer (3 for
// tetrahedra and prisms, 4 for hexahedra and the pyramid apex); k outermost, i fastest.
inline std::vector<RefPoint> su2_lattice(Shape s, int p) {
  std::vector<RefPoint> x;
  const auto h = [p](int i) { return static_cast<double>(i) / p; };
  const auto c = [p](int i) { return -1.0 + 2.0 * i / p; };
  switch (s) {
    case Shape::point: x.push_back({0, 0, 0}); break;
    case Shape::line:
      for (int i = 0; i <= p; ++i) x.push_back({c(i), 0, 0});
      break;
    case Shape::triangle:
      for (int j = 0; j <= p; ++j)
        for (int i = 0; i + j <= p; ++i) x.push_back({h(i), h(j), 0});
      break;
    case Shape::quadrilateral:
      for (int j = 0; j <= p; ++j)
        for (int i = 0; i <= p; ++i) x.push_back({c(i), c(j), 0});
      break;
    case Shape::tetrahedron:
      for (int k = 0; k <= p; ++k)
        for (int j = 0; j + k <= p; ++j)
          for (int i = 0; i + j + k <= p; ++i) x.push_back({h(i), h(j), h(k)});
      break;
    case Shape::hexahedron:
      for (int k = 0; k <= p; ++k)
        for (int j = 0; j <= p; ++j)
          for (int i = 0; i <= p; ++i) x.push_back({c(i), c(j), c(k)});
      break;
    case Shape::prism:
      for (int k = 0; k <= p; ++k)
        for (int j = 0; j <= p; ++j)
          for (int i = 0; i + j <= p; ++i) x.push_back({h(i), h(j), c(k)});
      break;
    case Shape::pyramid:
      for (int k = 0; k <= p; ++k)
        for (int j = 0; j <= p - k; ++j)
          for (int i = 0; i <= p - k; ++i) x.push_back({-1.0 + h(k) + 2.0 * h(i), -1.0 + h(k) + 2.0 * h(j), h(k)});
      break;
  }
  return x;
}

inline std::vector<int> make_su2_node_order(ElementType t) {
  if (order(t) <= 1 || su2_id(t) < 0) {
    const auto v = vtk_order(t);
    return {v.begin(), v.end()};
  }
  const auto ours = shape_basis(t).nodes;
  std::vector<int> out;
  for (const RefPoint& x : su2_lattice(shape(t), order(t))) {
    int found = -1;
    for (std::size_t i = 0; i < ours.size() && found < 0; ++i)
      if (std::abs(ours[i][0] - x[0]) + std::abs(ours[i][1] - x[1]) + std::abs(ours[i][2] - x[2]) < 1e-12) found = static_cast<int>(i);
    out.push_back(found);
  }
  return out;
}

}  // namespace detail

/// SU2's node order: the file's node k is our local node su2_node_order(type)[k]. Linear
/// elements: VTK's order (vtk_order(), empty for the identity); high-order elements: the
/// lattice of SU2's DG-FEM solver (vertex 0 first, rows along the edge to vertex 1).
[[nodiscard]] inline std::span<const int> su2_node_order(ElementType type) {
  static detail::PerTypeCache<std::vector<int>> orders;
  return orders.get(type, detail::make_su2_node_order);
}

/// Shape function values N_i(xi), i < num_nodes(type), written to `values` (size ≥ num_nodes).
inline void shape_functions(ElementType type, const RefPoint& xi, std::span<double> values) {
  const auto& basis = detail::shape_basis(type);
  const auto n = static_cast<Index>(basis.nodes.size());
  if (!basis.silvester_index.empty()) {
    const int p = order(type);
    const auto c = detail::silvester_coordinates(type, xi);
    for (std::size_t i = 0; i < basis.silvester_index.size(); ++i) {
      double v = 1.0;
      for (int j = 0; j < c.count; ++j)
        v *= detail::silvester_factor(basis.silvester_index[i][static_cast<std::size_t>(j)], p, c.lambda[static_cast<std::size_t>(j)]).value;
      values[i] = v;
    }
    return;
  }
  for (Index i = 0; i < n; ++i) values[static_cast<std::size_t>(i)] = 0.0;
  for (Index k = 0; k < n; ++k) {
    const double m = detail::monomial_value(basis.monomials[static_cast<std::size_t>(k)], xi);
    for (Index i = 0; i < n; ++i) values[static_cast<std::size_t>(i)] += basis.coefficients(k, i) * m;
  }
}

/// Derivatives dN_i/dxi_d at xi: gradients[i][d] for i < num_nodes(type), d < 3 (components
/// beyond dimension(type) are 0). `gradients` must hold num_nodes(type) entries.
inline void shape_derivatives(ElementType type, const RefPoint& xi, std::span<std::array<double, 3>> gradients) {
  const auto& basis = detail::shape_basis(type);
  const auto n = static_cast<Index>(basis.nodes.size());
  if (!basis.silvester_index.empty()) {
    // ∂N/∂ξ_k = Σ_j ∂λ_j/∂ξ_k ∂N/∂λ_j, each ∂N/∂λ_j the product with one factor's slope.
    const int p = order(type), d = dimension(type);
    const auto c = detail::silvester_coordinates(type, xi);
    for (std::size_t i = 0; i < basis.silvester_index.size(); ++i) {
      std::array<detail::SilvesterFactor, 5> f{};
      for (int j = 0; j < c.count; ++j)
        f[static_cast<std::size_t>(j)] = detail::silvester_factor(basis.silvester_index[i][static_cast<std::size_t>(j)], p, c.lambda[static_cast<std::size_t>(j)]);
      gradients[i] = {0.0, 0.0, 0.0};
      for (int j = 0; j < c.count; ++j) {
        double g = f[static_cast<std::size_t>(j)].slope;
        for (int m = 0; m < c.count; ++m)
          if (m != j) g *= f[static_cast<std::size_t>(m)].value;
        for (int k = 0; k < d; ++k) gradients[i][static_cast<std::size_t>(k)] += detail::silvester_slope(c, j, k) * g;
      }
    }
    return;
  }
  for (Index i = 0; i < n; ++i) gradients[static_cast<std::size_t>(i)] = {0.0, 0.0, 0.0};
  for (Index k = 0; k < n; ++k) {
    const auto g = detail::monomial_gradient(basis.monomials[static_cast<std::size_t>(k)], xi);
    for (Index i = 0; i < n; ++i)
      for (std::size_t d = 0; d < 3; ++d) gradients[static_cast<std::size_t>(i)][d] += basis.coefficients(k, i) * g[d];
  }
}

/// Jacobian matrix dx/dxi of the map of one element: `coords` is space_dim × num_nodes(type)
/// (a column per local node); the result is space_dim × dimension(type).
template <class Derived>
[[nodiscard]] Eigen::Matrix<double, Derived::RowsAtCompileTime, Eigen::Dynamic, 0, Derived::RowsAtCompileTime, 3>
jacobian(ElementType type, const Eigen::MatrixBase<Derived>& coords, const RefPoint& xi) {
  constexpr int space_dim = Derived::RowsAtCompileTime;
  static_assert(space_dim >= 1 && space_dim <= 3, "jacobian: coords needs a fixed number of rows (1 to 3)");
  const int n = num_nodes(type), rd = dimension(type);
  std::array<std::array<double, 3>, max_element_nodes> grads;  // the first n written below; zeroing 729 would cost more
  shape_derivatives(type, xi, std::span<std::array<double, 3>>(grads.data(), static_cast<std::size_t>(n)));
  Eigen::Matrix<double, space_dim, Eigen::Dynamic, 0, space_dim, 3> jac =
      Eigen::Matrix<double, space_dim, Eigen::Dynamic, 0, space_dim, 3>::Zero(space_dim, rd);
  for (int i = 0; i < n; ++i)
    for (int d = 0; d < rd; ++d) jac.col(d) += coords.col(i) * grads[static_cast<std::size_t>(i)][static_cast<std::size_t>(d)];
  return jac;
}

/// Jacobian determinant at xi: det(dx/dxi) when dimension(type) equals the space dimension,
/// otherwise the measure sqrt(det(JᵀJ)) (always ≥ 0). `coords` as in jacobian().
template <class Derived>
[[nodiscard]] double jacobian_determinant(ElementType type, const Eigen::MatrixBase<Derived>& coords, const RefPoint& xi) {
  const auto jac = jacobian(type, coords, xi);
  if (jac.rows() == jac.cols()) return jac.rows() == 0 ? 1.0 : Eigen::MatrixXd(jac).determinant();
  return std::sqrt(std::max(0.0, Eigen::MatrixXd(jac.transpose() * jac).determinant()));
}

/// The physical point x(xi) = Σ N_i(xi) x_i of one element; `coords` as in jacobian().
template <class Derived>
[[nodiscard]] Eigen::Matrix<double, Derived::RowsAtCompileTime, 1> map_to_physical(ElementType type,
                                                                                  const Eigen::MatrixBase<Derived>& coords,
                                                                                  const RefPoint& xi) {
  std::array<double, max_element_nodes> values;  // the first num_nodes(type) written below
  shape_functions(type, xi, std::span<double>(values.data(), static_cast<std::size_t>(num_nodes(type))));
  Eigen::Matrix<double, Derived::RowsAtCompileTime, 1> x = Eigen::Matrix<double, Derived::RowsAtCompileTime, 1>::Zero(coords.rows());
  for (int i = 0; i < num_nodes(type); ++i) x += coords.col(i) * values[static_cast<std::size_t>(i)];
  return x;
}

}  // namespace meshmotion
