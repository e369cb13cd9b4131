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
#include <numbers>
#include <string>
#include <type_traits>

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

TEST_CASE("derivatives of the RBF set up at rest, which blends each move's rigid part, agree with finite differences",
          "[movers]") {
  // Set up with nothing moving, then moved far: a large turn (and translation) plus a small
  // random part. The fit and the blend are not linear in the displacements; their derivatives
  // (through the polar decomposition and SO(3)'s left Jacobian) must still be exact, at nodes
  // that take the whole fit, a share of it, and none.
  const auto check = [](const auto& mesh, const auto& boundary, const auto& turn) {
    constexpr int Dim = std::remove_cvref_t<decltype(mesh)>::dim;
    CAPTURE(Dim);
    AnyMover<Dim> mover = make_mover<Dim>("rbf");
    mover.setup(mesh, boundary);
    REQUIRE(mover.stats().rigid_part);
    Points<Dim> d = test::random_displacements<Dim>(boundary.size(), 1, 1e-3);
    Points<Dim> w = test::random_displacements<Dim>(boundary.size(), 2, 1.0);
    for (Index k = 0; k < boundary.size(); ++k) {
      const Vec<Dim> x = mesh.points.col(boundary.nodes[static_cast<std::size_t>(k)]);
      if (boundary.kinds[static_cast<std::size_t>(k)] == BoundaryKind::prescribed) {
        d.col(k) += turn(x) - x;
      } else {
        d.col(k).setZero();
        w.col(k).setZero();
      }
    }
    const Points<Dim> v = test::random_displacements<Dim>(mesh.num_nodes(), 3, 1.0);
    (void)mover.move(d);  // the derivatives are those at the last move
    const Points<Dim> jw = mover.derivative_forward(w);
    const Points<Dim> jtv = mover.derivative_reverse(v);
    const double h = 1e-5;
    const Points<Dim> fd = (mover.move(d + h * w) - mover.move(d - h * w)) / (2.0 * h);
    CHECK((fd - jw).norm() <= 1e-7 * jw.norm());
    CHECK(dot<Dim>(jtv, w) == Approx(dot<Dim>(v, jw)).epsilon(1e-10));
    // Nodes between the body and the held wall take part of the turn: their derivative is not
    // the rigid one's or zero.
    CHECK(jw.norm() > 0.0);
  };
  {
    const Mesh<2> ring = annulus_mesh({.n_around = 32});
    BoundarySpec<2> spec;
    spec.moving("inner", Translation<2>{Vec<2>::Zero()}).fixed("outer");
    check(ring, spec.resolve(ring), [](const Vec<2>& x) { return Vec<2>(Eigen::Rotation2Dd(2.5) * x + Vec<2>(0.05, -0.02)); });
  }
  {
    const Mesh<3> box = box_mesh({.nx = 5, .ny = 5, .nz = 6, .z_max = 3.0, .cells = BoxCells::tet4});
    BoundarySpec<3> spec;
    spec.prescribed("bottom").fixed("top");
    const Eigen::AngleAxisd turn(2.2, Vec<3>(1.0, 2.0, 3.0).normalized());
    check(box, spec.resolve(box), [&](const Vec<3>& x) { return Vec<3>(turn * (x - Vec<3>(0.5, 0.5, 0.0)) + Vec<3>(0.5, 0.5, 0.1)); });
  }
}

TEST_CASE("grid velocities: every linear mover's velocity() is the rate of change of its positions in time",
          "[movers]") {
  // An ALE solver's protocol: set up once with no motion, then per step the positions
  // X + move(d(t)) and the velocities velocity(ḋ(t)); these must be the positions' rate of
  // change (the geometric conservation law), here against a central difference in time. The
  // inner wall of a ring pitches, θ(t) = 0.4 sin(2π t), the outer one is held; the RBF with
  // its default radius, which grows with the motion at the first steps.
  const Mesh<2> ring = annulus_mesh({.n_around = 32});
  BoundarySpec<2> spec;
  spec.moving("inner", Translation<2>{Vec<2>::Zero()}).fixed("outer");
  const ResolvedBoundary<2> boundary = spec.resolve(ring);
  const auto wall = [&](double t, bool rate) {
    const double angle = 0.4 * std::sin(2.0 * std::numbers::pi * t);
    const double speed = 0.4 * 2.0 * std::numbers::pi * std::cos(2.0 * std::numbers::pi * t);
    Points<2> out = Points<2>::Zero(2, boundary.size());
    for (Index k = 0; k < boundary.size(); ++k) {
      if (boundary.kinds[static_cast<std::size_t>(k)] != BoundaryKind::prescribed) continue;
      const Vec<2> r = Eigen::Rotation2Dd(angle) * Vec<2>(ring.points.col(boundary.nodes[static_cast<std::size_t>(k)]));
      out.col(k) = rate ? Vec<2>(speed * Vec<2>(-r.y(), r.x())) : Vec<2>(r - ring.points.col(boundary.nodes[static_cast<std::size_t>(k)]));
    }
    return out;
  };
  for (const std::string method : {"rbf", "spring", "le", "dgm"}) {
    CAPTURE(method);
    AnyMover<2> mover = make_mover<2>(method);
    mover.setup(ring, boundary);
    for (const double t : {0.05, 0.15, 0.3, 0.6}) {
      CAPTURE(t);
      (void)mover.move(wall(t, false));  // the step's move (the RBF may set up again here)
      const Points<2> velocity = mover.velocity(wall(t, true));
      const double h = 1e-5;
      const Points<2> difference = (mover.move(wall(t + h, false)) - mover.move(wall(t - h, false))) / (2.0 * h);
      CHECK((velocity - difference).colwise().norm().maxCoeff() <= 1e-8 * velocity.colwise().norm().maxCoeff());
      for (Index k = 0; k < boundary.size(); ++k)  // the wall's nodes at their own velocity, the held ones still
        CHECK((velocity.col(boundary.nodes[static_cast<std::size_t>(k)]) - wall(t, true).col(k)).norm() <= 1e-12);
    }
  }
  AnyMover<2> nonlinear = make_mover<2>("nle");
  nonlinear.setup(ring, boundary);
  CHECK_THROWS_WITH(nonlinear.velocity(wall(0.1, true)), Catch::Contains("not linear in the displacements"));
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
