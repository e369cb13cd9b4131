#include "meshmotion/core/threads.hpp"
#include "meshmotion/solvers.hpp"

#include <catch2/catch.hpp>

#include <memory>
#include <vector>

using namespace meshmotion;

namespace {

/// 2D Poisson 5-point matrix on an m × m grid: SPD, well known.
SparseMatrix poisson(int m, double shift = 0.0) {
  std::vector<Eigen::Triplet<double>> t;
  const auto id = [m](int i, int j) { return i * m + j; };
  for (int i = 0; i < m; ++i)
    for (int j = 0; j < m; ++j) {
      t.emplace_back(id(i, j), id(i, j), 4.0 + shift);
      if (i > 0) t.emplace_back(id(i, j), id(i - 1, j), -1.0);
      if (i + 1 < m) t.emplace_back(id(i, j), id(i + 1, j), -1.0);
      if (j > 0) t.emplace_back(id(i, j), id(i, j - 1), -1.0);
      if (j + 1 < m) t.emplace_back(id(i, j), id(i, j + 1), -1.0);
    }
  SparseMatrix a(m * m, m * m);
  a.setFromTriplets(t.begin(), t.end());
  return a;
}

}  // namespace

TEST_CASE("every sparse solver kind solves an SPD system with several right-hand sides", "[solvers]") {
  const SparseMatrix a = poisson(12);
  Eigen::MatrixXd x_true = Eigen::MatrixXd::Random(a.rows(), 3);
  const Eigen::MatrixXd b = a * x_true;
  for (auto kind : {SolverKind::simplicial_ldlt, SolverKind::simplicial_llt, SolverKind::sparse_lu,
                    SolverKind::cg_jacobi, SolverKind::cg_incomplete_cholesky, SolverKind::bicgstab}) {
    CAPTURE(name(kind));
    LinearSolver solver(SolverOptions{kind, 1e-12, 0, false});
    solver.compute(a);
    const Eigen::MatrixXd x = solver.solve(b);
    CHECK((x - x_true).norm() / x_true.norm() < 1e-9);
    CHECK(solver.report().residual < 1e-10);
    CHECK(solver.report().factorizations == 1);
    CHECK(solver.report().fell_back == false);
    if (is_iterative(kind)) CHECK(solver.report().iterations > 0);
  }
}

TEST_CASE("a second compute with the same pattern re-uses the symbolic analysis", "[solvers]") {
  LinearSolver solver;
  solver.compute(poisson(8));
  solver.compute(poisson(8, 1.0));
  CHECK(solver.report().analyses == 1);
  CHECK(solver.report().factorizations == 2);
  const Eigen::VectorXd b = Eigen::VectorXd::Ones(64);
  const Eigen::MatrixXd x = solver.solve(b);
  CHECK((poisson(8, 1.0) * x - b).norm() < 1e-10);
  solver.compute(poisson(9));
  CHECK(solver.report().analyses == 2);
}

TEST_CASE("solver failures raise SolverError naming solver, iterations and residual", "[solvers]") {
  SECTION("LLT of an indefinite matrix") {
    LinearSolver solver(SolverOptions{SolverKind::simplicial_llt});
    CHECK_THROWS_AS(solver.compute(poisson(6, -6.0)), SolverError);
  }
  SECTION("CG capped at 2 iterations") {
    LinearSolver solver(SolverOptions{SolverKind::cg_jacobi, 1e-12, 2, false});
    solver.compute(poisson(10));
    const Eigen::VectorXd b = Eigen::VectorXd::Ones(100);
    CHECK_THROWS_WITH(solver.solve(b), Catch::Contains("cg_jacobi") && Catch::Contains("iterations 2") &&
                                           Catch::Contains("residual"));
  }
  SECTION("CG capped at 2 iterations falls back to a direct solve when asked") {
    LinearSolver solver(SolverOptions{SolverKind::cg_jacobi, 1e-12, 2, true});
    solver.compute(poisson(10));
    const Eigen::VectorXd b = Eigen::VectorXd::Ones(100);
    const Eigen::MatrixXd x = solver.solve(b);
    CHECK((poisson(10) * x - b).norm() < 1e-10);
    CHECK(solver.report().fell_back);
  }
  SECTION("bad inputs") {
    LinearSolver solver;
    CHECK_THROWS_AS(solver.solve(Eigen::VectorXd::Ones(3)), InputError);
    CHECK_THROWS_AS(solver.compute(SparseMatrix(3, 4)), InputError);
    solver.compute(poisson(3));
    CHECK_THROWS_AS(solver.solve(Eigen::VectorXd::Ones(4)), InputError);
    Eigen::VectorXd nan_rhs = Eigen::VectorXd::Ones(9);
    nan_rhs[2] = std::numeric_limits<double>::quiet_NaN();
    CHECK_THROWS_AS(solver.solve(nan_rhs), InputError);
  }
}

TEST_CASE("dense solvers agree and detect failures", "[solvers]") {
  const Eigen::MatrixXd a = Eigen::MatrixXd(poisson(5));
  const Eigen::MatrixXd b = Eigen::MatrixXd::Random(25, 2);
  for (auto kind : {DenseSolverKind::llt, DenseSolverKind::ldlt, DenseSolverKind::partial_piv_lu}) {
    DenseSolver solver(kind);
    solver.compute(a);
    CHECK((a * solver.solve(b) - b).norm() < 1e-10);
  }
  DenseSolver llt(DenseSolverKind::llt);
  CHECK_THROWS_AS(llt.compute(-a), SolverError);
  DenseSolver lu;
  lu.compute(Eigen::MatrixXd::Zero(3, 3));
  CHECK_THROWS_AS(lu.solve(Eigen::VectorXd::Ones(3)), SolverError);
}

TEST_CASE("CHOLMOD's supernodal Cholesky: asked for, chosen for large matrices, refused without it", "[solvers]") {
  const SparseMatrix a = poisson(30);
  const Eigen::MatrixXd x_true = Eigen::MatrixXd::Random(a.rows(), 3);
  const Eigen::MatrixXd b = a * x_true;
  if (!have_cholmod()) {
    LinearSolver solver(SolverOptions{SolverKind::cholmod_supernodal});
    CHECK_THROWS_WITH(solver.compute(a), Catch::Contains("no CHOLMOD"));
    // The simplicial kinds stay simplicial whatever the size.
    LinearSolver large(SolverOptions{.supernodal_min_rows = 10});
    large.compute(a);
    CHECK_FALSE(large.report().supernodal);
    WARN("skipped the CHOLMOD cases: this build has no CHOLMOD (libsuitesparse-dev)");
    return;
  }
  LinearSolver asked(SolverOptions{SolverKind::cholmod_supernodal});
  asked.compute(a);
  CHECK(asked.report().supernodal);
  CHECK((asked.solve(b) - x_true).norm() / x_true.norm() < 1e-12);

  // The default simplicial_ldlt hands a matrix past supernodal_min_rows to CHOLMOD, and equals
  // the simplicial answer to rounding.
  LinearSolver small(SolverOptions{.supernodal_min_rows = a.rows() + 1});
  small.compute(a);
  CHECK_FALSE(small.report().supernodal);
  LinearSolver large(SolverOptions{.supernodal_min_rows = a.rows()});
  large.compute(a);
  CHECK(large.report().supernodal);
  CHECK((large.solve(b) - small.solve(b)).norm() / x_true.norm() < 1e-13);

  // A matrix CHOLMOD finds indefinite (LDLᵀ takes it) goes back to the simplicial LDLᵀ;
  // asked for explicitly, CHOLMOD's failure is an error naming it.
  SparseMatrix indefinite = poisson(30, 0.0);
  for (Index k = 0; k < 10; ++k) indefinite.coeffRef(k, k) = -4.0;
  LinearSolver back(SolverOptions{.supernodal_min_rows = 1});
  back.compute(indefinite);
  CHECK_FALSE(back.report().supernodal);
  const Eigen::VectorXd y = back.solve(Eigen::VectorXd::Ones(indefinite.rows()));
  CHECK((indefinite * y - Eigen::VectorXd::Ones(indefinite.rows())).norm() < 1e-8);
  LinearSolver refused(SolverOptions{SolverKind::cholmod_supernodal});
  CHECK_THROWS_WITH(refused.compute(indefinite), Catch::Contains("cholmod_supernodal"));
}

#ifdef MESHMOTION_HAVE_CHOLMOD
TEST_CASE("CHOLMOD's BLAS works with the library's threads when it is OpenBLAS", "[solvers]") {
  // OpenBLAS's pthreads build sizes its pool by the machine: ranks sharing a node would each
  // take every core in a factorization.
  using Count = int (*)();
  const auto count = reinterpret_cast<Count>(dlsym(detail::cholmod_api().handle, "openblas_get_num_threads"));
  if (count == nullptr) {
    WARN("skipped: CHOLMOD's BLAS is not OpenBLAS (libopenblas0-pthread)");
    return;
  }
  for (const int n : {1, 2}) {
    set_num_threads(n);
    LinearSolver solver(SolverOptions{SolverKind::cholmod_supernodal});
    solver.compute(poisson(20));
    CHECK(count() == n);
  }
  set_num_threads(0);
}

TEST_CASE("the supernodal factor in single precision solves as CHOLMOD does, to float's rounding", "[solvers]") {
  // Large enough for supernodes of many columns (the BLAS's triangles and products), with
  // right-hand sides whose columns differ by 1e40 (each is scaled before it is rounded).
  const SparseMatrix a = poisson(120, 0.01);
  const auto factorized = [](const SparseMatrix& m) {
    auto llt = std::make_unique<detail::CholmodSupernodalLLT>();
    llt->analyzePattern(m);
    llt->factorize(m);
    REQUIRE(llt->info() == Eigen::Success);
    return llt;
  };
  Eigen::MatrixXd b = Eigen::MatrixXd::Random(a.rows(), 3);
  b.col(1) *= 1e20;
  b.col(2) *= 1e-20;
  const Eigen::MatrixXd exact = factorized(a)->solve(b);
  // Scaled beyond float's range too (the factor by 1e35, or 1e-45): the same answer.
  for (const double s : {1.0, 1e70, 1e-90}) {
    CAPTURE(s);
    auto llt = factorized(SparseMatrix(s * a));
    detail::SingleSupernodalFactor single;
    REQUIRE(single.take(llt));
    CHECK(llt == nullptr);  // rounded in place: CHOLMOD's factor is the single one's now
    Eigen::MatrixXd x = b;
    single.solve_in_place(x);
    for (Index c = 0; c < 3; ++c) {
      CAPTURE(c);
      const double error = (s * x.col(c) - exact.col(c)).cwiseAbs().maxCoeff();
      CHECK(error < 1e-5 * exact.col(c).cwiseAbs().maxCoeff());
      CHECK(error > 0.0);  // float, not CHOLMOD's double, answered
    }
  }
  // A diagonal 1e-40 of the largest entry is beyond float: not taken, the factor left whole.
  SparseMatrix graded = a;
  graded.coeffRef(0, 0) = 1e-80;
  graded.coeffRef(1, 0) = graded.coeffRef(0, 1) = 0.0;
  graded.coeffRef(120, 0) = graded.coeffRef(0, 120) = 0.0;  // node 0 on its own
  graded.prune(0.0);
  auto llt = factorized(graded);
  detail::SingleSupernodalFactor single;
  CHECK_FALSE(single.take(llt));
  REQUIRE(llt != nullptr);
  CHECK(llt->solve(b).allFinite());
}
#endif
