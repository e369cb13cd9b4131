// The distributed elasticity mover (PETSc) against the serial ElasticityMover (direct
// Cholesky) on the whole mesh: equal within the solver's tolerance at any number of ranks.
#include "parallel_support.hpp"

#include "meshmotion/core/generators.hpp"
#include "meshmotion/movers/elasticity.hpp"
#include "meshmotion/parallel.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <utility>

using namespace meshmotion;
using namespace meshmotion::parallel;
using test::global_max;
using test::world;

namespace {

template <int Dim>
double relative_error(const Mesh<Dim>& whole, const BoundarySpec<Dim>& spec, const DistributedElasticityOptions& options,
                      std::span<const int> cell_ranks = {}, MoverStats* stats = nullptr) {
  const ResolvedBoundary<Dim> b = spec.resolve(whole);
  ElasticityMover<Dim> serial(options.elasticity);
  serial.setup(whole, b);
  const Points<Dim> expected = serial.move(b.displacements);

  const DistributedMesh<Dim> part = partition_mesh(world(), whole, cell_ranks);
  const ResolvedBoundary<Dim> local_b = distribute_boundary(part, b);
  DistributedElasticityMover<Dim> mover(options);
  mover.setup(part, local_b);
  const Points<Dim> got = mover.move(local_b.displacements);
  if (stats != nullptr) *stats = mover.stats();
  double worst = 0.0;
  for (Index i = 0; i < part.local.num_nodes(); ++i)
    worst = std::max(worst, (got.col(i) - expected.col(part.global_ids[static_cast<std::size_t>(i)])).norm());
  return global_max(worst) / expected.colwise().norm().maxCoeff();
}

}  // namespace

TEST_CASE("distributed elasticity equals serial within the solver tolerance (2D, sliding side)", "[parallel][elasticity]") {
  const Mesh<2> mesh = rectangle_mesh({.nx = 24, .ny = 16, .cells = RectangleCells::tri_quad});
  BoundarySpec<2> spec;
  spec.moving("bottom", Rotation2D{{0.5, 0.0}, radians(6.0)}).fixed("top").sliding("left").sliding("right");
  DistributedElasticityOptions options;
  options.elasticity.poisson_ratio = 0.4;
  options.petsc_tolerance = 1e-12;
  SECTION("CG + GAMG") { CHECK(relative_error(mesh, spec, options) <= 1e-9); }
  SECTION("CG + BoomerAMG") {
    options.petsc_solver = PetscSolverKind::cg_hypre;
    CHECK(relative_error(mesh, spec, options) <= 1e-9);
  }
  SECTION("MUMPS") {
    options.petsc_solver = PetscSolverKind::direct_mumps;
    CHECK(relative_error(mesh, spec, options) <= 1e-11);
  }
}

TEST_CASE("distributed stiffened elasticity equals serial in 3D", "[parallel][elasticity]") {
  const Mesh<3> mesh = box_mesh({.nx = 8, .ny = 6, .nz = 5, .cells = BoxCells::tet_pyramid_prism});
  BoundarySpec<3> spec;
  spec.moving("bottom", Rotation3D{{0.5, 0.5, 0.0}, {1.0, 0.0, 0.0}, radians(4.0)}).fixed("top").sliding("front").sliding("left");
  DistributedElasticityOptions options;
  options.elasticity.stiffening_exponent = 2.0;
  options.petsc_tolerance = 1e-12;
  MoverStats stats;
  CHECK(relative_error(mesh, spec, options, {}, &stats) <= 1e-9);
  CHECK(stats.moves == 1);
  CHECK(global_max(stats.residual) <= 1e-12);
}

TEST_CASE("distributed elasticity in a time loop: each move starts from the last, the serial result in fewer iterations",
          "[parallel][elasticity]") {
  // Set up once with nothing moving, then moved step by step as a solver does; the forward
  // derivative of the same displacements is the same solve started from zero (a cold start).
  const Mesh<3> whole = box_mesh({.nx = 8, .ny = 6, .nz = 5, .cells = BoxCells::tet_pyramid_prism});
  BoundarySpec<3> spec;
  spec.moving("bottom", Rotation3D{{0.5, 0.5, 0.0}, {1.0, 0.0, 0.0}, radians(8.0)}).fixed("top").sliding("front");
  const ResolvedBoundary<3> b = spec.resolve(whole);
  ElasticityMover<3> serial;
  serial.setup(whole, b);
  const DistributedMesh<3> part = partition_mesh(world(), whole);
  ResolvedBoundary<3> local = distribute_boundary(part, b);
  const Points<3> final_motion = local.displacements;
  local.displacements.setZero();
  DistributedElasticityOptions options;
  options.petsc_tolerance = 1e-10;
  DistributedElasticityMover<3> mover(options);
  mover.setup(part, local);
  // A motion slowing to its top, then one step back past the reference (the history then
  // predicts badly: the start is zero again, no worse than cold).
  const int steps = 6;
  for (int k = 1; k <= steps + 1; ++k) {
    const double s = k <= steps ? std::sin(0.5 * std::numbers::pi * k / steps) : -0.5;
    const Points<3> expected = serial.move(s * b.displacements);
    const Points<3> got = mover.move(s * final_motion);
    const Index warm = mover.stats().iterations;
    const Points<3> cold_got = mover.derivative_forward(s * final_motion);
    const Index cold = mover.stats().iterations;
    double worst = 0.0, worst_cold = 0.0;
    for (Index i = 0; i < part.local.num_nodes(); ++i) {
      const meshmotion::Vec<3> e = expected.col(part.global_ids[static_cast<std::size_t>(i)]);
      worst = std::max(worst, (got.col(i) - e).norm());
      worst_cold = std::max(worst_cold, (cold_got.col(i) - e).norm());
    }
    INFO("step " << k << ": " << warm << " iterations from the last move, " << cold << " from zero");
    CHECK(global_max(worst) <= 1e-7 * expected.colwise().norm().maxCoeff());
    CHECK(global_max(worst_cold) <= 1e-7 * expected.colwise().norm().maxCoeff());
    CHECK(warm <= cold);
    if (k > 1 && k <= steps) CHECK(warm < cold);
  }
}

TEST_CASE("distributed elasticity: an empty rank and a rank without boundary nodes", "[parallel][elasticity]") {
  const Mesh<2> mesh = rectangle_mesh({.nx = 10, .ny = 10});
  const std::vector<int> ranks = test::row_bands(10, 10);
  BoundarySpec<2> spec;
  spec.moving("bottom", Translation<2>{{0.02, 0.05}}).fixed("top");
  DistributedElasticityOptions options;
  options.petsc_tolerance = 1e-12;
  CHECK(relative_error(mesh, spec, options, ranks) <= 1e-9);
}

TEST_CASE("distributed elasticity derivatives: the ranks' reverse gradients add up to the serial one, a dot test holds",
          "[parallel][elasticity][derivatives]") {
  const Mesh<2> whole = rectangle_mesh({.nx = 20, .ny = 12, .cells = RectangleCells::tri_quad});
  BoundarySpec<2> spec;
  spec.moving("bottom", Rotation2D{{0.5, 0.0}, radians(4.0)}).fixed("top").sliding("left").sliding("right");
  const ResolvedBoundary<2> b = spec.resolve(whole);
  DistributedElasticityOptions options;
  options.elasticity.stiffening_exponent = 1.0;
  options.petsc_tolerance = 1e-13;
  ElasticityMover<2> serial(options.elasticity);
  serial.setup(whole, b);
  // One seed per node of the whole mesh, the same on every rank.
  Points<2> v(2, whole.num_nodes());
  for (Index i = 0; i < whole.num_nodes(); ++i) v.col(i) << std::sin(3.0 * i), std::cos(5.0 * i);
  const Points<2> expected = serial.derivative_reverse(v);

  const DistributedMesh<2> part = partition_mesh(world(), whole);
  const ResolvedBoundary<2> local_b = distribute_boundary(part, b);
  DistributedElasticityMover<2> mover(options);
  mover.setup(part, local_b);
  Points<2> local_v(2, part.local.num_nodes());
  for (Index i = 0; i < part.local.num_nodes(); ++i) local_v.col(i) = v.col(part.global_ids[static_cast<std::size_t>(i)]);
  const Points<2> local_gradient = mover.derivative_reverse(local_v);
  Points<2> gradient = Points<2>::Zero(2, b.size());
  for (Index k = 0; k < local_b.size(); ++k)
    gradient.col(b.column(part.global_ids[static_cast<std::size_t>(local_b.nodes[static_cast<std::size_t>(k)])])) += local_gradient.col(k);
  MPI_Allreduce(MPI_IN_PLACE, gradient.data(), static_cast<int>(gradient.size()), MPI_DOUBLE, MPI_SUM, world());
  // The prescribed entries' rows (a fixed entry's displacement is zero by contract: the
  // distributed mover reads none and gives it no gradient, the serial one reads it).
  double worst = 0.0, largest = 0.0;
  for (Index k = 0; k < b.size(); ++k) {
    if (b.kinds[static_cast<std::size_t>(k)] != BoundaryKind::prescribed) continue;
    worst = std::max(worst, (gradient.col(k) - expected.col(k)).cwiseAbs().maxCoeff());
    largest = std::max(largest, expected.col(k).cwiseAbs().maxCoeff());
  }
  CHECK(worst <= 1e-9 * largest);
  CHECK(largest > 0.0);

  // ⟨v, J w⟩ over the owned nodes equals Σ ⟨Jᵀ v, w⟩ over the ranks' entries.
  Points<2> w = Points<2>::Zero(2, local_b.size());
  for (Index k = 0; k < local_b.size(); ++k) {
    const auto g = static_cast<double>(part.global_ids[static_cast<std::size_t>(local_b.nodes[static_cast<std::size_t>(k)])]);
    w.col(k) << std::cos(0.7 * g), std::sin(1.3 * g);
  }
  const Points<2> jw = mover.derivative_forward(w);
  double sums[2] = {0.0, 0.0};
  for (Index i = 0; i < part.num_owned; ++i) sums[0] += local_v.col(i).dot(jw.col(i));
  for (Index k = 0; k < local_b.size(); ++k) sums[1] += local_gradient.col(k).dot(w.col(k));
  MPI_Allreduce(MPI_IN_PLACE, sums, 2, MPI_DOUBLE, MPI_SUM, world());
  CHECK(sums[0] == Approx(sums[1]).epsilon(1e-9));
}

TEST_CASE("distributed elasticity: a solver failure raises on every rank, or falls back when asked", "[parallel][elasticity]") {
  const Mesh<2> mesh = rectangle_mesh({.nx = 16, .ny = 16, .cells = RectangleCells::tri3});
  BoundarySpec<2> spec;
  spec.moving("bottom", Translation<2>{{0.0, 0.05}}).fixed("top");
  DistributedElasticityOptions options;
  options.petsc_tolerance = 1e-14;
  options.petsc_max_iterations = 1;
  options.petsc_solver = PetscSolverKind::cg_hypre;
  CHECK_THROWS_AS(relative_error(mesh, spec, options), SolverError);
  options.petsc_fallback_to_direct = true;
  MoverStats stats;
  CHECK(relative_error(mesh, spec, options, {}, &stats) <= 1e-11);
  CHECK(stats.fell_back);

  DistributedElasticityOptions unsupported;
  unsupported.elasticity.active_radius = 0.3;
  CHECK_THROWS_WITH(relative_error(mesh, spec, unsupported), Catch::Contains("not supported in parallel"));
}

TEST_CASE("PETSc plumbing: a failed call names the caller, the call and PETSc's own text, handles own", "[parallel][petsc]") {
  using meshmotion::parallel::detail::OwnedVec;
  using meshmotion::parallel::detail::petsc_check;
  CHECK_NOTHROW(petsc_check(0, "here", "VecCreate"));
  const char* text = nullptr;
  PetscErrorMessage(PETSC_ERR_ARG_OUTOFRANGE, &text, nullptr);
  REQUIRE(text != nullptr);
  CHECK_THROWS_AS(petsc_check(PETSC_ERR_ARG_OUTOFRANGE, "here", "MatSetSizes"), SolverError);
  CHECK_THROWS_WITH(petsc_check(PETSC_ERR_ARG_OUTOFRANGE, "DistributedElasticityMover::setup", "MatSetSizes"),
                    Catch::Contains("DistributedElasticityMover::setup: PETSc's MatSetSizes failed") &&
                        Catch::Contains(std::string(text)));
  OwnedVec v;
  CHECK_FALSE(v);
  REQUIRE(VecCreateSeq(PETSC_COMM_SELF, 4, v.out()) == 0);
  CHECK(v);
  OwnedVec w = std::move(v);
  CHECK(w);
  CHECK_FALSE(v);  // NOLINT(bugprone-use-after-move): a moved-from handle is empty by contract
  PetscInt size = 0;
  REQUIRE(VecGetSize(w.get(), &size) == 0);
  CHECK(size == 4);
  w.reset();
  CHECK_FALSE(w);
}
