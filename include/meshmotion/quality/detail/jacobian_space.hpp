#pragma once
/// \file
/// The polynomial space of det J of each element type, in Bernstein (Bézier) form, with the
/// tables the scaled-Jacobian check needs (Johnen, Remacle & Geuzaine, "Geometrical validity
/// of curvilinear finite elements", J. Comput. Phys. 233, 2013).
///
/// det J of a P-order element lies in: simplices of dimension d, degree d(p-1); quads and
/// hexes, degree dp-1 in each direction; prisms, degree 3p-2 on the triangle times 3p-1 along
/// the axis (serendipity types lie in the space of their complete sibling). A function of
/// that space is sampled at the uniform lattice of the space, converted to Bézier
/// coefficients (BezierFactor::to_bezier per factor), which bound it from below and above; subdividing the domain into
/// 2^d similar children tightens the bounds (child coefficients = child_bezier[c] × parent
/// coefficients, exactly, since children are affine images of the reference element).
///
/// Pyramids: the map of Gmsh's (Bergot's) space is rational in (u, v, w), but in the collapsed
/// coordinates û = u/(1−w), v̂ = v/(1−w), w of the cube [−1,1]² × [0,1] each term is
/// f_a(û) g_b(v̂) (1−w)^m h_c(w), m = max(a, b) ≥ a, b: a polynomial. With X(û, v̂, w) the map there,
/// ∂x/∂u = ∂X/∂û / (1−w) and ∂x/∂v = ∂X/∂v̂ / (1−w) are polynomials (each term with a or b ≥ 1
/// carries (1−w)^m, m ≥ 1), and ∂X/∂w = ∂x/∂w − û ∂x/∂u − v̂ ∂x/∂v differs from ∂x/∂w by those
/// columns: det J = det[∂X/∂û / (1−w), ∂X/∂v̂ / (1−w), ∂X/∂w], a polynomial of degree 3p−1 in û
/// and in v̂ and 3p−3 in w (Johnen & Geuzaine's result for these pyramids). It is bounded as a
/// hexahedron's on the cube (w's degree raised to 3p−1, one line factor for all three axes).

#include "meshmotion/core/detail/table_kernels.hpp"
#include "meshmotion/core/element.hpp"
#include "meshmotion/core/error.hpp"
#include "meshmotion/core/shape_functions.hpp"
#include "meshmotion/core/types.hpp"

#include <Eigen/Core>
#include <Eigen/LU>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

namespace meshmotion::detail {

// Bézier tables of one factor of a space: the simplex coordinates together, or one line
// coordinate. A space's Bernstein basis is the product of its factors' bases, so its tables are
// Kronecker products of these, applied factor by factor (a hex27's 216 × 216 transform becomes
// three passes of a 6 × 6 one).
struct BezierFactor {
  Eigen::MatrixXd to_bezier;              // Bézier coefficients = to_bezier × lattice values
  std::vector<Eigen::MatrixXd> child_bezier;  // Bézier coefficients of child c = child_bezier[c] × coefficients
  // Tetrahedra past a tet84's det J (degree 15, 816 coefficients) keep no child tables: they
  // would grow as the square of the coefficients (8 × 2,024² doubles at order 8, a quarter of a
  // gigabyte, and 66 billion multiply-adds to form), where de Casteljau's algorithm gives a
  // child from its parent in about the table's multiply-adds (tet_child_coefficients). The
  // children's vertices instead, in the parent's barycentric coordinates.
  std::vector<std::array<std::array<double, 4>, 4>> child_vertices;
  [[nodiscard]] int num_children() const {
    return static_cast<int>(child_bezier.empty() ? child_vertices.size() : child_bezier.size());
  }
};

struct JacobianSpace {
  int dim = 0;            // reference dimension
  int simplex_dim = 0;    // 0 (none), 2 (triangle) or 3 (tetrahedron) leading coordinates
  int simplex_degree = 0;
  int line_dims = 0;      // trailing coordinates in [-1, 1] with a 1D Bernstein factor each
  int line_degree = 0;
  bool bezier = false;    // Bézier bounds (every 2D and 3D type)
  int num_points = 0;
  int num_nodes = 0;      // nodes of the element type
  std::vector<RefPoint> points;                // sampling lattice
  std::vector<std::array<int, 4>> simplex_index;  // barycentric multi-index per point
  std::vector<std::array<int, 3>> line_index;     // 1D index per line dimension per point
  Eigen::MatrixXd gradients;                   // (num_points · dim) × num_nodes: row point · dim + d (empty for tensor elements)
  std::vector<double> linear_gradients;        // vertex shape gradients at the centroid: [vertex * dim + d]
  // Higher-order types: column i = the linear cell's shape functions at node i, so that
  // x_vertices × linear_embedding are the node positions of the straight-sided cell.
  Eigen::MatrixXd linear_embedding;
  // Tensor-product elements of degree 2 (quad9, hex27): the Jacobians at the lattice by sum
  // factorization, a 1D table per reference axis instead of `gradients` (a hex27's 52k
  // multiply-adds become 10k).
  std::vector<int> tensor_node;                // element node at each tensor position (empty: not a tensor element)
  Eigen::MatrixXd line_values;                 // (line_degree + 1) × (order + 1): 1D Lagrange basis at the line lattice
  Eigen::MatrixXd line_derivatives;            // the same for its derivative
  // Prisms from order 4: the same by the triangle times the line. Values, ∂u and ∂v of the
  // triangle's basis of order p at the lattice's triangle points ((simplex points) × (triangle
  // nodes)), and the element node at triangle node t and line node l (position t · (p + 1) + l).
  // With a prism405's gradient table (19,872 × 405) its Jacobians took 10 ms a cell; so, 0.12 ms.
  std::array<Eigen::MatrixXd, 3> prism_triangle;
  std::vector<int> prism_node;
  // Pyramids, on the collapsed cube (file comment): per term k of the type's space its (a, b);
  // the nodes' functions in the terms (terms × nodes); f_a and f_a' at the line lattice
  // ((line_degree + 1) × (p + 1), for û and v̂ alike); and at the lattice's w (terms as columns)
  // (1−w)^(m−1) h_c(w), the factor of ∂X/∂û / (1−w) and ∂X/∂v̂ / (1−w), and ∂/∂w of (1−w)^m h_c(w).
  std::vector<std::array<int, 2>> pyramid_ab;
  Eigen::MatrixXd pyramid_coefficients, pyramid_f, pyramid_df, pyramid_wa, pyramid_wc;
  std::vector<int> corners;                    // lattice points at the element's vertices
  BezierFactor simplex;                        // when simplex_dim > 0
  BezierFactor line;                           // when line_dims > 0
  // Children of a subdivision: simplex child outermost, then one bit per line coordinate.
  [[nodiscard]] int num_children() const {
    return (simplex_dim > 0 ? simplex.num_children() : 1) << line_dims;
  }
};

inline double factorial(int n) {
  double f = 1.0;
  for (int k = 2; k <= n; ++k) f *= k;
  return f;
}

// Value of the Bernstein function with lattice index k of `space` at reference point x.
inline double bernstein(const JacobianSpace& s, std::size_t k, const RefPoint& x) {
  double b = 1.0;
  if (s.simplex_dim > 0) {
    std::array<double, 4> lambda{1.0, 0.0, 0.0, 0.0};
    for (int d = 0; d < s.simplex_dim; ++d) {
      lambda[static_cast<std::size_t>(d + 1)] = x[static_cast<std::size_t>(d)];
      lambda[0] -= x[static_cast<std::size_t>(d)];
    }
    const auto& alpha = s.simplex_index[k];
    b *= factorial(s.simplex_degree);
    for (int i = 0; i <= s.simplex_dim; ++i) {
      const auto ii = static_cast<std::size_t>(i);
      b *= int_pow(lambda[ii], alpha[ii]) / factorial(alpha[ii]);
    }
  }
  for (int l = 0; l < s.line_dims; ++l) {
    const double t = 0.5 * (x[static_cast<std::size_t>(s.simplex_dim + l)] + 1.0);
    const int i = s.line_index[k][static_cast<std::size_t>(l)], n = s.line_degree;
    b *= factorial(n) / (factorial(i) * factorial(n - i)) * int_pow(t, i) * int_pow(1.0 - t, n - i);
  }
  return b;
}

struct AffineChild {
  RefPoint origin{0, 0, 0};
  std::array<RefPoint, 3> axes{};  // image of the reference unit vector of each coordinate
};

inline RefPoint map_child(const AffineChild& c, const RefPoint& x) {
  RefPoint y = c.origin;
  for (std::size_t i = 0; i < 3; ++i)
    for (std::size_t d = 0; d < 3; ++d) y[d] += c.axes[i][d] * x[i];
  return y;
}

// The 4 (triangle) or 8 (tetrahedron) similar children of the unit simplex, as vertex lists.
inline std::vector<std::vector<RefPoint>> simplex_children(int sd) {
  std::vector<RefPoint> v(static_cast<std::size_t>(sd + 1), RefPoint{0, 0, 0});
  for (int d = 0; d < sd; ++d) v[static_cast<std::size_t>(d + 1)][static_cast<std::size_t>(d)] = 1.0;
  const auto mid = [&v](int a, int b) {
    RefPoint m{};
    for (std::size_t d = 0; d < 3; ++d) m[d] = 0.5 * (v[static_cast<std::size_t>(a)][d] + v[static_cast<std::size_t>(b)][d]);
    return m;
  };
  if (sd == 2) {
    const auto m01 = mid(0, 1), m12 = mid(1, 2), m20 = mid(2, 0);
    return {{v[0], m01, m20}, {m01, v[1], m12}, {m20, m12, v[2]}, {m12, m20, m01}};
  }
  const auto m01 = mid(0, 1), m02 = mid(0, 2), m03 = mid(0, 3), m12 = mid(1, 2), m13 = mid(1, 3), m23 = mid(2, 3);
  // Corner tetrahedra, then the inner octahedron cut along its diagonal m02-m13.
  return {{v[0], m01, m02, m03}, {m01, v[1], m12, m13}, {m02, m12, v[2], m23}, {m03, m13, m23, v[3]},
          {m02, m13, m01, m12},  {m02, m13, m12, m23}, {m02, m13, m23, m03}, {m02, m13, m03, m01}};
}

inline std::vector<AffineChild> make_children(const JacobianSpace& s) {
  std::vector<AffineChild> simplex;
  if (s.simplex_dim > 0) {
    for (const auto& verts : simplex_children(s.simplex_dim)) {
      AffineChild c;
      c.origin = verts[0];
      for (int d = 0; d < s.simplex_dim; ++d)
        for (std::size_t e = 0; e < 3; ++e)
          c.axes[static_cast<std::size_t>(d)][e] = verts[static_cast<std::size_t>(d + 1)][e] - verts[0][e];
      simplex.push_back(c);
    }
  } else {
    simplex.push_back(AffineChild{});
  }
  std::vector<AffineChild> all;
  for (const auto& base : simplex)
    for (int bits = 0; bits < (1 << s.line_dims); ++bits) {
      AffineChild c = base;
      for (int l = 0; l < s.line_dims; ++l) {
        const auto d = static_cast<std::size_t>(s.simplex_dim + l);
        c.axes[d][d] = 0.5;                                // [-1,1] onto a half
        c.origin[d] = (bits >> l) & 1 ? 0.5 : -0.5;
      }
      all.push_back(c);
    }
  return all;
}

// Point i of the line lattice of degree m on [-1, 1]: equispaced, and past degree 11 the
// Chebyshev–Lobatto points (-cos(π i / m)). The Bernstein conversion from equispaced values
// loses digits as 2^m: at degree 23 (a hex729's det J) three passes of it turned a det J of 1
// into bounds of -1.5 and 10.2; the Lobatto points keep it at round-off. Any points give the
// same Bézier coefficients in exact arithmetic, and both sets hold the ends (the vertices).
inline double line_point(int i, int m) {
  if (m == 0) return 0.0;
  if (m < 12) return 2.0 * i / m - 1.0;
  return -std::cos(std::numbers::pi * i / m);
}

// Coordinate d of the triangle or tetrahedron lattice point α of degree n: equispaced, and for
// triangles past degree 11 Blyth and Pozrikidis's points on the Chebyshev–Lobatto ones
// ((1 + 2 v_i − v_j − v_k) / 3 with v the 1D points on [0, 1]): from equispaced values a
// prism405's triangle factor (degree 22) bounded a det J of 0.955 by −0.198, and subdivision
// never recovered (0.768 at depth 10). Vertices stay vertices, and edge points on their edge.
inline double simplex_point(const std::array<int, 4>& alpha, int sd, int n, int d) {
  if (n == 0) return 1.0 / (sd + 1);
  if (sd != 2 || n < 12) return static_cast<double>(alpha[static_cast<std::size_t>(d + 1)]) / n;
  const auto v = [n](int i) { return 0.5 * (line_point(i, n) + 1.0); };
  const int i = alpha[static_cast<std::size_t>(d + 1)], j = alpha[static_cast<std::size_t>(2 - d)], k = alpha[0];
  return (1.0 + 2.0 * v(i) - v(j) - v(k)) / 3.0;
}

inline void add_lattice(JacobianSpace& s) {
  std::vector<std::array<int, 4>> simplex;
  const int sd = s.simplex_dim, n = s.simplex_degree;
  if (sd == 0) simplex.push_back({0, 0, 0, 0});
  for (int a1 = 0; sd > 0 && a1 <= n; ++a1)
    for (int a2 = 0; a1 + a2 <= n; ++a2) {
      if (sd == 2) simplex.push_back({n - a1 - a2, a1, a2, 0});
      for (int a3 = 0; sd == 3 && a1 + a2 + a3 <= n; ++a3) simplex.push_back({n - a1 - a2 - a3, a1, a2, a3});
    }
  std::vector<std::array<int, 3>> lines;
  const int m = s.line_degree;
  for (int i = 0; i <= (s.line_dims > 0 ? m : 0); ++i)
    for (int j = 0; j <= (s.line_dims > 1 ? m : 0); ++j)
      for (int k = 0; k <= (s.line_dims > 2 ? m : 0); ++k) lines.push_back({i, j, k});
  for (const auto& alpha : simplex)
    for (const auto& line : lines) {
      RefPoint x{0, 0, 0};
      for (int d = 0; d < sd; ++d) x[static_cast<std::size_t>(d)] = simplex_point(alpha, sd, n, d);
      for (int l = 0; l < s.line_dims; ++l)
        x[static_cast<std::size_t>(sd + l)] = line_point(line[static_cast<std::size_t>(l)], m);
      s.points.push_back(x);
      // A vertex of the element: its Bézier coefficient is the function's value there.
      const bool simplex_vertex = sd == 0 || n == 0 || std::find(alpha.begin(), alpha.begin() + sd + 1, n) != alpha.begin() + sd + 1;
      bool line_ends = true;
      for (int l = 0; l < s.line_dims; ++l) line_ends = line_ends && (line[static_cast<std::size_t>(l)] == 0 || line[static_cast<std::size_t>(l)] == m);
      if (simplex_vertex && line_ends) s.corners.push_back(static_cast<int>(s.points.size()) - 1);
      s.simplex_index.push_back(alpha);
      s.line_index.push_back(line);
    }
}

// Most lattice points of a det J held on the stack (a tet84's, degree 15): every type but the
// hexahedra past order 3 and the tetrahedra past order 6, whose lattices (1,728 points at a
// hex125, 13,824 at a hex729, 2,024 at a tet165) the certificate keeps on the heap
// (quality/scaled_jacobian.hpp).
inline constexpr int max_lattice_points = 816;

// Points of a tetrahedral lattice of degree m.
[[nodiscard]] constexpr Index tet_lattice_size(int m) { return m < 0 ? 0 : Index{m + 1} * (m + 2) * (m + 3) / 6; }

// Position of the multi-index (m − a1 − a2 − a3, a1, a2, a3) in a tetrahedral lattice of degree m
// (add_lattice's order: a1 outermost, a3 fastest).
[[nodiscard]] constexpr Index tet_lattice_offset(int m, int a1, int a2, int a3) {
  const auto tri = [](int k) { return k < 0 ? Index{0} : Index{k + 1} * (k + 2) / 2; };
  return tet_lattice_size(m) - tet_lattice_size(m - a1) + tri(m - a1) - tri(m - a1 - a2) + a3;
}

// One step of de Casteljau's algorithm in place: the net of degree m (tet_lattice_offset's
// order) becomes the net of degree m − 1 of the blossom with one argument w (barycentric). Each
// entry is written before any entry after it is read, so one buffer serves.
inline void tet_casteljau_step(int m, const std::array<double, 4>& w, double* net) {
  Index out = 0;
  for (int a1 = 0; a1 < m; ++a1)
    for (int a2 = 0; a1 + a2 < m; ++a2) {
      const double* same = net + tet_lattice_offset(m, a1, a2, 0);
      const double* up1 = net + tet_lattice_offset(m, a1 + 1, a2, 0);
      const double* up2 = net + tet_lattice_offset(m, a1, a2 + 1, 0);
      for (int a3 = 0; a1 + a2 + a3 < m; ++a3, ++out)
        net[out] = w[0] * same[a3] + w[1] * up1[a3] + w[2] * up2[a3] + w[3] * same[a3 + 1];
    }
}

// The Bézier coefficients of a child tetrahedron (vertices v, barycentric in the parent) of a
// degree-n polynomial with coefficients `parent`: coefficient α of the child is the blossom
// at v0 (α0 times), v1 (α1 times), v2, v3, taken argument by argument, each partial blossom
// shared by every coefficient that starts with it (about (n + 7)! / (n! 7!) × 4 multiply-adds:
// 4.7 million at degree 21, a 2,024² table's 4.1).
inline void tet_child_coefficients(int n, const std::array<std::array<double, 4>, 4>& v, const double* parent, double* child) {
  thread_local std::array<std::vector<double>, 4> nets;
  const auto size = static_cast<std::size_t>(tet_lattice_size(n));
  for (auto& net : nets) net.resize(size);
  std::copy(parent, parent + size, nets[0].begin());
  for (int a1 = 0; a1 <= n; ++a1) {
    if (a1 > 0) tet_casteljau_step(n - a1 + 1, v[1], nets[0].data());
    std::copy_n(nets[0].begin(), tet_lattice_size(n - a1), nets[1].begin());
    for (int a2 = 0; a1 + a2 <= n; ++a2) {
      if (a2 > 0) tet_casteljau_step(n - a1 - a2 + 1, v[2], nets[1].data());
      std::copy_n(nets[1].begin(), tet_lattice_size(n - a1 - a2), nets[2].begin());
      for (int a3 = 0; a1 + a2 + a3 <= n; ++a3) {
        const int m = n - a1 - a2 - a3;
        if (a3 > 0) tet_casteljau_step(m + 1, v[3], nets[2].data());
        std::copy_n(nets[2].begin(), tet_lattice_size(m), nets[3].begin());
        for (int k = m; k > 0; --k) tet_casteljau_step(k, v[0], nets[3].data());
        child[tet_lattice_offset(n, a1, a2, a3)] = nets[3][0];
      }
    }
  }
}

// The Bézier tables of a space with one factor (simplex only, or a single line coordinate).
inline BezierFactor bezier_factor(JacobianSpace f) {
  add_lattice(f);
  const auto np = static_cast<Index>(f.points.size());
  const auto values_at = [&](const auto& point_of) {
    Eigen::MatrixXd e(np, np);
    for (Index j = 0; j < np; ++j)
      for (Index k = 0; k < np; ++k) e(j, k) = bernstein(f, static_cast<std::size_t>(k), point_of(j));
    return e;
  };
  BezierFactor out;
  out.to_bezier = table_inverse(values_at([&](Index j) { return f.points[static_cast<std::size_t>(j)]; }));
  if (f.simplex_dim == 3 && np > max_lattice_points) {
    for (const auto& verts : simplex_children(3)) {
      auto& bary = out.child_vertices.emplace_back();
      for (std::size_t i = 0; i < 4; ++i) bary[i] = {1.0 - verts[i][0] - verts[i][1] - verts[i][2], verts[i][0], verts[i][1], verts[i][2]};
    }
    return out;
  }
  for (const auto& child : make_children(f))
    out.child_bezier.push_back(
        table_product(out.to_bezier, values_at([&](Index j) { return map_child(child, f.points[static_cast<std::size_t>(j)]); })));
  return out;
}

// The 1D Lagrange basis on p + 1 equispaced nodes of [-1, 1] (and its derivative) at the line
// lattice.
inline void add_line_tables(JacobianSpace& s, int p) {
  const int m = s.line_degree;
  const auto node = [p](int a) { return 2.0 * a / p - 1.0; };
  s.line_values.resize(m + 1, p + 1);
  s.line_derivatives.resize(m + 1, p + 1);
  for (int r = 0; r <= m; ++r) {
    const double x = line_point(r, m);
    for (int a = 0; a <= p; ++a) {
      double value = 1.0, derivative = 0.0;
      for (int b = 0; b <= p; ++b) {
        if (b == a) continue;
        const double w = 1.0 / (node(a) - node(b));
        derivative = derivative * (x - node(b)) * w + value * w;
        value *= (x - node(b)) * w;
      }
      s.line_values(r, a) = value;
      s.line_derivatives(r, a) = derivative;
    }
  }
}

// The line tables, and each element node's place in the tensor order (first axis outermost, as
// the lattice).
inline void add_tensor_tables(JacobianSpace& s, ElementType t, int p) {
  add_line_tables(s, p);
  const auto nodes = reference_nodes(t);
  s.tensor_node.assign(nodes.size(), -1);
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    int position = 0;
    for (int d = 0; d < s.dim; ++d) position = position * (p + 1) + static_cast<int>(std::lround((nodes[i][static_cast<std::size_t>(d)] + 1.0) * 0.5 * p));
    s.tensor_node[static_cast<std::size_t>(position)] = static_cast<int>(i);
  }
}

// The prism's tables for sum factorization (see JacobianSpace::prism_triangle).
inline void add_prism_tables(JacobianSpace& s, ElementType t, int p) {
  add_line_tables(s, p);
  const ElementType triangle = element_type(Shape::triangle, p);
  const auto triangle_nodes = reference_nodes(triangle);
  const auto nt = static_cast<Index>(triangle_nodes.size());
  const Index lines = s.line_degree + 1, na = s.num_points / lines;
  for (auto& table : s.prism_triangle) table.resize(na, nt);
  std::vector<double> values(static_cast<std::size_t>(nt));
  std::vector<std::array<double, 3>> gradients(static_cast<std::size_t>(nt));
  for (Index a = 0; a < na; ++a) {
    const RefPoint& x = s.points[static_cast<std::size_t>(a * lines)];
    const RefPoint uv{x[0], x[1], 0.0};
    shape_functions(triangle, uv, values);
    shape_derivatives(triangle, uv, gradients);
    for (Index k = 0; k < nt; ++k) {
      s.prism_triangle[0](a, k) = values[static_cast<std::size_t>(k)];
      s.prism_triangle[1](a, k) = gradients[static_cast<std::size_t>(k)][0];
      s.prism_triangle[2](a, k) = gradients[static_cast<std::size_t>(k)][1];
    }
  }
  const auto nodes = reference_nodes(t);
  s.prism_node.assign(nodes.size(), -1);
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    Index k = 0;
    while (k < nt && std::abs(triangle_nodes[static_cast<std::size_t>(k)][0] - nodes[i][0]) +
                             std::abs(triangle_nodes[static_cast<std::size_t>(k)][1] - nodes[i][1]) > 1e-9)
      ++k;
    const auto l = std::lround((nodes[i][2] + 1.0) * 0.5 * p);
    s.prism_node[static_cast<std::size_t>(k * (p + 1) + l)] = static_cast<int>(i);
  }
}

// The pyramid's tables (JacobianSpace::pyramid_ab and after) on the lattice add_lattice() made,
// whose third coordinate t ∈ [−1, 1] is w = (t + 1) / 2.
inline void add_pyramid_tables(JacobianSpace& s, ElementType t, int p) {
  const ShapeBasis& basis = shape_basis(t);
  const Index terms = static_cast<Index>(basis.monomials.size()), lines = s.line_degree + 1;
  s.pyramid_coefficients = basis.coefficients;
  s.pyramid_f.resize(lines, p + 1);
  s.pyramid_df.resize(lines, p + 1);
  s.pyramid_wa.resize(lines, terms);
  s.pyramid_wc.resize(lines, terms);
  // Complete pyramids take Legendre polynomials of û, v̂ and 2w − 1, the others powers.
  const bool legendre = basis.monomials.front().pyramid;
  for (Index r = 0; r < lines; ++r) {
    const double x = line_point(static_cast<int>(r), s.line_degree);
    for (int a = 0; a <= p; ++a) {
      s.pyramid_f(r, a) = legendre ? legendre_derivative(a, 0, x) : int_pow(x, a);
      s.pyramid_df(r, a) = legendre ? legendre_derivative(a, 1, x) : (a == 0 ? 0.0 : a * int_pow(x, a - 1));
    }
  }
  for (Index k = 0; k < terms; ++k) {
    const Monomial& term = basis.monomials[static_cast<std::size_t>(k)];
    const int m = std::max(term.a, term.b), c = term.c;
    s.pyramid_ab.push_back({term.a, term.b});
    for (Index r = 0; r < lines; ++r) {
      const double w = 0.5 * (line_point(static_cast<int>(r), s.line_degree) + 1.0), rest = 1.0 - w;
      const double h = legendre ? legendre_derivative(c, 0, 2.0 * w - 1.0) : int_pow(w, c);
      const double dh = legendre ? 2.0 * legendre_derivative(c, 1, 2.0 * w - 1.0) : (c == 0 ? 0.0 : c * int_pow(w, c - 1));
      const double lower = m == 0 ? 0.0 : int_pow(rest, m - 1);
      s.pyramid_wa(r, k) = lower * h;
      s.pyramid_wc(r, k) = -m * lower * h + int_pow(rest, m) * dh;
    }
  }
}

inline JacobianSpace make_jacobian_space(ElementType t) {
  JacobianSpace s;
  s.dim = dimension(t);
  s.num_nodes = num_nodes(t);
  const int p = order(t);
  switch (shape(t)) {
    case Shape::triangle: s.simplex_dim = 2; s.simplex_degree = 2 * (p - 1); break;
    case Shape::tetrahedron: s.simplex_dim = 3; s.simplex_degree = 3 * (p - 1); break;
    case Shape::quadrilateral: s.line_dims = 2; s.line_degree = 2 * p - 1; break;
    case Shape::hexahedron: s.line_dims = 3; s.line_degree = 3 * p - 1; break;
    case Shape::prism:
      s.simplex_dim = 2; s.simplex_degree = 3 * p - 2;
      s.line_dims = 1; s.line_degree = 3 * p - 1;
      break;
    case Shape::pyramid: s.line_dims = 3; s.line_degree = 3 * p - 1; break;  // on the collapsed cube
    default: break;
  }
  s.bezier = s.dim >= 2;
  if (s.bezier) add_lattice(s);
  s.num_points = static_cast<int>(s.points.size());

  // Sum factorization pays from degree 2 on (quad9, hex27; prism18 2.9 → 2.5 µs a cell, prism40
  // 22 → 9.8); for quad4 and hex8 its many tiny passes cost more than the gradient table's
  // multiply-adds. Complete cells only: their nodes are the product of two lattices.
  const bool tensor_shape = shape(t) == Shape::quadrilateral || shape(t) == Shape::hexahedron;
  if (p >= 2 && tensor_shape && s.num_nodes == (s.dim == 2 ? (p + 1) * (p + 1) : (p + 1) * (p + 1) * (p + 1))) {
    add_tensor_tables(s, t, p);
  } else if (shape(t) == Shape::prism && p >= 2 && s.num_nodes == (p + 1) * (p + 1) * (p + 2) / 2) {
    add_prism_tables(s, t, p);
  } else if (shape(t) == Shape::pyramid) {
    add_pyramid_tables(s, t, p);
  } else {
    std::vector<std::array<double, 3>> g(static_cast<std::size_t>(s.num_nodes));
    s.gradients.resize(static_cast<Index>(s.num_points) * s.dim, s.num_nodes);
    for (int j = 0; j < s.num_points; ++j) {
      shape_derivatives(t, s.points[static_cast<std::size_t>(j)], g);
      for (int i = 0; i < s.num_nodes; ++i)
        for (int d = 0; d < s.dim; ++d) s.gradients(j * s.dim + d, i) = g[static_cast<std::size_t>(i)][static_cast<std::size_t>(d)];
    }
  }
  const ElementType lin = linear_type(t);
  std::vector<std::array<double, 3>> gl(static_cast<std::size_t>(num_nodes(lin)));
  shape_derivatives(lin, reference_centroid(lin), gl);
  for (const auto& gi : gl)
    for (int d = 0; d < s.dim; ++d) s.linear_gradients.push_back(gi[static_cast<std::size_t>(d)]);
  if (lin != t) {  // pyramids too: a straight pyramid285's own det J carried 4e-10 of rounding
    const int nv = num_nodes(lin);
    std::vector<double> values(static_cast<std::size_t>(nv));
    s.linear_embedding.resize(nv, s.num_nodes);
    const auto nodes = reference_nodes(t);
    for (int i = 0; i < s.num_nodes; ++i) {
      shape_functions(lin, nodes[static_cast<std::size_t>(i)], values);
      for (int v = 0; v < nv; ++v) s.linear_embedding(v, i) = values[static_cast<std::size_t>(v)];
    }
  }

  if (!s.bezier) return s;
  if (s.simplex_dim > 0) {
    JacobianSpace factor;
    factor.simplex_dim = s.simplex_dim;
    factor.simplex_degree = s.simplex_degree;
    s.simplex = bezier_factor(factor);
  }
  if (s.line_dims > 0) {
    JacobianSpace factor;
    factor.line_dims = 1;
    factor.line_degree = s.line_degree;
    s.line = bezier_factor(factor);
  }
  return s;
}

// Each type's tables on its first use: those of every type at once (the P4 tetrahedron's Bézier
// inverse and its subdivision products among them) took 25 ms of curving the 30P30N's
// triangles, an eighth of the whole program.
inline const JacobianSpace& jacobian_space(ElementType t) {
  static PerTypeCache<JacobianSpace> spaces;
  return spaces.get(t, [](ElementType type) { return dimension(type) >= 2 ? make_jacobian_space(type) : JacobianSpace{}; });
}

}  // namespace meshmotion::detail
