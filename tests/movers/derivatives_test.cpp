// Derivatives of every mover linear in the boundary displacements (issue 18): the forward
// product against central finite differences of move(), the reverse product against the
// forward one (⟨v, J w⟩ = ⟨Jᵀ v, w⟩) and against finite differences of ⟨v, move(d)⟩, with
// prescribed, fixed and sliding groups in 2D and 3D, through the run-time registry.

#include "meshmotion/core/generators.hpp"
#include "meshmotion/movers.hpp"
#include "meshmotion/movers/boundary.hpp"

#include "random_field.hpp"

#include <catch2/catch.hpp>

#include <limits>
#include <string>

using namespace meshmotion;

namespace {

template <int Dim>
double dot(const Points<Dim>& a, const Points<Dim>& b) {
  return (a.array() * b.array()).sum();
}

template <int Dim>
void check_derivatives(const Mesh<Dim>& mesh, const ResolvedBoundary<Dim>& boundary, const std::string& method) {
  CAPTURE(method, Dim);
  AnyMover<Dim> mover = make_mover<Dim>(method, method == "rbf" ? KeyValues{{"support_radius", "0.8"}} : KeyValues{});
  REQUIRE(mover.has_derivatives());
  mover.setup(mesh, boundary);
  // Small displacements: the Delaunay graph of DGM must not fold at d ± h w.
  Points<Dim> d = test::random_displacements<Dim>(boundary.size(), 1, 1e-3);
  Points<Dim> w = test::random_displacements<Dim>(boundary.size(), 2, 1.0);
  for (Index k = 0; k < boundary.size(); ++k)
    if (boundary.kinds[static_cast<std::size_t>(k)] == BoundaryKind::fixed) {
      d.col(k).setZero();
      w.col(k).setZero();
    }
  const Points<Dim> v = test::random_displacements<Dim>(mesh.num_nodes(), 3, 1.0);

  const double h = 1e-4;
  const Points<Dim> fd = (mover.move(d + h * w) - mover.move(d - h * w)) / (2.0 * h);
  const Points<Dim> jw = mover.derivative_forward(w);
  REQUIRE(jw.norm() > 0.0);
  CHECK((fd - jw).norm() <= 1e-8 * jw.norm());

  const Points<Dim> jtv = mover.derivative_reverse(v);
  REQUIRE(jtv.cols() == boundary.size());
  CHECK(dot<Dim>(jtv, w) == Approx(dot<Dim>(v, jw)).epsilon(1e-10));
  // move() ignores the input of sliding nodes: their gradient is zero, not a spurious entry.
  for (Index k = 0; k < boundary.size(); ++k)
    if (boundary.kinds[static_cast<std::size_t>(k)] == BoundaryKind::sliding) CHECK(jtv.col(k).isZero(0.0));
  // One prescribed coordinate, by finite differences of ⟨v, move(d)⟩.
  Index k = 0;
  while (boundary.kinds[static_cast<std::size_t>(k)] != BoundaryKind::prescribed) ++k;
  Points<Dim> e = Points<Dim>::Zero(Dim, boundary.size());
  e(Dim - 1, k) = 1.0;
  const double fd_scalar = (dot<Dim>(v, mover.move(d + h * e)) - dot<Dim>(v, mover.move(d - h * e))) / (2.0 * h);
  CHECK(jtv(Dim - 1, k) == Approx(fd_scalar).epsilon(1e-8));
}

}  // namespace

TEST_CASE("derivatives of every linear mover agree with finite differences (2D, sliding sides)", "[movers]") {
  for (const auto cells : {RectangleCells::tri3, RectangleCells::quad4}) {
    const Mesh<2> mesh = rectangle_mesh({.nx = 9, .ny = 7, .cells = cells});
    BoundarySpec<2> spec;
    spec.prescribed("bottom").fixed("top").sliding("left").sliding("right");
    const auto boundary = spec.resolve(mesh);
    for (const std::string method : {"rbf", "spring", "torsion", "le", "sle", "dgm", "idgm", "dgrbf"}) check_derivatives(mesh, boundary, method);
  }
}

TEST_CASE("derivatives of every linear mover agree with finite differences (3D tetrahedra)", "[movers]") {
  const Mesh<3> mesh = box_mesh({.nx = 4, .ny = 3, .nz = 3, .cells = BoxCells::tet4});
  BoundarySpec<3> spec;
  spec.prescribed("bottom").fixed("top").sliding("left").fixed("right").fixed("front").fixed("back");
  const auto boundary = spec.resolve(mesh);
  for (const std::string method : {"rbf", "spring", "torsion", "le", "sle", "dgm", "idgm", "dgrbf"}) check_derivatives(mesh, boundary, method);
}

TEST_CASE("movers that are not linear in the displacements have no derivatives", "[movers]") {
  const Mesh<2> mesh = rectangle_mesh({.nx = 4, .ny = 4});
  BoundarySpec<2> spec;
  spec.prescribed("bottom").fixed("top").fixed("left").fixed("right");
  const auto boundary = spec.resolve(mesh);
  for (const std::string method : {"nle", "dgrbf2"}) {
    CAPTURE(method);
    AnyMover<2> mover = make_mover<2>(method);
    CHECK_FALSE(mover.has_derivatives());
    mover.setup(mesh, boundary);
    CHECK_THROWS_WITH(mover.derivative_reverse(Points<2>::Zero(2, mesh.num_nodes())), Catch::Contains("no derivatives"));
  }
}

TEST_CASE("derivatives refuse a missing setup and a seed of the wrong shape", "[movers]") {
  const Mesh<2> mesh = rectangle_mesh({.nx = 4, .ny = 4});
  BoundarySpec<2> spec;
  spec.prescribed("bottom").fixed("top");
  const auto boundary = spec.resolve(mesh);
  for (const std::string method : {"rbf", "sle", "dgm"}) {
    CAPTURE(method);
    AnyMover<2> mover = make_mover<2>(method);
    CHECK_THROWS_WITH(mover.derivative_reverse(Points<2>::Zero(2, mesh.num_nodes())), Catch::Contains("setup() was not called"));
    mover.setup(mesh, boundary);
    CHECK_THROWS_WITH(mover.derivative_reverse(Points<2>::Zero(2, 3)), Catch::Contains("expected " + std::to_string(mesh.num_nodes())));
    Points<2> v = Points<2>::Zero(2, mesh.num_nodes());
    v(1, 4) = std::numeric_limits<double>::quiet_NaN();
    CHECK_THROWS_WITH(mover.derivative_reverse(v), Catch::Contains("node 4 is not finite"));
    CHECK_THROWS_WITH(mover.derivative_forward(Points<2>::Zero(2, 2)), Catch::Contains("expected " + std::to_string(boundary.size())));
  }
}
