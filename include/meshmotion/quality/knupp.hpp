#pragma once
/// \file
/// Knupp's algebraic quality metrics of linear elements (P. Knupp, "Algebraic mesh quality
/// metrics", SIAM J. Sci. Comput. 23(1), 2001; thesis section 2.3, eqs. 2.19–2.21).
///
/// Every metric is built from corner Jacobian matrices A_k (the edge vectors leaving vertex k,
/// ordered so that det A_k > 0 on a positively oriented element) and the same matrices W_k
/// of the ideal element (equilateral triangle, square, regular tetrahedron, cube, right prism
/// on an equilateral triangle, square pyramid with equilateral sides). With T_k = A_k W_k^-1:
/// - shape: the harmonic mean over corners of d det(T_k)^(2/d) / |T_k|_F^2 (for triangles
///   this is eq. 2.19, for quadrilaterals eq. 2.20; simplices use one corner, where every
///   corner gives the same value);
/// - skew (quadrilaterals, hexahedra): the harmonic mean of det(Q_k)^(2/d) with Q_k = A_k with
///   unit columns (eq. 2.21 in 2D: the sines of the corner angles). Simplices, prisms and
///   pyramids have no skew of their own; their skew is their shape (thesis section 2.3:
///   "for triangular meshes ... no difference between shape and skew");
/// - relative size: min(τ, 1/τ) with τ = measure / reference_measure;
/// - size-shape and size-skew: the products.
/// Values lie in [0, 1]; 1 for the ideal element, 0 for a degenerate one. An element with a
/// corner determinant ≤ 0 (inverted, collapsed) or a non-finite coordinate is invalid: all
/// its metrics are 0 and `valid` is false. P2 elements are judged by their vertices.

#include "meshmotion/core/element.hpp"
#include "meshmotion/core/types.hpp"

#include <Eigen/Core>
#include <Eigen/LU>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

namespace meshmotion {

/// Knupp metrics of one element.
struct KnuppQuality {
  double relative_size = 0.0;
  double shape = 0.0;
  double skew = 0.0;
  double size_shape = 0.0;
  double size_skew = 0.0;
  double measure = 0.0;  ///< area or volume from the corner Jacobians (≤ 0 when invalid)
  bool valid = false;    ///< all corner determinants > 0 and all coordinates finite
};

namespace detail {

struct KnuppCorner {
  int vertex;
  std::array<int, 3> neighbours;      // first `dim` entries used
  Eigen::Matrix3d ideal_inverse;      // W_k^-1 (top-left dim × dim block used)
};

struct KnuppTable {
  int dim = 0;
  double measure_factor = 0.0;  // measure = factor × mean corner determinant
  bool has_skew = false;
  std::vector<KnuppCorner> corners;
};

inline std::vector<Eigen::Vector3d> ideal_vertices(Shape s) {
  const double r3 = std::sqrt(3.0);
  switch (s) {
    case Shape::triangle: return {{0, 0, 0}, {1, 0, 0}, {0.5, r3 / 2, 0}};
    case Shape::quadrilateral: return {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
    case Shape::tetrahedron: return {{0, 0, 0}, {1, 0, 0}, {0.5, r3 / 2, 0}, {0.5, r3 / 6, std::sqrt(2.0 / 3.0)}};
    case Shape::hexahedron:
      return {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
    case Shape::prism: return {{0, 0, 0}, {1, 0, 0}, {0.5, r3 / 2, 0}, {0, 0, 1}, {1, 0, 1}, {0.5, r3 / 2, 1}};
    case Shape::pyramid: return {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0.5, 0.5, 1 / std::sqrt(2.0)}};
    default: return {};
  }
}

inline KnuppTable make_knupp_table(Shape s) {
  KnuppTable table;
  const auto ideal = ideal_vertices(s);
  if (ideal.empty()) return table;
  const ElementType t = element_type(s, 1);
  table.dim = dimension(t);
  table.has_skew = s == Shape::quadrilateral || s == Shape::hexahedron;
  switch (s) {
    case Shape::triangle: table.measure_factor = 0.5; break;
    case Shape::tetrahedron: table.measure_factor = 1.0 / 6.0; break;
    case Shape::prism: table.measure_factor = 0.5; break;
    case Shape::pyramid: table.measure_factor = 1.0 / 3.0; break;
    default: table.measure_factor = 1.0;
  }
  const bool simplex = s == Shape::triangle || s == Shape::tetrahedron;
  const int nv = simplex ? 1 : (s == Shape::pyramid ? 4 : num_vertices(t));  // pyramid: base corners
  for (int v = 0; v < nv; ++v) {
    KnuppCorner c{v, {0, 0, 0}, Eigen::Matrix3d::Identity()};
    int k = 0;
    for (const auto& e : edges(t))
      if (e[0] == v || e[1] == v) c.neighbours[static_cast<std::size_t>(k++)] = e[0] == v ? e[1] : e[0];
    Eigen::Matrix3d w = Eigen::Matrix3d::Identity();
    for (int d = 0; d < table.dim; ++d)
      w.col(d).head(table.dim) = (ideal[static_cast<std::size_t>(c.neighbours[static_cast<std::size_t>(d)])] -
                                  ideal[static_cast<std::size_t>(v)]).head(table.dim);
    if (w.determinant() < 0) {
      std::swap(c.neighbours[0], c.neighbours[1]);
      w.col(0).swap(w.col(1));
    }
    c.ideal_inverse = w.inverse();
    table.corners.push_back(c);
  }
  return table;
}

inline const KnuppTable& knupp_table(Shape s) {
  static const std::array<KnuppTable, 8> tables = [] {
    std::array<KnuppTable, 8> t;
    for (int i = 0; i < 8; ++i) t[static_cast<std::size_t>(i)] = make_knupp_table(static_cast<Shape>(i));
    return t;
  }();
  return tables[static_cast<std::size_t>(s)];
}

// d det(T)^(2/d) / |T|_F^2: 1 for a similarity, 0 when T is singular.
template <int D>
double corner_shape(const Eigen::Matrix<double, D, D>& t, double det) {
  const double frob2 = t.squaredNorm();
  if (!(frob2 > 0)) return 0.0;
  return D == 2 ? 2.0 * det / frob2 : 3.0 * std::cbrt(det * det) / frob2;
}

template <int D>
KnuppQuality knupp_quality_fixed(const KnuppTable& table, const auto& coords, double reference_measure) {
  KnuppQuality q;
  if (table.corners.empty()) return q;
  double inv_shape = 0.0, inv_skew = 0.0, det_sum = 0.0;
  bool valid = true;
  for (const auto& c : table.corners) {
    Eigen::Matrix<double, D, D> a;
    for (int d = 0; d < D; ++d) a.col(d) = coords.col(c.neighbours[static_cast<std::size_t>(d)]).template head<D>() -
                                           coords.col(c.vertex).template head<D>();
    const double det = a.determinant();
    det_sum += det;
    if (!(det > 0) || !std::isfinite(det)) {
      valid = false;
      continue;
    }
    const Eigen::Matrix<double, D, D> t = a * c.ideal_inverse.template topLeftCorner<D, D>();
    const double shape = corner_shape<D>(t, t.determinant());
    inv_shape += shape > 0 ? 1.0 / shape : std::numeric_limits<double>::infinity();
    double col_norms = 1.0;
    for (int d = 0; d < D; ++d) col_norms *= a.col(d).norm();
    const double sine = det / col_norms;  // det of A with unit columns
    const double skew = D == 2 ? sine : std::cbrt(sine * sine);
    inv_skew += skew > 0 ? 1.0 / skew : std::numeric_limits<double>::infinity();
  }
  q.measure = table.measure_factor * det_sum / static_cast<double>(table.corners.size());
  if (!valid || !std::isfinite(q.measure)) {
    if (!std::isfinite(q.measure)) q.measure = 0.0;
    return q;
  }
  const double n = static_cast<double>(table.corners.size());
  q.valid = true;
  q.shape = std::isfinite(inv_shape) ? std::min(1.0, n / inv_shape) : 0.0;
  q.skew = table.has_skew ? (std::isfinite(inv_skew) ? std::min(1.0, n / inv_skew) : 0.0) : q.shape;
  if (reference_measure > 0 && std::isfinite(reference_measure)) {
    const double tau = q.measure / reference_measure;
    q.relative_size = std::min(tau, 1.0 / tau);
  }
  q.size_shape = q.relative_size * q.shape;
  q.size_skew = q.relative_size * q.skew;
  return q;
}

}  // namespace detail

/// Knupp metrics of one linear (or P2, judged by its vertices) element of dimension ≥ 2.
///
/// `coords` is space_dim × n (a column per local node, at least num_vertices(type) columns),
/// space_dim = dimension(type). `reference_measure` is the area/volume of relative size 1
/// (the library's default is the mesh's mean cell measure); ≤ 0 gives relative size 0.
/// Lines and points give an invalid, all-zero result.
template <class Derived>
[[nodiscard]] KnuppQuality knupp_quality(ElementType type, const Eigen::MatrixBase<Derived>& coords,
                                         double reference_measure) {
  const auto& table = detail::knupp_table(shape(type));
  if (table.dim == 2 && coords.rows() >= 2) return detail::knupp_quality_fixed<2>(table, coords, reference_measure);
  if (table.dim == 3 && coords.rows() >= 3) return detail::knupp_quality_fixed<3>(table, coords, reference_measure);
  return {};
}

}  // namespace meshmotion
