#pragma once
/// \file
/// Element integration shared by the mechanics movers: quadrature rules per reference shape,
/// per-type tables of shape functions and reference gradients at the quadrature points, the
/// geometry of one element at a quadrature point (Jacobian, its determinant, physical
/// gradients), and triplet assembly of element matrices with per-thread storage.
///
/// Rules: optimal symmetric rules on triangles (degree 0, 2, 4) and tetrahedra (degree 0, 2),
/// Gauss–Legendre tensor products on quadrilaterals, hexahedra and prisms (triangle rule ×
/// line), and a collapsed (Duffy) Gauss rule on pyramids and for higher simplex degrees.
/// The default rule of a type integrates the stiffness of an affine element exactly
/// (polynomial degree 2(p-1) on simplices, full Gauss integration on tensor elements).

#include "meshmotion/core/element.hpp"
#include "meshmotion/core/error.hpp"
#include "meshmotion/core/mesh.hpp"
#include "meshmotion/core/shape_functions.hpp"
#include "meshmotion/core/threads.hpp"
#include "meshmotion/core/types.hpp"
#include "meshmotion/solvers/linear_solver.hpp"

#include <Eigen/Core>
#include <Eigen/LU>
#include <Eigen/SparseCore>

#include <algorithm>
#include <array>
#include <cmath>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#ifdef _OPENMP
#include <omp.h>
#endif

namespace meshmotion::detail {

/// One quadrature point of a reference element.
struct QuadraturePoint {
  RefPoint xi;
  double weight;
};

/// Gauss–Legendre nodes and weights on [-1, 1] with n points (exact to degree 2n - 1).
[[nodiscard]] inline std::vector<std::array<double, 2>> gauss_legendre(int n) {
  std::vector<std::array<double, 2>> out;
  constexpr double pi = 3.14159265358979323846;
  for (int i = 0; i < n; ++i) {
    // Newton on P_n from the Chebyshev guess; converges in a few steps for n ≤ 20.
    double x = std::cos(pi * (i + 0.75) / (n + 0.5));
    double derivative = 1.0;
    for (int it = 0; it < 100; ++it) {
      double p0 = 1.0, p1 = x;
      for (int k = 2; k <= n; ++k) {
        const double p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      derivative = n * (x * p1 - p0) / (x * x - 1.0);
      const double step = p1 / derivative;
      x -= step;
      if (std::abs(step) < 1e-16) break;
    }
    out.push_back({x, 2.0 / ((1.0 - x * x) * derivative * derivative)});
  }
  return out;
}

/// Collapsed Gauss rule with n points per direction on a triangle, tetrahedron or pyramid.
[[nodiscard]] inline std::vector<QuadraturePoint> collapsed_rule(Shape s, int n) {
  const auto g = gauss_legendre(n);
  std::vector<QuadraturePoint> out;
  // Gauss points mapped to [0, 1].
  std::vector<std::array<double, 2>> t;
  for (const auto& [x, w] : g) t.push_back({0.5 * (x + 1.0), 0.5 * w});
  if (s == Shape::triangle) {
    for (const auto& [a, wa] : t)
      for (const auto& [b, wb] : t) out.push_back({{a * (1.0 - b), b, 0.0}, wa * wb * (1.0 - b)});
  } else if (s == Shape::tetrahedron) {
    for (const auto& [a, wa] : t)
      for (const auto& [b, wb] : t)
        for (const auto& [c, wc] : t)
          out.push_back({{a * (1.0 - b) * (1.0 - c), b * (1.0 - c), c}, wa * wb * wc * (1.0 - b) * (1.0 - c) * (1.0 - c)});
  } else {  // pyramid: base [-1,1]² shrinking to the apex at w = 1
    for (const auto& [x, wx] : g)
      for (const auto& [y, wy] : g)
        for (const auto& [c, wc] : t)
          out.push_back({{x * (1.0 - c), y * (1.0 - c), c}, wx * wy * wc * (1.0 - c) * (1.0 - c)});
  }
  return out;
}

/// A quadrature rule on the reference element of shape `s` exact for polynomials of degree
/// `degree` (for pyramids: of the collapsed-coordinate degree).
[[nodiscard]] inline std::vector<QuadraturePoint> quadrature_rule(Shape s, int degree) {
  const int gauss_points = degree / 2 + 1;
  switch (s) {
    case Shape::triangle:
      if (degree <= 0) return {{{1.0 / 3.0, 1.0 / 3.0, 0.0}, 0.5}};
      if (degree <= 2) return {{{1.0 / 6.0, 1.0 / 6.0, 0.0}, 1.0 / 6.0}, {{2.0 / 3.0, 1.0 / 6.0, 0.0}, 1.0 / 6.0},
                               {{1.0 / 6.0, 2.0 / 3.0, 0.0}, 1.0 / 6.0}};
      if (degree <= 4) {
        // Dunavant's 6-point degree-4 rule.
        constexpr double a = 0.445948490915965, wa = 0.223381589678011 / 2.0;
        constexpr double b = 0.091576213509771, wb = 0.109951743655322 / 2.0;
        return {{{a, a, 0}, wa}, {{1 - 2 * a, a, 0}, wa}, {{a, 1 - 2 * a, 0}, wa},
                {{b, b, 0}, wb}, {{1 - 2 * b, b, 0}, wb}, {{b, 1 - 2 * b, 0}, wb}};
      }
      return collapsed_rule(s, gauss_points + 1);
    case Shape::tetrahedron:
      if (degree <= 0) return {{{0.25, 0.25, 0.25}, 1.0 / 6.0}};
      if (degree <= 2) {
        constexpr double a = 0.5854101966249685, b = 0.1381966011250105, w = 1.0 / 24.0;
        return {{{b, b, b}, w}, {{a, b, b}, w}, {{b, a, b}, w}, {{b, b, a}, w}};
      }
      return collapsed_rule(s, gauss_points + 1);
    case Shape::quadrilateral: {
      std::vector<QuadraturePoint> out;
      const auto g = gauss_legendre(gauss_points);
      for (const auto& [x, wx] : g)
        for (const auto& [y, wy] : g) out.push_back({{x, y, 0.0}, wx * wy});
      return out;
    }
    case Shape::hexahedron: {
      std::vector<QuadraturePoint> out;
      const auto g = gauss_legendre(gauss_points);
      for (const auto& [x, wx] : g)
        for (const auto& [y, wy] : g)
          for (const auto& [z, wz] : g) out.push_back({{x, y, z}, wx * wy * wz});
      return out;
    }
    case Shape::prism: {
      std::vector<QuadraturePoint> out;
      const auto g = gauss_legendre(gauss_points);
      for (const auto& tri : quadrature_rule(Shape::triangle, degree))
        for (const auto& [z, wz] : g) out.push_back({{tri.xi[0], tri.xi[1], z}, tri.weight * wz});
      return out;
    }
    case Shape::pyramid: return collapsed_rule(s, gauss_points + 1);
    case Shape::point:
    case Shape::line: break;
  }
  return {};
}

/// Shape function values and reference gradients of one cell type at its default quadrature
/// points: values[q * n + i] = N_i(ξ_q), gradients[q * n + i][d] = ∂N_i/∂ξ_d.
struct QuadratureTable {
  int num_nodes = 0;
  std::vector<double> weights;
  std::vector<double> values;
  std::vector<std::array<double, 3>> gradients;

  [[nodiscard]] int size() const noexcept { return static_cast<int>(weights.size()); }
};

/// Polynomial degree the default rule of `type` integrates exactly (see the file comment).
[[nodiscard]] constexpr int default_quadrature_degree(ElementType type) {
  const int p = order(type);
  switch (shape(type)) {
    case Shape::triangle:
    case Shape::tetrahedron: return 2 * (p - 1);
    case Shape::prism: return 2 * p;  // P_p(u,v) ⊗ P_p(w) products reach degree 2p in (u, v)
    default: return 2 * p;           // tensor and pyramid: p + 1 Gauss points per direction
  }
}

[[nodiscard]] inline QuadratureTable make_quadrature_table(ElementType type, int degree) {
  QuadratureTable t;
  t.num_nodes = num_nodes(type);
  const auto n = static_cast<std::size_t>(t.num_nodes);
  for (const auto& qp : quadrature_rule(shape(type), degree)) {
    t.weights.push_back(qp.weight);
    const std::size_t at = t.values.size();
    t.values.resize(at + n);
    t.gradients.resize(at + n);
    shape_functions(type, qp.xi, std::span<double>(t.values.data() + at, n));
    shape_derivatives(type, qp.xi, std::span<std::array<double, 3>>(t.gradients.data() + at, n));
  }
  return t;
}

/// The default table of a cell type (built on its first use, thread-safe).
[[nodiscard]] inline const QuadratureTable& quadrature_table(ElementType type) {
  static PerTypeCache<QuadratureTable> tables;
  return tables.get(type, [](ElementType t) {
    return dimension(t) >= 2 ? make_quadrature_table(t, default_quadrature_degree(t)) : QuadratureTable{};
  });
}

// Per-cell storage on the heap, kept per thread by the assembly loops: cells of every order fit
// (a hex729's element matrix is 2,187 square), where the stack held cells of up to 40 nodes
// (Eigen's 128 KiB) and refused a hex64.

/// Node coordinates of one element: Dim × n.
template <int Dim>
using FemCoords = Eigen::Matrix<double, Dim, Eigen::Dynamic>;

/// Physical gradients of the shape functions at a quadrature point: n × Dim.
template <int Dim>
using ElementGradients = Eigen::Matrix<double, Eigen::Dynamic, Dim>;

/// Element matrix with Dim dofs per node in node-major order (a * Dim + i).
template <int Dim>
using ElementMatrix = Eigen::MatrixXd;

/// Geometry of an element at quadrature point q: the Jacobian J = ∂x/∂ξ (Dim × Dim), its
/// determinant, and the physical gradients G = (∂N/∂ξ) J⁻¹ (n × Dim). Returns det J.
template <int Dim>
double element_geometry(const QuadratureTable& table, int q, const FemCoords<Dim>& x, ElementGradients<Dim>& g,
                        Eigen::Matrix<double, Dim, Dim>& jacobian) {
  const int n = table.num_nodes;
  thread_local ElementGradients<Dim> reference;
  reference.resize(n, Dim);
  for (int i = 0; i < n; ++i)
    for (int d = 0; d < Dim; ++d) reference(i, d) = table.gradients[static_cast<std::size_t>(q * n + i)][static_cast<std::size_t>(d)];
  jacobian.noalias() = x * reference;
  const double det = jacobian.determinant();
  g.resize(n, Dim);
  g.noalias() = reference * jacobian.inverse();
  return det;
}

/// Size measure of an element at a quadrature point: |det J| times the reference measure,
/// i.e. the element's area/volume for affine elements of any type (thesis eq. 2.8's J_κ,
/// made comparable across element types of a mixed mesh).
[[nodiscard]] inline double reference_measure(ElementType type) {
  switch (shape(type)) {
    case Shape::triangle: return 0.5;
    case Shape::quadrilateral: return 4.0;
    case Shape::tetrahedron: return 1.0 / 6.0;
    case Shape::hexahedron: return 8.0;
    case Shape::prism: return 1.0;
    case Shape::pyramid: return 4.0 / 3.0;
    default: return 1.0;
  }
}

/// Appends the element matrix k (node-major, Dim dofs per node) of a cell with global
/// `nodes` as triplets.
template <int Dim, class Triplets>
void scatter_element_matrix(std::span<const Index> nodes, const ElementMatrix<Dim>& k, Triplets& out) {
  const auto n = static_cast<int>(nodes.size());
  for (int a = 0; a < n; ++a)
    for (int b = 0; b < n; ++b)
      for (int i = 0; i < Dim; ++i)
        for (int j = 0; j < Dim; ++j)
          out.emplace_back(static_cast<int>(nodes[static_cast<std::size_t>(a)] * Dim + i),
                           static_cast<int>(nodes[static_cast<std::size_t>(b)] * Dim + j), k(a * Dim + i, b * Dim + j));
}

/// Lamé parameters of an isotropic material.
struct Lame {
  double lambda;
  double mu;
};

/// λ = Eν/((1+ν)(1−2ν)), μ = E/(2(1+ν)) (plane strain in 2D). Throws InputError unless E > 0
/// and −1 < ν < 1/2.
[[nodiscard]] inline Lame lame_parameters(double youngs_modulus, double poisson_ratio, const std::string& where) {
  if (!(youngs_modulus > 0.0) || !std::isfinite(youngs_modulus))
    throw InputError(where + ": Young's modulus must be positive (got " + std::to_string(youngs_modulus) + ")");
  if (!(poisson_ratio > -1.0 && poisson_ratio < 0.5))
    throw InputError(where + ": Poisson ratio must lie in (-1, 0.5) (got " + std::to_string(poisson_ratio) + ")");
  const double e = youngs_modulus, nu = poisson_ratio;
  return {e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)), e / (2.0 * (1.0 + nu))};
}

/// Adds the isotropic linear-elastic stiffness of one quadrature point (thesis eqs. 2.3–2.5,
/// Galerkin): K[(a,i),(b,j)] += c (λ G_ai G_bj + μ G_aj G_bi + μ δ_ij G_a·G_b).
template <int Dim>
void add_elastic_stiffness(const ElementGradients<Dim>& g, double lambda, double mu, double c, ElementMatrix<Dim>& k) {
  const auto n = static_cast<int>(g.rows());
  for (int a = 0; a < n; ++a)
    for (int b = 0; b < n; ++b) {
      const double dot = mu * g.row(a).dot(g.row(b));
      for (int i = 0; i < Dim; ++i)
        for (int j = 0; j < Dim; ++j)
          k(a * Dim + i, b * Dim + j) += c * (lambda * g(a, i) * g(b, j) + mu * g(a, j) * g(b, i) + (i == j ? dot : 0.0));
    }
}

/// True when cell e of `block` has a node flagged in `nodes` (every cell when it is empty).
[[nodiscard]] inline bool touches(const ElementBlock& block, Index e, const std::vector<bool>& nodes) {
  if (nodes.empty()) return true;
  for (const Index v : block.element(e))
    if (nodes[static_cast<std::size_t>(v)]) return true;
  return false;
}

/// The pattern of a matrix with `components` dofs per node (node-major) coupling every pair
/// of nodes that share a cell touching a node of `only_touching` (any cell when empty):
/// column-major with sorted rows, values zero. `neighbours` gets each node's sorted
/// neighbours (itself included) from `start`.
template <int Dim>
[[nodiscard]] SparseMatrix cell_pattern(const Mesh<Dim>& mesh, Index components, const std::vector<bool>& only_touching,
                                        std::vector<Index>& start, std::vector<Index>& neighbours) {
  const Index n = mesh.num_nodes();
  std::vector<Index> cell_start(static_cast<std::size_t>(n) + 1, 0);
  for (const auto& block : mesh.cells)
    for (Index e = 0; e < block.size(); ++e)
      if (touches(block, e, only_touching))
        for (const Index v : block.element(e)) ++cell_start[static_cast<std::size_t>(v) + 1];
  for (Index v = 0; v < n; ++v) cell_start[static_cast<std::size_t>(v) + 1] += cell_start[static_cast<std::size_t>(v)];
  // Each node's cells as (block, element).
  std::vector<std::pair<Index, Index>> incidence(static_cast<std::size_t>(cell_start.back()));
  std::vector<Index> fill(cell_start.begin(), cell_start.end() - 1);
  for (Index b = 0; b < static_cast<Index>(mesh.cells.size()); ++b) {
    const ElementBlock& block = mesh.cells[static_cast<std::size_t>(b)];
    for (Index e = 0; e < block.size(); ++e)
      if (touches(block, e, only_touching))
        for (const Index v : block.element(e)) incidence[static_cast<std::size_t>(fill[static_cast<std::size_t>(v)]++)] = {b, e};
  }
  start.assign(static_cast<std::size_t>(n) + 1, 0);
  neighbours.clear();
  std::vector<Index> mark(static_cast<std::size_t>(n), -1);
  for (Index v = 0; v < n; ++v) {
    const std::size_t first = neighbours.size();
    for (Index k = cell_start[static_cast<std::size_t>(v)]; k < cell_start[static_cast<std::size_t>(v) + 1]; ++k) {
      const auto [b, e] = incidence[static_cast<std::size_t>(k)];
      for (const Index w : mesh.cells[static_cast<std::size_t>(b)].element(e))
        if (mark[static_cast<std::size_t>(w)] != v) {
          mark[static_cast<std::size_t>(w)] = v;
          neighbours.push_back(w);
        }
    }
    std::sort(neighbours.begin() + static_cast<std::ptrdiff_t>(first), neighbours.end());
    start[static_cast<std::size_t>(v) + 1] = static_cast<Index>(neighbours.size());
  }
  const Index c = components;
  SparseMatrix pattern(n * c, n * c);
  pattern.resizeNonZeros(static_cast<Index>(neighbours.size()) * c * c);
  int* outer = pattern.outerIndexPtr();
  int* inner = pattern.innerIndexPtr();
  Index at = 0;
  for (Index v = 0; v < n; ++v)
    for (Index j = 0; j < c; ++j) {
      outer[v * c + j] = static_cast<int>(at);
      for (Index k = start[static_cast<std::size_t>(v)]; k < start[static_cast<std::size_t>(v) + 1]; ++k)
        for (Index i = 0; i < c; ++i) inner[at++] = static_cast<int>(neighbours[static_cast<std::size_t>(k)] * c + i);
    }
  outer[n * c] = static_cast<int>(at);
  std::fill(pattern.valuePtr(), pattern.valuePtr() + at, 0.0);
  return pattern;
}

/// Sparse matrix (size × size, size / nodes dofs per node, node-major) from per-cell
/// contributions over the cells of `mesh`: `cell(block, element, out)` appends that cell's
/// entries with out.emplace_back(row, column, value), between nodes of the cell (duplicates
/// add), and must not throw. With `only_touching` (one flag per node) only the cells touching
/// a flagged node are assembled. The pattern couples every pair of nodes sharing such a cell
/// (cell_pattern). Cells are computed by OpenMP threads a chunk at a time, each thread with
/// its own list reserved for `per_node_pair` entries per pair of cell nodes, and the lists are
/// added in cell order: the sums do not depend on the threads, and the memory is the matrix's
/// and one chunk's (one list of every cell's entries took 2.2 GB for 80k hexahedra).
template <int Dim, class CellFn>
[[nodiscard]] SparseMatrix assemble(const Mesh<Dim>& mesh, Index size, Index per_node_pair, CellFn&& cell,
                                    const std::vector<bool>& only_touching = {}) {
  using Triplet = Eigen::Triplet<double, int>;
#ifdef _OPENMP
  const auto threads = static_cast<std::size_t>(::meshmotion::num_threads());
#else
  const std::size_t threads = 1;
#endif
  const Index nodes = mesh.num_nodes();
  const Index c = nodes > 0 ? size / nodes : 1;
  std::vector<Index> start, neighbours;
  SparseMatrix k = cell_pattern(mesh, c, only_touching, start, neighbours);
  const int* outer = k.outerIndexPtr();
  double* values = k.valuePtr();
  // Entries come in runs of one node pair (an element matrix's c × c block).
  Index last_row_node = -1, last_column_node = -1, slot = 0;
  const auto add = [&](const Triplet& t) {
    const Index row_node = t.row() / c, column_node = t.col() / c;
    if (row_node != last_row_node || column_node != last_column_node) {
      const auto first = neighbours.begin() + static_cast<std::ptrdiff_t>(start[static_cast<std::size_t>(column_node)]);
      const auto last = neighbours.begin() + static_cast<std::ptrdiff_t>(start[static_cast<std::size_t>(column_node) + 1]);
      const auto found = std::lower_bound(first, last, row_node);
      if (found == last || *found != row_node)
        throw std::logic_error("assemble: an entry between nodes that share no cell");
      slot = static_cast<Index>(found - first);
      last_row_node = row_node;
      last_column_node = column_node;
    }
    values[outer[t.col()] + slot * c + t.row() % c] += t.value();
  };
  constexpr Index chunk_per_thread = 1024;
  std::vector<std::vector<Triplet>> lists(threads);
  for (Index b = 0; b < static_cast<Index>(mesh.cells.size()); ++b) {
    const ElementBlock& block = mesh.cells[static_cast<std::size_t>(b)];
    const Index n_cells = block.size();
    const Index per_cell = per_node_pair * num_nodes(block.type) * num_nodes(block.type);
    for (auto& l : lists) l.reserve(static_cast<std::size_t>(chunk_per_thread * per_cell));
    for (Index begin = 0; begin < n_cells; begin += chunk_per_thread * static_cast<Index>(threads)) {
      const Index end = std::min(n_cells, begin + chunk_per_thread * static_cast<Index>(threads));
      detail::RegionErrors errors;
      // Static schedule: thread t takes the t-th contiguous run, so adding the lists in
      // thread order adds the cells in order.
#pragma omp parallel for num_threads(::meshmotion::num_threads()) schedule(static)
      for (Index e = begin; e < end; ++e) {
#ifdef _OPENMP
        std::vector<Triplet>& mine = lists[static_cast<std::size_t>(omp_get_thread_num())];
#else
        std::vector<Triplet>& mine = lists[0];
#endif
        if (touches(block, e, only_touching)) errors.run([&] { cell(b, e, mine); });
      }
      errors.rethrow();
      for (auto& l : lists) {
        for (const Triplet& t : l) add(t);
        l.clear();
      }
    }
  }
  return k;
}

/// Node coordinates of element e of `block` into x (Dim × n).
template <int Dim>
void gather_coords(const Points<Dim>& points, const ElementBlock& block, Index e, FemCoords<Dim>& x) {
  const auto nodes = block.element(e);
  x.resize(Dim, static_cast<Index>(nodes.size()));
  for (std::size_t i = 0; i < nodes.size(); ++i) x.col(static_cast<Index>(i)) = points.col(nodes[i]);
}

}  // namespace meshmotion::detail
