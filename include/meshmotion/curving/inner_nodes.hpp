#pragma once
/// \file
/// Nodes inside the faces and cells of a curved element, placed from the nodes around them.
///
/// Past order 2 a triangle has nodes inside it, and a tetrahedron inside its faces and itself.
/// When a wall edge is curved, those nodes must follow it: left at their straight place they
/// pinch the cell near the curved edge.
/// Each such node takes the discrete harmonic extension of the displacements of the nodes
/// around it (the element's Laplacian on its straight shape, solved for the inside nodes):
/// faces first, from their edges, then the cell's inside, from its faces and edges. The
/// extension reproduces every affine motion exactly, lies in the element's own polynomial
/// space, and follows the straight shape's anisotropy (a thin boundary-layer cell spreads a
/// wall's displacement across its thickness, not along the wall).

#include "meshmotion/core/element.hpp"
#include "meshmotion/core/mesh.hpp"
#include "meshmotion/core/shape_functions.hpp"
#include "meshmotion/core/types.hpp"
#include "meshmotion/movers/detail/fem_assembly.hpp"

#include <Eigen/Dense>

#include <array>
#include <span>
#include <vector>

namespace meshmotion {

namespace detail {

/// First local node strictly inside an element of type t (num_nodes(t) when none): after the
/// vertices and edge nodes of a 2D element, after the face nodes of a 3D one.
[[nodiscard]] constexpr int first_inside_node(ElementType t) {
  if (!element_info(t).complete || order(t) < 2) return num_nodes(t);
  if (dimension(t) == 3) return first_face_node(t, static_cast<int>(face_order(shape(t)).size()));
  return num_vertices(t) + static_cast<int>(edges(t).size()) * (order(t) - 1);
}

// Row vector of ∂^(du,dv,dw) N_i(x) over the nodes i of `type`.
inline Eigen::RowVectorXd shape_derivative_row(ElementType type, const RefPoint& x, int du, int dv, int dw) {
  const ShapeBasis& basis = shape_basis(type);
  Eigen::RowVectorXd row = Eigen::RowVectorXd::Zero(static_cast<Index>(basis.nodes.size()));
  for (std::size_t k = 0; k < basis.monomials.size(); ++k) {
    const double d = term_derivative(basis.monomials[k], x, du, dv, dw);
    if (d != 0.0) row += d * basis.coefficients.row(static_cast<Index>(k));
  }
  return row;
}

// The ordered tuples of `count` reference directions among the first `dims`: each as the
// number of times it takes each direction.
inline std::vector<std::array<int, 3>> direction_tuples(int dims, int count) {
  std::vector<std::array<int, 3>> out;
  int total = 1;
  for (int k = 0; k < count; ++k) total *= dims;
  for (int code = 0; code < total; ++code) {
    std::array<int, 3> times{};
    for (int k = 0, c = code; k < count; ++k, c /= dims) ++times[static_cast<std::size_t>(c % dims)];
    out.push_back(times);
  }
  return out;
}

// How many orders below p the energy of a simplex of order p adds (simplex_energy()): one
// from order 4, and down to the lowest degree of the element's inside functions (the bubble
// λ0λ1λ2, degree 3, of a triangle; λ0λ1λ2λ3, degree 4, of a tetrahedron), below which none of
// them has a derivative to penalize.
inline int lower_energy_orders(ElementType type) {
  const int p = order(type);
  return std::max(p >= 4 ? 1 : 0, p - dimension(type) - 1);
}

// The derivatives of order p - j (j = 0 .. lower_energy_orders()) of the nodal basis of a
// simplex of order p at its centroid: row r is ∂^tuple N_i for the ordered direction tuple r
// of direction_tuples(d, p - j).
inline const Eigen::MatrixXd& simplex_derivatives(ElementType type, int j) {
  static PerTypeCache<std::vector<Eigen::MatrixXd>> all;
  return all.get(type, [](ElementType t) {
    std::vector<Eigen::MatrixXd> out;
    for (int k = 0; k <= lower_energy_orders(t); ++k) {
      const auto tuples = direction_tuples(dimension(t), order(t) - k);
      Eigen::MatrixXd& rows = out.emplace_back(static_cast<Index>(tuples.size()), num_nodes(t));
      for (std::size_t r = 0; r < tuples.size(); ++r)
        rows.row(static_cast<Index>(r)) = shape_derivative_row(t, reference_centroid(t), tuples[r][0], tuples[r][1], tuples[r][2]);
    }
    return out;
  })[static_cast<std::size_t>(j)];
}

// The energy of a tensor shape or prism in reference coordinates (fixed per type): the
// integral of (∂ξ²∂η² u)² on quadrilaterals, (∂ξ²∂η²∂ζ² u)² on hexahedra, and of the squared
// (u, v) derivatives of order p of ∂w² u on prisms. Their kernels are the functions linear in
// one direction (transfinite interpolation) and, on prisms, those of lower degree across or
// linear along, which the minimizer reproduces from the boundary.
inline Eigen::MatrixXd reference_energy(ElementType type) {
  const int n = num_nodes(type), p = order(type);
  std::vector<std::pair<std::array<int, 3>, double>> derivatives;  // (orders, weight)
  switch (shape(type)) {
    case Shape::quadrilateral: derivatives.push_back({{2, 2, 0}, 1.0}); break;
    case Shape::hexahedron: derivatives.push_back({{2, 2, 2}, 1.0}); break;
    case Shape::prism:
      for (const auto& t : direction_tuples(2, p)) derivatives.push_back({{t[0], t[1], 2}, 1.0});
      break;
    default: return {};
  }
  Eigen::MatrixXd energy = Eigen::MatrixXd::Zero(n, n);
  for (const auto& qp : quadrature_rule(shape(type), 2 * p))
    for (const auto& [orders, weight] : derivatives) {
      const Eigen::RowVectorXd row = shape_derivative_row(type, qp.xi, orders[0], orders[1], orders[2]);
      energy.noalias() += qp.weight * weight * row.transpose() * row;
    }
  return energy;
}

inline const Eigen::MatrixXd& cached_reference_energy(ElementType type) {
  static PerTypeCache<Eigen::MatrixXd> all;
  return all.get(type, [](ElementType t) { return order(t) >= 2 && element_info(t).complete ? reference_energy(t) : Eigen::MatrixXd{}; });
}

// The straight element's Laplacian (the fallback on pyramids, whose rational space has no
// simple lowest-degree lift): the element's space holds the straight map, so its gradients
// give the straight Jacobian. Empty for a degenerate straight element.
template <int Dim>
Eigen::MatrixXd straight_laplacian(ElementType type, const Eigen::Matrix<double, Dim, Eigen::Dynamic>& straight) {
  const int n = num_nodes(type), d = dimension(type);
  const QuadratureTable& table = quadrature_table(type);
  Eigen::MatrixXd stiffness = Eigen::MatrixXd::Zero(n, n);
  Eigen::MatrixXd grad(d, n);
  for (int q = 0; q < table.size(); ++q) {
    for (int i = 0; i < n; ++i)
      for (int r = 0; r < d; ++r) grad(r, i) = table.gradients[static_cast<std::size_t>(q * n + i)][static_cast<std::size_t>(r)];
    const Eigen::MatrixXd jacobian = straight * grad.transpose();  // Dim × d
    const Eigen::MatrixXd metric = jacobian.transpose() * jacobian;
    const double volume = std::sqrt(std::max(metric.determinant(), 0.0));
    if (!(volume > 0.0)) return {};
    stiffness.noalias() += table.weights[static_cast<std::size_t>(q)] * volume * grad.transpose() * metric.inverse() * grad;
  }
  return stiffness;
}

// The squared norm of a derivative tensor (rows: ordered direction tuples, base-d digits) in
// the straight element's own coordinates: Σ T[a] T[b] Π M[a_k][b_k] over tuples, M the inverse
// metric, computed by contracting each slot with the Cholesky factor of M.
inline Eigen::MatrixXd tensor_energy(Eigen::MatrixXd tensor, const Eigen::MatrixXd& factor) {
  const auto d = factor.rows();
  for (Index stride = 1; stride < tensor.rows(); stride *= d) {
    Eigen::MatrixXd next = Eigen::MatrixXd::Zero(tensor.rows(), tensor.cols());
    for (Index row = 0; row < tensor.rows(); ++row) {
      const Index digit = (row / stride) % d;
      const Index base = row - digit * stride;
      for (Index c = 0; c < d; ++c) next.row(base + c * stride) += factor(digit, c) * tensor.row(row);
    }
    tensor = std::move(next);
  }
  return tensor.transpose() * tensor;
}

// On a simplex of order p: the squared norm of the p-th derivatives in the straight element's
// coordinates (invariant under its symmetries), whose minimizer reproduces the boundary data of
// a polynomial of degree p - 1. From order 4 the cubic bubble has no p-th derivative, so a
// small share of the lower derivatives' norms (orders p - 1 down to the lowest bubble's degree,
// each scaled to the same trace) picks a low-degree one among the minimizers; past order 4 a
// single order below p would leave the bubbles of lower degree free.
template <int Dim>
Eigen::MatrixXd simplex_energy(ElementType type, const Eigen::Matrix<double, Dim, Eigen::Dynamic>& straight) {
  const int n = num_nodes(type), d = dimension(type);
  const QuadratureTable& table = quadrature_table(type);
  Eigen::MatrixXd grad(d, n);
  for (int i = 0; i < n; ++i)
    for (int r = 0; r < d; ++r) grad(r, i) = table.gradients[static_cast<std::size_t>(i)][static_cast<std::size_t>(r)];
  const Eigen::MatrixXd jacobian = straight * grad.transpose();
  const Eigen::MatrixXd metric = jacobian.transpose() * jacobian;
  if (!(metric.determinant() > 0.0)) return {};
  const Eigen::MatrixXd factor = Eigen::LLT<Eigen::MatrixXd>(metric.inverse()).matrixL();
  Eigen::MatrixXd energy = tensor_energy(simplex_derivatives(type, 0), factor);
  const double share = 1e-8 * energy.trace();
  for (int j = 1; j <= lower_energy_orders(type); ++j) {
    const Eigen::MatrixXd lower = tensor_energy(simplex_derivatives(type, j), factor);
    energy += share / lower.trace() * lower;
  }
  return energy;
}

/// Moves the nodes of one element listed in `inside` (local indices) to the lowest-degree
/// extension of the other nodes' displacements from the straight element through the
/// vertices (see place_inner_nodes()). `x` holds the element's nodes (Dim × num_nodes(type),
/// element order); the element may be a face in 3D (dimension(type) < Dim).
template <int Dim>
void extend_inside(ElementType type, Eigen::Ref<Eigen::Matrix<double, Dim, Eigen::Dynamic>> x, std::span<const int> inside) {
  const int n = num_nodes(type);
  const int nv = num_vertices(type);
  const auto nodes = reference_nodes(type);
  // The straight place of every node: the linear map of the vertices.
  Eigen::Matrix<double, Dim, Eigen::Dynamic> straight(Dim, n);
  std::array<double, 8> linear{};
  for (int i = 0; i < n; ++i) {
    shape_functions(linear_type(type), nodes[static_cast<std::size_t>(i)], linear);
    straight.col(i).setZero();
    for (int k = 0; k < nv; ++k) straight.col(i) += linear[static_cast<std::size_t>(k)] * x.col(k);
  }
  Eigen::MatrixXd energy;
  switch (shape(type)) {
    case Shape::triangle:
    case Shape::tetrahedron: energy = simplex_energy<Dim>(type, straight); break;
    case Shape::pyramid: energy = straight_laplacian<Dim>(type, straight); break;
    default: energy = cached_reference_energy(type); break;
  }
  if (energy.size() == 0) return;  // a degenerate straight element: nothing sensible to extend
  std::vector<char> is_inside(static_cast<std::size_t>(n), 0);
  for (const int i : inside) is_inside[static_cast<std::size_t>(i)] = 1;
  std::vector<int> outside;
  for (int i = 0; i < n; ++i)
    if (!is_inside[static_cast<std::size_t>(i)]) outside.push_back(i);
  const auto ni = static_cast<Index>(inside.size());
  const auto no = static_cast<Index>(outside.size());
  Eigen::MatrixXd kii(ni, ni), kio(ni, no), known(no, Dim);
  for (Index a = 0; a < ni; ++a) {
    for (Index b = 0; b < ni; ++b) kii(a, b) = energy(inside[static_cast<std::size_t>(a)], inside[static_cast<std::size_t>(b)]);
    for (Index b = 0; b < no; ++b) kio(a, b) = energy(inside[static_cast<std::size_t>(a)], outside[static_cast<std::size_t>(b)]);
  }
  for (Index b = 0; b < no; ++b) {
    const int i = outside[static_cast<std::size_t>(b)];
    known.row(b) = (x.col(i) - straight.col(i)).transpose();
  }
  const Eigen::LDLT<Eigen::MatrixXd> solver(kii);
  if (solver.info() != Eigen::Success) return;
  const Eigen::MatrixXd moved = solver.solve(-kio * known);  // ni × Dim
  for (Index a = 0; a < ni; ++a) {
    const int i = inside[static_cast<std::size_t>(a)];
    x.col(i) = straight.col(i) + moved.row(a).transpose();
  }
}

}  // namespace detail

/// Places the nodes inside the faces and cells of every cell that holds a node of `curved`
/// (node flags): each face's inside nodes from the face's edges, then each cell's inside nodes
/// from all its other nodes, by the extension of the file comment. A face or cell keeps its
/// inside nodes when one of them is `fixed` (faces on the geometry; in the pipeline also nodes
/// the regularization moved, whose smooth field knows more than the edges: a face of a thin
/// layer over a curved wall must take the wall face's shape, which its edges do not hold).
/// Cells without inside nodes (P1, P2 triangles and tetrahedra, serendipity types) are left as
/// they are.
template <int Dim>
void place_inner_nodes(Mesh<Dim>& mesh, std::span<const char> curved, std::span<const char> fixed) {
  std::vector<char> done(static_cast<std::size_t>(mesh.num_nodes()), 0);
  Eigen::Matrix<double, Dim, Eigen::Dynamic> x;
  for (const auto& block : mesh.cells) {
    const ElementType t = block.type;
    const int first_inside = detail::first_inside_node(t);
    const int n = num_nodes(t);
    if (num_vertices(t) + static_cast<int>(edges(t).size()) * (order(t) - 1) >= n) continue;  // vertices and edges only
    for (Index c = 0; c < block.size(); ++c) {
      const auto el = block.element(c);
      bool touches = false;
      for (const Index v : el) touches = touches || curved[static_cast<std::size_t>(v)];
      if (!touches) continue;
      if constexpr (Dim == 3) {
        for (int f = 0; f < static_cast<int>(facets(t).size()); ++f) {
          std::array<int, max_facet_nodes> local{};
          const int m = facet_nodes(t, f, local);
          const ElementType ft = facet_type(t, f);
          const int face_first = detail::first_inside_node(ft);
          if (face_first >= m) continue;
          const Index key = el[static_cast<std::size_t>(local[static_cast<std::size_t>(face_first)])];
          if (done[static_cast<std::size_t>(key)]) continue;
          done[static_cast<std::size_t>(key)] = 1;
          bool kept = false;
          for (int k = face_first; k < m; ++k) kept = kept || fixed[static_cast<std::size_t>(el[static_cast<std::size_t>(local[static_cast<std::size_t>(k)])])];
          if (kept) continue;
          x.resize(Dim, m);
          for (int k = 0; k < m; ++k) x.col(k) = mesh.points.col(el[static_cast<std::size_t>(local[static_cast<std::size_t>(k)])]);
          std::array<int, max_facet_nodes> inside{};
          for (int k = face_first; k < m; ++k) inside[static_cast<std::size_t>(k - face_first)] = k;
          detail::extend_inside<Dim>(ft, x, std::span<const int>(inside.data(), static_cast<std::size_t>(m - face_first)));
          for (int k = face_first; k < m; ++k) mesh.points.col(el[static_cast<std::size_t>(local[static_cast<std::size_t>(k)])]) = x.col(k);
        }
      }
      bool kept = first_inside == n;
      for (int k = first_inside; k < n; ++k) kept = kept || fixed[static_cast<std::size_t>(el[static_cast<std::size_t>(k)])];
      if (kept) continue;
      x.resize(Dim, n);
      for (int k = 0; k < n; ++k) x.col(k) = mesh.points.col(el[static_cast<std::size_t>(k)]);
      std::array<int, max_element_nodes> inside{};
      for (int k = first_inside; k < n; ++k) inside[static_cast<std::size_t>(k - first_inside)] = k;
      detail::extend_inside<Dim>(t, x, std::span<const int>(inside.data(), static_cast<std::size_t>(n - first_inside)));
      for (int k = first_inside; k < n; ++k) mesh.points.col(el[static_cast<std::size_t>(k)]) = x.col(k);
    }
  }
}

}  // namespace meshmotion
