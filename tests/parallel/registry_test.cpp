// The distributed registry as the front ends use it: every method with a distributed mover
// gives, through it, what its mover gives directly (rbf: the serial RBF's displacements; le
// and sle: the serial elasticity's within the solver's tolerance), set up once with no motion
// and moved several times; a method without one is refused naming those that have one; the
// parallel keys are split off a method's keys in one place.
#include "parallel_support.hpp"

#include "meshmotion/core/generators.hpp"
#include "meshmotion/movers/elasticity.hpp"
#include "meshmotion/movers/motion.hpp"
#include "meshmotion/movers/rbf.hpp"
#include "meshmotion/movers/registry.hpp"
#include "meshmotion/parallel/partition.hpp"
#include "meshmotion/parallel/registry.hpp"

#include <catch2/catch.hpp>

#include <memory>
#include <string>
#include <vector>

using namespace meshmotion;
using namespace meshmotion::parallel;
using test::global_max;
using test::world;

TEST_CASE("distributed registry: rbf, le and sle through one type, set up once and moved many times", "[parallel][registry]") {
  const Mesh<2> mesh = rectangle_mesh({.nx = 16, .ny = 12, .cells = RectangleCells::tri_quad});
  BoundarySpec<2> spec;
  spec.moving("bottom", Rotation2D{{0.5, 0.0}, radians(1.0)}).fixed("top").fixed("left").fixed("right");
  const ResolvedBoundary<2> motion = spec.resolve(mesh);
  ResolvedBoundary<2> reference = motion;
  reference.displacements.setZero();
  const DistributedMesh<2> part = partition_mesh(world(), mesh);
  const ResolvedBoundary<2> local = distribute_boundary(part, reference);
  const ResolvedBoundary<2> local_motion = distribute_boundary(part, motion);
  for (const std::string method : {"rbf", "le", "sle"}) {
    INFO("method " << method);
    MoverConfig<2> config = mover_config<2>(method);
    if (method == "rbf") config.set("support_radius", "0.8");
    AnyMover<2> serial = make_mover(config);
    serial.setup(mesh, reference);
    const std::unique_ptr<DistributedMover<2>> mover = make_distributed_mover(config);
    mover->setup(part, local);
    CHECK(find_distributed_method<2>(method)->needs_cells == (method != "rbf"));
    const DistributedChoices chose = mover->choices();
    CHECK((chose.support_radius > 0.0) == (method == "rbf"));
    CHECK((chose.boundary_solve == "none") == (method != "rbf"));
    CHECK((chose.petsc_solver == "none") == (method == "rbf"));
    if (method != "rbf") CHECK(chose.petsc_solver == "mumps");  // automatic, resolved in 2D
    for (const double scale : {0.5, 1.0, -2.0}) {
      const Points<2> expected = serial.move(scale * motion.displacements);
      const Points<2> got = mover->move(scale * local_motion.displacements);
      double worst = 0.0;
      for (Index i = 0; i < part.local.num_nodes(); ++i)
        worst = std::max(worst, (got.col(i) - expected.col(part.global_ids[static_cast<std::size_t>(i)])).norm());
      CHECK(global_max(worst) <= (method == "rbf" ? 1e-12 : 1e-7) * expected.colwise().norm().maxCoeff());
    }
  }
}

TEST_CASE("distributed registry: methods without a distributed mover, and movers without cells", "[parallel][registry]") {
  CHECK(known_distributed_methods<3>() == "rbf, le, sle");
  CHECK(find_distributed_method<3>("dgm") == nullptr);
  CHECK_THROWS_WITH(make_distributed_mover(mover_config<3>("dgm")),
                    Catch::Contains("'dgm' has no distributed mover") && Catch::Contains("rbf, le, sle"));
  // Every distributed method is a serial one, with the serial registry's needs for cells.
  for (const DistributedMethod<3>& m : distributed_methods<3>())
    CHECK(mover_method<3>(m.name).needs_cells == m.needs_cells);
  // Elasticity without cells is refused with what to do instead.
  const Mesh<3> box = box_mesh({.nx = 2, .ny = 2, .nz = 2});
  const DistributedMesh<3> part = partition_mesh(world(), box);
  // rigid_part=blend with nothing prescribed is refused by the mover, naming why.
  MoverConfig<3> blend = mover_config<3>("rbf");
  blend.set("rigid_part", "blend");
  CHECK_THROWS_WITH(make_distributed_mover(blend)->setup(part.view(), ResolvedBoundary<3>{}),
                    Catch::Contains("rigid_part=blend: no prescribed node"));
  const std::unique_ptr<DistributedMover<3>> le = make_distributed_mover(mover_config<3>("le"));
  CHECK_THROWS_WITH(le->setup(part.view(), ResolvedBoundary<3>{}), Catch::Contains("needs the cells"));
}

TEST_CASE("parallel options: split off a method's keys in order, the rest left to the method", "[parallel][options]") {
  ParallelOptions parallel;
  const KeyValues rest = take_parallel_options(
      {{"support_radius", "2"}, {"boundary_solve", "petsc"}, {"petsc_solver", "cg_gamg"}, {"kernel", "wendland4"}}, parallel);
  CHECK(rest == KeyValues{{"support_radius", "2"}, {"kernel", "wendland4"}});
  CHECK(parallel.boundary.boundary_solve == BoundarySolve::petsc);
  CHECK(parallel.elasticity.petsc_solver == PetscSolverKind::cg_gamg);
  CHECK_THROWS_WITH(take_parallel_options({{"boundary_solve", "mumps"}}, parallel), Catch::Contains("boundary_solve"));
  // Every key once, in the docs the programs and Python show.
  const std::vector<std::string> keys = option_keys(ParallelOptions{});
  CHECK(keys.size() == option_keys(BoundarySolveOptions{}).size() + option_keys(DistributedElasticityOptions{}).size());
}
