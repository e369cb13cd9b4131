// RbfOptions::partition_of_unity: local systems on overlapping patches, blended (issue 22).

#include "meshmotion/core/generators.hpp"
#include "meshmotion/core/threads.hpp"
#include "meshmotion/movers.hpp"

#include "random_field.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <string>

using namespace meshmotion;
using test::random_displacements;

namespace {

Mesh<3> box(Index n) {
  BoxOptions b;
  b.nx = b.ny = b.nz = n;
  return box_mesh(b);
}

// The bottom of the unit box tilts about its middle line (displacements varying over the
// face); the top is fixed.
ResolvedBoundary<3> bottom_tilt(const Mesh<3>& mesh) {
  BoundarySpec<3> spec;
  spec.moving("bottom", Rotation3D{Vec<3>(0.5, 0.5, 0.0), Vec<3>::UnitX(), 0.05}).fixed("top");
  return spec.resolve(mesh);
}

RbfOptions patched(double radius, Index patch_centres) {
  RbfOptions o;
  o.support_radius = radius;
  o.partition_of_unity = true;
  o.patch_centres = patch_centres;
  return o;
}

}  // namespace

TEST_CASE("partition of unity: a single patch is the global interpolant", "[movers]") {
  const Mesh<3> mesh = box(8);
  const ResolvedBoundary<3> boundary = bottom_tilt(mesh);
  RbfOptions global;
  global.support_radius = 0.4;
  RbfMover<3> reference(global);
  reference.setup(mesh, boundary);
  RbfMover<3> one(patched(0.4, boundary.size()));
  one.setup(mesh, boundary);
  CHECK(one.patches() == 1);
  const Points<3> u = one.move(boundary.displacements), v = reference.move(boundary.displacements);
  CHECK((u - v).norm() <= 1e-12 * v.norm());
}

TEST_CASE("partition of unity: many patches interpolate, vanish beyond the support, stay close to the global one",
          "[movers]") {
  const Mesh<3> mesh = box(12);
  const ResolvedBoundary<3> boundary = bottom_tilt(mesh);
  const double radius = 0.3;
  RbfMover<3> mover(patched(radius, 60));
  // Probe nodes placed exactly on every boundary node, but not in the boundary: the blend itself
  // must give them the boundary value (the interpolation condition, not the copy of targets).
  Points<3> points(3, mesh.num_nodes() + boundary.size());
  points.leftCols(mesh.num_nodes()) = mesh.points;
  for (Index b = 0; b < boundary.size(); ++b) points.col(mesh.num_nodes() + b) = mesh.points.col(boundary.nodes[static_cast<std::size_t>(b)]);
  mover.setup_reference(points, boundary);
  CHECK(mover.patches() >= 8);  // 338 centres, at most 60 a patch
  const Points<3> u = mover.move(boundary.displacements);
  const double scale = boundary.displacements.cwiseAbs().maxCoeff();
  for (Index b = 0; b < boundary.size(); ++b) {
    CAPTURE(b);
    CHECK((u.col(mesh.num_nodes() + b) - boundary.displacements.col(b)).norm() <= 1e-11 * scale);
  }

  RbfOptions global;
  global.support_radius = radius;
  RbfMover<3> reference(global);
  reference.setup_reference(points, boundary);
  const Points<3> v = reference.move(boundary.displacements);
  Index beyond = 0;
  for (Index i = 0; i < mesh.num_nodes(); ++i) {
    double nearest = 1e300;
    for (const Index c : boundary.nodes) nearest = std::min(nearest, (mesh.points.col(i) - mesh.points.col(c)).norm());
    if (nearest >= radius) {
      ++beyond;
      CHECK(u.col(i).norm() == 0.0);
    }
  }
  CHECK(beyond > 0);
  // The blend approximates the global interpolant: measured 1.1e-3 of the largest displacement.
  CHECK((u - v).cwiseAbs().maxCoeff() <= 5e-3 * scale);
  CHECK((u - v).cwiseAbs().maxCoeff() > 0.0);  // it is not the global system in disguise
}

TEST_CASE("partition of unity: linear, with derivatives, the same on any thread count", "[movers]") {
  const Mesh<3> mesh = box(10);
  const ResolvedBoundary<3> boundary = bottom_tilt(mesh);
  RbfOptions options = patched(0.35, 50);
  options.repair = false;  // the map's own linearity: its random motions fold cells, which the repair would move
  RbfMover<3> mover(options);
  mover.setup(mesh, boundary);
  const Index m = boundary.size();
  const Points<3> d1 = random_displacements<3>(m, 1), d2 = random_displacements<3>(m, 2);
  const Points<3> u1 = mover.move(d1);
  CHECK((mover.move(2.0 * d1 - 3.0 * d2) - (2.0 * u1 - 3.0 * mover.move(d2))).norm() < 1e-12 * u1.norm());
  CHECK(mover.stats().factorizations == mover.patches());

  const Points<3> w = random_displacements<3>(m, 3, 1.0);
  const Points<3> v = random_displacements<3>(mesh.num_nodes(), 4, 1.0);
  const double h = 1e-6;
  const Points<3> fd = (mover.move(d1 + h * w) - mover.move(d1 - h * w)) / (2.0 * h);
  const Points<3> jw = mover.derivative_forward(w);
  CHECK((fd - jw).norm() < 1e-6 * jw.norm());
  const Points<3> jtv = mover.derivative_reverse(v);
  CHECK((v.array() * jw.array()).sum() == Approx((jtv.array() * w.array()).sum()).epsilon(1e-10));

  const int threads = num_threads();
  set_num_threads(1);
  RbfMover<3> serial(patched(0.35, 50));
  serial.setup(mesh, boundary);
  const Points<3> u_serial = serial.move(d1);
  set_num_threads(threads);
  CHECK((u_serial - u1).norm() == 0.0);
}

TEST_CASE("partition of unity: sliding walls stay on their planes", "[movers]") {
  RectangleOptions r;
  r.nx = r.ny = 24;
  const Mesh<2> mesh = rectangle_mesh(r);
  BoundarySpec<2> spec;
  spec.moving("left", Translation<2>{Vec<2>(0.05, 0.08)}).fixed("right").sliding("bottom").sliding("top");
  const ResolvedBoundary<2> boundary = spec.resolve(mesh);
  RbfOptions o;
  o.support_radius = 0.5;
  o.partition_of_unity = true;
  o.patch_centres = 20;
  RbfMover<2> mover(o);
  mover.setup(mesh, boundary);
  CHECK(mover.patches() > 2);
  const Points<2> u = mover.move(boundary.displacements);
  Index slid = 0;
  for (const auto& [wall, y] : {std::pair<const char*, double>{"bottom", 0.0}, {"top", 1.0}})
    for (const Index node : mesh.group_nodes(wall)) {
      const double x = mesh.points(0, node);
      if (x == 0.0 || x == 1.0) continue;
      CHECK(std::abs(mesh.points(1, node) + u(1, node) - y) < 1e-14);
      if (std::abs(u(0, node)) > 1e-4) ++slid;
    }
  CHECK(slid > 4);
}

TEST_CASE("partition of unity: options it cannot honour are refused by name", "[movers]") {
  const Mesh<3> mesh = box(4);
  const ResolvedBoundary<3> boundary = bottom_tilt(mesh);
  const auto refused = [&](RbfOptions o, const std::string& what) {
    RbfMover<3> mover(o);
    CHECK_THROWS_WITH(mover.setup(mesh, boundary), Catch::Contains("partition_of_unity") && Catch::Contains(what));
  };
  RbfOptions o = patched(0.5, 10);
  o.polynomial = true;
  refused(o, "polynomial");
  o = patched(0.5, 10);
  o.kernel = RbfKernel::gaussian;
  refused(o, "compact kernel");
  o = patched(0.5, 10);
  o.support_radii.assign(static_cast<std::size_t>(boundary.size()), 0.5);
  refused(o, "support_radii");
  o = patched(0.5, 0);
  refused(o, "patch_centres");
  o = patched(0.5, 10);
  o.patch_overlap = -1.0;
  refused(o, "patch_overlap");
}
