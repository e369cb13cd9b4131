// RbfOptions::levels: a wide radius on a coarse subset of the centres, every centre on ten
// boundary spacings (issue 69: a deforming boundary at a solver's cost).

#include "meshmotion/core/generators.hpp"
#include "meshmotion/movers.hpp"
#include "meshmotion/quality.hpp"

#include "random_field.hpp"

#include <catch2/catch.hpp>

#include <cmath>

using namespace meshmotion;
using test::random_displacements;

namespace {

// A terrain under a held lid: the bottom is prescribed, the top held, the four sides slide in
// their planes.
ResolvedBoundary<3> terrain_boundary(const Mesh<3>& mesh) {
  BoundarySpec<3> spec;
  spec.prescribed("bottom").fixed("top").sliding("left").sliding("right").sliding("front").sliding("back");
  return spec.resolve(mesh);
}

// Two hills of height `height` raised under the bottom (vertical motion: the sides' planes
// hold it).
Points<3> hills(const Mesh<3>& mesh, const ResolvedBoundary<3>& boundary, double height) {
  Points<3> d = Points<3>::Zero(3, boundary.size());
  for (Index b = 0; b < boundary.size(); ++b) {
    if (boundary.kinds[static_cast<std::size_t>(b)] != BoundaryKind::prescribed) continue;
    const Vec<3> x = mesh.points.col(boundary.nodes[static_cast<std::size_t>(b)]);
    const double bump = std::exp(-((x(0) - 0.35) * (x(0) - 0.35) + (x(1) - 0.5) * (x(1) - 0.5)) / 0.03) +
                        0.6 * std::exp(-((x(0) - 0.7) * (x(0) - 0.7) + (x(1) - 0.4) * (x(1) - 0.4)) / 0.02);
    d(2, b) = height * bump;
  }
  return d;
}

RbfOptions levels(RbfLevels l) {
  RbfOptions o;
  o.levels = l;
  return o;
}

// Largest distance of a sliding node's displacement from its plane.
double off_planes(const ResolvedBoundary<3>& boundary, const Points<3>& u) {
  double off = 0.0;
  for (Index b = 0; b < boundary.size(); ++b)
    if (boundary.kinds[static_cast<std::size_t>(b)] == BoundaryKind::sliding) {
      const Vec<3> v = u.col(boundary.nodes[static_cast<std::size_t>(b)]);
      off = std::max(off, (v - boundary.project(b, v)).norm());
    }
  return off;
}

}  // namespace

TEST_CASE("two levels: set up at rest, hills raised step by step: interpolating, on the planes, valid, as good as one level",
          "[movers]") {
  const Mesh<3> mesh = box_mesh({.nx = 16, .ny = 16, .nz = 16});
  const ResolvedBoundary<3> boundary = terrain_boundary(mesh);
  RbfMover<3> two(levels(RbfLevels::two)), one(levels(RbfLevels::one));
  two.setup(mesh, boundary);
  one.setup(mesh, boundary);
  for (int step = 1; step <= 8; ++step) {
    CAPTURE(step);
    const double height = 0.04 * step;
    const Points<3> d = hills(mesh, boundary, height);
    const Points<3> u = two.move(d), w = one.move(d);
    // Both took the same radius: the levels change how it is carried, not what it is.
    CHECK(two.support_radius() == one.support_radius());
    CHECK(two.coarse_centres() > 8);
    CHECK(3 * two.coarse_centres() < boundary.size());
    CHECK(two.stats().coarse_centres == two.coarse_centres());
    CHECK(one.coarse_centres() == 0);
    for (Index b = 0; b < boundary.size(); ++b)
      if (boundary.kinds[static_cast<std::size_t>(b)] != BoundaryKind::sliding)
        CHECK((u.col(boundary.nodes[static_cast<std::size_t>(b)]) - d.col(b)).norm() == 0.0);
    CHECK(off_planes(boundary, u) <= 1e-12);
    Mesh<3> moved = mesh, moved_one = mesh;
    moved.points += u;
    moved_one.points += w;
    const QualityReport q = quality_report(moved, Metric::scaled_jacobian), q_one = quality_report(moved_one, Metric::scaled_jacobian);
    CHECK(q.num_invalid == 0);
    CHECK(q.min >= 0.95 * q_one.min);  // 0.537 against 0.558 at the last step
    // The coarse level reaches as far as the one system: the volume's motion is alike.
    CHECK((u - w).cwiseAbs().maxCoeff() <= 0.1 * height);
  }
  CHECK(two.stats().radius_growths == one.stats().radius_growths);
}

TEST_CASE("two levels: the interpolation condition at every centre, linear, derivatives exact", "[movers]") {
  const Mesh<3> mesh = box_mesh({.nx = 10, .ny = 10, .nz = 10});
  const ResolvedBoundary<3> boundary = terrain_boundary(mesh);
  // Probe nodes on every boundary node, not in the boundary: the interpolant itself must give
  // them the boundary's values (sliding ones their projected values), not a copy of targets.
  Points<3> points(3, mesh.num_nodes() + boundary.size());
  points.leftCols(mesh.num_nodes()) = mesh.points;
  for (Index b = 0; b < boundary.size(); ++b) points.col(mesh.num_nodes() + b) = mesh.points.col(boundary.nodes[static_cast<std::size_t>(b)]);
  RbfOptions o = levels(RbfLevels::two);
  o.support_radius = 1.5;
  RbfMover<3> mover(o);
  mover.setup_reference(points, boundary);
  const Points<3> d = hills(mesh, boundary, 0.2) + random_displacements<3>(boundary.size(), 3, 0.01);
  const Points<3> u = mover.move(d);
  REQUIRE(mover.coarse_centres() > 1);
  const double scale = d.cwiseAbs().maxCoeff();
  for (Index b = 0; b < boundary.size(); ++b) {
    CAPTURE(b);
    const Index node = boundary.nodes[static_cast<std::size_t>(b)];
    const Vec<3> target = boundary.kinds[static_cast<std::size_t>(b)] == BoundaryKind::sliding ? Vec<3>(u.col(node)) : Vec<3>(d.col(b));
    CHECK((u.col(mesh.num_nodes() + b) - target).norm() <= 1e-10 * scale);
  }
  CHECK(off_planes(boundary, u) <= 1e-12 * scale);
  // Linear in the displacements, so the forward derivative is a move and a finite difference.
  const Points<3> e = random_displacements<3>(boundary.size(), 4, 0.02);
  const Points<3> sum = mover.move(2.0 * d - 3.0 * e), parts = 2.0 * u - 3.0 * mover.move(e);
  CHECK((sum - parts).cwiseAbs().maxCoeff() <= 1e-12 * sum.cwiseAbs().maxCoeff());
  const Points<3> forward = mover.derivative_forward(e);
  const double h = 1e-3;
  const Points<3> difference = (mover.move(d + h * e) - mover.move(d - h * e)) / (2.0 * h);
  CHECK((forward - difference).cwiseAbs().maxCoeff() <= 1e-9 * forward.cwiseAbs().maxCoeff());
  // The dot test: <v, J e> = <J^T v, e>, sliding entries' gradient zero.
  const Points<3> v = random_displacements<3>(points.cols(), 5, 1.0);
  const Points<3> gradient = mover.derivative_reverse(v);
  Points<3> e_constrained = e;
  for (Index b = 0; b < boundary.size(); ++b)
    if (boundary.kinds[static_cast<std::size_t>(b)] == BoundaryKind::sliding) {
      CHECK(gradient.col(b).norm() == 0.0);
      e_constrained.col(b).setZero();
    }
  const double lhs = (v.array() * forward.array()).sum(), rhs = (gradient.array() * e_constrained.array()).sum();
  CAPTURE(lhs, rhs);
  CHECK(std::abs(lhs - rhs) <= 1e-10 * std::abs(lhs));
}

TEST_CASE("two levels: automatic takes them for the default radius on a large boundary only", "[movers]") {
  const Mesh<3> mesh = box_mesh({.nx = 10, .ny = 10, .nz = 10});
  const ResolvedBoundary<3> boundary = terrain_boundary(mesh);
  RbfOptions small_boundary;  // 488 centres: below two_level_centres, one level
  RbfMover<3> few(small_boundary);
  few.setup(mesh, boundary);
  (void)few.move(hills(mesh, boundary, 0.3));
  CHECK(few.support_radius() > 1.0);
  CHECK(few.coarse_centres() == 0);
  RbfOptions large_boundary;
  large_boundary.two_level_centres = 400;
  RbfMover<3> many(large_boundary);
  many.setup(mesh, boundary);
  // From the setup at rest: the fine level is set up once, the coarse one follows the radius.
  const Index coarse = many.coarse_centres();
  CHECK(coarse > 0);
  const Points<3> u = many.move(hills(mesh, boundary, 0.3));
  CHECK(many.stats().radius_growths >= 1);
  CHECK(many.coarse_centres() == coarse);
  Mesh<3> moved = mesh;
  moved.points += u;
  CHECK(quality_report(moved, Metric::scaled_jacobian).num_invalid == 0);
  // A radius given, or options that two levels cannot carry, keep one.
  RbfOptions given = large_boundary, polynomial = large_boundary;
  given.support_radius = 2.0;
  polynomial.polynomial = true;
  for (const RbfOptions& o : {given, polynomial}) {
    RbfMover<3> one(o);
    one.setup(mesh, boundary);
    (void)one.move(hills(mesh, boundary, 0.3));
    CHECK(one.coarse_centres() == 0);
  }
  // Two levels asked for where they cannot be: refused by name.
  RbfOptions refused = levels(RbfLevels::two);
  refused.polynomial = true;
  RbfMover<3> mover(refused);
  CHECK_THROWS_WITH(mover.setup(mesh, boundary), Catch::Contains("levels=two") && Catch::Contains("polynomial"));
}

TEST_CASE("two levels: the coarse centres cover every centre within their spacing and keep it apart", "[movers]") {
  const Mesh<3> mesh = box_mesh({.nx = 12, .ny = 12, .nz = 12});
  const ResolvedBoundary<3> boundary = terrain_boundary(mesh);
  Points<3> centres(3, boundary.size());
  for (Index b = 0; b < boundary.size(); ++b) centres.col(b) = mesh.points.col(boundary.nodes[static_cast<std::size_t>(b)]);
  const double spacing = 0.2;
  const std::vector<Index> kept = detail::spaced_subset(centres, spacing);
  REQUIRE(kept.size() > 1);
  CHECK(std::is_sorted(kept.begin(), kept.end()));
  for (std::size_t i = 0; i < kept.size(); ++i)
    for (std::size_t j = i + 1; j < kept.size(); ++j) CHECK((centres.col(kept[i]) - centres.col(kept[j])).norm() >= spacing);
  for (Index c = 0; c < centres.cols(); ++c) {
    double nearest = 1e300;
    for (const Index k : kept) nearest = std::min(nearest, (centres.col(c) - centres.col(k)).norm());
    CHECK(nearest < spacing);
  }
}

TEST_CASE("two levels: the coarse centres follow the positions, not the numbering", "[movers]") {
  // A distributed mover's global ids may follow its ranks: the same points renumbered keep the
  // same coarse centres.
  const Mesh<3> mesh = box_mesh({.nx = 12, .ny = 12, .nz = 12});
  const ResolvedBoundary<3> boundary = terrain_boundary(mesh);
  const Index m = boundary.size();
  Points<3> centres(3, m), reversed(3, m);
  for (Index b = 0; b < m; ++b) {
    centres.col(b) = mesh.points.col(boundary.nodes[static_cast<std::size_t>(b)]);
    reversed.col(m - 1 - b) = centres.col(b);
  }
  std::vector<Index> kept = detail::spaced_subset(centres, 0.2), kept_reversed = detail::spaced_subset(reversed, 0.2);
  for (Index& k : kept_reversed) k = m - 1 - k;
  std::sort(kept_reversed.begin(), kept_reversed.end());
  CHECK(kept == kept_reversed);
}
