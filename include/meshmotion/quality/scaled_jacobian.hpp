#pragma once
/// \file
/// Scaled Jacobian of linear and curved (P2) elements, certified by Bézier bounds.
///
/// m = inf det J(ξ) / det J_lin (thesis eq. 3.3), where det J_lin is the Jacobian of the
/// straight-sided element at its barycentre (for quads, hexes and prisms the bi/trilinear map
/// at the centre, so a non-parallelogram quad has m < 1): Gmsh's definition, as reported by
/// its AnalyseMeshQuality (formerly AnalyseCurvedMesh) plugin.
///
/// The certified bound follows Johnen, Remacle & Geuzaine (J. Comput. Phys. 233, 2013):
/// det J is sampled on the lattice of its polynomial space, converted to Bézier coefficients,
/// whose minimum (maximum) bounds det J from below (above); the domain is subdivided where
/// the bound is further than `tolerance` from the sampled values. Types: every triangle,
/// quadrilateral, tetrahedron, hexahedron, prism and pyramid of the catalogue
/// (core/element.hpp: to order 8). A pyramid's det J, rational in its reference coordinates, is
/// a polynomial of its collapsed ones (quality/detail/jacobian_space.hpp), bounded there.

#include "meshmotion/core/element.hpp"
#include "meshmotion/core/error.hpp"
#include "meshmotion/core/mesh.hpp"
#include "meshmotion/core/threads.hpp"
#include "meshmotion/core/types.hpp"
#include "meshmotion/quality/detail/jacobian_space.hpp"

#include <Eigen/Core>
#include <Eigen/LU>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <span>
#include <string>
#include <type_traits>
#include <vector>

namespace meshmotion {

/// Options of the scaled-Jacobian check; each field is described once, in its visit_options()
/// (quality/quality_report.hpp).
struct ScaledJacobianOptions {
  bool certify = true;
  bool sharp = true;
  bool sharp_max = true;
  double tolerance = 1e-4;
  int max_depth = 10;
  int max_leaves = 4096;
};

/// Scaled Jacobian of one element. All values are det J / |det J_lin|: an inverted
/// straight-sided element gives negative values. Never NaN: an element with non-finite
/// coordinates or zero straight-sided measure (repeated nodes) is `degenerate`, invalid, and
/// all its values are 0.
struct ScaledJacobian {
  double certified_min = 0.0;  ///< certified lower bound of min det J / det J_lin
  double certified_max = 0.0;  ///< certified upper bound of max det J / det J_lin
  double sampled_min = 0.0;    ///< minimum over the sampling points (an upper bound of the true min)
  double sampled_max = 0.0;    ///< maximum over the sampling points
  double linear_det = 0.0;     ///< det J_lin (reference-to-straight-element Jacobian at the barycentre)
  bool valid = false;          ///< certified_min > 0
  bool certified = false;      ///< the bounds are Bézier bounds (false when certify = false)
  bool degenerate = false;     ///< non-finite coordinates or zero straight-sided measure
  int leaves = 0;              ///< subdomains used (1 without subdivision)

  /// min det J bound in physical units.
  [[nodiscard]] double min_det() const { return certified_min * std::abs(linear_det); }
  /// max det J bound in physical units.
  [[nodiscard]] double max_det() const { return certified_max * std::abs(linear_det); }
};

namespace detail {

template <int D>
using ElementCoords = Eigen::Matrix<double, D, Eigen::Dynamic, 0, D, max_element_nodes>;
// The lattice values of det J: on the stack up to a tet84's 816 points (every type but the
// hexahedra past order 3 and the tetrahedra past order 6), on the heap beyond (a hex729's
// 13,824). Sized for the largest, the stack frames of a P2 cell's certificate grew to 110 KiB
// and it ran 6 times slower.
using LatticeVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, max_lattice_points, 1>;
using LargeLatticeVector = Eigen::VectorXd;

// One pass of apply_factors: to[o, r, i] = Σ_b f(r, b) from[o, b, i], as whole rows over i (the
// compiler vectorizes them) or, on the last axis (inner = 1), as sums kept in a register. The
// factor sizes are compile-time constants: with 2–6 terms a runtime trip count costs more than
// the arithmetic (a third off the certification of the curved coarse 3D bump).
template <int In, int Out>
void factor_pass_fixed(const double* f, Index outer, Index inner, const double* from, double* to) {
  // f is column-major Out × In: f(r, b) = f[r + b * Out].
  if (inner == 1) {
    for (Index o = 0; o < outer; ++o, from += In, to += Out)
      for (int r = 0; r < Out; ++r) {
        double sum = 0.0;
        for (int b = 0; b < In; ++b) sum += f[r + b * Out] * from[b];
        to[r] = sum;
      }
    return;
  }
  for (Index o = 0; o < outer; ++o, from += In * inner, to += Out * inner)
    for (int r = 0; r < Out; ++r) {
      double* row = to + r * inner;
      for (Index i = 0; i < inner; ++i) {
        double sum = 0.0;
        for (int b = 0; b < In; ++b) sum += f[r + b * Out] * from[b * inner + i];
        row[i] = sum;
      }
    }
}

inline void factor_pass(const Eigen::MatrixXd& f, Index outer, Index inner, const double* from, double* to) {
  const Index in_len = f.cols(), out_len = f.rows();
  // Every line factor of the catalogue (P1/P2 lines: 2–6 lattice points); simplex factors of
  // other sizes take the generic loop.
  const auto dispatch = [&]<int In>(std::integral_constant<int, In>) {
    switch (out_len) {
      case 2: return factor_pass_fixed<In, 2>(f.data(), outer, inner, from, to), true;
      case 3: return factor_pass_fixed<In, 3>(f.data(), outer, inner, from, to), true;
      case 4: return factor_pass_fixed<In, 4>(f.data(), outer, inner, from, to), true;
      case 5: return factor_pass_fixed<In, 5>(f.data(), outer, inner, from, to), true;
      case 6: return factor_pass_fixed<In, 6>(f.data(), outer, inner, from, to), true;
      default: return false;
    }
  };
  bool done = false;
  switch (in_len) {
    case 2: done = dispatch(std::integral_constant<int, 2>{}); break;
    case 3: done = dispatch(std::integral_constant<int, 3>{}); break;
    case 4: done = dispatch(std::integral_constant<int, 4>{}); break;
    case 5: done = dispatch(std::integral_constant<int, 5>{}); break;
    case 6: done = dispatch(std::integral_constant<int, 6>{}); break;
    default: break;
  }
  if (done) return;
  if (inner == 1) {
    // A simplex's factor on its own (a tet's 84 lattice points at P3): Eigen's matrix product
    // runs down f's columns in vector registers, where one sum per row waited on each term
    // (4–8 times slower from 20 points up; the subdivision of P3 tets was a quarter of curving
    // the sphere).
    Eigen::Map<Eigen::MatrixXd>(to, out_len, outer).noalias() = f * Eigen::Map<const Eigen::MatrixXd>(from, in_len, outer);
    return;
  }
  for (Index o = 0; o < outer; ++o, from += in_len * inner, to += out_len * inner)
    for (Index r = 0; r < out_len; ++r) {
      double* row = to + r * inner;
      for (Index i = 0; i < inner; ++i) row[i] = f(r, 0) * from[i];
      for (Index b = 1; b < in_len; ++b) {
        const double w = f(r, b);
        const double* in = from + b * inner;
        for (Index i = 0; i < inner; ++i) row[i] += w * in[i];
      }
    }
}

// values ← (F_0 ⊗ F_1 ⊗ ...) values on the lattice order (simplex index outermost, then the line
// coordinates, the last fastest): one pass of a small matrix per factor. A factor may be
// rectangular (rows × cols maps an axis of cols entries to rows entries). The last axis goes
// first, while the data is smallest: its pass is the one that cannot be vectorized.
template <class Lattice>
void apply_factors(std::span<const Eigen::MatrixXd* const> factors, Lattice& values) {
  thread_local Lattice out;
  std::array<Index, 4> sizes{};
  for (std::size_t a = 0; a < factors.size(); ++a) sizes[a] = factors[a]->cols();
  for (std::size_t a = factors.size(); a-- > 0;) {
    const Eigen::MatrixXd& f = *factors[a];
    Index outer = 1, inner = 1;
    for (std::size_t b = 0; b < a; ++b) outer *= sizes[b];
    for (std::size_t b = a + 1; b < factors.size(); ++b) inner *= sizes[b];
    sizes[a] = f.rows();
    out.resize(outer * f.rows() * inner);
    factor_pass(f, outer, inner, values.data(), out.data());
    values.swap(out);
  }
}

// det J at every lattice point, divided by `scale`. The transposed Jacobians (row point · D +
// reference direction, column physical coordinate) come by sum factorization for complete
// quadrilaterals, hexahedra and prisms of order 2 on, for pyramids on their collapsed cube,
// otherwise as the product of the shape-gradient table with the coordinates.
template <int D, class Lattice>
void lattice_dets(const JacobianSpace& s, const ElementCoords<D>& x, double scale, Lattice& values) {
  thread_local Eigen::Matrix<double, Eigen::Dynamic, D> jacobians;
  jacobians.resize(static_cast<Index>(s.num_points) * D, D);
  if (!s.tensor_node.empty()) {
    std::array<const Eigen::MatrixXd*, D> f{};
    Lattice v;
    for (int c = 0; c < D; ++c)
      for (int d = 0; d < D; ++d) {
        v.resize(static_cast<Index>(s.tensor_node.size()));
        for (std::size_t q = 0; q < s.tensor_node.size(); ++q) v(static_cast<Index>(q)) = x(c, s.tensor_node[q]);
        for (int l = 0; l < D; ++l) f[static_cast<std::size_t>(l)] = l == d ? &s.line_derivatives : &s.line_values;
        apply_factors(f, v);
        for (int j = 0; j < s.num_points; ++j) jacobians(static_cast<Index>(j) * D + d, c) = v(j);
      }
  } else if (!s.prism_node.empty()) {
    // Along the line first (Y = X L^T, per triangle node), then across the triangle.
    const Index nt = s.prism_triangle[0].cols(), nl = s.line_values.cols(), nr = s.line_values.rows();
    const Index na = s.prism_triangle[0].rows();
    // Per thread, as `jacobians`: a certificate of a mesh allocates them once, not per cell.
    thread_local Eigen::MatrixXd nodes, along, across, slope;
    nodes.resize(nt, nl);
    for (int c = 0; c < D; ++c) {
      for (Index k = 0; k < nt; ++k)
        for (Index l = 0; l < nl; ++l) nodes(k, l) = x(c, s.prism_node[static_cast<std::size_t>(k * nl + l)]);
      along.noalias() = nodes * s.line_values.transpose();
      slope.noalias() = nodes * s.line_derivatives.transpose();
      for (int d = 0; d < D; ++d) {
        across.noalias() = d < 2 ? s.prism_triangle[static_cast<std::size_t>(d + 1)] * along : s.prism_triangle[0] * slope;
        for (Index a = 0; a < na; ++a)
          for (Index r = 0; r < nr; ++r) jacobians((a * nr + r) * D + d, c) = across(a, r);
      }
    }
  } else if (!s.pyramid_ab.empty()) {
    // On the collapsed cube: the map's coefficients in the type's terms, gathered per (a, b) at
    // each w of the lattice, then across û and v̂ (JacobianSpace::pyramid_ab).
    const Index nl = s.line_degree + 1, q = s.pyramid_f.cols();
    thread_local Eigen::MatrixXd terms, ma, mc, du, dv, dw;
    terms.noalias() = x * s.pyramid_coefficients.transpose();
    for (Index r = 0; r < nl; ++r)
      for (int c = 0; c < D; ++c) {
        ma.setZero(q, q);
        mc.setZero(q, q);
        for (std::size_t k = 0; k < s.pyramid_ab.size(); ++k) {
          const auto [a, b] = s.pyramid_ab[k];
          ma(a, b) += terms(c, static_cast<Index>(k)) * s.pyramid_wa(r, static_cast<Index>(k));
          mc(a, b) += terms(c, static_cast<Index>(k)) * s.pyramid_wc(r, static_cast<Index>(k));
        }
        du.noalias() = s.pyramid_df * ma * s.pyramid_f.transpose();
        dv.noalias() = s.pyramid_f * ma * s.pyramid_df.transpose();
        dw.noalias() = s.pyramid_f * mc * s.pyramid_f.transpose();
        for (Index i = 0; i < nl; ++i)
          for (Index j = 0; j < nl; ++j) {
            const Index row = ((i * nl + j) * nl + r) * D;
            jacobians(row, c) = du(i, j);
            jacobians(row + 1, c) = dv(i, j);
            jacobians(row + 2, c) = dw(i, j);
          }
      }
  } else {
    // Coefficient-wise: sums kept in registers beat read-modify-write passes over memory
    // (hex8 2.2 -> 1.5 µs per cell), and no GEMM dispatch.
    jacobians.noalias() = s.gradients.lazyProduct(x.transpose());
  }
  values.resize(s.num_points);
  for (int j = 0; j < s.num_points; ++j)
    values(j) = Eigen::Matrix<double, D, D>(jacobians.template middleRows<D>(static_cast<Index>(j) * D)).determinant() * scale;
}

// values ← Bézier coefficients of the lattice values.
template <class Lattice>
void to_bezier(const JacobianSpace& s, Lattice& values) {
  std::array<const Eigen::MatrixXd*, 4> f{};
  int count = 0;
  if (s.simplex_dim > 0) f[static_cast<std::size_t>(count++)] = &s.simplex.to_bezier;
  for (int l = 0; l < s.line_dims; ++l) f[static_cast<std::size_t>(count++)] = &s.line.to_bezier;
  apply_factors(std::span<const Eigen::MatrixXd* const>(f.data(), static_cast<std::size_t>(count)), values);
}

// visit(coefficients) for every child of a subdivision, from its parent's coefficients. The
// last factor is applied first, so children that differ only in earlier factors share the
// passes over the later ones: a hex's 8 children take 2 + 4 + 8 passes instead of 24, and
// only 2 of them are the unvectorized last-axis kind.
template <class Lattice, class Visit>
void for_each_child(const JacobianSpace& s, const Lattice& parent, Visit&& visit) {
  const int count = (s.simplex_dim > 0 ? 1 : 0) + s.line_dims;
  std::array<Index, 4> sizes{};
  for (int a = 0; a < count; ++a)
    sizes[static_cast<std::size_t>(a)] = (a == 0 && s.simplex_dim > 0) ? s.simplex.to_bezier.cols() : s.line.to_bezier.cols();
  thread_local std::array<Lattice, 4> levels;
  const auto descend = [&](const auto& self, int a, const Lattice& from) -> void {
    if (a < 0) {
      visit(from);
      return;
    }
    Index outer = 1, inner = 1;
    for (int b = 0; b < a; ++b) outer *= sizes[static_cast<std::size_t>(b)];
    for (int b = a + 1; b < count; ++b) inner *= sizes[static_cast<std::size_t>(b)];
    Lattice& to = levels[static_cast<std::size_t>(a)];
    if (a == 0 && s.simplex_dim > 0 && s.simplex.child_bezier.empty()) {
      // A tetrahedron past order 6 (no line factor: outer = inner = 1).
      for (const auto& vertices : s.simplex.child_vertices) {
        to.resize(from.size());
        tet_child_coefficients(s.simplex_degree, vertices, from.data(), to.data());
        self(self, a - 1, to);
      }
      return;
    }
    const auto& choices = (a == 0 && s.simplex_dim > 0) ? s.simplex.child_bezier : s.line.child_bezier;
    for (const auto& factor : choices) {
      to.resize(from.size());
      factor_pass(factor, outer, inner, from.data(), to.data());
      self(self, a - 1, to);
    }
  };
  descend(descend, count - 1, parent);
}

template <int D>
double linear_det(const JacobianSpace& s, const ElementCoords<D>& x) {
  Eigen::Matrix<double, D, D> jac = Eigen::Matrix<double, D, D>::Zero();
  const int nv = static_cast<int>(s.linear_gradients.size()) / D;
  for (int i = 0; i < nv; ++i)
    for (int d = 0; d < D; ++d) jac.col(d) += x.col(i) * s.linear_gradients[static_cast<std::size_t>(i * D + d)];
  return jac.determinant();
}

template <class Lattice>
struct BezierLeaf {
  Lattice coefficients;
  double min = 0.0, max = 0.0;
  int depth = 0;
};

template <class Lattice>
BezierLeaf<Lattice> make_leaf(const JacobianSpace& s, Lattice values, int depth) {
  to_bezier(s, values);
  BezierLeaf<Lattice> leaf{std::move(values), 0.0, 0.0, depth};
  leaf.min = leaf.coefficients.minCoeff();
  leaf.max = leaf.coefficients.maxCoeff();
  return leaf;
}

// Leaves of one cell's subdivision held at most: a hex729's leaf is 110 KB, and max_leaves of
// them would be 450 MB per thread. The bound stays a bound when the cap is reached.
inline constexpr std::size_t max_leaf_bytes = std::size_t{64} << 20;

// Adaptive subdivision (Johnen et al. 2013, sec. 4): refine the leaf whose bound is furthest
// from the best sampled value until every gap is within tolerance.
template <class Lattice>
void certify(const JacobianSpace& s, const Lattice& values, const ScaledJacobianOptions& opt, ScaledJacobian& r) {
  // Reused per thread: the common case (no subdivision) then allocates nothing.
  thread_local std::vector<BezierLeaf<Lattice>> leaves;
  leaves.clear();
  const int max_leaves = static_cast<int>(std::min<std::size_t>(
      static_cast<std::size_t>(std::max(opt.max_leaves, 1)),
      max_leaf_bytes / (sizeof(double) * static_cast<std::size_t>(std::max(s.num_points, 1)))));
  leaves.push_back(make_leaf(s, values, 0));
  double upper_min = r.sampled_min, lower_max = r.sampled_max;
  for (;;) {
    std::size_t worst_min = 0, worst_max = 0;
    for (std::size_t k = 1; k < leaves.size(); ++k) {
      if (leaves[k].min < leaves[worst_min].min) worst_min = k;
      if (leaves[k].max > leaves[worst_max].max) worst_max = k;
    }
    const double lower_min = leaves[worst_min].min, upper_max = leaves[worst_max].max;
    r.certified_min = lower_min;
    r.certified_max = upper_max;
    const bool decided = lower_min > 0 || upper_min <= 0;
    const bool min_sharp = upper_min - lower_min <= opt.tolerance;
    const bool max_sharp = !opt.sharp_max || upper_max - lower_max <= opt.tolerance;
    if (opt.sharp ? (min_sharp && max_sharp) : decided) break;
    const std::size_t pick = (opt.sharp && min_sharp) ? worst_max : worst_min;
    if (leaves[pick].depth >= opt.max_depth ||
        static_cast<int>(leaves.size()) + s.num_children() > max_leaves)
      break;
    const BezierLeaf<Lattice> parent = leaves[pick];
    leaves.erase(leaves.begin() + static_cast<std::ptrdiff_t>(pick));
    // Children's coefficients straight from the parent's (one pass per axis instead of two);
    // their corner coefficients are values of det J and tighten the sampled extremes.
    for_each_child(s, parent.coefficients, [&](const Lattice& coefficients) {
      BezierLeaf<Lattice> leaf{coefficients, 0.0, 0.0, parent.depth + 1};
      leaf.min = leaf.coefficients.minCoeff();
      leaf.max = leaf.coefficients.maxCoeff();
      for (const int k : s.corners) {
        upper_min = std::min(upper_min, leaf.coefficients(k));
        lower_max = std::max(lower_max, leaf.coefficients(k));
      }
      leaves.push_back(std::move(leaf));
    });
  }
  r.leaves = static_cast<int>(leaves.size());
  r.sampled_min = std::min(r.sampled_min, upper_min);
  r.sampled_max = std::max(r.sampled_max, lower_max);
}

template <int D>
ScaledJacobian scaled_jacobian_fixed(ElementType type, const ElementCoords<D>& x, const ScaledJacobianOptions& opt) {
  const JacobianSpace& s = jacobian_space(type);
  ScaledJacobian r;
  if (!x.allFinite()) {
    r.degenerate = true;
    return r;
  }
  // Zero straight-sided measure relative to the element's extent means repeated or collinear
  // vertices: the ratio is meaningless, the element is degenerate.
  const auto vertices = x.leftCols(num_vertices(type));
  const double extent = (vertices.rowwise().maxCoeff() - vertices.rowwise().minCoeff()).maxCoeff();
  const double lin = linear_det<D>(s, x);
  r.linear_det = lin;
  if (!(std::abs(lin) > 1e-12 * std::pow(extent, D))) {
    r.degenerate = true;
    return r;
  }
  // A straight-sided cell (every node where its linear cell's map puts it: most cells of a
  // curved mesh, away from the walls) has its linear cell's Jacobian, a polynomial of far
  // lower degree (a hex27's 216 Bézier coefficients become a hex8's 27).
  if (s.linear_embedding.size() > 0) {
    const double tolerance = 1e-12 * extent;
    const ElementCoords<D> straight = vertices.lazyProduct(s.linear_embedding);  // no GEMM dispatch for 3 × 8 × 27
    if (((x - straight).cwiseAbs().array() <= tolerance).all())
      return scaled_jacobian_fixed<D>(linear_type(type), ElementCoords<D>(vertices), opt);
  }
  const auto bound = [&]<class Lattice>(Lattice values) {
    lattice_dets<D>(s, x, 1.0 / std::abs(lin), values);
    r.sampled_min = r.certified_min = values.minCoeff();
    r.sampled_max = r.certified_max = values.maxCoeff();
    r.leaves = 1;
    if (opt.certify && s.bezier) {
      r.certified = true;
      certify(s, values, opt, r);
    }
  };
  if (s.num_points <= max_lattice_points)
    bound(LatticeVector{});
  else
    bound(LargeLatticeVector{});
  r.valid = r.certified_min > 0;
  return r;
}

}  // namespace detail

/// Scaled Jacobian of one cell. `coords` is D × num_nodes(type), D = dimension(type) = 2 or 3
/// (a column per local node, Gmsh order). Throws InputError for other shapes.
template <class Derived>
[[nodiscard]] ScaledJacobian scaled_jacobian(ElementType type, const Eigen::MatrixBase<Derived>& coords,
                                             const ScaledJacobianOptions& options = {}) {
  const int d = dimension(type);
  if (d < 2 || coords.rows() != d || coords.cols() != num_nodes(type))
    throw InputError("scaled_jacobian: " + std::string(name(type)) + " needs a " + std::to_string(d) + " × " +
                     std::to_string(num_nodes(type)) + " coordinate matrix of a 2D or 3D element (got " +
                     std::to_string(coords.rows()) + " × " + std::to_string(coords.cols()) + ")");
  if (d == 2) {
    const detail::ElementCoords<2> x = coords.template topRows<2>();
    return detail::scaled_jacobian_fixed<2>(type, x, options);
  }
  const detail::ElementCoords<3> x = coords.template topRows<3>();
  return detail::scaled_jacobian_fixed<3>(type, x, options);
}

/// Scaled Jacobian of every cell of `mesh`, in cell order (OpenMP over cells when enabled).
/// Precondition: node indices in range (see validate()).
template <int Dim>
[[nodiscard]] std::vector<ScaledJacobian> scaled_jacobians(const Mesh<Dim>& mesh, const ScaledJacobianOptions& options = {}) {
  std::vector<ScaledJacobian> out(static_cast<std::size_t>(mesh.num_cells()));
  Index offset = 0;
  for (const auto& block : mesh.cells) {
    const Index n = block.size();
    const int nn = block.nodes_per_element();
    if (dimension(block.type) != Dim)
      throw InputError("scaled_jacobians: a " + std::to_string(Dim) + "D mesh has a cell block of " +
                       std::string(name(block.type)) + " (expected elements of dimension " + std::to_string(Dim) + ")");
    (void)detail::jacobian_space(block.type);  // build the tables before the threads start
    detail::RegionErrors errors;
#if defined(_OPENMP)
#pragma omp parallel for num_threads(::meshmotion::num_threads()) schedule(dynamic, 256)
#endif
    for (Index e = 0; e < n; ++e)
      errors.run([&] {
        detail::ElementCoords<Dim> x(Dim, nn);
        const auto nodes = block.element(e);
        for (int i = 0; i < nn; ++i) x.col(i) = mesh.points.col(nodes[static_cast<std::size_t>(i)]);
        out[static_cast<std::size_t>(offset + e)] = detail::scaled_jacobian_fixed<Dim>(block.type, x, options);
      });
    errors.rethrow();
    offset += n;
  }
  return out;
}

}  // namespace meshmotion
