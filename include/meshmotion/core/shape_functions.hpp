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
///   û = u/(1-w), v̂ = v/(1-w), k ≤ p - max(i,j); pyramid13 drops (i,j) = (2,2).
/// Since the interpolant in a space is unique, these are the functions Gmsh uses.

#include "meshmotion/core/detail/table_kernels.hpp"
#include "meshmotion/core/element.hpp"
#include "meshmotion/core/types.hpp"

#include <Eigen/Core>
#include <Eigen/LU>

#include <algorithm>
#include <array>
#include <cmath>
#include <span>
#include <vector>

namespace meshmotion {

/// A point of a reference element: (u, v, w); unused coordinates are 0.
using RefPoint = std::array<double, 3>;

namespace detail {

// u^a v^b w^c (1-w)^e; e < 0 only for the rational pyramid terms.
struct Monomial {
  int a = 0, b = 0, c = 0, e = 0;
};

inline double int_pow(double x, int n) {
  if (n < 0) return 1.0 / int_pow(x, -n);
  double r = 1.0;
  for (int k = 0; k < n; ++k) r *= x;
  return r;
}

// At the pyramid apex (1-w = 0) the rational terms are direction dependent; like Gmsh we
// take û = v̂ = 0 there, which makes them (and their derivatives) vanish.
inline bool at_apex_singularity(const Monomial& m, double s) { return m.e < 0 && std::abs(s) < 1e-14; }

inline double monomial_value(const Monomial& m, const RefPoint& x) {
  const double s = 1.0 - x[2];
  if (at_apex_singularity(m, s)) return 0.0;
  return int_pow(x[0], m.a) * int_pow(x[1], m.b) * int_pow(x[2], m.c) * int_pow(s, m.e);
}

inline std::array<double, 3> monomial_gradient(const Monomial& m, const RefPoint& x) {
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

inline std::vector<RefPoint> make_reference_nodes(ElementType t) {
  std::vector<RefPoint> x = vertex_coordinates(shape(t));
  if (order(t) < 2) return x;
  const auto mean = [&x](std::span<const int> ids) {
    RefPoint c{0, 0, 0};
    for (int i : ids)
      for (int d = 0; d < 3; ++d) c[static_cast<std::size_t>(d)] += x[static_cast<std::size_t>(i)][static_cast<std::size_t>(d)];
    for (double& v : c) v /= static_cast<double>(ids.size());
    return c;
  };
  const std::size_t nv = x.size();
  for (const auto& e : edges(t)) x.push_back(mean(e));
  if (has_face_nodes(t)) {
    if (shape(t) == Shape::quadrilateral) {
      const std::array<int, 4> all{0, 1, 2, 3};
      x.push_back(mean(all));
    } else {
      for (const auto& f : facets(t))
        if (f.shape == Shape::quadrilateral) x.push_back(mean(std::span<const int>(f.vertices.data(), 4)));
    }
  }
  if (t == ElementType::hex27) {
    std::array<int, 8> all{};
    for (std::size_t i = 0; i < nv; ++i) all[i] = static_cast<int>(i);
    x.push_back(mean(all));
  }
  return x;
}

/// The nodal basis of one element type: N_i(x) = Σ_k coefficients(k, i) m_k(x).
struct ShapeBasis {
  std::vector<RefPoint> nodes;
  std::vector<Monomial> monomials;
  Eigen::MatrixXd coefficients;
};

inline ShapeBasis make_shape_basis(ElementType t) {
  ShapeBasis basis{make_reference_nodes(t), function_space(t), {}};
  const auto n = static_cast<Index>(basis.nodes.size());
  Eigen::MatrixXd vandermonde(n, n);
  for (Index i = 0; i < n; ++i)
    for (Index k = 0; k < n; ++k)
      vandermonde(i, k) = monomial_value(basis.monomials[static_cast<std::size_t>(k)], basis.nodes[static_cast<std::size_t>(i)]);
  basis.coefficients = table_inverse(vandermonde);
  return basis;
}

inline const ShapeBasis& shape_basis(ElementType t) {
  static const std::array<ShapeBasis, num_element_types> bases = [] {
    std::array<ShapeBasis, num_element_types> b;
    for (int i = 0; i < num_element_types; ++i) b[static_cast<std::size_t>(i)] = make_shape_basis(static_cast<ElementType>(i));
    return b;
  }();
  return bases[static_cast<std::size_t>(t)];
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

/// Shape function values N_i(xi), i < num_nodes(type), written to `values` (size ≥ num_nodes).
inline void shape_functions(ElementType type, const RefPoint& xi, std::span<double> values) {
  const auto& basis = detail::shape_basis(type);
  const auto n = static_cast<Index>(basis.nodes.size());
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
  std::array<std::array<double, 3>, 27> grads{};
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
  std::array<double, 27> values{};
  shape_functions(type, xi, std::span<double>(values.data(), static_cast<std::size_t>(num_nodes(type))));
  Eigen::Matrix<double, Derived::RowsAtCompileTime, 1> x = Eigen::Matrix<double, Derived::RowsAtCompileTime, 1>::Zero(coords.rows());
  for (int i = 0; i < num_nodes(type); ++i) x += coords.col(i) * values[static_cast<std::size_t>(i)];
  return x;
}

}  // namespace meshmotion
