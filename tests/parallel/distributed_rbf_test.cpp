// The distributed RBF mover against the serial one on the whole mesh, which every rank also
// holds here: equal to 1e-12 (relative) at any number of ranks, by METIS partitions and by
// partitions made to leave a rank without moving nodes, without group nodes, or empty.
#include "parallel_support.hpp"

#include "meshmotion/core/generators.hpp"
#include "meshmotion/io.hpp"
#include "meshmotion/movers/rbf.hpp"
#include "meshmotion/parallel.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <numbers>
#include <string>
#include <thread>

using namespace meshmotion;
using namespace meshmotion::parallel;
using test::global_max;
using test::world;

namespace {

struct Outcome {
  double error = 0.0;       // max |distributed - serial| / max |serial|, over all ranks
  double gradient = 0.0;    // the same for the reverse derivative
  // How far the serial reverse product itself moves when its seed changes in the last bits:
  // the ranks' partial sums of Eᵀv enter the transposed solve in another order than the
  // serial sum, and an ill-conditioned interpolation matrix (a wide support over a fine
  // wall) amplifies that rounding alike. The distributed gradient must agree within it.
  double gradient_rounding = 0.0;
  Index global_entries = 0;
  BoundarySolve solved_by = BoundarySolve::automatic;
  Index patches = 0;
  double radius = 0.0;  // the distributed mover's support radius
};

// Moves `whole` with `spec` serially and distributed (partitioned by `cell_ranks`, or METIS),
// and compares the displacements and the reverse derivatives node by node.
template <int Dim>
Outcome compare_with_serial(const Mesh<Dim>& whole, const ResolvedBoundary<Dim>& b, RbfOptions options,
                            std::span<const int> cell_ranks = {}, bool radius_per_entry = false,
                            BoundarySolveOptions solve = {BoundarySolve::replicated}) {
  const auto radius_at = [&](const meshmotion::Vec<Dim>& x) { return options.support_radius * (0.8 + 0.4 * std::abs(x[0])); };
  RbfOptions serial_options = options;
  if (radius_per_entry)
    for (const Index v : b.nodes) serial_options.support_radii.push_back(radius_at(whole.points.col(v)));
  RbfMover<Dim> serial(serial_options);
  serial.setup(whole, b);
  const Points<Dim> expected = serial.move(b.displacements);
  // A smooth seed for the reverse product: ⟨v, move(d)⟩ with v(x) = (sin x, cos y, ...).
  Points<Dim> v_whole(Dim, whole.num_nodes());
  for (Index i = 0; i < whole.num_nodes(); ++i)
    for (int a = 0; a < Dim; ++a) v_whole(a, i) = std::sin(1.0 + a + 2.0 * whole.points(a, i));
  const Points<Dim> expected_gradient = serial.derivative_reverse(v_whole);
  Points<Dim> v_rounded = v_whole;
  for (Index i = 0; i < v_rounded.cols(); ++i) v_rounded.col(i) *= 1.0 + 1e-15 * std::sin(3.0 * static_cast<double>(i));
  const double gradient_scale = std::max(1e-300, expected_gradient.colwise().norm().maxCoeff());

  const DistributedMesh<Dim> part = partition_mesh(world(), whole, cell_ranks);
  const ResolvedBoundary<Dim> local_b = distribute_boundary(part, b);
  RbfOptions local_options = options;
  if (radius_per_entry)
    for (const Index v : local_b.nodes) local_options.support_radii.push_back(radius_at(part.local.points.col(v)));
  DistributedRbfMover<Dim> mover(local_options, solve);
  mover.setup(part.view(), part.local, local_b);  // with the cells, as the serial mover: the same repair
  REQUIRE(mover.petsc_solve() == (solve.boundary_solve == BoundarySolve::petsc));
  const Points<Dim> got = mover.move(local_b.displacements);

  Outcome out;
  out.solved_by = mover.solved_by();
  out.patches = mover.num_patches();
  out.radius = mover.support_radius();
  if (!radius_per_entry) CHECK(out.radius == serial.support_radius());
  out.gradient_rounding = (serial.derivative_reverse(v_rounded) - expected_gradient).colwise().norm().maxCoeff() / gradient_scale;
  out.global_entries = mover.global_boundary_size();
  double worst = 0.0;
  for (Index i = 0; i < part.local.num_nodes(); ++i)
    worst = std::max(worst, (got.col(i) - expected.col(part.global_ids[static_cast<std::size_t>(i)])).norm());
  out.error = global_max(worst) / std::max(1e-300, expected.colwise().norm().maxCoeff());

  Points<Dim> v_local(Dim, part.local.num_nodes());
  for (Index i = 0; i < part.local.num_nodes(); ++i) v_local.col(i) = v_whole.col(part.global_ids[static_cast<std::size_t>(i)]);
  const Points<Dim> gradient = mover.derivative_reverse(v_local);
  worst = 0.0;
  for (Index k = 0; k < local_b.size(); ++k) {
    const Index local = local_b.nodes[static_cast<std::size_t>(k)];
    if (!part.view().owns(local)) {
      worst = std::max(worst, gradient.col(k).norm());  // ghost entries carry nothing
      continue;
    }
    const Index whole_entry = b.column(part.global_ids[static_cast<std::size_t>(local)]);
    worst = std::max(worst, (gradient.col(k) - expected_gradient.col(whole_entry)).norm());
  }
  out.gradient = global_max(worst) / gradient_scale;
  return out;
}

// The whole boundary's values `d` (serial entry order of `b`) for this rank's entries `local`.
template <int Dim>
Points<Dim> local_values(const DistributedMesh<Dim>& part, const ResolvedBoundary<Dim>& b, const ResolvedBoundary<Dim>& local,
                         const Points<Dim>& d) {
  Points<Dim> out(Dim, local.size());
  for (Index k = 0; k < local.size(); ++k)
    out.col(k) = d.col(b.column(part.global_ids[static_cast<std::size_t>(local.nodes[static_cast<std::size_t>(k)])]));
  return out;
}

// The largest distance over every rank between a local node's value in `got` and its node's
// value in the serial `expected`.
template <int Dim>
double largest_gap(const DistributedMesh<Dim>& part, const Points<Dim>& got, const Points<Dim>& expected) {
  double worst = 0.0;
  for (Index i = 0; i < part.local.num_nodes(); ++i)
    worst = std::max(worst, (got.col(i) - expected.col(part.global_ids[static_cast<std::size_t>(i)])).norm());
  return global_max(worst);
}

}  // namespace

TEST_CASE("distributed RBF equals serial on a 2D mesh partitioned by METIS", "[parallel][rbf]") {
  RectangleOptions o;
  o.nx = 24;
  o.ny = 18;
  o.cells = RectangleCells::tri_quad;
  const Mesh<2> mesh = rectangle_mesh(o);
  BoundarySpec<2> spec;
  spec.moving("bottom", Rotation2D{{0.5, 0.0}, radians(8.0)}).fixed("top").fixed("left");
  for (const bool polynomial : {false, true}) {
    RbfOptions options;
    options.support_radius = 0.6;
    options.polynomial = polynomial;
    const Outcome r = compare_with_serial(mesh, spec.resolve(mesh), options);
    INFO("polynomial " << polynomial);
    CHECK(r.error <= 1e-12);
    CHECK(r.gradient <= 1e-12);
    CHECK(r.global_entries == static_cast<Index>(spec.resolve(mesh).size()));
  }
}

TEST_CASE("distributed RBF takes the serial default radius, from the whole boundary", "[parallel][rbf][petsc]") {
  const Mesh<2> mesh = rectangle_mesh({.nx = 24, .ny = 18, .cells = RectangleCells::tri_quad});
  BoundarySpec<2> spec;
  spec.moving("bottom", Rotation2D{{0.5, 0.0}, radians(20.0)}).fixed("top").fixed("left");
  for (const BoundarySolve solve : {BoundarySolve::replicated, BoundarySolve::petsc}) {
    const Outcome r = compare_with_serial(mesh, spec.resolve(mesh), RbfOptions{}, {}, false, {solve});
    CHECK(r.error <= 1e-12);
  }
}

TEST_CASE("distributed RBF shrinks the default radius to the serial mover's memory budget", "[parallel][rbf][petsc]") {
  // A bump of the bottom (no rigid part the serial mover could take out instead), and a
  // budget (about a sixth of the unreduced estimate) that binds: every rank must arrive at
  // the serial radius, sampling the same nodes whatever the partition.
  const Mesh<2> mesh = rectangle_mesh({.nx = 24, .ny = 18, .cells = RectangleCells::tri_quad});
  BoundarySpec<2> spec;
  spec.moving("bottom", Translation<2>{meshmotion::Vec<2>(0.0, 0.1)}).fixed("top").fixed("left").fixed("right");
  ResolvedBoundary<2> b = spec.resolve(mesh);
  for (Index k = 0; k < b.size(); ++k)
    if (b.kinds[static_cast<std::size_t>(k)] == BoundaryKind::prescribed)
      b.displacements.col(k) *= 2.0 * std::sin(3.14159 * mesh.points(0, b.nodes[static_cast<std::size_t>(k)]));
  RbfOptions options;
  options.max_memory_bytes = 1e5;
  RbfMover<2> serial(options);
  serial.setup(mesh, b);
  REQUIRE(serial.support_radius_reduced());
  REQUIRE_FALSE(serial.stats().rigid_part);
  for (const BoundarySolve solve : {BoundarySolve::replicated, BoundarySolve::petsc}) {
    const Outcome r = compare_with_serial(mesh, b, options, {}, false, {solve});
    CHECK(r.radius == serial.support_radius());
    CHECK(r.error <= 1e-12);
  }
}

TEST_CASE("distributed RBF set up once with no motion takes the serial budget radius and follows many moves",
          "[parallel][rbf]") {
  // As a solver runs it: both movers set up on the reference with zero displacements (the
  // radius from the boundary's spacing, cut to the budget), then moved again and again.
  const Mesh<2> mesh = rectangle_mesh({.nx = 24, .ny = 18, .cells = RectangleCells::tri_quad});
  BoundarySpec<2> spec;
  spec.moving("bottom", Translation<2>{meshmotion::Vec<2>(0.0, 0.1)}).fixed("top").fixed("left").fixed("right");
  ResolvedBoundary<2> b = spec.resolve(mesh);
  const Points<2> bump = b.displacements;
  b.displacements.setZero();
  RbfOptions options;
  options.max_memory_bytes = 1e5;
  RbfMover<2> serial(options);
  serial.setup(mesh, b);
  REQUIRE(serial.support_radius_reduced());
  const DistributedMesh<2> part = partition_mesh(world(), mesh);
  ResolvedBoundary<2> local_b = distribute_boundary(part, b);
  DistributedRbfMover<2> mover(options, {BoundarySolve::replicated});
  mover.setup(part.view(), local_b);
  CHECK(mover.support_radius() == serial.support_radius());
  CHECK(mover.stats().radius_reduced);
  for (const double scale : {0.5, 1.0, -2.0}) {
    Points<2> d = bump;
    for (Index k = 0; k < d.cols(); ++k)
      d.col(k) *= scale * std::sin(3.14159 * mesh.points(0, b.nodes[static_cast<std::size_t>(k)]));
    const Points<2> expected = serial.move(d);
    const Points<2> got = mover.move(local_values(part, b, local_b, d));
    INFO("scale " << scale);
    CHECK(largest_gap(part, got, expected) <= 1e-12 * expected.colwise().norm().maxCoeff());
  }
}

TEST_CASE("distributed RBF set up before the motion grows its radius with it as the serial mover does",
          "[parallel][rbf][petsc]") {
  // A ring whose whole boundary turns and stretches, moved from the reference in growing
  // steps after a setup with no motion: the ranks decide to set up again together, for the
  // same radius as the serial mover, and move every node as it does.
  const Mesh<2> ring = annulus_mesh({.n_around = 48});
  BoundarySpec<2> spec;
  spec.moving("inner", Translation<2>{meshmotion::Vec<2>::Zero()}).moving("outer", Translation<2>{meshmotion::Vec<2>::Zero()});
  const ResolvedBoundary<2> b = spec.resolve(ring);
  const auto motion = [&](double s) {
    Points<2> d(2, b.size());
    for (Index k = 0; k < d.cols(); ++k) {
      const meshmotion::Vec<2> x = ring.points.col(b.nodes[static_cast<std::size_t>(k)]);
      d.col(k) = Eigen::Rotation2Dd(s) * meshmotion::Vec<2>((1.0 + 0.2 * s) * x.x(), x.y()) - x;
    }
    return d;
  };
  for (const BoundarySolve solve : {BoundarySolve::replicated, BoundarySolve::petsc}) {
    CAPTURE(static_cast<int>(solve));
    RbfMover<2> serial;
    serial.setup(ring, b);
    const DistributedMesh<2> part = partition_mesh(world(), ring);
    const ResolvedBoundary<2> local_b = distribute_boundary(part, b);
    DistributedRbfMover<2> mover({}, {solve});
    {
      // The mover keeps its own copy of the part: the caller's arrays may go.
      Points<2> points = part.local.points;
      std::vector<std::int64_t> ids = part.global_ids;
      std::vector<int> owners = part.owner;
      mover.setup(PartitionView<2>{world(), points, ids, owners}, local_b);
    }
    for (const double s : {0.05, 0.2, 0.5, 0.9, 0.3, 0.9, 2.0}) {
      CAPTURE(s);
      const Points<2> d = motion(s);
      const Points<2> expected = serial.move(d);
      const Points<2> got = mover.move(local_values(part, b, local_b, d));
      CHECK(mover.support_radius() == serial.support_radius());
      CHECK(mover.stats().radius_growths == serial.stats().radius_growths);
      CHECK(largest_gap(part, got, expected) <= 1e-10 * expected.colwise().norm().maxCoeff());
      // The move's time split: set up again where the serial mover was (or built first), and solved.
      const MoverStats& split = mover.stats();
      CHECK((split.rebuild_seconds > 0.0) == (serial.stats().rebuild_seconds > 0.0));
      CHECK(split.solve_seconds > 0.0);
      CHECK(split.solve_seconds + split.rebuild_seconds <= split.move_seconds);
      // The grid velocity through the same map: the serial one, and no set-up again.
      const Points<2> v = motion(0.3 * s);
      const Points<2> expected_velocity = serial.derivative_forward(v);
      const Index growths = mover.stats().radius_growths;
      const Points<2> velocity = mover.velocity(local_values(part, b, local_b, v));
      CHECK(largest_gap(part, velocity, expected_velocity) <= 1e-10 * expected_velocity.colwise().norm().maxCoeff());
      CHECK(mover.stats().radius_growths == growths);
    }
    // The turn is each move's rigid part (blended by both alike); the stretch it leaves grows
    // the radius at 2.0 (the ring's spacing radius is 1.96).
    CHECK(serial.rigid_part_taken_out());
    CHECK(mover.stats().rigid_part);
    CHECK(serial.stats().radius_growths >= 1);
    CHECK(serial.stats().radius_growths <= 2);
  }
}

TEST_CASE("distributed RBF with the boundary system factorized across the ranks by MUMPS", "[parallel][rbf][petsc]") {
  const BoundarySolveOptions petsc{BoundarySolve::petsc};
  {
    const Mesh<2> mesh = rectangle_mesh({.nx = 24, .ny = 18, .cells = RectangleCells::tri_quad});
    BoundarySpec<2> spec;
    spec.moving("bottom", Rotation2D{{0.5, 0.0}, radians(8.0)}).fixed("top").fixed("left");
    for (const bool polynomial : {false, true}) {
      RbfOptions options;
      options.support_radius = 0.6;
      options.polynomial = polynomial;
      const Outcome r = compare_with_serial(mesh, spec.resolve(mesh), options, {}, false, petsc);
      INFO("polynomial " << polynomial << ": move " << r.error << ", gradient " << r.gradient << ", rounding " << r.gradient_rounding);
      CHECK(r.error <= 1e-12);
      CHECK(r.gradient <= std::max(1e-12, 100.0 * r.gradient_rounding));
    }
  }
  {
    const Mesh<3> mesh = box_mesh({.nx = 8, .ny = 6, .nz = 6, .cells = BoxCells::tet4});
    BoundarySpec<3> spec;
    spec.moving("bottom", Rotation3D{{0.5, 0.5, 0.0}, {1.0, 0.0, 0.0}, radians(5.0)}).fixed("top").fixed("front");
    RbfOptions options;
    options.support_radius = 0.7;
    options.polynomial = true;
    const Outcome r = compare_with_serial(mesh, spec.resolve(mesh), options, {}, false, petsc);
    INFO("move " << r.error << ", gradient " << r.gradient << ", rounding " << r.gradient_rounding);
    CHECK(r.error <= 1e-12);
    CHECK(r.gradient <= std::max(1e-12, 100.0 * r.gradient_rounding));
  }
  {
    // The partition that leaves ranks without moving nodes, without group nodes, or empty.
    const Mesh<2> mesh = rectangle_mesh({.nx = 10, .ny = 10});
    const std::vector<int> ranks = test::row_bands(10, 10);
    BoundarySpec<2> spec;
    spec.moving("bottom", Translation<2>{{0.0, 0.08}}).fixed("top");
    const Outcome r = compare_with_serial(mesh, spec.resolve(mesh), {.support_radius = 0.9}, ranks, false, petsc);
    CHECK(r.error <= 1e-12);
  }
  // What the PETSc path cannot take is refused on every rank, naming the reason.
  const Mesh<2> mesh = rectangle_mesh({.nx = 8, .ny = 8});
  BoundarySpec<2> spec;
  spec.moving("bottom", Translation<2>{{0.0, 0.05}}).fixed("top").sliding("left");
  const DistributedMesh<2> part = partition_mesh(world(), mesh);
  const ResolvedBoundary<2> b = distribute_boundary(part, spec.resolve(mesh));
  DistributedRbfMover<2> sliding({.support_radius = 0.5}, petsc);
  CHECK_THROWS_WITH(sliding.setup(part.view(), b), Catch::Contains("sliding nodes"));
  DistributedRbfMover<2> automatic({.support_radius = 0.5}, {BoundarySolve::automatic, 1});
  automatic.setup(part.view(), b);
  CHECK_FALSE(automatic.petsc_solve());
}

TEST_CASE("distributed partition of unity: patches on their ranks, the serial PU-RBF's result", "[parallel][rbf][patches]") {
  const BoundarySolveOptions patches{BoundarySolve::patches};
  RbfOptions options;
  options.partition_of_unity = true;
  options.patch_centres = 7;  // many patches, a run of them on each rank
  SECTION("2D, given and default radius") {
    const Mesh<2> mesh = rectangle_mesh({.nx = 24, .ny = 18, .cells = RectangleCells::tri_quad});
    BoundarySpec<2> spec;
    spec.moving("bottom", Rotation2D{{0.5, 0.0}, radians(8.0)}).fixed("top").fixed("left");
    for (const double radius : {0.3, 0.0}) {
      options.support_radius = radius;
      const Outcome r = compare_with_serial(mesh, spec.resolve(mesh), options, {}, false, patches);
      INFO("radius " << radius << ": move " << r.error << ", gradient " << r.gradient << ", rounding " << r.gradient_rounding);
      CHECK(r.solved_by == BoundarySolve::patches);
      CHECK(r.patches >= 8);
      CHECK(r.error <= 1e-12);
      CHECK(r.gradient <= std::max(1e-12, 100.0 * r.gradient_rounding));
      CHECK(r.global_entries == static_cast<Index>(spec.resolve(mesh).size()));
    }
  }
  SECTION("3D, and ranks without moving nodes, without group nodes, or empty") {
    const Mesh<3> mesh = box_mesh({.nx = 8, .ny = 6, .nz = 6, .cells = BoxCells::tet4});
    BoundarySpec<3> spec;
    spec.moving("bottom", Rotation3D{{0.5, 0.5, 0.0}, {1.0, 0.0, 0.0}, radians(5.0)}).fixed("top").fixed("front");
    options.support_radius = 0.4;
    options.patch_centres = 20;
    const Outcome r = compare_with_serial(mesh, spec.resolve(mesh), options, {}, false, patches);
    INFO("move " << r.error << ", gradient " << r.gradient << ", rounding " << r.gradient_rounding);
    CHECK(r.solved_by == BoundarySolve::patches);
    CHECK(r.error <= 1e-12);
    CHECK(r.gradient <= std::max(1e-12, 100.0 * r.gradient_rounding));
    const Mesh<2> square = rectangle_mesh({.nx = 10, .ny = 10});
    BoundarySpec<2> bands;
    bands.moving("bottom", Translation<2>{{0.0, 0.08}}).fixed("top");
    options.support_radius = 0.5;
    options.patch_centres = 4;
    const Outcome b = compare_with_serial(square, bands.resolve(square), options, test::row_bands(10, 10), false, patches);
    CHECK(b.error <= 1e-12);
    CHECK(b.gradient <= std::max(1e-12, 100.0 * b.gradient_rounding));
  }
  SECTION("what patches cannot take: replicated by automatic, refused when asked for") {
    const Mesh<2> mesh = rectangle_mesh({.nx = 12, .ny = 10});
    BoundarySpec<2> spec;
    spec.moving("bottom", Translation<2>{{0.0, 0.05}}).fixed("top").sliding("left");
    options.support_radius = 0.4;
    const Outcome r = compare_with_serial(mesh, spec.resolve(mesh), options);
    CHECK(r.solved_by == BoundarySolve::replicated);
    CHECK(r.error <= 1e-12);
    const DistributedMesh<2> part = partition_mesh(world(), mesh);
    const ResolvedBoundary<2> b = distribute_boundary(part, spec.resolve(mesh));
    DistributedRbfMover<2> sliding(options, patches);
    CHECK_THROWS_WITH(sliding.setup(part.view(), b), Catch::Contains("sliding nodes") && Catch::Contains("replicated"));
    DistributedRbfMover<2> no_patches({.support_radius = 0.4}, patches);
    CHECK_THROWS_WITH(no_patches.setup(part.view(), b), Catch::Contains("partition_of_unity"));
    // The serial refusal of a global kernel comes through the replicated path, on every rank.
    RbfOptions global = options;
    global.kernel = RbfKernel::gaussian;
    DistributedRbfMover<2> automatic(global);
    CHECK_THROWS_WITH(automatic.setup(part.view(), b), Catch::Contains("compact kernel"));
  }
}

TEST_CASE("distributed RBF moves straight into the caller's storage, and refuses another shape on every rank",
          "[parallel][rbf]") {
  // What Python's Warp(comm=) hands it: a numpy array of the part's size, written in place.
  const Mesh<2> mesh = rectangle_mesh({.nx = 16, .ny = 12, .cells = RectangleCells::tri_quad});
  BoundarySpec<2> spec;
  spec.moving("bottom", Rotation2D{{0.5, 0.0}, radians(6.0)}).fixed("top").fixed("left");
  const DistributedMesh<2> part = partition_mesh(world(), mesh);
  const ResolvedBoundary<2> b = distribute_boundary(part, spec.resolve(mesh));
  ResolvedBoundary<2> at_rest = b;  // set up before anything moves, as a solver does
  at_rest.displacements.setZero();
  RbfOptions patched;
  patched.partition_of_unity = true;
  patched.patch_centres = 7;
  const std::pair<RbfOptions, BoundarySolve> cases[] = {{RbfOptions{}, BoundarySolve::replicated},
                                                        {RbfOptions{}, BoundarySolve::petsc},
                                                        {patched, BoundarySolve::patches}};
  for (auto [options, solve] : cases) {
    options.support_radius = 0.4;
    DistributedRbfMover<2> mover(options, {solve});
    mover.setup(part.view(), at_rest);
    REQUIRE(mover.solved_by() == solve);
    const Points<2> expected = mover.move(b.displacements);
    Points<2> storage = Points<2>::Constant(2, part.local.num_nodes(), std::nan(""));
    mover.move_into(b.displacements, Eigen::Ref<Points<2>>(storage));
    INFO("boundary solve " << name(solve));
    CHECK(global_max((storage - expected).cwiseAbs().maxCoeff()) == 0.0);
    // One rank's storage of another size: every rank raises, none waits in a collective.
    Points<2> wrong(2, part.local.num_nodes() + (rank_of(world()) == 0 ? 1 : 0));
    CHECK_THROWS_WITH(mover.move_into(b.displacements, Eigen::Ref<Points<2>>(wrong)), Catch::Contains("columns"));
  }
}

TEST_CASE("parallel options: described once, set from text, bad values refused naming the key", "[parallel][options]") {
  BoundarySolveOptions solve;
  CHECK(set_option(solve, "boundary_solve", "petsc"));
  CHECK(solve.boundary_solve == BoundarySolve::petsc);
  CHECK(set_option(solve, "petsc_min_node_centres", "12"));
  CHECK(solve.petsc_min_node_centres == 12);
  CHECK_THROWS_WITH(set_option(solve, "boundary_solve", "mumps"), Catch::Contains("boundary_solve") && Catch::Contains("replicated"));
  DistributedElasticityOptions elasticity;
  CHECK(set_option(elasticity, "petsc_solver", "mumps"));
  CHECK(elasticity.petsc_solver == PetscSolverKind::direct_mumps);
  CHECK_FALSE(set_option(elasticity, "boundary_solve", "petsc"));
  // The defaults the docs show are the structs' own.
  for (const OptionDoc& d : option_docs(BoundarySolveOptions{}))
    if (d.key == "petsc_min_node_centres") CHECK(d.value == std::to_string(BoundarySolveOptions{}.petsc_min_node_centres));
}

TEST_CASE("automatic boundary solve: PETSc on several ranks once centres × ranks per node reach the threshold",
          "[parallel][rbf][petsc]") {
  // Every rank of a ctest run shares one node.
  CHECK(ranks_on_node(world()) == size_of(world()));
  const int share = node_share_of_cores(world());
  CHECK(share >= 1);
  CHECK(share <= std::max(1, static_cast<int>(std::thread::hardware_concurrency()) / size_of(world())));

  const Mesh<2> mesh = rectangle_mesh({.nx = 10, .ny = 10});
  BoundarySpec<2> spec;
  spec.moving("bottom", Translation<2>{{0.0, 0.05}}).fixed("top");
  const ResolvedBoundary<2> whole_b = spec.resolve(mesh);
  const auto centres = static_cast<Index>(whole_b.size());
  const DistributedMesh<2> part = partition_mesh(world(), mesh);
  const ResolvedBoundary<2> b = distribute_boundary(part, whole_b);
  const auto chooses_petsc = [&](Index node_centres) {
    BoundarySolveOptions solve;
    solve.petsc_min_node_centres = node_centres;
    DistributedRbfMover<2> mover({.support_radius = 0.5}, solve);
    mover.setup(part.view(), b);
    return mover.petsc_solve();
  };
  // ctest's 3 and 4 ranks on 2 cores run their factorizations in 2 rounds.
  const int rounds = (ranks_on_node(world()) + cores_of_node() - 1) / cores_of_node();
  const Index work = centres * ranks_on_node(world()) * rounds;
  // One rank keeps the serial mover's own solve; several take PETSc from the threshold on.
  CHECK(chooses_petsc(work) == (size_of(world()) > 1));
  CHECK_FALSE(chooses_petsc(work + 1));
  CHECK_FALSE(chooses_petsc(BoundarySolveOptions{}.petsc_min_node_centres));
}

TEST_CASE("distributed RBF keeps sliding nodes and per-node radii as serial does", "[parallel][rbf]") {
  const Mesh<2> mesh = rectangle_mesh({.nx = 20, .ny = 16, .cells = RectangleCells::tri3});
  BoundarySpec<2> spec;
  spec.moving("bottom", Translation<2>{{0.05, 0.02}}).fixed("top").sliding("left").sliding("right");
  RbfOptions options;
  options.support_radius = 0.5;
  CHECK(compare_with_serial(mesh, spec.resolve(mesh), options).error <= 1e-12);
  const Outcome radii = compare_with_serial(mesh, spec.resolve(mesh), options, {}, true);
  CHECK(radii.error <= 1e-12);
  CHECK(radii.gradient <= 1e-12);
}

TEST_CASE("distributed RBF equals serial on 3D meshes", "[parallel][rbf]") {
  for (const BoxCells cells : {BoxCells::tet4, BoxCells::hex_prism}) {
    const Mesh<3> mesh = box_mesh({.nx = 8, .ny = 6, .nz = 6, .cells = cells});
    BoundarySpec<3> spec;
    spec.moving("bottom", Rotation3D{{0.5, 0.5, 0.0}, {1.0, 0.0, 0.0}, radians(5.0)}).fixed("top").sliding("front");
    RbfOptions options;
    options.support_radius = 0.7;
    options.polynomial = cells == BoxCells::tet4;
    const Outcome r = compare_with_serial(mesh, spec.resolve(mesh), options);
    INFO("move " << r.error << ", gradient " << r.gradient << ", rounding " << r.gradient_rounding);
    CHECK(r.error <= 1e-12);
    CHECK(r.gradient <= 1e-12);
  }
}

TEST_CASE("distributed RBF equals serial on real meshes of ../shared/data", "[parallel][rbf][shared]") {
  const std::filesystem::path dir = MESHMOTION_SHARED_DATA_DIR;
  const auto naca = dir / "su2_naca0012_inviscid_tri.su2";
  if (!std::filesystem::exists(naca)) {
    WARN("skipped: " << naca << " is absent (../shared/data holds the public meshes)");
    return;
  }
  {
    const Mesh<2> mesh = std::get<Mesh<2>>(read_mesh(naca.string()));
    BoundarySpec<2> spec;
    spec.moving("airfoil", Rotation2D{{0.25, 0.0}, radians(3.0)}).fixed("farfield");
    RbfOptions options;
    options.support_radius = 3.0;
    // One kind of evaluation operator on every rank and in serial: whether a part stores its
    // operator dense depends on how much of the boundary its own nodes see, and the dense
    // product sums in another order, which this wide support over a fine wall (huge,
    // alternating coefficients) turns into 5e-12 instead of 1e-16.
    options.max_evaluation_cache_bytes = 0;
    const Outcome r = compare_with_serial(mesh, spec.resolve(mesh), options);
    INFO("move " << r.error << ", gradient " << r.gradient << ", rounding " << r.gradient_rounding);
    CHECK(r.error <= 1e-12);
    CHECK(r.gradient <= std::max(1e-12, 100.0 * r.gradient_rounding));
  }
  const auto sphere = dir / "meshopt_sphere_symmetry_linear_tet.msh";
  if (!std::filesystem::exists(sphere)) return;
  // Its facets carry no physical groups: the sphere (radius 0.5) moves, the symmetry plane
  // y = 0 slides, the rest of the box is held.
  const Mesh<3> mesh = std::get<Mesh<3>>(read_mesh(sphere.string()));
  GroupNodes groups{{"sphere", {}}, {"symmetry", {}}, {"box", {}}};
  std::vector<char> seen(static_cast<std::size_t>(mesh.num_nodes()), 0);
  for (const auto& block : mesh.facets)
    for (const Index v : block.connectivity) {
      if (seen[static_cast<std::size_t>(v)] != 0) continue;
      seen[static_cast<std::size_t>(v)] = 1;
      const meshmotion::Vec<3> x = mesh.points.col(v);
      groups[x.norm() < 0.6 ? "sphere" : std::abs(x[1]) < 1e-9 ? "symmetry" : "box"].push_back(v);
    }
  BoundarySpec<3> spec;
  spec.moving("sphere", Rotation3D{{0.0, 0.0, 0.0}, {0.0, 0.0, 1.0}, radians(4.0)}).sliding("symmetry", meshmotion::Vec<3>::UnitY()).fixed("box");
  RbfOptions options;
  options.support_radius = 5.0;
  const Outcome r = compare_with_serial(mesh, spec.resolve(mesh.points, groups), options);
  INFO("move " << r.error << ", gradient " << r.gradient << ", rounding " << r.gradient_rounding);
  CHECK(r.error <= 1e-12);
  CHECK(r.gradient <= std::max(1e-12, 100.0 * r.gradient_rounding));
}

TEST_CASE("distributed RBF: a rank without moving nodes, one without group nodes, an empty one", "[parallel][rbf]") {
  // test::row_bands: rank 0 on the moving bottom, rank 1 without group nodes, rank 2 with fixed
  // nodes only, rank 3 empty.
  const Mesh<2> mesh = rectangle_mesh({.nx = 10, .ny = 10});
  const std::vector<int> ranks = test::row_bands(10, 10);
  BoundarySpec<2> spec;
  spec.moving("bottom", Translation<2>{{0.0, 0.08}}).fixed("top");
  RbfOptions options;
  options.support_radius = 0.9;
  const Outcome r = compare_with_serial(mesh, spec.resolve(mesh), options, ranks);
  CHECK(r.error <= 1e-12);
  CHECK(r.gradient <= 1e-12);
}

TEST_CASE("distributed RBF: an error on one rank is raised on every rank", "[parallel][rbf]") {
  const Mesh<2> mesh = rectangle_mesh({.nx = 8, .ny = 8});
  BoundarySpec<2> spec;
  spec.moving("bottom", Translation<2>{{0.0, 0.05}}).fixed("top");
  const ResolvedBoundary<2> whole = spec.resolve(mesh);
  const DistributedMesh<2> part = partition_mesh(world(), mesh);
  const ResolvedBoundary<2> b = distribute_boundary(part, whole);
  const int last = size_of(world()) - 1;

  RbfOptions wrong;
  wrong.support_radius = 0.5;
  if (rank_of(world()) == last) wrong.support_radii.assign(static_cast<std::size_t>(b.size()) + 1, 0.5);
  DistributedRbfMover<2> refused(wrong);
  CHECK_THROWS_WITH(refused.setup(part.view(), b), Catch::Contains("rank " + std::to_string(last)) &&
                                                     Catch::Contains("support radii"));

  DistributedRbfMover<2> mover({.support_radius = 0.5});
  mover.setup(part.view(), b);
  Points<2> d = b.displacements;
  // The last rank's first owned entry gets a NaN: every rank hears of it.
  for (Index k = 0; k < b.size() && rank_of(world()) == last; ++k)
    if (part.view().owns(b.nodes[static_cast<std::size_t>(k)])) {
      d(0, k) = std::nan("");
      break;
    }
  int has_owned = 0;
  for (Index k = 0; k < b.size(); ++k) has_owned |= part.view().owns(b.nodes[static_cast<std::size_t>(k)]) ? 1 : 0;
  const bool poisoned = test::global_max(rank_of(world()) == last && has_owned != 0 ? 1.0 : 0.0) > 0.0;
  if (poisoned)
    CHECK_THROWS_AS(mover.move(d), InputError);
  CHECK_THROWS_WITH(mover.move(Points<2>::Zero(2, b.size() + (rank_of(world()) == 0 ? 1 : 0))),
                    Catch::Contains("rank 0") && Catch::Contains("one per local boundary entry"));
  // After refusals the mover still works.
  CHECK(test::global_max(mover.move(b.displacements).hasNaN() ? 1.0 : 0.0) == 0.0);
}

TEST_CASE("partition_mesh keeps every node once, and gather_owned restores the whole numbering", "[parallel][mesh]") {
  Mesh<3> mesh = box_mesh({.nx = 5, .ny = 4, .nz = 3, .cells = BoxCells::tet_pyramid_prism});
  mesh.first_node_id = 0;  // as SU2 and OpenFOAM number
  const DistributedMesh<3> part = partition_mesh(world(), mesh);
  // Each local node keeps the file's id of its node in the whole mesh.
  double wrong_id = 0.0;
  for (Index i = 0; i < part.local.num_nodes(); ++i)
    if (part.local.node_id(i) != mesh.node_id(static_cast<Index>(part.global_ids[static_cast<std::size_t>(i)]))) wrong_id = 1.0;
  CHECK(global_max(wrong_id) == 0.0);
  Index owned = part.num_owned, cells = part.local.num_cells();
  MPI_Allreduce(MPI_IN_PLACE, &owned, 1, MPI_INT64_T, MPI_SUM, world());
  MPI_Allreduce(MPI_IN_PLACE, &cells, 1, MPI_INT64_T, MPI_SUM, world());
  CHECK(owned == mesh.num_nodes());
  CHECK(cells == mesh.num_cells());
  const Points<3> gathered = gather_owned(part.view(), part.local.points, part.num_global_nodes);
  if (rank_of(world()) == 0) CHECK(gathered == mesh.points);
  // Every local cell's nodes are local, and the ghosts are owned elsewhere.
  double bad = 0.0;
  for (Index i = part.num_owned; i < part.local.num_nodes(); ++i)
    if (part.owner[static_cast<std::size_t>(i)] == rank_of(world())) bad = 1.0;
  CHECK(global_max(bad) == 0.0);
  CHECK_THROWS_WITH(partition_mesh(world(), mesh, std::vector<int>(3, 0)), Catch::Contains("cell ranks for"));
}

TEST_CASE("distributed RBF set up at rest blends each move's rigid part as the serial mover does",
          "[parallel][rbf][petsc]") {
  // A square turned inside a held circle from one setup with nothing moving: the ranks sum the
  // rigid fit together and blend it over their own nodes; moves, grid velocities and reverse
  // derivatives equal the serial mover's, with the boundary system replicated and through PETSc.
  const Mesh<2> mesh = o_mesh({.body = OMeshBody::square, .semi_axis_x = 1.0, .n_around = 48, .n_radial = 24,
                               .first_height = 0.02, .farfield_radius = 6.0});
  BoundarySpec<2> spec;
  spec.moving("wall", Translation<2>{meshmotion::Vec<2>::Zero()}).fixed("farfield");
  const ResolvedBoundary<2> b = spec.resolve(mesh);
  const auto motion = [&](double degrees, double wobble) {
    Points<2> d = Points<2>::Zero(2, b.size());
    for (Index k = 0; k < b.size(); ++k)
      if (b.kinds[static_cast<std::size_t>(k)] == BoundaryKind::prescribed) {
        const meshmotion::Vec<2> x = mesh.points.col(b.nodes[static_cast<std::size_t>(k)]);
        d.col(k) = Eigen::Rotation2Dd(degrees * std::numbers::pi / 180.0) * x - x +
                   wobble * meshmotion::Vec<2>(std::sin(3.0 * x.y()), std::cos(2.0 * x.x()));
      }
    return d;
  };
  Points<2> seed(2, mesh.num_nodes());
  for (Index i = 0; i < mesh.num_nodes(); ++i) seed.col(i) = meshmotion::Vec<2>(std::sin(1.0 + 2.0 * mesh.points(0, i)), std::cos(mesh.points(1, i)));
  for (const BoundarySolve solve : {BoundarySolve::replicated, BoundarySolve::petsc}) {
    CAPTURE(static_cast<int>(solve));
    RbfMover<2> serial;
    serial.setup(mesh, b);
    const DistributedMesh<2> part = partition_mesh(world(), mesh);
    const ResolvedBoundary<2> local_b = distribute_boundary(part, b);
    DistributedRbfMover<2> mover({}, {solve});
    mover.setup(part.view(), part.local, local_b);
    REQUIRE(mover.stats().rigid_part);
    // As the serial mover: nothing factorized while each move's rigid part carries it all.
    CHECK(mover.stats().factorizations == 0);
    const Points<2> turned = motion(30.0, 0.0);
    const Points<2> rigid = serial.move(turned);
    CHECK(largest_gap(part, mover.move(local_values(part, b, local_b, turned)), rigid) <= 1e-12 * rigid.colwise().norm().maxCoeff());
    CHECK(mover.stats().factorizations == 0);
    CHECK(mover.stats().moves == 1);
    Points<2> local_seed(2, part.local.num_nodes());
    for (Index i = 0; i < part.local.num_nodes(); ++i) local_seed.col(i) = seed.col(part.global_ids[static_cast<std::size_t>(i)]);
    for (const double degrees : {45.0, 135.0, 180.0, 60.0}) {
      CAPTURE(degrees);
      const Points<2> d = motion(degrees, 0.01);
      const Points<2> expected = serial.move(d);
      const Points<2> got = mover.move(local_values(part, b, local_b, d));
      CHECK(largest_gap(part, got, expected) <= 1e-10 * expected.colwise().norm().maxCoeff());
      CHECK(mover.stats().factorizations >= 1);
      const Points<2> v = motion(10.0, 0.05);
      const Points<2> expected_velocity = serial.derivative_forward(v);
      CHECK(largest_gap(part, mover.velocity(local_values(part, b, local_b, v)), expected_velocity) <=
            1e-10 * expected_velocity.colwise().norm().maxCoeff());
      const Points<2> expected_gradient = serial.derivative_reverse(seed);
      const Points<2> gradient = mover.derivative_reverse(local_seed);
      double worst = 0.0;
      for (Index k = 0; k < local_b.size(); ++k) {
        const Index local = local_b.nodes[static_cast<std::size_t>(k)];
        if (part.view().owns(local))
          worst = std::max(worst, (gradient.col(k) - expected_gradient.col(b.column(part.global_ids[static_cast<std::size_t>(local)]))).norm());
      }
      CHECK(global_max(worst) <= 1e-9 * expected_gradient.colwise().norm().maxCoeff());
    }
  }
}

TEST_CASE("distributed RBF given the cells repairs what a half turn folds as the serial mover does", "[parallel][rbf]") {
  // The coarse O-mesh whose linear cells a half turn folds (rbf_test.cpp): the ranks gather
  // the folded cells' patch and repair it in the serial order, so the points are the serial ones.
  const Mesh<2> mesh = o_mesh({.body = OMeshBody::square, .semi_axis_x = 1.0, .n_around = 64, .n_radial = 40,
                               .first_height = 0.01, .farfield_radius = 6.0});
  BoundarySpec<2> spec;
  spec.moving("wall", Translation<2>{meshmotion::Vec<2>::Zero()}).fixed("farfield");
  const ResolvedBoundary<2> b = spec.resolve(mesh);
  RbfMover<2> serial;
  serial.setup(mesh, b);
  const DistributedMesh<2> part = partition_mesh(world(), mesh);
  const ResolvedBoundary<2> local_b = distribute_boundary(part, b);
  DistributedRbfMover<2> mover;
  mover.setup(part.view(), part.local, local_b);
  Index folded = 0;
  for (const double degrees : {90.0, 150.0, 165.0, 180.0}) {
    CAPTURE(degrees);
    Points<2> d = Points<2>::Zero(2, b.size());
    for (Index k = 0; k < b.size(); ++k)
      if (b.kinds[static_cast<std::size_t>(k)] == BoundaryKind::prescribed) {
        const meshmotion::Vec<2> x = mesh.points.col(b.nodes[static_cast<std::size_t>(k)]);
        d.col(k) = Eigen::Rotation2Dd(degrees * std::numbers::pi / 180.0) * x - x;
      }
    const Points<2> expected = serial.move(d);
    const Points<2> got = mover.move(local_values(part, b, local_b, d));
    CHECK(largest_gap(part, got, expected) <= 1e-10 * expected.colwise().norm().maxCoeff());
    CHECK(mover.stats().folded_cells == serial.stats().folded_cells);
    CHECK(mover.stats().repaired_nodes == serial.stats().repaired_nodes);
    CHECK(mover.stats().left_folded == 0);
    folded += serial.stats().folded_cells;
  }
  CHECK(folded > 0);
}

TEST_CASE("distributed RBF on two levels: the serial mover's levels, moves and gradients", "[parallel][rbf]") {
  // A terrain under a held lid, the sides sliding: set up at rest on both, the bottom raised
  // step by step. Above two_level_centres boundary nodes with the default radius, both take two
  // levels (the coarse nodes chosen from the gathered boundary in the serial order).
  const Mesh<3> mesh = box_mesh({.nx = 10, .ny = 10, .nz = 8});
  BoundarySpec<3> spec;
  spec.prescribed("bottom").fixed("top").sliding("left").sliding("right").sliding("front").sliding("back");
  const ResolvedBoundary<3> b = spec.resolve(mesh);
  const auto hills = [&](double height) {
    Points<3> d = Points<3>::Zero(3, b.size());
    for (Index k = 0; k < b.size(); ++k) {
      const meshmotion::Vec<3> x = mesh.points.col(b.nodes[static_cast<std::size_t>(k)]);
      if (b.kinds[static_cast<std::size_t>(k)] == BoundaryKind::prescribed)
        d(2, k) = height * std::exp(-((x(0) - 0.4) * (x(0) - 0.4) + (x(1) - 0.5) * (x(1) - 0.5)) / 0.04);
    }
    return d;
  };
  RbfOptions options;
  options.two_level_centres = 200;
  RbfMover<3> serial(options);
  serial.setup(mesh, b);
  const DistributedMesh<3> part = partition_mesh(world(), mesh);
  const ResolvedBoundary<3> local_b = distribute_boundary(part, b);
  DistributedRbfMover<3> mover(options);
  mover.setup(part.view(), local_b);
  CHECK_FALSE(mover.petsc_solve());
  for (const double height : {0.02, 0.1, 0.25, 0.1, 0.4}) {
    CAPTURE(height);
    const Points<3> d = hills(height);
    const Points<3> expected = serial.move(d);
    const Points<3> got = mover.move(local_values(part, b, local_b, d));
    REQUIRE(serial.coarse_centres() > 0);
    CHECK(mover.support_radius() == serial.support_radius());
    CHECK(mover.stats().radius_growths == serial.stats().radius_growths);
    CHECK(largest_gap(part, got, expected) <= 1e-10 * expected.colwise().norm().maxCoeff());
  }
  CHECK(serial.stats().radius_growths >= 1);
  // levels=two asked for, a radius given: the reverse derivative too.
  RbfOptions two;
  two.levels = RbfLevels::two;
  two.support_radius = 0.8;
  ResolvedBoundary<3> raised = b;
  raised.displacements = hills(0.2);
  const Outcome r = compare_with_serial(mesh, raised, two);
  INFO("move " << r.error << ", gradient " << r.gradient << ", rounding " << r.gradient_rounding);
  CHECK(r.error <= 1e-12);
  CHECK(r.gradient <= std::max(1e-12, 10.0 * r.gradient_rounding));
}
