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
/// the bound is further than `tolerance` from the sampled values. Types: tri3/6, quad4/8/9,
/// tet4/10, hex8/20/27, prism6/15/18. Pyramids (rational maps) are sampled only: there
/// `certified` is false and the "certified" bounds are the sampled extremes.

#include "meshmotion/core/element.hpp"
#include "meshmotion/core/error.hpp"
#include "meshmotion/core/mesh.hpp"
#include "meshmotion/core/types.hpp"
#include "meshmotion/quality/detail/jacobian_space.hpp"

#include <Eigen/Core>
#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace meshmotion {

/// Options of the scaled-Jacobian check.
struct ScaledJacobianOptions {
  bool certify = true;        ///< false: sampled extremes only (fast screening)
  bool sharp = true;          ///< refine both bounds to `tolerance`; false: stop once validity is decided
  bool sharp_max = true;      ///< with `sharp`: refine the upper bound too (false when only the minimum is used)
  double tolerance = 1e-4;    ///< wanted gap between Bézier bound and sampled extreme (scaled units)
  int max_depth = 10;         ///< deepest subdivision level
  int max_leaves = 4096;      ///< subdomains per element at most (the bound stays a bound when hit)
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
  bool valid = false;          ///< certified_min > 0 (sampled_min > 0 for pyramids)
  bool certified = false;      ///< the bounds are Bézier bounds (false for pyramids and when certify = false)
  bool degenerate = false;     ///< non-finite coordinates or zero straight-sided measure
  int leaves = 0;              ///< subdomains used (1 without subdivision)

  /// min det J bound in physical units.
  [[nodiscard]] double min_det() const { return certified_min * std::abs(linear_det); }
  /// max det J bound in physical units.
  [[nodiscard]] double max_det() const { return certified_max * std::abs(linear_det); }
};

namespace detail {

template <int D>
using ElementCoords = Eigen::Matrix<double, D, Eigen::Dynamic, 0, D, 27>;
using LatticeVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 216, 1>;

template <int D>
double det_at(const JacobianSpace& s, const ElementCoords<D>& x, int point) {
  Eigen::Matrix<double, D, D> jac = Eigen::Matrix<double, D, D>::Zero();
  const double* g = s.gradients.data() + static_cast<std::size_t>(point) * static_cast<std::size_t>(s.num_nodes * D);
  for (int i = 0; i < s.num_nodes; ++i)
    for (int d = 0; d < D; ++d) jac.col(d) += x.col(i) * g[i * D + d];
  return jac.determinant();
}

template <int D>
double linear_det(const JacobianSpace& s, const ElementCoords<D>& x) {
  Eigen::Matrix<double, D, D> jac = Eigen::Matrix<double, D, D>::Zero();
  const int nv = static_cast<int>(s.linear_gradients.size()) / D;
  for (int i = 0; i < nv; ++i)
    for (int d = 0; d < D; ++d) jac.col(d) += x.col(i) * s.linear_gradients[static_cast<std::size_t>(i * D + d)];
  return jac.determinant();
}

struct BezierLeaf {
  LatticeVector coefficients;
  double min = 0.0, max = 0.0;
  int depth = 0;
};

inline BezierLeaf make_leaf(const JacobianSpace& s, const LatticeVector& values, int depth) {
  BezierLeaf leaf{s.lag2bez * values, 0.0, 0.0, depth};
  leaf.min = leaf.coefficients.minCoeff();
  leaf.max = leaf.coefficients.maxCoeff();
  return leaf;
}

// Adaptive subdivision (Johnen et al. 2013, sec. 4): refine the leaf whose bound is furthest
// from the best sampled value until every gap is within tolerance.
inline void certify(const JacobianSpace& s, const LatticeVector& values, const ScaledJacobianOptions& opt,
                    ScaledJacobian& r) {
  // Reused per thread: the common case (no subdivision) then allocates nothing.
  thread_local std::vector<BezierLeaf> leaves;
  leaves.clear();
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
        static_cast<int>(leaves.size() + s.child_values.size()) > opt.max_leaves)
      break;
    const BezierLeaf parent = leaves[pick];
    leaves.erase(leaves.begin() + static_cast<std::ptrdiff_t>(pick));
    for (const auto& child : s.child_values) {
      const LatticeVector v = child * parent.coefficients;
      upper_min = std::min(upper_min, v.minCoeff());
      lower_max = std::max(lower_max, v.maxCoeff());
      leaves.push_back(make_leaf(s, v, parent.depth + 1));
    }
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
  const double scale = 1.0 / std::abs(lin);
  LatticeVector values(s.num_points);
  for (int j = 0; j < s.num_points; ++j) values(j) = det_at<D>(s, x, j) * scale;
  r.sampled_min = r.certified_min = values.minCoeff();
  r.sampled_max = r.certified_max = values.maxCoeff();
  r.leaves = 1;
  if (opt.certify && s.bezier) {
    r.certified = true;
    certify(s, values, opt, r);
  }
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
#if defined(_OPENMP)
#pragma omp parallel for schedule(dynamic, 256)
#endif
    for (Index e = 0; e < n; ++e) {
      detail::ElementCoords<Dim> x(Dim, nn);
      const auto nodes = block.element(e);
      for (int i = 0; i < nn; ++i) x.col(i) = mesh.points.col(nodes[static_cast<std::size_t>(i)]);
      out[static_cast<std::size_t>(offset + e)] = detail::scaled_jacobian_fixed<Dim>(block.type, x, options);
    }
    offset += n;
  }
  return out;
}

}  // namespace meshmotion
