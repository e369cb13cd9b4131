// Delaunay-graph movers: DGM, DGRBF, DGRBF2 and the improved DGM (thesis sections 2.2.1,
// 2.2.3, 2.2.4): exact reproduction of the motions theory promises, boundary targets,
// repeated moves, inversion refusal, sliding walls and bad input.

#include "meshmotion/core/generators.hpp"
#include "meshmotion/movers.hpp"
#include "meshmotion/movers/dgm.hpp"
#include "meshmotion/movers/dgrbf.hpp"
#include "meshmotion/movers/dgrbf2.hpp"
#include "meshmotion/movers/improved_dgm.hpp"
#include "meshmotion/quality/quality_report.hpp"

#include "messages.hpp"

#include <catch2/catch.hpp>

#include <limits>
#include <string>

using namespace meshmotion;

namespace {

Mesh<2> square(Index n = 12) {
  RectangleOptions o;
  o.nx = o.ny = n;
  o.cells = RectangleCells::tri3;
  return rectangle_mesh(o);
}

Mesh<3> cube(Index n = 5) {
  BoxOptions o;
  o.nx = o.ny = o.nz = n;
  return box_mesh(o);
}

Mesh<2> ellipse(Index around = 64, Index radial = 24) {
  OMeshOptions o;
  o.semi_axis_x = 0.5;
  o.semi_axis_y = 0.25;
  o.n_around = around;
  o.n_radial = radial;
  o.first_height = 1e-3;
  o.farfield_radius = 5.0;
  return o_mesh(o);
}

/// Every named group of `mesh` moving by `motion`.
template <int Dim>
BoundarySpec<Dim> all_moving(const Mesh<Dim>& mesh, const Motion<Dim>& motion) {
  BoundarySpec<Dim> spec;
  for (const auto& g : mesh.groups) spec.moving(g.name, motion);
  return spec;
}

/// Largest distance between each node's mapped position and where `motion` puts it.
template <int Dim>
double motion_error(const Mesh<Dim>& mesh, const Points<Dim>& u, const Motion<Dim>& motion) {
  double worst = 0.0;
  for (Index i = 0; i < mesh.num_nodes(); ++i)
    worst = std::max(worst, (mesh.points.col(i) + u.col(i) - motion.position(mesh.points.col(i))).norm());
  return worst;
}

template <int Dim>
double target_error(const ResolvedBoundary<Dim>& b, const Points<Dim>& u) {
  double worst = 0.0;
  for (Index k = 0; k < b.size(); ++k)
    worst = std::max(worst, (u.col(b.nodes[static_cast<std::size_t>(k)]) - b.displacements.col(k)).norm());
  return worst;
}

/// An affine map x → A x + b, as a Motion (not rigid, but Motion only needs position()).
template <int Dim>
struct Affine {
  Eigen::Matrix<double, Dim, Dim> a;
  Vec<Dim> b;
  [[nodiscard]] Vec<Dim> position(const Vec<Dim>& x, double t = 1.0) const {
    return x + t * ((a - Eigen::Matrix<double, Dim, Dim>::Identity()) * x + b);
  }
};


}  // namespace

TEST_CASE("DGM reproduces affine motions exactly inside the graph", "[movers]") {
  SECTION("2D") {
    const Mesh<2> mesh = square();
    Affine<2> f{(Eigen::Matrix2d() << 1.2, 0.3, -0.1, 0.9).finished(), Vec<2>(0.2, -0.1)};
    const auto b = all_moving<2>(mesh, f).resolve(mesh);
    DgmMover<2> mover;
    mover.setup(mesh, b);
    const Points<2> u = mover.move(b.displacements);
    CHECK(motion_error<2>(mesh, u, f) < 1e-12);
    CHECK(mover.num_outside() == 0);
    CHECK(mover.stats().evaluated_nodes == mesh.num_nodes() - b.size());
  }
  SECTION("3D") {
    const Mesh<3> mesh = cube();
    Affine<3> f{(Eigen::Matrix3d() << 1.1, 0.2, 0.0, 0.0, 0.9, 0.1, -0.2, 0.0, 1.05).finished(), Vec<3>(0.1, 0.0, -0.3)};
    const auto b = all_moving<3>(mesh, f).resolve(mesh);
    DgmMover<3> mover;
    mover.setup(mesh, b);
    CHECK(motion_error<3>(mesh, mover.move(b.displacements), f) < 1e-12);
  }
}

TEST_CASE("DGRBF interpolates per simplex: targets met, translations exact", "[movers]") {
  const Mesh<2> mesh = ellipse();
  const Motion<2> shift = Translation<2>{Vec<2>(0.05, -0.02)};
  SECTION("whole boundary translated: every node translated (normalized weights)") {
    const auto b = all_moving<2>(mesh, shift).resolve(mesh);
    DgrbfMover<2> mover;
    mover.setup(mesh, b);
    CHECK(motion_error<2>(mesh, mover.move(b.displacements), shift) < 1e-12);
    CHECK(mover.num_fallback() == 0);
  }
  SECTION("plain eq. 2.15 weights do not reproduce translations, but meet the targets") {
    DgrbfOptions o;
    o.rbf.normalize = false;
    const auto b = all_moving<2>(mesh, shift).resolve(mesh);
    DgrbfMover<2> mover(o);
    mover.setup(mesh, b);
    const Points<2> u = mover.move(b.displacements);
    CHECK(target_error(b, u) == 0.0);
    CHECK(motion_error<2>(mesh, u, shift) > 1e-6);
  }
  SECTION("wall translated, farfield fixed: targets met, valid mesh") {
    BoundarySpec<2> spec;
    spec.moving("wall", shift).fixed("farfield");
    const auto b = spec.resolve(mesh);
    DgrbfMover<2> mover;
    mover.setup(mesh, b);
    const Points<2> u = mover.move(b.displacements);
    CHECK(target_error(b, u) == 0.0);
    Mesh<2> moved = mesh;
    moved.points += u;
    CHECK(quality_report(moved, Metric::skew).num_invalid == 0);
  }
}

TEST_CASE("DGRBF2 reproduces rigid rotations exactly", "[movers]") {
  SECTION("2D rotation about a centre") {
    const Mesh<2> mesh = ellipse();
    const Rotation2D rotation{Vec<2>(0.3, -0.1), radians(75.0)};
    const auto b = all_moving<2>(mesh, rotation).resolve(mesh);
    Dgrbf2Mover<2> mover(dgrbf2_options(rotation));
    mover.setup(mesh, b);
    CHECK(motion_error<2>(mesh, mover.move(b.displacements), rotation) < 1e-11);
    CHECK(mover.fitted_angle() == Approx(radians(75.0)).margin(1e-12));
  }
  SECTION("2D rotation followed by a translation, centre not given") {
    const Mesh<2> mesh = ellipse();
    const Motion<2> motion = Composition<2>{{Rotation2D{Vec<2>(0.0, 0.0), radians(40.0)}, Translation<2>{Vec<2>(0.3, 0.2)}}};
    const auto b = all_moving<2>(mesh, motion).resolve(mesh);
    Dgrbf2Mover<2> mover;
    mover.setup(mesh, b);
    CHECK(motion_error<2>(mesh, mover.move(b.displacements), motion) < 1e-11);
  }
  SECTION("3D rotation about an axis") {
    const Mesh<3> mesh = cube();
    const Rotation3D rotation{Vec<3>(0.5, 0.5, 0.5), Vec<3>(1.0, 2.0, 2.0), radians(50.0)};
    const auto b = all_moving<3>(mesh, rotation).resolve(mesh);
    Dgrbf2Mover<3> mover(dgrbf2_options(rotation));
    mover.setup(mesh, b);
    CHECK(motion_error<3>(mesh, mover.move(b.displacements), rotation) < 1e-11);
  }
}

TEST_CASE("DGRBF2 rotates an object 120 degrees in one step with a valid mesh", "[movers]") {
  const Mesh<2> mesh = ellipse();
  BoundarySpec<2> spec;
  spec.moving("wall", Rotation2D{Vec<2>::Zero(), radians(120.0)}).fixed("farfield");
  const auto b = spec.resolve(mesh);
  Dgrbf2Mover<2> mover(dgrbf2_options(Rotation2D{Vec<2>::Zero(), 0.0}));
  mover.setup(mesh, b);
  const Points<2> u = mover.move(b.displacements);
  CHECK(target_error(b, u) < 1e-12);
  Mesh<2> moved = mesh;
  moved.points += u;
  CHECK(quality_report(moved, Metric::skew).num_invalid == 0);
}

TEST_CASE("Delaunay-graph movers: repeated move equals a fresh setup", "[movers]") {
  const Mesh<2> mesh = ellipse();
  BoundarySpec<2> first, second;
  first.moving("wall", Rotation2D{Vec<2>::Zero(), radians(10.0)}).fixed("farfield");
  second.moving("wall", Translation<2>{Vec<2>(0.02, 0.01)}).fixed("farfield");
  const auto b1 = first.resolve(mesh), b2 = second.resolve(mesh);
  const auto check = [&](auto mover) {
    mover.setup(mesh, b1);
    (void)mover.move(b1.displacements);
    const Points<2> again = mover.move(b2.displacements);
    decltype(mover) fresh(mover.options());
    fresh.setup(mesh, b2);
    CHECK((again - fresh.move(b2.displacements)).cwiseAbs().maxCoeff() == 0.0);
    CHECK(mover.stats().moves == 2);
  };
  check(DgmMover<2>());
  check(DgrbfMover<2>());
  check(Dgrbf2Mover<2>());
  check(ImprovedDgmMover<2>());
}

TEST_CASE("DGM refuses an inverted graph, run_steps rebuilds it each step", "[movers]") {
  const Mesh<2> mesh = ellipse();
  BoundarySpec<2> spec;
  spec.moving("wall", Rotation2D{Vec<2>::Zero(), radians(120.0)}).fixed("farfield");
  const auto b = spec.resolve(mesh);
  DgmMover<2> mover;
  mover.setup(mesh, b);
  CHECK_THAT(test::message_of<InvalidMeshError>([&] { (void)mover.move(b.displacements); }), Catch::Matchers::Contains("inverts") && Catch::Matchers::Contains("more steps") &&
                           Catch::Matchers::Contains("mesh nodes"));
  DgmOptions unchecked;
  unchecked.check_inversion = false;
  DgmMover<2> blind(unchecked);
  blind.setup(mesh, b);
  CHECK_NOTHROW(blind.move(b.displacements));
  // Small increments keep every graph valid: each step's graph is built on the moved mesh.
  const StepResult<2> stepped = run_steps(mover, mesh, spec, StepOptions{12, Metric::skew});
  CHECK(stepped.steps.size() == 12);
  for (Index k = 0; k < b.size(); ++k)
    CHECK((stepped.displacements.col(b.nodes[static_cast<std::size_t>(k)]) - b.displacements.col(k)).norm() < 1e-12);
}

TEST_CASE("Delaunay-graph movers: sliding nodes stay on their plane", "[movers]") {
  const Mesh<2> mesh = square();
  BoundarySpec<2> spec;
  spec.moving("top", Translation<2>{Vec<2>(0.1, -0.05)}).fixed("bottom").sliding("left").sliding("right");
  const auto b = spec.resolve(mesh);
  const auto check = [&](auto mover) {
    mover.setup(mesh, b);
    const Points<2> u = mover.move(b.displacements);
    for (Index k = 0; k < b.size(); ++k) {
      const Index v = b.nodes[static_cast<std::size_t>(k)];
      if (b.kinds[static_cast<std::size_t>(k)] == BoundaryKind::sliding) {
        CHECK(std::abs(u(0, v)) < 1e-14);
      } else {
        CHECK((u.col(v) - b.displacements.col(k)).norm() == 0.0);
      }
    }
    // The sliding wall's nodes do move along it (interior of the side, not the corners).
    double along = 0.0;
    for (Index k = 0; k < b.size(); ++k)
      if (b.kinds[static_cast<std::size_t>(k)] == BoundaryKind::sliding)
        along = std::max(along, std::abs(u(1, b.nodes[static_cast<std::size_t>(k)])));
    CHECK(along > 1e-3);
  };
  check(DgmMover<2>());
  check(DgrbfMover<2>());
}

TEST_CASE("Delaunay-graph movers: two tilted symmetry planes give finite coordinates", "[movers]") {
  // A sector of a cylinder around a body, between planes at 10 and 50 degrees: the nodes of
  // each plane are coplanar only to rounding, and the graph of the other boundary nodes closes
  // its hull over them with slivers that thin. Points located in one got NaN coordinates (49
  // nodes of a sphere slice, for a zero displacement), or moved so that the graph folded.
  BoxOptions box;
  box.nx = 6;
  box.ny = 5;
  box.nz = 4;
  box.cells = BoxCells::tet4;
  Mesh<3> mesh = box_mesh(box);
  for (Index v = 0; v < mesh.num_nodes(); ++v) {
    const double r = 0.5 + 4.5 * mesh.points(0, v), angle = radians(10.0 + 40.0 * mesh.points(1, v));
    mesh.points.col(v) = Vec<3>(r * std::cos(angle), r * std::sin(angle), 4.0 * mesh.points(2, v));
  }
  BoundarySpec<3> spec;
  spec.fixed("left").fixed("right").fixed("bottom").fixed("top").sliding("front").sliding("back");
  const auto still = spec.resolve(mesh);
  spec = BoundarySpec<3>{};
  spec.moving("left", Translation<3>{Vec<3>(0.0, 0.0, 0.05)}).fixed("right").fixed("bottom").fixed("top").sliding("front").sliding("back");
  const auto lifted = spec.resolve(mesh);
  for (const char* method : {"dgm", "idgm", "dgrbf", "dgrbf2"}) {
    CAPTURE(method);
    AnyMover<3> mover = make_mover(MoverConfig<3>{method, mover_method<3>(method).defaults()});
    mover.setup(mesh, still);
    const Points<3> zero = mover.move(still.displacements);
    CHECK(zero.cwiseAbs().maxCoeff() == 0.0);
    mover.setup(mesh, lifted);
    const Points<3> u = mover.move(lifted.displacements);
    REQUIRE(u.allFinite());
    CHECK(u.cwiseAbs().maxCoeff() == Approx(0.05));
  }
}

TEST_CASE("Improved DGM: a wall-hugging layer in the graph, moved by RBF", "[movers]") {
  const Mesh<2> mesh = ellipse();
  BoundarySpec<2> spec;
  spec.moving("wall", Rotation2D{Vec<2>::Zero(), radians(20.0)}).fixed("farfield");
  const auto b = spec.resolve(mesh);
  ImprovedDgmMover<2> mover;
  mover.setup(mesh, b);
  // The layer is the o_mesh ring (ring j holds nodes j n_around .. (j+1) n_around - 1) about
  // one wall spacing (≈ 0.04 here) from the wall.
  REQUIRE(!mover.layer().empty());
  Index first_ring = 1000, last_ring = 0;
  for (const Index v : mover.layer()) {
    first_ring = std::min(first_ring, v / 64);
    last_ring = std::max(last_ring, v / 64);
  }
  CHECK(first_ring > 1);
  CHECK(last_ring == first_ring);
  CHECK(mover.layer().size() <= 64);
  const Points<2> u = mover.move(b.displacements);
  CHECK(target_error(b, u) == 0.0);
  Mesh<2> moved = mesh;
  moved.points += u;
  CHECK(quality_report(moved, Metric::skew).num_invalid == 0);
}

TEST_CASE("Delaunay-graph movers in the registry", "[movers]") {
  const Mesh<2> mesh = ellipse();
  BoundarySpec<2> spec;
  spec.moving("wall", Rotation2D{Vec<2>(0.1, 0.0), radians(30.0)}).fixed("farfield");
  for (const char* method : {"dgm", "dgrbf", "dgrbf2", "idgm"}) {
    AnyMover<2> mover = make_mover<2>(method, std::string(method) == "dgrbf2" ? KeyValues{{"center", "0.1,0"}} : KeyValues{});
    const StepResult<2> r = run_steps(mover, mesh, spec, StepOptions{3, Metric::skew});
    CHECK(r.steps.back().quality->num_invalid == 0);
  }
  CHECK_THAT(test::message_of<InputError>([&] { (void)make_mover<2>("dgrbf2", KeyValues{{"center", "0.1;0"}}); }),
             Catch::Matchers::Contains("center"));
  // A key another method takes is refused by this one, naming it.
  CHECK_THAT(test::message_of<InputError>([&] { (void)make_mover<2>("dgm", KeyValues{{"center", "0.1,0"}}); }),
             Catch::Matchers::Contains("'center'"));
}

TEST_CASE("Delaunay-graph movers: bad input", "[movers]") {
  const Mesh<2> mesh = square(4);
  BoundarySpec<2> spec;
  spec.moving("top", Translation<2>{Vec<2>(0.1, 0.0)}).fixed("bottom");
  const auto b = spec.resolve(mesh);
  DgmMover<2> mover;
  CHECK_THAT(test::message_of<InputError>([&] { (void)mover.move(b.displacements); }), Catch::Matchers::Contains("setup() was not called"));

  ResolvedBoundary<2> collinear;
  collinear.nodes = mesh.group_nodes("bottom");
  collinear.kinds.assign(collinear.nodes.size(), BoundaryKind::fixed);
  collinear.displacements.setZero(2, static_cast<Index>(collinear.nodes.size()));
  collinear.normals = collinear.displacements;
  CHECK_THAT(test::message_of<InputError>([&] { (void)mover.setup(mesh, collinear); }), Catch::Matchers::Contains("Delaunay graph"));

  ResolvedBoundary<2> two = collinear;
  two.nodes.resize(2);
  two.kinds.resize(2);
  two.displacements.resize(2, 2);
  two.normals.setZero(2, 2);
  CHECK_THAT(test::message_of<InputError>([&] { (void)mover.setup(mesh, two); }), Catch::Matchers::Contains("at least 3"));

  ResolvedBoundary<2> unsorted = b;
  std::swap(unsorted.nodes[0], unsorted.nodes[1]);
  CHECK_THAT(test::message_of<InputError>([&] { (void)mover.setup(mesh, unsorted); }), Catch::Matchers::Contains("sorted"));
  ResolvedBoundary<2> outside = b;
  outside.nodes.back() = mesh.num_nodes();
  CHECK_THAT(test::message_of<InputError>([&] { (void)mover.setup(mesh, outside); }), Catch::Matchers::Contains("out of range"));

  mover.setup(mesh, b);
  CHECK_THAT(test::message_of<InputError>([&] { (void)mover.move(Points<2>::Zero(2, b.size() - 1)); }), Catch::Matchers::Contains("expected"));
  Points<2> nan = b.displacements;
  nan(0, 0) = std::numeric_limits<double>::quiet_NaN();
  CHECK_THAT(test::message_of<InputError>([&] { (void)mover.move(nan); }), Catch::Matchers::Contains("not finite"));

  DgrbfOptions negative;
  negative.rbf.simplex_support = -1.0;
  DgrbfMover<2> dgrbf(negative);
  CHECK_THAT(test::message_of<InputError>([&] { (void)dgrbf.setup(mesh, b); }), Catch::Matchers::Contains("support"));
  Dgrbf2Options<3> zero_axis;
  zero_axis.axis.setZero();
  CHECK_THAT(test::message_of<InputError>([&] { (void)Dgrbf2Mover<3>(zero_axis); }), Catch::Matchers::Contains("axis"));
  ImprovedDgmOptions no_hops;
  no_hops.layer_offset = 0.0;
  ImprovedDgmMover<2> idgm(no_hops);
  CHECK_THAT(test::message_of<InputError>([&] { (void)idgm.setup(mesh, b); }), Catch::Matchers::Contains("layer_offset"));
}
