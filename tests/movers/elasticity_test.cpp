// Mechanics movers: lineal and torsional springs, linear and stiffened elasticity, neo-Hookean.
#include "meshmotion/core/generators.hpp"
#include "meshmotion/curving/p2_conversion.hpp"
#include "meshmotion/movers/detail/fem_assembly.hpp"
#include "meshmotion/movers/elasticity.hpp"
#include "meshmotion/movers/nonlinear_elasticity.hpp"
#include "meshmotion/movers/spring.hpp"
#include "meshmotion/movers/torsion_spring.hpp"
#include "meshmotion/quality/cell_quality.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <random>

using namespace meshmotion;

namespace {

/// Every boundary-facet node of `mesh` prescribed with displacement f(x).
template <int Dim, class F>
ResolvedBoundary<Dim> prescribed_boundary(const Mesh<Dim>& mesh, F&& f) {
  std::vector<Index> nodes;
  for (const auto& b : mesh.facets) nodes.insert(nodes.end(), b.connectivity.begin(), b.connectivity.end());
  std::sort(nodes.begin(), nodes.end());
  nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
  ResolvedBoundary<Dim> r;
  r.nodes = nodes;
  r.kinds.assign(nodes.size(), BoundaryKind::prescribed);
  const auto m = static_cast<Index>(nodes.size());
  r.displacements.resize(Dim, m);
  r.normals.setZero(Dim, m);
  for (Index k = 0; k < m; ++k) r.displacements.col(k) = f(Vec<Dim>(mesh.points.col(nodes[static_cast<std::size_t>(k)])));
  return r;
}

/// Moves interior nodes randomly by up to `amount` of the grid spacing (fixed seed).
template <int Dim>
void perturb_interior(Mesh<Dim>& mesh, double amount) {
  std::vector<bool> boundary(static_cast<std::size_t>(mesh.num_nodes()), false);
  for (const auto& b : mesh.facets)
    for (const Index v : b.connectivity) boundary[static_cast<std::size_t>(v)] = true;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-amount, amount);
  for (Index i = 0; i < mesh.num_nodes(); ++i)
    if (!boundary[static_cast<std::size_t>(i)])
      for (int d = 0; d < Dim; ++d) mesh.points(d, i) += u(rng);
}

template <int Dim>
Mesh<Dim> with_order(const Mesh<Dim>& linear, int order, bool complete = true) {
  return order == 1 ? linear : to_quadratic(linear, P2Options{complete});
}

/// Largest |out(:, i) − f(x_i)| over all nodes.
template <int Dim, class F>
double max_error(const Mesh<Dim>& mesh, const Points<Dim>& out, F&& f) {
  double e = 0.0;
  for (Index i = 0; i < mesh.num_nodes(); ++i) e = std::max(e, (out.col(i) - f(Vec<Dim>(mesh.points.col(i)))).norm());
  return e;
}

template <int Dim>
double min_signed_jacobian(const Mesh<Dim>& mesh, const Points<Dim>& points) {
  double worst = std::numeric_limits<double>::infinity();
  for (const auto& block : mesh.cells) {
    const auto& table = detail::quadrature_table(block.type);
    detail::ElementCoords<Dim> x;
    detail::ElementGradients<Dim> g;
    Eigen::Matrix<double, Dim, Dim> jac;
    for (Index e = 0; e < block.size(); ++e) {
      detail::gather_coords(points, block, e, x);
      for (int q = 0; q < table.size(); ++q) worst = std::min(worst, detail::element_geometry<Dim>(table, q, x, g, jac));
    }
  }
  return worst;
}

Mesh<2> rectangle(RectangleCells cells, Index n = 4) {
  RectangleOptions o;
  o.nx = o.ny = n;
  o.cells = cells;
  return rectangle_mesh(o);
}

Mesh<3> box(BoxCells cells, Index n = 3) {
  BoxOptions o;
  o.nx = o.ny = o.nz = n;
  o.cells = cells;
  return box_mesh(o);
}

template <int Dim>
Eigen::Matrix<double, Dim, Dim> affine_gradient() {
  Eigen::Matrix<double, Dim, Dim> a;
  if constexpr (Dim == 2)
    a << 0.10, -0.05, 0.03, 0.08;
  else
    a << 0.10, -0.05, 0.02, 0.03, 0.08, -0.04, 0.01, 0.06, -0.07;
  return a;
}

template <int Dim>
void check_affine_patch(const Mesh<Dim>& mesh, double tolerance) {
  const Eigen::Matrix<double, Dim, Dim> a = affine_gradient<Dim>();
  const Vec<Dim> c = Vec<Dim>::Constant(0.02);
  const auto affine = [&](const Vec<Dim>& x) -> Vec<Dim> { return a * x + c; };
  const auto boundary = prescribed_boundary(mesh, affine);
  ElasticityMover<Dim> mover(ElasticityOptions{1.0, 0.35});
  mover.setup(mesh, boundary);
  const Points<Dim> out = mover.move(boundary.displacements);
  CHECK(max_error(mesh, out, affine) < tolerance);
}

}  // namespace

TEST_CASE("linear elasticity reproduces affine motions on every P1 and P2 element type", "[movers]") {
  for (const auto cells : {RectangleCells::tri3, RectangleCells::quad4, RectangleCells::tri_quad}) {
    Mesh<2> linear = rectangle(cells);
    perturb_interior(linear, 0.05);
    for (const int order : {1, 2})
      for (const bool complete : {true, false}) {
        if (order == 1 && !complete) continue;
        INFO("2D cells " << static_cast<int>(cells) << " order " << order << " complete " << complete);
        check_affine_patch(with_order(linear, order, complete), 1e-10);
      }
  }
  for (const auto cells : {BoxCells::hex8, BoxCells::tet4, BoxCells::prism6, BoxCells::pyramid5, BoxCells::hex_prism,
                           BoxCells::tet_pyramid_prism}) {
    Mesh<3> linear = box(cells);
    perturb_interior(linear, 0.04);
    for (const int order : {1, 2})
      for (const bool complete : {true, false}) {
        if (order == 1 && !complete) continue;
        INFO("3D cells " << static_cast<int>(cells) << " order " << order << " complete " << complete);
        check_affine_patch(with_order(linear, order, complete), 1e-9);
      }
  }
}
