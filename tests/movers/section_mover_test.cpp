// A 2D case stored in 3D (one cell thick, front and back as one group) moved as its section:
// every method gives the front and the back the 2D mover's displacement and none along the
// axis, which the 3D elasticity does not.

#include "meshmotion/core/extrusion.hpp"
#include "meshmotion/core/generators.hpp"
#include "meshmotion/movers.hpp"
#include "meshmotion/movers/section_mover.hpp"
#include "meshmotion/movers/step_driver.hpp"

#include "messages.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

using namespace meshmotion;

namespace {

struct Case {
  std::string name;
  Mesh<2> flat;
  BoundarySpec<2> spec2;
  BoundarySpec<3> spec3;
};

std::vector<Case> cases() {
  std::vector<Case> out;
  {
    // A ring of hexahedra whose inner wall turns 15 degrees.
    Case c{"annulus", annulus_mesh({.n_around = 24, .inner_first_height = 0.01, .outer_first_height = 0.02, .core_spacing = 0.1}), {}, {}};
    c.spec2.moving("inner", Rotation2D{{0.0, 0.0}, radians(15.0)}).fixed("outer");
    c.spec3.moving("inner", Rotation3D{{0.0, 0.0, 0.0}, Vec<3>::UnitZ(), radians(15.0)}).fixed("outer").sliding("z_min").sliding("z_max");
    out.push_back(std::move(c));
  }
  {
    // Prisms and hexahedra; the top slides along x, the sides in their planes.
    Case c{"channel", rectangle_mesh({.nx = 6, .ny = 4, .x_max = 2.0, .cells = RectangleCells::tri_quad}), {}, {}};
    c.spec2.moving("top", Translation<2>{{0.1, -0.05}}).fixed("bottom").sliding("left").sliding("right");
    c.spec3.moving("top", Translation<3>{{0.1, -0.05, 0.0}}).fixed("bottom").sliding("left").sliding("right");
    out.push_back(std::move(c));
  }
  return out;
}

}  // namespace

TEST_CASE("a 2D case stored in 3D moves as its section with every method: front and back alike, none along the axis",
          "[movers][section]") {
  for (const Case& c : cases()) {
    const Mesh<3> slab = extrude_mesh(c.flat, {.layers = 1, .height = 0.05});
    const Index n = c.flat.num_nodes();
    for (const auto& method : mover_methods<2>()) {
      INFO(c.name << " " << method.name);
      // In three steps with the extrusion given, as move_mesh --steps 3 moves it: a mover set
      // up again each step is set up on the moved section.
      const int steps = 3;
      AnyMover<2> flat_mover = make_mover(mover_config<2>(std::string(method.name)));
      const StepResult<2> expected = run_steps(flat_mover, c.flat, c.spec2, StepOptions{steps});
      const auto extrusion = find_extrusion(slab);
      REQUIRE(extrusion);
      SectionMover mover(make_mover(mover_config<2>(std::string(method.name))), *extrusion);
      const StepResult<3> moved = run_steps(mover, slab, c.spec3, StepOptions{steps});
      CHECK(mover.extrusion().axis == 2);
      double in_plane = 0.0, along = 0.0, apart = 0.0;
      for (Index v = 0; v < n; ++v) {
        in_plane = std::max(in_plane, (moved.mesh.points.col(v).head<2>() - expected.mesh.points.col(v)).norm());
        apart = std::max(apart, (moved.mesh.points.col(v).head<2>() - moved.mesh.points.col(v + n).head<2>()).norm());
        along = std::max({along, std::abs(moved.displacements(2, v)), std::abs(moved.displacements(2, v + n))});
      }
      CHECK(in_plane <= 1e-12);
      CHECK(apart == 0.0);
      CHECK(along == 0.0);
      CHECK(moved.steps.back().quality->num_invalid == expected.steps.back().quality->num_invalid);
    }
  }
  // What the section mover prevents: the 3D elasticity moves the front and back off their
  // planes (the Poisson effect of a slab one cell thick) unless they are told to slide.
  const Mesh<3> ring = extrude_mesh(cases().front().flat, {.layers = 1, .height = 0.05});
  AnyMover<3> elasticity = make_mover(mover_config<3>("le"));
  const StepResult<3> in_3d = run_steps(
      elasticity, ring, BoundarySpec<3>{}.moving("inner", Rotation3D{{0.0, 0.0, 0.0}, Vec<3>::UnitZ(), radians(15.0)}).fixed("outer"));
  CHECK(in_3d.displacements.row(2).cwiseAbs().maxCoeff() > 1e-6);
}

TEST_CASE("a motion that is not two-dimensional is refused on the section, naming the node", "[movers][section]") {
  const Mesh<2> flat = rectangle_mesh({.nx = 4, .ny = 3, .cells = RectangleCells::tri_quad});
  const Mesh<3> slab = extrude_mesh(flat, {.layers = 1, .height = 0.05});
  const auto ext = find_extrusion(slab);
  REQUIRE(ext);
  const auto refusal = [&](const BoundarySpec<3>& spec) {
    return test::message_of<NotTwoDimensional>([&] { (void)section_boundary(*ext, slab, spec.resolve(slab)); });
  };
  CHECK_THAT(refusal(BoundarySpec<3>{}.moving("top", Translation<3>{{0.1, 0.0, 0.01}}).fixed("bottom")),
             Catch::Contains("moves along the axis"));
  CHECK_THAT(refusal(BoundarySpec<3>{}.moving("top", Rotation3D{{0.0, 1.0, 0.0}, Vec<3>::UnitX(), radians(5.0)})),
             Catch::Contains("moves along the axis"));
  // The top wall's back copies move unlike the front ones, or are left out.
  const std::vector<Index> top = slab.group_nodes("top");
  Points<3> d = Points<3>::Zero(3, static_cast<Index>(top.size()));
  for (std::size_t k = 0; k < top.size(); ++k) d(0, static_cast<Index>(k)) = top[k] < flat.num_nodes() ? 0.1 : 0.12;
  CHECK_THAT(refusal(BoundarySpec<3>{}.moving("top", top, d)), Catch::Contains("moves differently"));
  const ResolvedBoundary<3> whole = BoundarySpec<3>{}.moving("top", Translation<3>{{0.1, 0.0, 0.0}}).resolve(slab);
  const ResolvedBoundary<3> front_only = detail::collect_boundary<3>(whole.size() / 2, [&](auto&& add) {
    for (Index k = 0; k < whole.size(); ++k)
      if (whole.nodes[static_cast<std::size_t>(k)] < flat.num_nodes())
        add(whole.nodes[static_cast<std::size_t>(k)], BoundaryEntry<3>{BoundaryKind::prescribed, whole.displacements.col(k)});
  });
  CHECK_THAT(test::message_of<NotTwoDimensional>([&] { (void)section_boundary(*ext, slab, front_only); }),
             Catch::Contains("is free"));
  CHECK_THAT(refusal(BoundarySpec<3>{}.moving("top", Translation<3>{{0.1, 0.0, 0.0}}).sliding("left", Vec<3>(1.0, 0.0, 1.0).normalized())),
             Catch::Contains("slides in a plane oblique to the axis"));
  // The front and back sliding in their own planes are free in the section.
  CHECK_NOTHROW(section_boundary(*ext, slab, BoundarySpec<3>{}.moving("top", Translation<3>{{0.1, 0.0, 0.0}}).sliding("z_min").sliding("z_max").resolve(slab)));
  // Front and back agree at setup, then move() is given different displacements.
  SectionMover mover(make_mover(mover_config<2>("rbf")));
  const ResolvedBoundary<3> b = BoundarySpec<3>{}.moving("top", Translation<3>{{0.1, 0.0, 0.0}}).fixed("bottom").resolve(slab);
  mover.setup(slab, b);
  Points<3> uneven = b.displacements;
  uneven(0, b.column(slab.group_nodes("top").back())) += 0.01;
  CHECK_THAT(test::message_of<NotTwoDimensional>([&] { (void)mover.move(uneven); }), Catch::Contains("not two-dimensional"));
  CHECK_NOTHROW(mover.move(b.displacements));
  // A mesh that is not one cell thick.
  const Mesh<3> thick = extrude_mesh(flat, {.layers = 2});
  CHECK_THAT(test::message_of<InputError>([&] { mover.setup(thick, BoundarySpec<3>{}.fixed("bottom").resolve(thick)); }),
             Catch::Contains("not one cell thick"));
  // Given the extrusion the caller found, the mover moves as when it finds it, and refuses a
  // mesh it was not found on.
  SectionMover given(make_mover(mover_config<2>("rbf")), *ext);
  given.setup(slab, b);
  CHECK(given.move(b.displacements) == mover.move(b.displacements));
  CHECK_THAT(test::message_of<InputError>([&] { given.setup(thick, BoundarySpec<3>{}.fixed("bottom").resolve(thick)); }),
             Catch::Contains("the given extrusion pairs"));
}
