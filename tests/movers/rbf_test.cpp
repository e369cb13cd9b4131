#include "meshmotion/core/generators.hpp"
#include "meshmotion/curving/order_conversion.hpp"
#include "meshmotion/curving/p2_conversion.hpp"
#include "meshmotion/movers.hpp"
#include "meshmotion/quality.hpp"

#include "random_field.hpp"

#include <Eigen/SVD>
#include <catch2/catch.hpp>

#include <numbers>
#include <random>

using namespace meshmotion;

namespace {

/// Structured grid on [0,1]^Dim with n intervals per axis (quads / hexes), with node groups
/// "x0", "x1", "y0", "y1" (and "z0", "z1") for the sides.
template <int Dim>
struct Grid {
  Mesh<Dim> mesh;
  GroupNodes groups;
};

template <int Dim>
Grid<Dim> grid(int n) {
  Grid<Dim> g;
  const int nz = Dim == 3 ? n : 0;
  const auto id = [n](int i, int j, int k) { return static_cast<Index>(i + (n + 1) * (j + (n + 1) * k)); };
  g.mesh.points.resize(Dim, static_cast<Index>((n + 1) * (n + 1) * (nz + 1)));
  for (int k = 0; k <= nz; ++k)
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i) {
        const Index v = id(i, j, k);
        g.mesh.points(0, v) = double(i) / n;
        g.mesh.points(1, v) = double(j) / n;
        if constexpr (Dim == 3) g.mesh.points(2, v) = double(k) / n;
        const int c[3] = {i, j, k};
        for (int d = 0; d < Dim; ++d) {
          if (c[d] == 0) g.groups[std::string(1, "xyz"[d]) + "0"].push_back(v);
          if (c[d] == n) g.groups[std::string(1, "xyz"[d]) + "1"].push_back(v);
        }
      }
  ElementBlock& b = g.mesh.block(Dim == 2 ? ElementType::quad4 : ElementType::hex8);
  for (int k = 0; k < std::max(nz, 1); ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        if constexpr (Dim == 2)
          b.add({id(i, j, 0), id(i + 1, j, 0), id(i + 1, j + 1, 0), id(i, j + 1, 0)});
        else
          b.add({id(i, j, k), id(i + 1, j, k), id(i + 1, j + 1, k), id(i, j + 1, k), id(i, j, k + 1),
                 id(i + 1, j, k + 1), id(i + 1, j + 1, k + 1), id(i, j + 1, k + 1)});
      }
  return g;
}

/// The whole outer boundary of the grid as one group "outer".
template <int Dim>
GroupNodes with_outer(GroupNodes groups) {
  std::vector<Index> all;
  for (const auto& [name, list] : groups) all.insert(all.end(), list.begin(), list.end());
  groups["outer"] = all;
  return groups;
}

using test::random_displacements;

template <int Dim>
void check_properties(int n) {
  const Grid<Dim> g = grid<Dim>(n);
  const GroupNodes groups = with_outer<Dim>(g.groups);
  BoundarySpec<Dim> spec;
  spec.fixed("outer");
  const ResolvedBoundary<Dim> boundary = spec.resolve(g.mesh.points, groups);
  const Index m = boundary.size();
  RbfOptions options;
  options.support_radius = 0.35;
  options.repair = false;  // the map's own properties: its random motions fold cells, which the repair would move
  RbfMover<Dim> mover(options);
  mover.setup(g.mesh, boundary);
  static_assert(MeshMover<RbfMover<Dim>>);

  const Points<Dim> d1 = random_displacements<Dim>(m, 1);
  const Points<Dim> d2 = random_displacements<Dim>(m, 2);
  const Points<Dim> u1 = mover.move(d1);

  SECTION("boundary targets met, and the interpolant meets them too") {
    for (Index b = 0; b < m; ++b) CHECK((u1.col(boundary.nodes[std::size_t(b)]) - d1.col(b)).norm() <= 1e-10 * d1.norm());
    CHECK(mover.stats().residual < 1e-10);
  }
  SECTION("zero displacement is the identity") { CHECK(mover.move(Points<Dim>::Zero(Dim, m)).norm() == 0.0); }
  SECTION("superposition") {
    const Points<Dim> u = mover.move(2.0 * d1 - 3.0 * d2);
    CHECK((u - (2.0 * u1 - 3.0 * mover.move(d2))).norm() < 1e-12 * u.norm());
  }
  SECTION("repeated move equals a fresh setup and move; one factorization over many moves") {
    for (int i = 0; i < 20; ++i) (void)mover.move(random_displacements<Dim>(m, 10u + unsigned(i)));
    CHECK(mover.stats().factorizations == 1);
    CHECK(mover.stats().moves == 21);
    RbfMover<Dim> fresh(options);
    fresh.setup(g.mesh, boundary);
    CHECK((fresh.move(d1) - mover.move(d1)).norm() < 1e-13);
  }
  SECTION("displacement vanishes beyond the support radius of every boundary node") {
    Index beyond = 0;
    for (Index i = 0; i < g.mesh.num_nodes(); ++i) {
      double nearest = 1e300;
      for (const Index v : boundary.nodes) nearest = std::min(nearest, (g.mesh.points.col(i) - g.mesh.points.col(v)).norm());
      if (nearest >= options.support_radius) {
        ++beyond;
        CHECK(u1.col(i).norm() == 0.0);
      } else if (nearest > 0.0) {
        CHECK(u1.col(i).norm() > 0.0);
      }
    }
    CHECK(beyond > 0);
    CHECK(mover.stats().evaluated_nodes < g.mesh.num_nodes() - m);
  }
}

}  // namespace

TEST_CASE("RBF mover properties on 2D and 3D grids", "[movers]") {
  SECTION("2D") { check_properties<2>(24); }
  SECTION("3D") { check_properties<3>(10); }
}

TEST_CASE("Wendland C2 matrices are symmetric positive definite in 2D and 3D", "[movers]") {
  const auto check = [](auto dim_tag) {
    constexpr int Dim = decltype(dim_tag)::value;
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    Points<Dim> c(Dim, 200);
    for (Index i = 0; i < c.cols(); ++i)
      for (int d = 0; d < Dim; ++d) c(d, i) = u(rng);
    std::vector<Index> rows(200);
    for (Index i = 0; i < 200; ++i) rows[std::size_t(i)] = i;
    const KdTree<Dim> tree(c);
    const auto within = [&](const Vec<Dim>& x, std::vector<Neighbor>& out) { tree.radius_search(x, 0.4, out); };
    const Eigen::MatrixXd a(detail::compact_kernel_rows<Dim>(c, rows, within, 200, {RbfKernel::wendland2, 0.4, false}));
    CHECK((a - a.transpose()).norm() == 0.0);
    CHECK(a(3, 3) == 1.0);
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(a);
    CHECK(eig.eigenvalues().minCoeff() > 0.0);
  };
  check(std::integral_constant<int, 2>{});
  check(std::integral_constant<int, 3>{});
}

// The one-pass products of kernel rows a move and a reverse derivative use: Eigen's products'
// sums in Eigen's order, so bit for bit, whatever the threads.
TEST_CASE("kernel rows times centre values, and transposed, are Eigen's products exactly", "[movers]") {
  const auto check = [](auto dim_tag) {
    constexpr int Dim = decltype(dim_tag)::value;
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    const Index k = 300, n = 3000;
    Points<Dim> centres(Dim, k), at(Dim, n);
    for (Index i = 0; i < k; ++i)
      for (int d = 0; d < Dim; ++d) centres(d, i) = u(rng);
    for (Index i = 0; i < n; ++i)
      for (int d = 0; d < Dim; ++d) at(d, i) = u(rng);
    std::vector<Index> rows(static_cast<std::size_t>(n));
    for (Index i = 0; i < n; ++i) rows[std::size_t(i)] = i;
    const KdTree<Dim> tree(centres);
    const auto within = [&](const Vec<Dim>& x, std::vector<Neighbor>& out) { tree.radius_search(x, 0.5, out); };
    const detail::KernelRows e = detail::compact_kernel_rows<Dim>(at, rows, within, k, {RbfKernel::wendland2, 0.5, false});
    REQUIRE(e.nonZeros() > 20000);  // the threaded path
    Eigen::MatrixXd x(k, Dim), v(n, Dim);
    for (Index i = 0; i < x.size(); ++i) x.data()[i] = u(rng);
    for (Index i = 0; i < v.size(); ++i) v.data()[i] = u(rng);
    const Eigen::MatrixXd forward = e * x;
    const Eigen::MatrixXd backward = e.transpose() * v;
    for (const int threads : {1, 2}) {
      CAPTURE(Dim, threads);
      set_num_threads(threads);
      Points<Dim> buffer;
      Eigen::MatrixXd got(n, Dim);
      detail::kernel_rows_times<Dim>(e, x, buffer, [&](Index r, const Vec<Dim>& value) { got.row(r) = value.transpose(); });
      CHECK((got - forward).cwiseAbs().maxCoeff() == 0.0);
      Eigen::MatrixXd got_back;
      detail::kernel_rows_transpose_times<Dim>(e, [&](Index r) -> Vec<Dim> { return v.row(r).transpose(); }, buffer, got_back);
      REQUIRE(got_back.rows() == k);
      CHECK((got_back - backward).cwiseAbs().maxCoeff() == 0.0);
    }
    set_num_threads(0);
  };
  check(std::integral_constant<int, 2>{});
  check(std::integral_constant<int, 3>{});
}

TEST_CASE("kernels: Wendland values and support", "[movers]") {
  CHECK(rbf_value(RbfKernel::wendland2, 0.5, 1.0) == Approx(0.0625 * 3.0));  // (1-ξ)^4 (4ξ+1), eq. 2.14
  for (const RbfKernel k : {RbfKernel::wendland0, RbfKernel::wendland2, RbfKernel::wendland4, RbfKernel::wendland6}) {
    CHECK(rbf_value(k, 0.0, 2.0) == Approx(1.0));
    CHECK(rbf_value(k, 2.0, 2.0) == 0.0);
    CHECK(rbf_value(k, 1.99, 2.0) > 0.0);
    CHECK(rbf_kernel_from_name(name(k)) == k);
  }
  CHECK_THROWS_AS(rbf_kernel_from_name("cubic"), InputError);
}

TEST_CASE("affine motions are reproduced exactly with polynomial augmentation", "[movers]") {
  const Grid<2> g = grid<2>(16);
  const GroupNodes groups = with_outer<2>(g.groups);
  Eigen::Matrix2d a;
  a << 0.05, -0.02, 0.03, 0.01;
  const Vec<2> t(0.1, -0.05);
  for (const RbfKernel kernel : {RbfKernel::wendland2, RbfKernel::wendland6, RbfKernel::thin_plate_spline,
                                 RbfKernel::gaussian, RbfKernel::multiquadric, RbfKernel::inverse_multiquadric}) {
    CAPTURE(name(kernel));
    BoundarySpec<2> spec;
    const std::vector<Index>& outer = [&]() -> const std::vector<Index>& { return groups.at("outer"); }();
    std::vector<Index> sorted = outer;
    std::sort(sorted.begin(), sorted.end());
    sorted.erase(std::unique(sorted.begin(), sorted.end()), sorted.end());
    Points<2> d(2, Index(sorted.size()));
    for (std::size_t k = 0; k < sorted.size(); ++k) d.col(Index(k)) = a * g.mesh.points.col(sorted[k]) + t;
    spec.moving("outer", d);
    RbfOptions options;
    options.kernel = kernel;
    options.support_radius = is_compact(kernel) ? 0.3 : 0.15;  // smooth global kernels: small scale, well conditioned
    options.polynomial = true;
    RbfMover<2> mover(options);
    const auto boundary = spec.resolve(g.mesh.points, groups);
    mover.setup(g.mesh, boundary);
    const Points<2> u = mover.move(boundary.displacements);
    for (Index i = 0; i < g.mesh.num_nodes(); ++i) CHECK((u.col(i) - (a * g.mesh.points.col(i) + t)).norm() < 1e-9);
  }
}

TEST_CASE("the default support radius follows the mesh: a mesh 1000 times larger moves 1000 times more", "[movers]") {
  const Grid<2> g = grid<2>(16);
  BoundarySpec<2> spec;
  spec.moving("x0", Rotation2D{Vec<2>(0.0, 0.5), 0.2}).fixed("x1").sliding("y0").sliding("y1");
  const auto boundary = spec.resolve(g.mesh.points, g.groups);
  RbfMover<2> unit;
  unit.setup(g.mesh, boundary);
  const Points<2> u = unit.move(boundary.displacements);
  Mesh<2> large = g.mesh;
  large.points *= 1000.0;
  ResolvedBoundary<2> large_boundary = boundary;
  large_boundary.displacements *= 1000.0;
  RbfMover<2> scaled;
  scaled.setup(large, large_boundary);
  const Points<2> v = scaled.move(large_boundary.displacements);
  CHECK(scaled.support_radius() == Approx(1000.0 * unit.support_radius()).epsilon(1e-12));
  CHECK((v - 1000.0 * u).cwiseAbs().maxCoeff() <= 1e-9 * v.cwiseAbs().maxCoeff());
  // The radius the boundary proposes: max(5 × the largest displacement, 10 × the spacing).
  Points<2> at(2, boundary.size());
  for (Index k = 0; k < boundary.size(); ++k) at.col(k) = g.mesh.points.col(boundary.nodes[static_cast<std::size_t>(k)]);
  CHECK(unit.support_radius() == suggest_support_radius(at, boundary.displacements));
  CHECK(unit.options().support_radius == 0.0);
}

TEST_CASE("conditionally positive definite kernels always get the polynomial", "[movers]") {
  // Without it tps is ill-posed: a rotation of the whole boundary gave garbage with no error.
  const Grid<2> g = grid<2>(12);
  const GroupNodes groups = with_outer<2>(g.groups);
  BoundarySpec<2> spec;
  spec.moving("outer", Rotation2D{Vec<2>(0.5, 0.5), 0.3});
  const auto boundary = spec.resolve(g.mesh.points, groups);
  const Eigen::Rotation2Dd turn(0.3);
  for (const RbfKernel kernel : {RbfKernel::thin_plate_spline, RbfKernel::multiquadric}) {
    CAPTURE(name(kernel));
    CHECK(needs_polynomial(kernel));
    RbfOptions options;
    options.kernel = kernel;
    options.support_radius = kernel == RbfKernel::thin_plate_spline ? 1.0 : 0.15;
    options.polynomial = false;
    RbfMover<2> mover(options);
    CHECK(mover.options().polynomial);
    mover.setup(g.mesh, boundary);
    const Points<2> u = mover.move(boundary.displacements);
    for (Index i = 0; i < g.mesh.num_nodes(); ++i) {
      const Vec<2> x = g.mesh.points.col(i), c(0.5, 0.5);
      CHECK((u.col(i) - (turn * (x - c) + c - x)).norm() < 1e-9);
    }
  }
  for (const RbfKernel kernel : {RbfKernel::wendland2, RbfKernel::gaussian, RbfKernel::inverse_multiquadric})
    CHECK_FALSE(needs_polynomial(kernel));
}

TEST_CASE("a support radius per boundary entry: interpolation, reach of each centre, affine reproduction", "[movers]") {
  const Grid<2> g = grid<2>(20);
  BoundarySpec<2> spec;
  spec.moving("x0", Translation<2>{Vec<2>(0.0, 0.02)}).fixed("x1").fixed("y0").fixed("y1");
  const auto boundary = spec.resolve(g.mesh.points, g.groups);
  // The moving side gets a short support, the fixed sides a long one, as two walls whose
  // layers differ.
  std::vector<double> radii(static_cast<std::size_t>(boundary.size()));
  for (Index b = 0; b < boundary.size(); ++b) radii[std::size_t(b)] = g.mesh.points(0, boundary.nodes[std::size_t(b)]) == 0.0 ? 0.15 : 0.4;
  for (const RbfKernel kernel : {RbfKernel::wendland2, RbfKernel::gaussian}) {
    CAPTURE(name(kernel));
    RbfOptions options;
    options.kernel = kernel;
    options.support_radii = radii;
    // Global kernels: shape scales below the side length keep the dense system well conditioned.
    if (!is_compact(kernel))
      for (double& r : options.support_radii) r *= 0.375;
    RbfMover<2> mover(options);
    mover.setup(g.mesh, boundary);
    const Points<2> d = random_displacements<2>(boundary.size(), 7);
    const Points<2> u = mover.move(d);
    for (Index b = 0; b < boundary.size(); ++b) CHECK((u.col(boundary.nodes[std::size_t(b)]) - d.col(b)).norm() == 0.0);
    CHECK(mover.stats().residual < (is_compact(kernel) ? 1e-10 : 1e-8));  // the Gaussian system is less well conditioned
    // The reverse derivative goes through Aᵀ, factorized on the first call and reused:
    // ⟨v, J w⟩ = ⟨Jᵀ v, w⟩ both times.
    const Points<2> w = random_displacements<2>(boundary.size(), 9, 1.0);
    const Points<2> v = random_displacements<2>(g.mesh.num_nodes(), 10, 1.0);
    const double forward = (v.array() * mover.derivative_forward(w).array()).sum();
    for (int call = 0; call < 2; ++call)
      CHECK((mover.derivative_reverse(v).array() * w.array()).sum() == Approx(forward).epsilon(1e-8));
    if (!is_compact(kernel)) continue;
    // Each centre reaches exactly its own radius: a node is moved iff some centre covers it.
    Index beyond = 0, covered_only_by_long = 0;
    for (Index i = 0; i < g.mesh.num_nodes(); ++i) {
      bool covered = false, by_short = false;
      for (Index b = 0; b < boundary.size(); ++b) {
        const double r = (g.mesh.points.col(i) - g.mesh.points.col(boundary.nodes[std::size_t(b)])).norm();
        if (r == 0.0) covered = by_short = true;
        if (r < radii[std::size_t(b)]) {
          covered = true;
          by_short = by_short || radii[std::size_t(b)] < 0.2;
        }
      }
      CHECK((u.col(i).norm() > 0.0) == covered);
      beyond += covered ? 0 : 1;
      covered_only_by_long += covered && !by_short && g.mesh.points(0, i) < 0.5 ? 1 : 0;
    }
    CHECK(beyond > 0);
    CHECK(covered_only_by_long > 0);  // the long supports of the fixed sides reach there, the short ones not
  }
  SECTION("a radius per node (too many to query one radius at a time): each still reaches its own") {
    std::vector<double> graded(static_cast<std::size_t>(boundary.size()));
    for (Index b = 0; b < boundary.size(); ++b) graded[std::size_t(b)] = 0.1 + 0.3 * double(b) / double(boundary.size());
    RbfOptions options;
    options.support_radii = graded;
    RbfMover<2> mover(options);
    mover.setup(g.mesh, boundary);
    const Points<2> d = random_displacements<2>(boundary.size(), 8);
    const Points<2> u = mover.move(d);
    Index beyond = 0;
    for (Index i = 0; i < g.mesh.num_nodes(); ++i) {
      bool covered = false;
      for (Index b = 0; b < boundary.size(); ++b) {
        const double r = (g.mesh.points.col(i) - g.mesh.points.col(boundary.nodes[std::size_t(b)])).norm();
        covered = covered || r < graded[std::size_t(b)];
      }
      CHECK((u.col(i).norm() > 0.0) == covered);
      beyond += covered ? 0 : 1;
    }
    CHECK(beyond > 0);
    for (Index b = 0; b < boundary.size(); ++b) CHECK((u.col(boundary.nodes[std::size_t(b)]) - d.col(b)).norm() == 0.0);
  }
  SECTION("equal per-entry radii are the uniform radius") {
    RbfOptions uniform;
    uniform.support_radius = 0.3;
    RbfOptions listed = uniform;
    listed.support_radii.assign(static_cast<std::size_t>(boundary.size()), 0.3);
    RbfMover<2> a(uniform), b(listed);
    a.setup(g.mesh, boundary);
    b.setup(g.mesh, boundary);
    const Points<2> ua = a.move(boundary.displacements);
    CHECK((ua - b.move(boundary.displacements)).norm() <= 1e-13 * ua.norm());
  }
  SECTION("affine motions are reproduced exactly with polynomial augmentation") {
    Eigen::Matrix2d a;
    a << 0.05, -0.02, 0.03, 0.01;
    const Vec<2> t(0.1, -0.05);
    Points<2> d(2, boundary.size());
    for (Index b = 0; b < boundary.size(); ++b) d.col(b) = a * g.mesh.points.col(boundary.nodes[std::size_t(b)]) + t;
    RbfOptions options;
    options.support_radii = radii;
    options.polynomial = true;
    RbfMover<2> mover(options);
    mover.setup(g.mesh, boundary);
    const Points<2> u = mover.move(d);
    for (Index i = 0; i < g.mesh.num_nodes(); ++i) CHECK((u.col(i) - (a * g.mesh.points.col(i) + t)).norm() < 1e-9);
  }
  SECTION("a radius list that does not match the boundary, or a non-positive radius, is named") {
    RbfOptions options;
    options.support_radii.assign(3, 0.2);
    CHECK_THROWS_WITH(RbfMover<2>(options).setup(g.mesh, boundary), Catch::Contains("3 support radii for a boundary of"));
    options.support_radii = radii;
    options.support_radii[5] = 0.0;
    CHECK_THROWS_WITH(RbfMover<2>(options).setup(g.mesh, boundary), Catch::Contains("boundary entry 5 (node"));
  }
}

TEST_CASE("radii differing only between centres out of each other's reach keep the RBF system symmetric", "[movers]") {
  // Two rings of 32 centres (spacing 0.196), each with its own radius; a ring's radius reaches
  // its own neighbours, and the other ring only when the rings are moved close.
  const auto rings = [](double gap) {
    Points<2> c(2, 64);
    for (Index i = 0; i < 32; ++i) {
      const double t = 2.0 * std::numbers::pi * double(i) / 32.0;
      c.col(i) = Vec<2>(std::cos(t), std::sin(t));
      c.col(32 + i) = Vec<2>(2.0 + gap + std::cos(t), std::sin(t));
    }
    return c;
  };
  detail::RbfKernelSettings kernel;
  for (Index i = 0; i < 64; ++i) kernel.radii.push_back(i < 32 ? 0.5 : 0.8);
  kernel.radius = 0.8;
  for (const double gap : {8.0, 0.3}) {
    CAPTURE(gap);
    const Points<2> c = rings(gap);
    detail::RbfSystem<2> system;
    system.setup(c, kernel, SolverOptions{}, DenseSolverKind::partial_piv_lu, 4000);
    CHECK(system.symmetric() == (gap > 1.0));
    const Points<2> values = random_displacements<2>(64, 11, 1.0);
    Eigen::MatrixXd alpha;
    detail::RbfPolynomial<2>::Coefficients beta;
    system.solve(values.transpose(), alpha, beta);
    // Interpolation: Σ_j α_j φ(|c_i − c_j| / ρ_j) = values_i, summed here over every centre.
    Eigen::MatrixXd a(64, 64);
    for (Index i = 0; i < 64; ++i)
      for (Index j = 0; j < 64; ++j) a(i, j) = rbf_value(kernel.kernel, (c.col(i) - c.col(j)).norm(), kernel.radius_of(j));
    CHECK((a * alpha - values.transpose()).norm() < 1e-12 * values.norm());
    // The transposed solve (the reverse derivative) is Aᵀ's, from the factorization kept
    // (symmetric) or from Aᵀ's own.
    const Eigen::MatrixXd bar = random_displacements<2>(64, 12, 1.0).transpose();
    Eigen::MatrixXd values_bar;
    system.solve_transpose(bar, detail::RbfPolynomial<2>::Coefficients::Zero(), values_bar);
    CHECK((a.transpose() * values_bar - bar).norm() < 1e-12 * bar.norm());
  }
}

TEST_CASE("the RBF condition estimate is a close lower bound, and an ill-conditioned system still sets up", "[movers]") {
  // A ring of 48 centres and one more 1e-5 from the first, as a blunt trailing edge's two
  // sides: the condition grows with the radius, past 1e11.
  Points<2> c(2, 49);
  for (Index i = 0; i < 48; ++i) {
    const double t = 2.0 * std::numbers::pi * double(i) / 48.0;
    c.col(i) = Vec<2>(std::cos(t), std::sin(t));
  }
  c.col(48) = c.col(0) + Vec<2>(0.0, 1e-5);
  double previous = 0.0;
  for (const double radius : {0.2, 0.5, 2.0}) {
    CAPTURE(radius);
    detail::RbfKernelSettings kernel;
    kernel.radius = radius;
    detail::RbfSystem<2> system;
    system.setup(c, kernel, SolverOptions{}, DenseSolverKind::partial_piv_lu, 4000);
    Eigen::MatrixXd a(49, 49);
    for (Index i = 0; i < 49; ++i)
      for (Index j = 0; j < 49; ++j) a(i, j) = rbf_value(kernel.kernel, (c.col(i) - c.col(j)).norm(), radius);
    const Eigen::VectorXd sigma = Eigen::JacobiSVD<Eigen::MatrixXd>(a).singularValues();
    const double exact = sigma(0) / sigma(sigma.size() - 1);
    CHECK(system.condition() <= exact * (1.0 + 1e-6));
    CHECK(system.condition() >= exact / 2.0);
    CHECK(system.condition() > previous);
    previous = system.condition();
  }
  CHECK(previous > 1e11);
  // The mover reports it, largest over its systems.
  const Grid<2> g = grid<2>(12);
  BoundarySpec<2> spec;
  spec.fixed("outer");
  const auto boundary = spec.resolve(g.mesh.points, with_outer<2>(g.groups));
  RbfOptions options;
  options.support_radius = 0.3;
  RbfMover<2> small(options);
  small.setup(g.mesh, boundary);
  options.support_radius = 3.0;
  RbfMover<2> large(options);
  large.setup(g.mesh, boundary);
  CHECK(small.stats().condition >= 1.0);
  CHECK(large.stats().condition > 100.0 * small.stats().condition);
}

TEST_CASE("near-coincident centres under a large radius are thinned: exact, continuous, derivatives consistent",
          "[movers]") {
  // A wall (side x0) with one more node 3.6e-6 above its middle node, as a blunt trailing
  // edge's two sides, moved with a kink of 1e-7 between them; two points (in no cell) 1e-10
  // off each side probe the interpolant where only the thinned centre's bump reaches.
  Grid<2> g = grid<2>(16);
  const Index middle = 8 * 17, extra = g.mesh.num_nodes();
  g.mesh.points.conservativeResize(2, extra + 3);
  g.mesh.points.col(extra) = g.mesh.points.col(middle) + Vec<2>(0.0, 3.6e-6);
  g.mesh.points.col(extra + 1) = g.mesh.points.col(middle) + Vec<2>(1e-10, 0.0);
  g.mesh.points.col(extra + 2) = g.mesh.points.col(extra) + Vec<2>(1e-10, 0.0);
  g.groups["x0"].push_back(extra);
  BoundarySpec<2> spec;
  spec.moving("x0", Rotation2D{Vec<2>(0.5, 0.5), 0.05}).fixed("x1").fixed("y0").fixed("y1");
  const auto boundary = spec.resolve(g.mesh.points, g.groups);
  Points<2> d = boundary.displacements;
  const auto entry = static_cast<Index>(std::find(boundary.nodes.begin(), boundary.nodes.end(), extra) - boundary.nodes.begin());
  d(0, entry) += 1e-7;
  RbfOptions unlimited;
  unlimited.condition_limit = 0.0;
  unlimited.support_radius = 20.0;
  RbfMover<2> uncured(unlimited);
  // Without thinning, rounding may grow by 1e14 or more in a solve: a few digits at best, and
  // the residual check fails on some right-hand sides (conditioning_bench: on a RANS grid the
  // gradient's from radius 20, the move's from 100).
  uncured.setup(g.mesh, boundary);
  CHECK(uncured.stats().condition > 1e14);
  CHECK(uncured.stats().thinned_centres == 0);
  for (const double radius : {2.0, 20.0, 1000.0}) {
    CAPTURE(radius);
    RbfOptions options;
    options.support_radius = radius;
    RbfMover<2> mover(options);
    mover.setup(g.mesh, boundary);
    CHECK(mover.stats().thinned_centres >= 1);
    CHECK(mover.stats().condition <= options.condition_limit);
    const Points<2> out = mover.move(d);
    for (Index b = 0; b < boundary.size(); ++b) CHECK(out.col(boundary.nodes[std::size_t(b)]) == d.col(b));
    // The interpolant is continuous at both sides: the evaluation uses the thinned radii.
    CHECK((out.col(extra + 1) - out.col(middle)).norm() < 1e-9);
    CHECK((out.col(extra + 2) - out.col(extra)).norm() < 1e-9);
    // Forward and reverse products go through A and Aᵀ separately: they agree only when both
    // solves are accurate (to about condition × 1e-16).
    const Points<2> w = random_displacements<2>(boundary.size(), 3, 1.0);
    const Points<2> v = random_displacements<2>(g.mesh.num_nodes(), 4, 1.0);
    const Points<2> jw = mover.derivative_forward(w);
    const Points<2> jtv = mover.derivative_reverse(v);
    CHECK((v.array() * jw.array()).sum() == Approx((jtv.array() * w.array()).sum()).epsilon(1e-6));
    const double h = 1e-6;
    const Points<2> fd = (mover.move(d + h * w) - mover.move(d - h * w)) / (2.0 * h);
    CHECK((fd - jw).norm() < 1e-5 * jw.norm());
  }
  // A well-separated boundary is not thinned: the same result as without the limit.
  const Grid<2> plain = grid<2>(16);
  BoundarySpec<2> plain_spec;
  plain_spec.moving("x0", Rotation2D{Vec<2>(0.5, 0.5), 0.05}).fixed("x1").fixed("y0").fixed("y1");
  const auto plain_boundary = plain_spec.resolve(plain.mesh.points, plain.groups);
  RbfOptions options;
  options.support_radius = 0.6;
  RbfMover<2> limited(options);
  limited.setup(plain.mesh, plain_boundary);
  options.condition_limit = 0.0;
  RbfMover<2> free(options);
  free.setup(plain.mesh, plain_boundary);
  CHECK(limited.stats().thinned_centres == 0);
  CHECK(limited.move(plain_boundary.displacements) == free.move(plain_boundary.displacements));
}

TEST_CASE("global kernels refuse large systems and suggest a compact kernel", "[movers]") {
  const Grid<2> g = grid<2>(30);
  BoundarySpec<2> spec;
  spec.fixed("outer");
  RbfOptions options;
  options.kernel = RbfKernel::gaussian;
  options.max_dense_centres = 50;
  RbfMover<2> mover(options);
  CHECK_THROWS_WITH(mover.setup(g.mesh, spec.resolve(g.mesh.points, with_outer<2>(g.groups))),
                    Catch::Contains("compact kernel"));
}

TEST_CASE("sliding channel walls: nodes stay on their walls exactly", "[movers]") {
  // Channel [0,1]^2: the left side translates up and right, the right side is fixed, the
  // bottom and top walls slide along themselves.
  const Grid<2> g = grid<2>(20);
  BoundarySpec<2> spec;
  spec.moving("x0", Translation<2>{Vec<2>(0.05, 0.08)}).fixed("x1").sliding("y0").sliding("y1", Vec<2>(0.0, 2.0));
  const auto boundary = spec.resolve(g.mesh.points, g.groups);
  RbfOptions options;
  options.support_radius = 0.5;
  RbfMover<2> mover(options);
  mover.setup(g.mesh, boundary);
  const Points<2> u = mover.move(boundary.displacements);
  Index moved = 0;
  for (const auto& [wall, y] : {std::pair<const char*, double>{"y0", 0.0}, {"y1", 1.0}}) {
    for (const Index v : g.groups.at(wall)) {
      const bool corner = g.mesh.points(0, v) == 0.0 || g.mesh.points(0, v) == 1.0;
      if (corner) continue;  // the corners belong to the prescribed/fixed sides
      CHECK(std::abs(g.mesh.points(1, v) + u(1, v) - y) < 1e-14);
      if (std::abs(u(0, v)) > 1e-4) ++moved;
    }
  }
  CHECK(moved > 4);  // they do slide
  CHECK(mover.stats().factorizations == 2);
}

TEST_CASE("coincident boundary nodes are merged, conflicting displacements are named", "[movers]") {
  // Two nodes at the same place (a seam): node 4 duplicates node 0.
  Mesh<2> mesh;
  mesh.points.resize(2, 6);
  mesh.points << 0, 1, 1, 0, 0, 0.5, 0, 0, 1, 1, 0, 0.5;
  mesh.block(ElementType::tri3).add({0, 1, 5});
  mesh.block(ElementType::tri3).add({1, 2, 5});
  mesh.block(ElementType::tri3).add({2, 3, 5});
  mesh.block(ElementType::tri3).add({3, 4, 5});
  BoundarySpec<2> spec;
  spec.fixed("walls");
  const auto boundary = spec.resolve(mesh.points, GroupNodes{{"walls", {0, 1, 2, 3, 4}}});
  RbfMover<2> mover(RbfOptions{RbfKernel::wendland2, 2.0});
  mover.setup(mesh, boundary);
  CHECK(mover.stats().boundary_nodes == 4);
  Points<2> d = Points<2>::Zero(2, 5);
  d(0, 0) = d(0, 4) = 0.1;
  const Points<2> u = mover.move(d);
  CHECK(u(0, 5) > 0.0);
  d(0, 4) = 0.2;
  CHECK_THROWS_WITH(mover.move(d), Catch::Contains("nodes 0 and 4 coincide") && Catch::Contains("(they are 0 apart"));
  // A node at x = 2^31 stretches the boundary's diagonal, and with it the tolerance, until
  // nodes 0.5 apart count as one: the message gives the distance and the diagonal that did it.
  Mesh<2> far = mesh;
  far.points(0, 3) = 2147483648.0;
  far.points(0, 1) = 0.1;
  RbfMover<2> stretched(RbfOptions{RbfKernel::wendland2, 2.0});
  stretched.setup(far, spec.resolve(far.points, GroupNodes{{"walls", {0, 1, 2, 3, 4}}}));
  Points<2> apart = Points<2>::Zero(2, 5);
  apart(0, 0) = apart(0, 4) = 0.1;
  CHECK_THROWS_WITH(stretched.move(apart), Catch::Contains("nodes 0 and 1 coincide but get different displacements (they are 0.1 apart") &&
                                               Catch::Contains("x the boundary's diagonal 2147483648"));
}

TEST_CASE("bad inputs raise InputError", "[movers]") {
  const Grid<2> g = grid<2>(6);
  const GroupNodes groups = with_outer<2>(g.groups);
  BoundarySpec<2> spec;
  spec.fixed("outer");
  const auto boundary = spec.resolve(g.mesh.points, groups);
  RbfMover<2> mover;
  CHECK_THROWS_AS(mover.move(Points<2>::Zero(2, boundary.size())), InputError);  // no setup
  mover.setup(g.mesh, boundary);
  Points<2> d = Points<2>::Zero(2, boundary.size());
  d(1, 3) = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_AS(mover.move(d), InputError);
  CHECK_THROWS_AS(mover.move(Points<2>::Zero(2, boundary.size() + 1)), InputError);
  BoundarySpec<2> unknown;
  unknown.fixed("inlet");
  CHECK_THROWS_WITH(unknown.resolve(g.mesh.points, groups), Catch::Contains("no group named 'inlet'"));
  BoundarySpec<2> wrong_size;
  wrong_size.moving("x0", Points<2>::Zero(2, 3));
  CHECK_THROWS_AS(wrong_size.resolve(g.mesh.points, groups), InputError);
  CHECK_THROWS_AS(spec.resolve(g.mesh.points, GroupNodes{{"outer", {0, 1000}}}), InputError);
  ResolvedBoundary<2> bad = boundary;
  bad.nodes.back() = 1000;
  CHECK_THROWS_AS(mover.setup(g.mesh, bad), InputError);
  CHECK_THROWS_AS(RbfMover<2>(RbfOptions{RbfKernel::wendland2, -1.0}).setup(g.mesh, boundary), InputError);
  BoundarySpec<2> curved;
  curved.sliding("outer");
  CHECK_THROWS_WITH(curved.resolve(g.mesh.points, groups), Catch::Contains("not planar"));
}

TEST_CASE("derivatives: forward and reverse products agree with finite differences", "[movers]") {
  const Grid<2> g = grid<2>(14);
  BoundarySpec<2> spec;
  spec.moving("x0", Rotation2D{Vec<2>(0.5, 0.5), 0.1}).fixed("x1").sliding("y0").sliding("y1");
  const auto boundary = spec.resolve(g.mesh.points, g.groups);
  // Per-entry radii (0.35 on the rotating side, 0.6 elsewhere) make the system nonsymmetric:
  // the reverse product then needs the transposed factorization.
  std::vector<double> varying(static_cast<std::size_t>(boundary.size()));
  for (Index b = 0; b < boundary.size(); ++b) varying[std::size_t(b)] = g.mesh.points(0, boundary.nodes[std::size_t(b)]) == 0.0 ? 0.35 : 0.6;
  for (const bool per_entry : {false, true})
  for (const bool polynomial : {false, true}) {
    CAPTURE(per_entry, polynomial);
    RbfOptions options;
    options.support_radius = 0.6;
    options.polynomial = polynomial;
    if (per_entry) options.support_radii = varying;
    RbfMover<2> mover(options);
    mover.setup(g.mesh, boundary);
    const Points<2> d = boundary.displacements;
    const Points<2> w = random_displacements<2>(boundary.size(), 3, 1.0);
    const Points<2> v = random_displacements<2>(g.mesh.num_nodes(), 4, 1.0);
    const double h = 1e-6;
    const Points<2> fd = (mover.move(d + h * w) - mover.move(d - h * w)) / (2.0 * h);
    const Points<2> jw = mover.derivative_forward(w);
    CHECK((fd - jw).norm() < 1e-6 * jw.norm());
    const Points<2> jtv = mover.derivative_reverse(v);
    // ⟨v, J w⟩ = ⟨Jᵀ v, w⟩, with the finite-difference J w.
    CHECK((v.array() * fd.array()).sum() == Approx((jtv.array() * w.array()).sum()).epsilon(1e-6));
    // Reverse against finite differences of ⟨v, move(d)⟩ in one boundary coordinate.
    Points<2> e = Points<2>::Zero(2, boundary.size());
    e(0, 2) = 1.0;
    const double fd_scalar = ((v.array() * (mover.move(d + h * e) - mover.move(d - h * e)).array()).sum()) / (2.0 * h);
    CHECK(jtv(0, 2) == Approx(fd_scalar).epsilon(1e-6));
  }
}

TEST_CASE("support radius heuristic grows with displacement and spacing", "[movers]") {
  Points<2> b(2, 11);
  for (Index i = 0; i < 11; ++i) b.col(i) = Vec<2>(0.1 * double(i), 0.0);
  const double small = suggest_support_radius<2>(b, Points<2>::Zero(2, 11));
  CHECK(small == Approx(1.0));  // 10 × spacing 0.1
  Points<2> d = Points<2>::Zero(2, 11);
  d(1, 5) = 0.5;
  CHECK(suggest_support_radius(b, d) == Approx(2.5));
  CHECK_THROWS_AS(suggest_support_radius<2>(Points<2>(2, 1), Points<2>(2, 1)), InputError);
}

#include "meshmotion/core/generators.hpp"

namespace {

// An O-mesh of 48 × 16 quadrilaterals around an ellipse of semi-axes 0.5 and `semi_axis_y`.
Mesh<2> ellipse_ring(double semi_axis_y) {
  OMeshOptions o;
  o.semi_axis_x = 0.5;
  o.semi_axis_y = semi_axis_y;
  o.n_around = 48;
  o.n_radial = 16;
  o.first_height = 1e-3;
  return o_mesh(o);
}

}  // namespace

TEST_CASE("step driver: a rotated ellipse O-mesh, wall rotated rigidly, quality reported per step", "[movers]") {
  const Mesh<2> mesh = ellipse_ring(0.2);
  BoundarySpec<2> spec;
  spec.moving("wall", Rotation2D{Vec<2>::Zero(), radians(60.0)}).fixed("farfield");
  for (const int steps : {1, 3}) {
    auto mover = make_mover<2>("rbf", KeyValues{{"support_radius", "3.0"}});
    const StepResult<2> r = run_steps(mover, mesh, spec, StepOptions{steps, Metric::skew});
    REQUIRE(r.steps.size() == std::size_t(steps));
    for (const Index v : mesh.group_nodes("wall")) {
      const Vec<2> expected = Eigen::Rotation2Dd(radians(60.0)) * mesh.points.col(v);
      CHECK((r.mesh.points.col(v) - expected).norm() < 1e-12);
    }
    for (const Index v : mesh.group_nodes("farfield")) CHECK(r.displacements.col(v).norm() == 0.0);
    REQUIRE(r.steps.back().quality);
    CHECK(r.steps.back().quality->num_invalid == 0);
    CHECK(r.steps.back().stats.factorizations == 1);
  }
  CHECK_THROWS_AS(make_mover<2>("no_such_method"), InputError);
}

TEST_CASE("step driver: the RBF moves from one setup at rest as a time loop does, other movers are set up each step",
          "[movers]") {
  const Mesh<2> mesh = ellipse_ring(0.1);
  BoundarySpec<2> spec;
  spec.moving("wall", Rotation2D{Vec<2>(0.1, 0.0), radians(150.0)}).fixed("farfield");
  const int steps = 5;
  auto stepped = make_mover<2>("rbf");
  const StepResult<2> r = run_steps(stepped, mesh, spec, StepOptions{steps, Metric::skew});
  // The time loop: set up on the reference with nothing moved, then each step's whole target.
  auto looped = make_mover<2>("rbf");
  ResolvedBoundary<2> rest = spec.resolve(mesh);
  rest.displacements.setZero();
  looped.setup(mesh, rest);
  for (int s = 1; s <= steps; ++s) {
    const Points<2> u = looped.move(spec.resolve(mesh, double(s) / steps).displacements);
    const StepInfo& info = r.steps[static_cast<std::size_t>(s - 1)];
    CHECK(info.stats.moves == s);
    CHECK(info.stats.rigid_part);
    REQUIRE(info.quality);
    CHECK(info.quality->num_invalid == 0);
    if (s == steps) CHECK((r.displacements - u).cwiseAbs().maxCoeff() < 1e-13);
  }
  // A spring's operator is the reference's: set up again on the moved mesh for every step.
  auto spring = make_mover<2>("spring");
  const StepResult<2> springs = run_steps(spring, mesh, spec, StepOptions{steps, Metric::skew});
  for (const StepInfo& info : springs.steps) CHECK(info.stats.moves == 1);
  const MoveReport report = move_report("spring", quality_report(mesh, Metric::skew), springs);
  double summed = 0.0;
  for (const StepInfo& info : springs.steps) summed += info.stats.setup_seconds;
  CHECK(report.setup_seconds == summed);
  CHECK(move_report("rbf", quality_report(mesh, Metric::skew), r).setup_seconds == r.steps.front().stats.setup_seconds);
}

TEST_CASE("sliding groups: two planes meet in a line (3D), a point (2D), parallel planes stay a plane", "[movers]") {
  const Grid<3> g3 = grid<3>(3);
  BoundarySpec<3> spec3;
  spec3.sliding("x0").sliding("y0").sliding("x1", Vec<3>(-2.0, 0.0, 0.0)).sliding("z0");
  const auto b3 = spec3.resolve(g3.mesh.points, g3.groups);
  Index lines = 0, planes = 0, fixed = 0;
  for (Index k = 0; k < b3.size(); ++k) {
    const Vec<3> x = g3.mesh.points.col(b3.nodes[static_cast<std::size_t>(k)]);
    const bool on_x = x(0) == 0.0 || x(0) == 1.0, on_y = x(1) == 0.0, on_z = x(2) == 0.0;
    const int on = on_x + on_y + on_z;
    if (b3.kinds[static_cast<std::size_t>(k)] == BoundaryKind::fixed) {
      ++fixed;
      CHECK(on == 3);  // a corner on three planes
    } else if (b3.slides_on_line(k)) {
      ++lines;
      CHECK(on == 2);
      const Vec<3> expected = !on_x ? Vec<3>::UnitX() : !on_y ? Vec<3>::UnitY() : Vec<3>::UnitZ();
      CHECK(std::abs(std::abs(b3.directions.col(k).dot(expected)) - 1.0) < 1e-14);
      const Vec<3> u(0.3, -0.2, 0.5);
      CHECK((b3.project(k, u) - expected.dot(u) * expected).norm() < 1e-15);
      CHECK(b3.sliding_basis(k).cols() == 1);
    } else {
      ++planes;
      CHECK(on == 1);
      CHECK(b3.sliding_basis(k).cols() == 2);
    }
  }
  CHECK(fixed == 2);              // (0,0,0) and (1,0,0); the parallel planes x0 and x1 never meet
  CHECK(lines == 4 * 3 + 2);      // z edges x0∩y0, x1∩y0 and y edges x0∩z0, x1∩z0 (3 each), x edge y0∩z0 (2)
  CHECK(planes == b3.size() - 16);

  // A line node meeting a third plane that contains the line stays on the line (the third
  // plane is a group of its own: one group takes one condition).
  GroupNodes with_twin = g3.groups;
  with_twin["x0_twin"] = with_twin.at("x0");
  BoundarySpec<3> same;
  same.sliding("x0").sliding("y0").sliding("x0_twin", Vec<3>(1.0, 0.0, 0.0));
  const auto b_same = same.resolve(g3.mesh.points, with_twin);
  Index same_lines = 0;
  for (Index k = 0; k < b_same.size(); ++k) same_lines += b_same.slides_on_line(k);
  CHECK(same_lines == 4);

  // 2D: two non-parallel lines leave a point; parallel lines stay a line.
  const Grid<2> g2 = grid<2>(4);
  BoundarySpec<2> spec2;
  spec2.sliding("x0").sliding("y0").sliding("x1");
  const auto b2 = spec2.resolve(g2.mesh.points, g2.groups);
  for (Index k = 0; k < b2.size(); ++k) {
    const Vec<2> x = g2.mesh.points.col(b2.nodes[static_cast<std::size_t>(k)]);
    const bool corner = x(1) == 0.0 && (x(0) == 0.0 || x(0) == 1.0);
    CHECK((b2.kinds[static_cast<std::size_t>(k)] == BoundaryKind::fixed) == corner);
    CHECK(!b2.slides_on_line(k));
  }
}

TEST_CASE("edge of two symmetry planes: RBF and elasticity move its nodes along the line", "[movers]") {
  BoxOptions o;
  o.nx = o.ny = o.nz = 4;
  o.cells = BoxCells::tet4;
  const Mesh<3> box = box_mesh(o);
  BoundarySpec<3> spec;
  spec.moving("top", Translation<3>{Vec<3>(0.1, 0.08, 0.12)}).fixed("bottom").sliding("left").sliding("front");
  const ResolvedBoundary<3> b = spec.resolve(box);
  const auto check = [&](const Points<3>& u, const char* who) {
    INFO(who);
    Index on_line = 0;
    double along = 0.0;
    for (Index k = 0; k < b.size(); ++k) {
      if (b.kinds[static_cast<std::size_t>(k)] != BoundaryKind::sliding) continue;
      const Index v = b.nodes[static_cast<std::size_t>(k)];
      const Vec<3> moved = box.points.col(v) + u.col(v);
      if (box.points(0, v) == 0.0) CHECK(std::abs(moved(0)) < 1e-12);
      if (box.points(1, v) == 0.0) CHECK(std::abs(moved(1)) < 1e-12);
      if (b.slides_on_line(k)) {
        ++on_line;
        along = std::max(along, std::abs(u(2, v)));
      } else {
        CHECK(u.col(v).norm() > 1e-4);  // plane nodes slide too
      }
    }
    CHECK(on_line == 3);    // the z edge between the fixed bottom and the moving top
    CHECK(along > 0.02);    // and they do move along it
  };
  RbfOptions options;
  options.support_radius = 1.5;
  RbfMover<3> rbf(options);
  rbf.setup(box, b);
  check(rbf.move(b.displacements), "rbf");
  ElasticityMover<3> elasticity;
  elasticity.setup(box, b);
  check(elasticity.move(b.displacements), "linear elasticity");
}

TEST_CASE("a compact support covering the mesh is evaluated dense, with the sparse result", "[movers]") {
  const Grid<2> g = grid<2>(12);
  BoundarySpec<2> spec;
  spec.moving("x0", Rotation2D{Vec<2>(0.5, 0.5), 0.3}).fixed("x1").sliding("y0").sliding("y1");
  const auto boundary = spec.resolve(g.mesh.points, g.groups);
  RbfOptions options;
  options.support_radius = 5.0;  // the unit square lies inside every support
  RbfMover<2> dense(options);
  dense.setup(g.mesh, boundary);
  CHECK(dense.evaluation_cached());
  options.max_evaluation_cache_bytes = 0;
  RbfMover<2> sparse(options);
  sparse.setup(g.mesh, boundary);
  CHECK_FALSE(sparse.evaluation_cached());
  const Points<2> d = boundary.displacements;
  CHECK((dense.move(d) - sparse.move(d)).cwiseAbs().maxCoeff() < 1e-12);
  const Points<2> v = random_displacements<2>(g.mesh.num_nodes(), 4);
  CHECK((dense.derivative_reverse(v) - sparse.derivative_reverse(v)).cwiseAbs().maxCoeff() < 1e-12);
  // A support of a few cells stays sparse whatever the budget.
  options.max_evaluation_cache_bytes = std::size_t{1} << 30;
  options.support_radius = 0.25;
  RbfMover<2> local(options);
  local.setup(g.mesh, boundary);
  CHECK_FALSE(local.evaluation_cached());
}

TEST_CASE("global kernels: the cached evaluation matrix gives the uncached result", "[movers]") {
  const Grid<2> g = grid<2>(12);
  BoundarySpec<2> spec;
  spec.moving("x0", Translation<2>{Vec<2>(0.05, 0.02)}).fixed("x1").sliding("y0").sliding("y1");
  const auto boundary = spec.resolve(g.mesh.points, g.groups);
  for (const RbfKernel kernel : {RbfKernel::thin_plate_spline, RbfKernel::gaussian, RbfKernel::multiquadric,
                                 RbfKernel::inverse_multiquadric}) {
    INFO(name(kernel));
    RbfOptions options;
    options.kernel = kernel;
    // Shape scales of about the grid spacing keep the dense systems well conditioned.
    options.support_radius = kernel == RbfKernel::thin_plate_spline ? 1.0 : 0.1;
    options.polynomial = kernel == RbfKernel::thin_plate_spline;
    RbfMover<2> cached(options);
    cached.setup(g.mesh, boundary);
    CHECK(cached.evaluation_cached());
    options.max_evaluation_cache_bytes = 0;
    RbfMover<2> direct(options);
    direct.setup(g.mesh, boundary);
    CHECK_FALSE(direct.evaluation_cached());
    CHECK(cached.stats().nonzeros == direct.stats().nonzeros + cached.stats().evaluated_nodes * cached.stats().boundary_nodes);
    // Repeated moves on the cached mover equal a fresh setup + move without the cache.
    Points<2> u;
    for (unsigned seed = 1; seed <= 3; ++seed) {
      const Points<2> d = random_displacements<2>(boundary.size(), seed);
      cached.move_into(d, u);
      RbfMover<2> fresh(options);
      fresh.setup(g.mesh, boundary);
      CHECK((u - fresh.move(d)).cwiseAbs().maxCoeff() < 1e-13);
    }
    CHECK(cached.stats().moves == 3);
    CHECK(cached.stats().factorizations == 2);  // the sliding walls' two systems, once
    const Points<2> v = random_displacements<2>(g.mesh.num_nodes(), 9);
    CHECK((cached.derivative_reverse(v) - direct.derivative_reverse(v)).cwiseAbs().maxCoeff() < 1e-12);
  }
}

TEST_CASE("rbf: the memory is estimated before assembly, a default radius shrinks to the budget and a given one is refused",
          "[movers]") {
  // A quarter turn of the whole boundary, interpolated (rigid_part=none; automatic would move
  // every node rigidly): the default radius (5 × the largest displacement) reaches every centre
  // from every node, a dense system and operator (about 14 MB estimated here).
  const Grid<3> g = grid<3>(10);
  BoundarySpec<3> spec;
  spec.moving("outer", Rotation3D{Vec<3>(0.5, 0.5, 0.5), Vec<3>(0.0, 0.0, 1.0), 1.5707963267948966});
  const auto boundary = spec.resolve(g.mesh.points, with_outer<3>(g.groups));
  RbfOptions options;
  options.rigid_part = RigidPart::none;
  RbfMover<3> unlimited(options);
  unlimited.setup(g.mesh, boundary);
  CHECK_FALSE(unlimited.support_radius_reduced());  // within max(1 KiB a node, 256 MiB)

  options.max_memory_bytes = 1e6;
  RbfMover<3> limited(options);
  limited.setup(g.mesh, boundary);
  CHECK(limited.support_radius_reduced());
  // What the programs take as the default is the mover's.
  const DefaultSupportRadius fitted = default_support_radius(g.mesh.points, boundary, options);
  CHECK(fitted.reduced);
  CHECK(fitted.radius == limited.support_radius());
  CHECK(limited.support_radius() < 0.5 * unlimited.support_radius());
  CHECK(12.0 * static_cast<double>(limited.stats().nonzeros) < options.max_memory_bytes);
  CHECK(12.0 * static_cast<double>(unlimited.stats().nonzeros) > 4.0 * options.max_memory_bytes);
  // Still an interpolant of the rotation.
  const Points<3> moved = limited.move(boundary.displacements);
  for (Index b = 0; b < boundary.size(); ++b)
    CHECK((moved.col(boundary.nodes[static_cast<std::size_t>(b)]) - boundary.displacements.col(b)).norm() < 1e-12);

  options.support_radius = unlimited.support_radius();
  RbfMover<3> given(options);
  try {
    given.setup(g.mesh, boundary);
    FAIL("a given radius beyond max_memory_bytes was accepted");
  } catch (const InputError& e) {
    const std::string what = e.what();
    CHECK(what.find("max_memory_bytes") != std::string::npos);
    CHECK(what.find("support radius " + format_option_value(options.support_radius)) != std::string::npos);
  }
  options.max_memory_bytes = -1.0;
  RbfMover<3> negative(options);
  CHECK_THROWS_AS(negative.setup(g.mesh, boundary), InputError);
}

namespace {

/// The boundary of every facet of `mesh`, prescribed, with no displacement yet.
template <int Dim>
ResolvedBoundary<Dim> whole_boundary(const Mesh<Dim>& mesh) {
  ResolvedBoundary<Dim> boundary;
  for (const auto& block : boundary_facets(mesh)) boundary.nodes.insert(boundary.nodes.end(), block.connectivity.begin(), block.connectivity.end());
  std::sort(boundary.nodes.begin(), boundary.nodes.end());
  boundary.nodes.erase(std::unique(boundary.nodes.begin(), boundary.nodes.end()), boundary.nodes.end());
  const auto m = static_cast<Index>(boundary.nodes.size());
  boundary.kinds.assign(boundary.nodes.size(), BoundaryKind::prescribed);
  boundary.displacements = boundary.normals = boundary.directions = Points<Dim>::Zero(Dim, m);
  return boundary;
}

/// Step s ∈ [0, 1] of a whole-boundary motion of the ring (3 across): turned by `degrees` with a
/// swirl of ±0.15 rad round it, stretched by 1.16 and 1/1.16, translated by 0.31 of its radius.
Vec<2> ring_motion(const Vec<2>& x, double s, double degrees = 56.0) {
  const double swirl = 0.15 * std::cos(2.0 * std::atan2(x.y(), x.x()));
  const double turn = s * (degrees * std::numbers::pi / 180.0 + swirl);
  const Vec<2> stretched(std::pow(1.16, s) * x.x(), std::pow(1.16, -s) * x.y());
  return Eigen::Rotation2Dd(turn) * stretched + Vec<2>(s * 0.31 * 1.5, 0.0);
}

}  // namespace

TEST_CASE("set up once on the reference, the default RBF follows a whole boundary turning 56 degrees in 10 moves",
          "[movers]") {
  // As a time loop runs it: set up before anything moves (the default radius is then ten
  // boundary spacings), moved from the reference at every step. With that radius held, the
  // ring's interior stayed behind its boundary and folded (min scaled Jacobian -36.7 at the
  // last step); the rigid part of each move (rotation and translation) is now blended in first
  // (RigidPartAtMove: nothing is held, so every node takes it whole) and the radius grows with
  // what is left, at most once per doubling of it, and an oscillation within the motion seen
  // sets nothing up again. P1 and P2 (boundary-layer cells on the inner circle).
  const Mesh<2> ring = annulus_mesh();
  for (const Mesh<2>& mesh : {ring, convert_to_quadratic(ring).mesh}) {
    CAPTURE(mesh.num_nodes());
    ResolvedBoundary<2> boundary = whole_boundary(mesh);
    RbfMover<2> mover;
    mover.setup(mesh, boundary);
    const double first_radius = mover.support_radius();
    CHECK(first_radius < 1.0);  // the spacing's radius: nothing moved yet
    const auto displacements = [&](double s) {
      Points<2> d(2, boundary.size());
      for (Index k = 0; k < d.cols(); ++k) {
        const Vec<2> x = mesh.points.col(boundary.nodes[static_cast<std::size_t>(k)]);
        d.col(k) = ring_motion(x, s) - x;
      }
      return d;
    };
    REQUIRE(mover.rigid_part_taken_out());
    std::vector<double> grown_at;  // the largest interpolated displacement of each move that set up again
    Index growths = 0;
    for (int step = 1; step <= 10; ++step) {
      CAPTURE(step);
      const Points<2> d = displacements(0.1 * step);
      Mesh<2> moved = mesh;
      moved.points += mover.move(d);
      CHECK(mover.stats().moves == step);
      // The move's time split: a set up again is timed where it happened, and only there.
      const MoverStats& s = mover.stats();
      CHECK(s.solve_seconds > 0.0);
      CHECK(s.solve_seconds + s.rebuild_seconds <= s.move_seconds);
      CHECK((s.rebuild_seconds > 0.0) == (step == 1 || s.radius_growths > growths));
      if (mover.stats().radius_growths > growths) {
        double rest = 0.0;
        for (Index k = 0; k < boundary.size(); ++k)
          rest = std::max(rest, (d.col(k) - mover.rigid_part_displacement().col(boundary.nodes[static_cast<std::size_t>(k)])).norm());
        grown_at.push_back(rest);
        growths = mover.stats().radius_growths;
        // Set up for twice the motion: the radius covers it with room to double.
        CHECK(mover.support_radius() == Approx(10.0 * grown_at.back()).epsilon(1e-12));
      }
      for (Index k = 0; k < boundary.size(); ++k)
        CHECK((moved.points.col(boundary.nodes[static_cast<std::size_t>(k)]) - mesh.points.col(boundary.nodes[static_cast<std::size_t>(k)]) - d.col(k)).norm() < 1e-12);
      const QualityReport q = quality_report(moved, Metric::scaled_jacobian);
      CHECK(q.num_invalid == 0);
      CHECK(q.min > 0.9);  // 0.95 at the last step measured
    }
    REQUIRE(grown_at.size() >= 2);
    for (std::size_t g = 1; g < grown_at.size(); ++g) CHECK(grown_at[g] > 2.0 * grown_at[g - 1]);
    const double radius = mover.support_radius();
    // Back and forth within the motion seen: nothing set up again, the same map as before.
    const Points<2> half = mover.move(displacements(0.5));
    CHECK(mover.move(displacements(1.0)).allFinite());
    CHECK(mover.stats().radius_growths == growths);
    CHECK(mover.stats().rebuild_seconds == 0.0);
    CHECK(mover.support_radius() == radius);
    CHECK((mover.move(displacements(0.5)) - half).norm() == 0.0);
    // The derivative at the last move meets a central difference of moves about it.
    const Points<2> w = displacements(0.3), at = displacements(0.7);
    (void)mover.move(at);
    const Points<2> forward = mover.derivative_forward(w);
    const double h = 1e-6;
    const Points<2> difference = (mover.move(at + h * w) - mover.move(at - h * w)) / (2.0 * h);
    CHECK((forward - difference).norm() <= 1e-6 * forward.norm());
    // The setup's radius held, interpolating the whole motion, folds the ring.
    RbfOptions held;
    held.support_radius = first_radius;
    held.rigid_part = RigidPart::none;
    RbfMover<2> folding(held);
    folding.setup(mesh, boundary);
    Mesh<2> folded = mesh;
    folded.points += folding.move(displacements(1.0));
    CHECK(quality_report(folded, Metric::scaled_jacobian).num_invalid > 0);
  }
}

TEST_CASE("set up once, the default RBF follows a whole boundary turning 90 degrees at P1 to P7", "[movers]") {
  // The same protocol to a quarter turn (with the swirl, stretch and translation), on a
  // coarser ring at every order to 7: each step valid by the certified scaled Jacobian. At P8
  // the first cells (1e-4 thick) hold node rows 1.25e-5 apart, finer than the grown radius's
  // interpolation resolves: 24 cells fold at the 9th step.
  const Mesh<2> ring = annulus_mesh({.n_around = 48, .core_spacing = 0.08});
  for (int order = 1; order <= 7; ++order) {
    CAPTURE(order);
    const Mesh<2> mesh = order == 1 ? ring : convert_to_order(ring, order).mesh;
    const ResolvedBoundary<2> boundary = whole_boundary(mesh);
    RbfMover<2> mover;
    mover.setup(mesh, boundary);
    double lowest = 1.0;
    for (int step = 1; step <= 10; ++step) {
      CAPTURE(step);
      Points<2> d(2, boundary.size());
      for (Index k = 0; k < d.cols(); ++k) {
        const Vec<2> x = mesh.points.col(boundary.nodes[static_cast<std::size_t>(k)]);
        d.col(k) = ring_motion(x, 0.1 * step, 90.0) - x;
      }
      Mesh<2> moved = mesh;
      moved.points += mover.move(d);
      const QualityReport q = quality_report(moved, Metric::scaled_jacobian);
      CHECK(q.num_invalid == 0);
      lowest = std::min(lowest, q.min);
    }
    CHECK(lowest > 0.8);  // 0.95 at P1, 0.90 at P2 to P4 measured
    CHECK(mover.rigid_part_taken_out());
  }
}

TEST_CASE("a given radius, or one the memory budget holds, does not grow", "[movers]") {
  const Mesh<2> ring = annulus_mesh();
  ResolvedBoundary<2> boundary = whole_boundary(ring);
  Points<2> d(2, boundary.size());
  for (Index k = 0; k < d.cols(); ++k) {
    const Vec<2> x = ring.points.col(boundary.nodes[static_cast<std::size_t>(k)]);
    d.col(k) = ring_motion(x, 1.0) - x;
  }
  RbfOptions given;
  given.support_radius = 0.4;
  RbfMover<2> fixed_radius(given);
  fixed_radius.setup(ring, boundary);
  (void)fixed_radius.move(d);
  CHECK(fixed_radius.support_radius() == 0.4);
  CHECK(fixed_radius.stats().radius_growths == 0);

  RbfOptions budget;
  budget.max_memory_bytes = 2e5;  // room for the spacing's radius, not for the motion's
  RbfMover<2> held(budget);
  held.setup(ring, boundary);
  const double radius = held.support_radius();
  (void)held.move(d);
  (void)held.move(d);
  CHECK(held.stats().radius_growths <= 1);
  CHECK(held.support_radius() < 5.0 * d.colwise().norm().maxCoeff());
  if (held.stats().radius_growths == 1) CHECK(held.support_radius_reduced());
  CHECK(held.support_radius() >= radius);
}

namespace {

/// The boundary of a body (group `body`) turned by `motion` inside held walls (`fixed`), and
/// `sliding` groups (plane normals from the mesh).
template <int Dim, class M>
ResolvedBoundary<Dim> turned_body(const Mesh<Dim>& mesh, const M& motion, std::vector<std::string> fixed,
                                  std::vector<std::string> sliding = {}) {
  BoundarySpec<Dim> spec;
  spec.moving("inner", motion);
  for (auto& g : fixed) spec.fixed(std::move(g));
  for (auto& g : sliding) spec.sliding(std::move(g));
  return spec.resolve(mesh);
}

}  // namespace

TEST_CASE("a body turned 90 degrees inside held walls: its rigid motion is blended in, valid, nothing factorized",
          "[movers]") {
  // The ring's inner circle turns a quarter turn, its outer circle is held, and the memory
  // budget (1 MB here) cuts the default radius, as 3 GB cut it on a 28.8k-point case.
  // Interpolated displacements (rigid_part=none) pull the cells halfway between towards the
  // centre and fold them; the blended rotation shears them instead.
  const Mesh<2> ring = annulus_mesh({.n_around = 96});
  const auto boundary = turned_body<2>(ring, Rotation2D{Vec<2>::Zero(), std::numbers::pi / 2}, {"outer"});
  RbfOptions budget;
  budget.max_memory_bytes = 1e6;
  RbfMover<2> mover(budget);
  mover.setup(ring, boundary);
  REQUIRE(mover.rigid_part_taken_out());
  CHECK(mover.stats().rigid_part);
  Mesh<2> moved = ring;
  moved.points += mover.move(boundary.displacements);
  CHECK(mover.stats().nonzeros == 0);  // the rigid motion left nothing to interpolate
  const QualityReport blended = quality_report(moved, Metric::scaled_jacobian);
  CHECK(blended.num_invalid == 0);
  for (Index v = 0; v < ring.num_nodes(); ++v) {
    const Vec<2> x = ring.points.col(v), y = moved.points.col(v);
    CAPTURE(v, x.norm());
    CHECK(std::abs(y.norm() - x.norm()) < 1e-12);  // turned, never pulled towards the centre
    if (x.norm() < 0.5 + 1e-9) CHECK((y - Vec<2>(-x.y(), x.x())).norm() < 1e-12);  // the body, exactly
    if (x.norm() > 1.5 - 1e-9) CHECK(y == x);                                        // the held wall, untouched
  }
  RbfOptions plain = budget;
  plain.rigid_part = RigidPart::none;
  RbfMover<2> interpolated(plain);
  interpolated.setup(ring, boundary);
  CHECK_FALSE(interpolated.rigid_part_taken_out());
  CHECK(interpolated.support_radius_reduced());
  // Without the budget's cut the interpolation spreads the turn as it wants: automatic keeps it.
  RbfMover<2> unbounded;
  unbounded.setup(ring, boundary);
  CHECK_FALSE(unbounded.rigid_part_taken_out());
  Mesh<2> folded = ring;
  folded.points += interpolated.move(boundary.displacements);
  const QualityReport q = quality_report(folded, Metric::scaled_jacobian);
  CAPTURE(blended.min, q.min, q.num_invalid);
  CHECK(blended.min > q.min + 0.1);
}

TEST_CASE("rigid part: sliding planes the rotation keeps move with the blend, others hold it, a narrow gap and a "
          "radius within the budget stay interpolated", "[movers]") {
  // The ring extruded: its ends slide in their planes, normal to the axis of the turn. A
  // budget of 1 MB cuts the default radii.
  const Mesh<3> ring = extrude_mesh(annulus_mesh({.n_around = 48, .core_spacing = 0.08}), {.layers = 2, .height = 0.3});
  const auto about_z = turned_body<3>(ring, Rotation3D{Vec<3>::Zero(), Vec<3>::UnitZ(), std::numbers::pi / 2}, {"outer"},
                                      {"z_min", "z_max"});
  RbfOptions budget;
  budget.max_memory_bytes = 1e6;
  RbfMover<3> mover(budget);
  mover.setup(ring, about_z);
  REQUIRE(mover.rigid_part_taken_out());
  Mesh<3> moved = ring;
  moved.points += mover.move(about_z.displacements);
  CHECK(quality_report(moved, Metric::scaled_jacobian).num_invalid == 0);
  CHECK((moved.points.row(2) - ring.points.row(2)).cwiseAbs().maxCoeff() < 1e-12);  // the ends stay in their planes
  // Turned about x instead, the ends' planes would be left: they hold the blend, 1e-4 from the
  // body (its first cells) leaves no room for one, and automatic interpolates the whole motion
  // (the nodes' determinants alone read 1 there: no node lies within the gap).
  const auto about_x = turned_body<3>(ring, Rotation3D{Vec<3>::Zero(), Vec<3>::UnitX(), 0.05}, {"outer"}, {"z_min", "z_max"});
  RbfMover<3> tilted(budget);
  tilted.setup(ring, about_x);
  CHECK(tilted.support_radius_reduced());
  CHECK_FALSE(tilted.rigid_part_taken_out());
  RbfOptions forced;
  forced.rigid_part = RigidPart::blend;
  RbfMover<3> blended(forced);
  blended.setup(ring, about_x);
  CHECK(blended.rigid_part_taken_out());
  // A small turn, whose radius fits the default budget, is interpolated.
  const Mesh<2> flat = annulus_mesh({.n_around = 48, .core_spacing = 0.08});
  RbfMover<2> small;
  small.setup(flat, turned_body<2>(flat, Rotation2D{Vec<2>::Zero(), 0.02}, {"outer"}));
  CHECK_FALSE(small.support_radius_reduced());
  CHECK_FALSE(small.rigid_part_taken_out());
}

TEST_CASE("rigid part: moves are affine, derivatives are the interpolation's, a non-rigid motion is refused by blend",
          "[movers]") {
  const Mesh<2> ring = annulus_mesh({.n_around = 48, .core_spacing = 0.08});
  const auto boundary = turned_body<2>(ring, Rotation2D{Vec<2>(0.01, -0.02), 1.2}, {"outer"});
  RbfOptions budget;
  budget.max_memory_bytes = 2e5;
  RbfMover<2> mover(budget);
  mover.setup(ring, boundary);
  REQUIRE(mover.rigid_part_taken_out());
  const Points<2> d = boundary.displacements;
  Points<2> w = random_displacements<2>(boundary.size(), 5, 1e-2);
  for (Index b = 0; b < boundary.size(); ++b)
    if (boundary.kinds[static_cast<std::size_t>(b)] != BoundaryKind::prescribed) w.col(b).setZero();
  const Points<2> at_d = mover.move(d);
  const Points<2> at_dw = mover.move(d + w);  // not the setup's rigid motion: interpolated
  CHECK(mover.stats().nonzeros > 0);
  const Points<2> jw = mover.derivative_forward(w);
  CHECK((at_dw - at_d - jw).norm() < 1e-12 * jw.norm());
  for (Index b = 0; b < boundary.size(); ++b)
    CHECK((at_dw.col(boundary.nodes[static_cast<std::size_t>(b)]) - (d + w).col(b)).norm() < 1e-15);
  const Points<2> v = random_displacements<2>(ring.num_nodes(), 6, 1.0);
  CHECK((v.array() * jw.array()).sum() == Approx((mover.derivative_reverse(v).array() * w.array()).sum()).epsilon(1e-10));
  // A fresh setup is as lazy: its first derivative builds the interpolation.
  RbfMover<2> fresh(budget);
  fresh.setup(ring, boundary);
  CHECK((fresh.derivative_forward(w) - jw).norm() < 1e-12 * jw.norm());

  Points<2> grow = Points<2>::Zero(2, boundary.size());
  for (Index b = 0; b < boundary.size(); ++b)
    if (boundary.kinds[static_cast<std::size_t>(b)] == BoundaryKind::prescribed)
      grow.col(b) = 0.3 * ring.points.col(boundary.nodes[static_cast<std::size_t>(b)]);
  ResolvedBoundary<2> growing = boundary;
  growing.displacements = grow;
  RbfOptions forced;
  forced.rigid_part = RigidPart::blend;
  CHECK_THROWS_WITH(RbfMover<2>(forced).setup(ring, growing), Catch::Contains("do not move as one rigid body"));
  RbfMover<2> automatic(budget);
  automatic.setup(ring, growing);
  CHECK_FALSE(automatic.rigid_part_taken_out());
}

TEST_CASE("set up at rest, a square turned inside a held circle from the reference to 180 degrees stays valid",
          "[movers]") {
  // A solver's protocol for a body turning inside held walls: one setup with nothing moving,
  // then moves from the reference in 15 degree steps to a half turn. Each move's rigid part is
  // fitted and blended by weights of the distance to the body's centre alone (RigidPartAtMove),
  // a twist whose Jacobian determinant is 1 at any angle; what is left to fold is the cells'
  // own resolution of it (64 × 40 quadrilaterals: 16 fold at 180°, min 0.16 at 150°).
  // Interpolating the whole motion (as before, and as rigid_part=none does) folds the mesh
  // from 105°. Sharp corners, quadrilaterals and triangles.
  for (const bool triangles : {false, true}) {
    CAPTURE(triangles);
    const Mesh<2> mesh = o_mesh({.body = OMeshBody::square, .semi_axis_x = 1.0, .n_around = 96, .n_radial = 48,
                                 .first_height = 0.01, .farfield_radius = 6.0, .triangles = triangles});
    BoundarySpec<2> spec;
    spec.moving("wall", Translation<2>{Vec<2>::Zero()}).fixed("farfield");
    const ResolvedBoundary<2> boundary = spec.resolve(mesh);
    const auto turned = [&](double degrees) {
      Points<2> d = Points<2>::Zero(2, boundary.size());
      for (Index k = 0; k < boundary.size(); ++k)
        if (boundary.kinds[static_cast<std::size_t>(k)] == BoundaryKind::prescribed) {
          const Vec<2> x = mesh.points.col(boundary.nodes[static_cast<std::size_t>(k)]);
          d.col(k) = Eigen::Rotation2Dd(degrees * std::numbers::pi / 180.0) * x - x;
        }
      return d;
    };
    RbfMover<2> mover;
    mover.setup(mesh, boundary);
    REQUIRE(mover.rigid_part_taken_out());
    double lowest = 1.0;
    for (int degrees = 15; degrees <= 180; degrees += 15) {
      CAPTURE(degrees);
      const Points<2> d = turned(degrees);
      Mesh<2> moved = mesh;
      moved.points += mover.move(d);
      const QualityReport q = quality_report(moved, Metric::scaled_jacobian);
      CHECK(q.num_invalid == 0);
      lowest = std::min(lowest, q.min);
      for (Index k = 0; k < boundary.size(); ++k)  // the body where it was put, the circle held
        CHECK((moved.points.col(boundary.nodes[static_cast<std::size_t>(k)]) - mesh.points.col(boundary.nodes[static_cast<std::size_t>(k)]) -
               d.col(k)).norm() <= 1e-12);
    }
    CHECK(lowest > 0.1);  // 0.14 measured (quadrilaterals at 180°)
    // A rigid body leaves nothing to interpolate: the radius never grew, nothing was factorized again.
    CHECK(mover.stats().radius_growths == 0);
    RbfOptions whole;
    whole.rigid_part = RigidPart::none;
    RbfMover<2> interpolating(whole);
    interpolating.setup(mesh, boundary);
    Mesh<2> folded = mesh;
    folded.points += interpolating.move(turned(120.0));
    CHECK(quality_report(folded, Metric::scaled_jacobian).num_invalid > 0);
  }
}

/// Turns `mesh`'s prescribed nodes about the z axis from one setup at rest, in 15 degree steps to
/// a half turn, with and without RbfOptions::repair; returns the cells folded without it.
template <int Dim>
Index repaired_half_turn(const Mesh<Dim>& mesh, const ResolvedBoundary<Dim>& boundary) {
  RbfMover<Dim> mover;
  mover.setup(mesh, boundary);
  RbfOptions off;
  off.repair = false;
  RbfMover<Dim> plain(off);
  plain.setup(mesh, boundary);
  Index folded_somewhere = 0;
  for (int degrees = 15; degrees <= 180; degrees += 15) {
    CAPTURE(degrees);
    const Eigen::Matrix3d turn = Eigen::AngleAxisd(degrees * std::numbers::pi / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    Points<Dim> d = Points<Dim>::Zero(Dim, boundary.size());
    for (Index k = 0; k < boundary.size(); ++k)
      if (boundary.kinds[static_cast<std::size_t>(k)] == BoundaryKind::prescribed) {
        const Vec<Dim> x = mesh.points.col(boundary.nodes[static_cast<std::size_t>(k)]);
        d.col(k) = turn.topLeftCorner<Dim, Dim>() * x - x;
      }
    Mesh<Dim> moved = mesh, unrepaired = mesh;
    moved.points += mover.move(d);
    unrepaired.points += plain.move(d);
    const Index folded = quality_report(unrepaired, Metric::scaled_jacobian).num_invalid;
    CHECK(quality_report(moved, Metric::scaled_jacobian).num_invalid == 0);
    CHECK(mover.stats().folded_cells == folded);
    CHECK(mover.stats().left_folded == 0);
    if (folded == 0) {
      CHECK(moved.points == unrepaired.points);
      CHECK(mover.stats().repaired_nodes == 0);
    } else {
      CHECK(mover.stats().repaired_nodes > 0);
    }
    folded_somewhere += folded;
    for (Index k = 0; k < boundary.size(); ++k) {  // the body where it was put, the walls held, the ends in their planes
      const Index v = boundary.nodes[static_cast<std::size_t>(k)];
      if (boundary.kinds[static_cast<std::size_t>(k)] == BoundaryKind::sliding)
        CHECK(std::abs(boundary.normals.col(k).dot(moved.points.col(v) - mesh.points.col(v))) <= 1e-12);
      else
        CHECK(moved.points.col(v) == unrepaired.points.col(v));
    }
    // The derivatives are the map's before the repair.
    CHECK(mover.derivative_forward(d) == plain.derivative_forward(d));
  }
  return folded_somewhere;
}

/// The nodes of `box` within |x| ≤ 1.5, |y|, |z| ≤ 0.8 prescribed, those on its sides fixed.
ResolvedBoundary<3> block_in_box(const Mesh<3>& box) {
  ResolvedBoundary<3> b;
  for (Index v = 0; v < box.num_nodes(); ++v) {
    const Vec<3> x = box.points.col(v);
    if (std::abs(x.x()) <= 1.5 + 1e-9 && std::abs(x.y()) <= 0.8 && std::abs(x.z()) <= 0.8) {
      b.nodes.push_back(v);
      b.kinds.push_back(BoundaryKind::prescribed);
    } else if (x.cwiseAbs().maxCoeff() > 6.0 - 1e-9) {
      b.nodes.push_back(v);
      b.kinds.push_back(BoundaryKind::fixed);
    }
  }
  b.displacements = b.normals = Points<3>::Zero(3, b.size());
  return b;
}

TEST_CASE("set up at rest on a coarse mesh, the cells a half turn folds are repaired", "[movers]") {
  // The square above in a coarser O-mesh (quadrilaterals, and hexahedra extruded from them, the
  // ends sliding in their planes): the twist folds linear cells from 150 degrees. After each
  // move the folded cells' free nodes and two rings around them move until they unfold
  // (RbfOptions::repair); a move that folds nothing is the move unrepaired, bit for bit.
  const Mesh<2> mesh = o_mesh({.body = OMeshBody::square, .semi_axis_x = 1.0, .n_around = 64, .n_radial = 40,
                               .first_height = 0.01, .farfield_radius = 6.0});
  BoundarySpec<2> spec;
  spec.prescribed("wall").fixed("farfield");
  const ResolvedBoundary<2> boundary = spec.resolve(mesh);
  CHECK(repaired_half_turn(mesh, boundary) > 0);  // 16 quadrilaterals at 180 degrees without it
  // A block 3 x 1.5 x 1.5 of nodes inside a held box of tetrahedra 16 cells wide: 620 fold at 180.
  const Mesh<3> box = box_mesh({.nx = 16, .ny = 16, .nz = 16, .x_min = -6, .x_max = 6, .y_min = -6, .y_max = 6,
                                .z_min = -6, .z_max = 6, .cells = BoxCells::tet4});
  CHECK(repaired_half_turn(box, block_in_box(box)) > 0);
  // Without the cells (coordinates alone) there is nothing to repair.
  RbfMover<2> points_only;
  points_only.setup_reference(mesh.points, boundary);
  Points<2> half = Points<2>::Zero(2, boundary.size());
  for (Index k = 0; k < boundary.size(); ++k)
    if (boundary.kinds[static_cast<std::size_t>(k)] == BoundaryKind::prescribed)
      half.col(k) = -2.0 * mesh.points.col(boundary.nodes[static_cast<std::size_t>(k)]);
  Mesh<2> moved = mesh;
  moved.points += points_only.move(half);
  CHECK(points_only.stats().folded_cells == 0);
  CHECK(quality_report(moved, Metric::scaled_jacobian).num_invalid > 0);
  // Hexahedra are searched by their corners and centres, then certified: what the repair says
  // it left is what quality_report finds, and fewer than it found.
  const Mesh<3> hexes = box_mesh({.nx = 16, .ny = 16, .nz = 16, .x_min = -6, .x_max = 6, .y_min = -6, .y_max = 6,
                                  .z_min = -6, .z_max = 6});
  const ResolvedBoundary<3> block = block_in_box(hexes);
  RbfMover<3> hex_mover;
  hex_mover.setup(hexes, block);
  Points<3> turned = Points<3>::Zero(3, block.size());
  for (Index k = 0; k < block.size(); ++k)
    if (block.kinds[static_cast<std::size_t>(k)] == BoundaryKind::prescribed)
      turned.col(k) = Eigen::AngleAxisd(0.8 * std::numbers::pi, Vec<3>::UnitZ()) * hexes.points.col(block.nodes[static_cast<std::size_t>(k)]) -
                      hexes.points.col(block.nodes[static_cast<std::size_t>(k)]);
  Mesh<3> moved_hexes = hexes;
  const Points<3> hex_move = hex_mover.move(turned);
  moved_hexes.points += hex_move;
  CHECK(hex_mover.stats().folded_cells > 0);
  CHECK(quality_report(moved_hexes, Metric::scaled_jacobian).num_invalid == hex_mover.stats().left_folded);
  CHECK(hex_mover.stats().left_folded < hex_mover.stats().folded_cells / 4);
  // Into a caller's storage whose columns are not contiguous (4 rows apart): the same repair.
  Eigen::MatrixXd storage = Eigen::MatrixXd::Constant(4, hexes.num_nodes(), 7.0);
  Eigen::Map<Points<3>, 0, Eigen::OuterStride<>> strided(storage.data(), 3, hexes.num_nodes(), Eigen::OuterStride<>(4));
  hex_mover.move_into(turned, strided);
  CHECK(hex_mover.stats().folded_cells > 0);
  CHECK(Points<3>(strided) == hex_move);
  CHECK((storage.row(3).array() == 7.0).all());
}

TEST_CASE("a linear cell's sign margin: no motion within it flips a corner, one a few times larger does", "[movers]") {
  // The repair's check skips a cell whose vertices moved relative to its first by less than
  // detail::sign_margin_squared. Each corner matrix A is perturbed by −t σ_min(A) u vᵀ (u, v its smallest singular vectors), which makes it
  // singular at t = 1: made by moving the corner's neighbours alone, scaled so the largest
  // relative move is the margin, no determinant changes sign; at t = 1.01 this one has.
  std::mt19937 random(7);
  std::uniform_real_distribution<double> jitter(-0.15, 0.15);
  for (const ElementType type : {ElementType::quad4, ElementType::hex8, ElementType::prism6, ElementType::pyramid5}) {
    CAPTURE(name(type));
    const Shape s = shape(type);
    const int nv = num_vertices(type);
    const auto check = [&]<int D>(std::integral_constant<int, D>) {
      const auto reference = reference_nodes(type);
      for (int trial = 0; trial < 20; ++trial) {
        std::array<Vec<D>, 8> p{};
        for (int k = 0; k < nv; ++k)
          for (int a = 0; a < D; ++a) p[static_cast<std::size_t>(k)](a) = reference[static_cast<std::size_t>(k)][static_cast<std::size_t>(a)] + jitter(random);
        REQUIRE(detail::corners_keep_sign<D>(s, 1.0, p.data()));
        const double margin = std::sqrt(detail::sign_margin_squared<D>(s, p.data()));
        REQUIRE(margin > 0.01);
        for (const detail::KnuppCorner& corner : detail::knupp_table(s).corners) {
          Eigen::Matrix<double, D, D> a;
          for (int d = 0; d < D; ++d) a.col(d) = p[static_cast<std::size_t>(corner.neighbours[static_cast<std::size_t>(d)])] - p[static_cast<std::size_t>(corner.vertex)];
          const Eigen::JacobiSVD<Eigen::MatrixXd> svd(Eigen::MatrixXd(a), Eigen::ComputeFullU | Eigen::ComputeFullV);
          const Eigen::Matrix<double, D, D> flip =
              -svd.singularValues()(D - 1) * svd.matrixU().col(D - 1) * svd.matrixV().col(D - 1).transpose();
          // Column d of the change is the move of neighbour d, relative to the corner's vertex
          // (which stays); relative to vertex 0 a move is at most twice the largest column.
          const double largest = 2.0 * flip.colwise().norm().maxCoeff();
          for (const double t : {margin / largest, 1.01}) {
            std::array<Vec<D>, 8> q = p;
            for (int d = 0; d < D; ++d) q[static_cast<std::size_t>(corner.neighbours[static_cast<std::size_t>(d)])] += t * flip.col(d);
            double rho = 0.0;
            for (int k = 1; k < nv; ++k) rho = std::max(rho, ((q[static_cast<std::size_t>(k)] - p[static_cast<std::size_t>(k)]) - (q[0] - p[0])).norm());
            if (t < 1.0) {
              CHECK(rho <= margin * (1.0 + 1e-12));
              CHECK(detail::corners_keep_sign<D>(s, 1.0, q.data()));
            } else {
              Eigen::Matrix<double, D, D> b;
              for (int d = 0; d < D; ++d) b.col(d) = q[static_cast<std::size_t>(corner.neighbours[static_cast<std::size_t>(d)])] - q[static_cast<std::size_t>(corner.vertex)];
              CHECK(b.determinant() < 0.0);
              CHECK_FALSE(detail::corners_keep_sign<D>(s, 1.0, q.data()));
              CHECK(rho > margin);
            }
          }
        }
      }
      // The unit square's and cube's corners (and the cube's centre): A = I, σ_min 1, ‖A‖_F² = D.
      if (type == ElementType::quad4 || type == ElementType::hex8) {
        std::array<Vec<D>, 8> p{};
        for (int k = 0; k < nv; ++k)
          for (int a = 0; a < D; ++a) p[static_cast<std::size_t>(k)](a) = (reference[static_cast<std::size_t>(k)][static_cast<std::size_t>(a)] + 1.0) / 2.0;
        const double lower = D == 2 ? 1.0 / std::sqrt(2.0) : 2.0 / 3.0;
        CHECK_THAT(detail::sign_margin_squared<D>(s, p.data()), Catch::Matchers::WithinRel(std::pow(0.99 * lower / (2.0 * std::sqrt(double(D))), 2.0), 1e-12));
      }
    };
    if (dimension(type) == 2)
      check(std::integral_constant<int, 2>{});
    else
      check(std::integral_constant<int, 3>{});
  }
}

TEST_CASE("rigid_part=blend on a mover set up at rest names what stops it", "[movers]") {
  const Mesh<2> mesh = rectangle_mesh({.nx = 6, .ny = 6});
  RbfOptions blend;
  blend.rigid_part = RigidPart::blend;
  BoundarySpec<2> touching;  // the moving wall meets the held sides at its ends
  touching.prescribed("bottom").fixed("top").fixed("left").fixed("right");
  RbfMover<2> mover(blend);
  CHECK_THROWS_WITH(mover.setup(mesh, touching.resolve(mesh)), Catch::Contains("rigid_part=blend: a held node lies"));
  BoundarySpec<2> held_only;
  held_only.fixed("top");
  CHECK_THROWS_WITH(mover.setup(mesh, held_only.resolve(mesh)), Catch::Contains("rigid_part=blend: no prescribed node"));
  // automatic takes nothing out there, and interpolates the whole motion as before.
  RbfMover<2> automatic;
  automatic.setup(mesh, touching.resolve(mesh));
  CHECK_FALSE(automatic.rigid_part_taken_out());
}
