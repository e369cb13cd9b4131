#include "meshmotion/delaunay.hpp"
#include "meshmotion/delaunay/detail/spatial_sort.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

using namespace meshmotion;

namespace {

template <int Dim>
int orient(const std::array<const double*, Dim + 1>& p) {
  if constexpr (Dim == 2) {
    return orient2d(p[0], p[1], p[2]);
  } else {
    return orient3d(p[0], p[1], p[2], p[3]);
  }
}

template <int Dim>
int in_sphere(const std::array<const double*, Dim + 1>& p, const double* q) {
  if constexpr (Dim == 2) {
    return incircle(p[0], p[1], p[2], q);
  } else {
    return insphere(p[0], p[1], p[2], p[3], q);
  }
}

template <int Dim>
std::array<const double*, Dim + 1> corners(const DelaunayTriangulation<Dim>& dt, Index s) {
  std::array<const double*, Dim + 1> p{};
  for (int j = 0; j <= Dim; ++j) p[j] = dt.points().col(dt.simplices()(j, s)).data();
  return p;
}

template <int Dim>
std::array<Index, Dim> facet(const DelaunayTriangulation<Dim>& dt, Index s, int j) {
  std::array<Index, Dim> f{};
  for (int k = 0, m = 0; k <= Dim; ++k) {
    if (k != j) f[m++] = dt.simplices()(k, s);
  }
  std::sort(f.begin(), f.end());
  return f;
}

/// Checks every property a Delaunay triangulation of `points` must have; `brute_force` adds
/// the empty-circumsphere and convexity tests against every point (quadratic: small inputs).
/// Violations are counted and asserted once per property to keep large cases fast.
template <int Dim>
void check_delaunay(const Points<Dim>& points, const DelaunayTriangulation<Dim>& dt,
                    bool brute_force) {
  const Index n = points.cols();
  const auto& simplices = dt.simplices();
  const auto& neighbours = dt.neighbours();
  REQUIRE(dt.points().cols() == n);
  REQUIRE(dt.num_simplices() > 0);
  REQUIRE(simplices.minCoeff() >= 0);
  REQUIRE(simplices.maxCoeff() < n);

  // Every unique point is a vertex, no duplicate is; duplicates have equal coordinates.
  std::vector<int> used(static_cast<std::size_t>(n), 0);
  for (Index s = 0; s < dt.num_simplices(); ++s) {
    for (int j = 0; j <= Dim; ++j) used[static_cast<std::size_t>(simplices(j, s))] = 1;
  }
  Index unique = 0;
  Index bad_representatives = 0;
  for (Index i = 0; i < n; ++i) {
    const Index r = dt.representative(i);
    bad_representatives += r > i || points.col(r) != points.col(i) ||
                           used[static_cast<std::size_t>(i)] != (r == i ? 1 : 0);
    unique += r == i;
  }
  CHECK(bad_representatives == 0);
  CHECK(n - unique == dt.num_duplicates());

  Index hull_facets = 0;
  Index not_positive = 0;
  Index asymmetric = 0;
  Index not_locally_delaunay = 0;
  for (Index s = 0; s < dt.num_simplices(); ++s) {
    const auto p = corners(dt, s);
    not_positive += orient<Dim>(p) != 1;
    for (int j = 0; j <= Dim; ++j) {
      const Index t = neighbours(j, s);
      if (t < 0) {
        ++hull_facets;
        continue;
      }
      // Symmetric adjacency through the same facet.
      int back = -1;
      for (int k = 0; k <= Dim; ++k) {
        if (neighbours(k, t) == s) back = k;
      }
      if (back < 0 || facet(dt, s, j) != facet(dt, t, back)) {
        ++asymmetric;
        continue;
      }
      // Locally Delaunay: the opposite vertex is not strictly inside the circumsphere.
      not_locally_delaunay += in_sphere<Dim>(p, points.col(simplices(back, t)).data()) > 0;
    }
  }
  CHECK(not_positive == 0);
  CHECK(asymmetric == 0);
  CHECK(not_locally_delaunay == 0);
  REQUIRE(hull_facets == static_cast<Index>(dt.hull_facets().size()));

  // The hull is a closed surface (each hull ridge in exactly two hull facets) and convex: no
  // vertex of a hull facet is strictly beyond an adjacent hull facet (local convexity of a
  // closed surface implies convexity), and with brute force no point at all.
  const auto& hull = dt.hull_facets();
  auto beyond = [&](std::size_t h, Index v) {
    auto p = corners(dt, hull[h].first);
    p[hull[h].second] = points.col(v).data();
    return orient<Dim>(p) < 0;
  };
  Index not_convex = 0;
  // (ridge vertices, hull facet) sorted by ridge: each ridge must appear exactly twice.
  std::vector<std::pair<std::array<Index, 2>, std::size_t>> ridges;
  for (std::size_t h = 0; h < hull.size(); ++h) {
    const auto f = facet(dt, hull[h].first, hull[h].second);
    for (std::size_t skip = 0; skip < f.size(); ++skip) {
      std::array<Index, 2> ridge{-1, -1};
      for (std::size_t k = 0, m = 0; k < f.size(); ++k) {
        if (k != skip) ridge[m++] = f[k];
      }
      ridges.emplace_back(ridge, h);
    }
    if (brute_force) {
      for (Index v = 0; v < n; ++v) not_convex += beyond(h, v);
    }
  }
  std::sort(ridges.begin(), ridges.end());
  REQUIRE(ridges.size() % 2 == 0);
  Index open_ridges = 0;
  for (std::size_t r = 0; r < ridges.size(); r += 2) {
    if (ridges[r].first != ridges[r + 1].first ||
        (r + 2 < ridges.size() && ridges[r + 2].first == ridges[r].first)) {
      ++open_ridges;
      continue;
    }
    const std::size_t around[2] = {ridges[r].second, ridges[r + 1].second};
    for (int k = 0; k < 2; ++k) {
      for (Index v : facet(dt, hull[around[k]].first, hull[around[k]].second)) {
        not_convex += beyond(around[1 - k], v);
      }
    }
  }
  CHECK(open_ridges == 0);
  CHECK(not_convex == 0);

  // Euler characteristic of a triangulated ball: V - E + F (- T) = 1.
  std::vector<std::pair<Index, Index>> edges;
  for (Index s = 0; s < dt.num_simplices(); ++s) {
    for (int a = 0; a <= Dim; ++a) {
      for (int b = a + 1; b <= Dim; ++b) {
        const Index u = simplices(a, s), w = simplices(b, s);
        edges.emplace_back(std::min(u, w), std::max(u, w));
      }
    }
  }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  const Index cells = dt.num_simplices();
  const Index facets = ((Dim + 1) * cells + hull_facets) / 2;
  const auto e = static_cast<Index>(edges.size());
  if constexpr (Dim == 2) {
    CHECK(unique - e + cells == 1);
  } else {
    CHECK(unique - e + facets - cells == 1);
  }

  if (brute_force) {
    Index not_empty = 0;
    for (Index s = 0; s < dt.num_simplices(); ++s) {
      const auto p = corners(dt, s);
      for (Index v = 0; v < n; ++v) not_empty += in_sphere<Dim>(p, points.col(v).data()) > 0;
    }
    CHECK(not_empty == 0);
  }
}

template <int Dim>
Points<Dim> random_points(Index n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Points<Dim> p(Dim, n);
  for (Index i = 0; i < n; ++i) {
    for (int d = 0; d < Dim; ++d) p(d, i) = u(rng);
  }
  return p;
}

template <int Dim>
void check_locate(const DelaunayTriangulation<Dim>& dt, const Points<Dim>& queries) {
  Index hint = -1;
  for (Index i = 0; i < queries.cols(); ++i) {
    const Vec<Dim> q = queries.col(i);
    const LocateResult<Dim> r = dt.locate(q, hint);
    REQUIRE(r.simplex >= 0);
    REQUIRE(r.barycentric.sum() == Approx(1.0).margin(1e-12));
    const Vec<Dim> back = dt.corner_points(r.simplex) * r.barycentric;
    REQUIRE((back - q).norm() <= 1e-12 * (1.0 + q.norm()));
    if (!r.outside) REQUIRE(r.barycentric.minCoeff() >= -1e-12);
    if (r.outside) REQUIRE(r.barycentric.minCoeff() < 0.0);
    hint = r.simplex;
  }
}

}  // namespace

template <int Dim>
void check_random_sorted_and_unsorted(Index n, std::uint64_t seed) {
  const Points<Dim> p = random_points<Dim>(n, seed);
  check_delaunay(p, delaunay<Dim>(p), true);
  DelaunayOptions unsorted;
  unsorted.spatial_sort = false;
  check_delaunay(p, delaunay<Dim>(p, unsorted), true);
}

TEST_CASE("delaunay of random points", "[delaunay]") {
  SECTION("2D brute force") { check_random_sorted_and_unsorted<2>(600, 1); }
  SECTION("3D brute force") { check_random_sorted_and_unsorted<3>(400, 2); }
}

TEST_CASE("delaunay of 10^5 random points", "[delaunay][slow]") {
  const Points<2> p2 = random_points<2>(100000, 3);
  check_delaunay(p2, delaunay<2>(p2), false);
  const Points<3> p3 = random_points<3>(100000, 4);
  check_delaunay(p3, delaunay<3>(p3), false);
}

TEST_CASE("delaunay of regular grids (co-circular, co-spherical)", "[delaunay]") {
  SECTION("2D") {
    const int m = 30;
    Points<2> p(2, m * m);
    for (int i = 0; i < m; ++i) {
      for (int j = 0; j < m; ++j) p.col(i * m + j) << 0.1 * i, 0.1 * j;
    }
    const auto dt = delaunay<2>(p);
    check_delaunay(p, dt, true);
    CHECK(dt.num_simplices() == 2 * (m - 1) * (m - 1));
  }
  SECTION("3D") {
    const int m = 9;
    Points<3> p(3, m * m * m);
    for (int i = 0; i < m; ++i) {
      for (int j = 0; j < m; ++j) {
        for (int k = 0; k < m; ++k) p.col((i * m + j) * m + k) << 0.3 * i, 0.7 * j, 0.1 * k;
      }
    }
    const auto dt = delaunay<3>(p);
    check_delaunay(p, dt, true);
    // Every tetrahedron lies in one grid cube (co-spherical cube corners): volumes add up.
    double volume = 0.0;
    for (Index s = 0; s < dt.num_simplices(); ++s) {
      const auto c = dt.corner_points(s);
      Eigen::Matrix3d e;
      for (int k = 0; k < 3; ++k) e.col(k) = c.col(k + 1) - c.col(0);
      volume += detail::small_determinant<3>(e) / 6.0;
    }
    CHECK(volume == Approx(0.3 * 0.7 * 0.1 * std::pow(m - 1, 3)).epsilon(1e-12));
  }
}

TEST_CASE("delaunay of points on a circle and on a sphere", "[delaunay]") {
  SECTION("circle with centre") {
    const int m = 200;
    Points<2> p(2, m + 1);
    for (int i = 0; i < m; ++i) {
      const double t = 2.0 * std::numbers::pi * i / m;
      p.col(i) << std::cos(t), std::sin(t);
    }
    p.col(m) << 0.0, 0.0;
    check_delaunay(p, delaunay<2>(p), true);
  }
  SECTION("circle only (all on the hull)") {
    const int m = 128;
    Points<2> p(2, m);
    for (int i = 0; i < m; ++i) {
      const double t = 2.0 * std::numbers::pi * i / m;
      p.col(i) << 3.0 + std::cos(t), -1.0 + std::sin(t);
    }
    const auto dt = delaunay<2>(p);
    check_delaunay(p, dt, true);
    CHECK(dt.num_simplices() == m - 2);
  }
  SECTION("sphere") {
    const int m = 400;
    Points<3> p(3, m + 1);
    const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
    for (int i = 0; i < m; ++i) {
      const double z = 1.0 - 2.0 * (i + 0.5) / m;
      const double r = std::sqrt(1.0 - z * z);
      p.col(i) << r * std::cos(golden * i), r * std::sin(golden * i), z;
    }
    p.col(m) << 0.0, 0.0, 0.0;
    check_delaunay(p, delaunay<3>(p), true);
  }
  SECTION("structured cylinder surface (co-spherical rings)") {
    const int rings = 12, around = 24;
    Points<3> p(3, rings * around);
    for (int r = 0; r < rings; ++r) {
      for (int a = 0; a < around; ++a) {
        const double t = 2.0 * std::numbers::pi * a / around;
        p.col(r * around + a) << std::cos(t), std::sin(t), 0.25 * r;
      }
    }
    check_delaunay(p, delaunay<3>(p), true);
  }
}

TEST_CASE("delaunay of near-degenerate inputs", "[delaunay]") {
  SECTION("2D grid perturbed by one ulp") {
    std::mt19937_64 rng(9);
    const int m = 20;
    Points<2> p(2, m * m);
    for (int i = 0; i < m; ++i) {
      for (int j = 0; j < m; ++j) {
        double x = 1.0 + i, y = 1.0 + j;
        if (rng() % 2) x = std::nextafter(x, 0.0);
        if (rng() % 2) y = std::nextafter(y, 1e9);
        p.col(i * m + j) << x, y;
      }
    }
    check_delaunay(p, delaunay<2>(p), true);
  }
  SECTION("3D slivers: grid perturbed by one ulp") {
    std::mt19937_64 rng(10);
    const int m = 6;
    Points<3> p(3, m * m * m);
    for (int i = 0; i < m * m * m; ++i) {
      double c[3] = {1.0 + i % m, 1.0 + (i / m) % m, 1.0 + i / (m * m)};
      for (double& x : c) {
        if (rng() % 3 == 0) x = std::nextafter(x, rng() % 2 ? 0.0 : 1e9);
      }
      p.col(i) << c[0], c[1], c[2];
    }
    check_delaunay(p, delaunay<3>(p), true);
  }
  SECTION("points nearly on a line, then one off it") {
    Points<2> p(2, 50);
    for (int i = 0; i < 49; ++i) p.col(i) << 0.1 * i, 0.1 * i;
    p(1, 17) = std::nextafter(p(1, 17), 10.0);
    p.col(49) << 0.0, 1.0;
    check_delaunay(p, delaunay<2>(p), true);
  }
  SECTION("3D: coplanar points and one apex") {
    Points<3> p(3, 101);
    const Points<2> flat = random_points<2>(100, 11);
    for (Index i = 0; i < 100; ++i) p.col(i) << flat(0, i), flat(1, i), 0.0;
    p.col(100) << 0.0, 0.0, 1e-3;
    check_delaunay(p, delaunay<3>(p), true);
  }
}

TEST_CASE("delaunay skips duplicate points", "[delaunay]") {
  std::mt19937_64 rng(12);
  Points<2> p(2, 500);
  for (Index i = 0; i < p.cols(); ++i) {
    p.col(i) << static_cast<double>(rng() % 10), static_cast<double>(rng() % 10);
  }
  const auto dt = delaunay<2>(p);
  check_delaunay(p, dt, true);
  CHECK(dt.num_duplicates() == 500 - 100);
  CHECK(dt.num_simplices() == 2 * 9 * 9);

  Points<3> q = random_points<3>(200, 13);
  q.col(150) = q.col(3);
  q.col(199) = q.col(3);
  q.col(7) = q.col(120);
  const auto dt3 = delaunay<3>(q);
  check_delaunay(q, dt3, true);
  CHECK(dt3.num_duplicates() == 3);
  CHECK(dt3.representative(199) == 3);
  CHECK(dt3.representative(120) == 7);
}

TEST_CASE("delaunay rejects degenerate input", "[delaunay]") {
  Points<2> line(2, 10);
  for (Index i = 0; i < 10; ++i) line.col(i) << 0.5 * i, 1.0 - 0.25 * i;
  CHECK_THROWS_AS(delaunay<2>(line), InputError);
  CHECK_THROWS_WITH(delaunay<2>(line), Catch::Contains("collinear"));

  // Exactly coplanar: integer coordinates on the plane z = x - 2y.
  std::mt19937_64 rng(14);
  Points<3> plane(3, 30);
  for (Index i = 0; i < 30; ++i) {
    const double x = static_cast<double>(rng() % 100), y = static_cast<double>(rng() % 100);
    plane.col(i) << x, y, x - 2.0 * y;
  }
  CHECK_THROWS_WITH(delaunay<3>(plane), Catch::Contains("coplanar"));

  Points<3> repeated(3, 5);
  repeated.setOnes();
  CHECK_THROWS_AS(delaunay<3>(repeated), InputError);
  CHECK_THROWS_WITH(delaunay<2>(Points<2>(2, 2)), Catch::Contains("too few points"));

  Points<2> nan = random_points<2>(10, 15);
  nan(1, 4) = std::nan("");
  CHECK_THROWS_WITH(delaunay<2>(nan), Catch::Contains("point 4"));
}

TEST_CASE("locate returns barycentric coordinates of the containing simplex", "[delaunay]") {
  SECTION("2D") {
    const Points<2> p = random_points<2>(2000, 16);
    const auto dt = delaunay<2>(p);
    check_locate(dt, Points<2>(random_points<2>(500, 17) * 0.999));
    check_locate(dt, Points<2>(random_points<2>(100, 18) * 3.0));  // many outside the hull
    // A vertex is located with a unit barycentric coordinate.
    const auto r = dt.locate(p.col(5), dt.vertex_simplex(5));
    CHECK_FALSE(r.outside);
    CHECK(r.barycentric.maxCoeff() == Approx(1.0));
  }
  SECTION("3D") {
    const Points<3> p = random_points<3>(2000, 19);
    const auto dt = delaunay<3>(p);
    check_locate(dt, Points<3>(random_points<3>(500, 20) * 0.999));
    check_locate(dt, Points<3>(random_points<3>(100, 21) * 3.0));
  }
  SECTION("outside points get the nearest hull simplex") {
    Points<2> square(2, 4);
    square << 0, 1, 1, 0, 0, 0, 1, 1;
    const auto dt = delaunay<2>(square);
    const auto r = dt.locate(Vec<2>(2.0, 0.5));
    CHECK(r.outside);
    bool touches_right_edge = false;
    for (const auto& [s, j] : dt.hull_facets()) {
      if (s != r.simplex) continue;
      const auto c = dt.corner_points(s);
      int on_right = 0;
      for (int k = 0; k < 3; ++k) on_right += (k != j && c(0, k) == 1.0);
      touches_right_edge = touches_right_edge || on_right == 2;
    }
    CHECK(touches_right_edge);
    CHECK_THROWS_AS(dt.locate(Vec<2>(std::nan(""), 0.0)), InputError);
  }
}

TEST_CASE("Hilbert order visits grid cells by unit steps", "[delaunay]") {
  // Consecutive keys of a full 2^k grid are face neighbours: the curve is continuous.
  const int m = 32;
  std::vector<std::array<int, 2>> at(m * m);
  for (std::uint32_t x = 0; x < m; ++x) {
    for (std::uint32_t y = 0; y < m; ++y) {
      std::uint32_t cell[2] = {x << 11, y << 11};
      at[detail::hilbert_key<2, 16>(cell) >> 22] = {static_cast<int>(x), static_cast<int>(y)};
    }
  }
  int jumps = 0;
  for (int k = 1; k < m * m; ++k) {
    jumps += std::abs(at[k][0] - at[k - 1][0]) + std::abs(at[k][1] - at[k - 1][1]) != 1;
  }
  CHECK(jumps == 0);
  const int q = 8;
  std::vector<std::array<int, 3>> at3(q * q * q);
  for (std::uint32_t x = 0; x < q; ++x) {
    for (std::uint32_t y = 0; y < q; ++y) {
      for (std::uint32_t z = 0; z < q; ++z) {
        std::uint32_t cell[3] = {x << 7, y << 7, z << 7};
        at3[detail::hilbert_key<3, 10>(cell) >> 21] = {static_cast<int>(x), static_cast<int>(y),
                                                       static_cast<int>(z)};
      }
    }
  }
  for (int k = 1; k < q * q * q; ++k) {
    int step = 0;
    for (int d = 0; d < 3; ++d) step += std::abs(at3[k][d] - at3[k - 1][d]);
    jumps += step != 1;
  }
  CHECK(jumps == 0);
  // The BRIO order is a permutation.
  const Points<2> p = random_points<2>(5000, 22);
  std::vector<Index> order = detail::brio_order<2>(p, 3);
  std::sort(order.begin(), order.end());
  for (Index i = 0; i < 5000; ++i) REQUIRE(order[static_cast<std::size_t>(i)] == i);
}

TEST_CASE("graph mapping reproduces affine motions and detects inversion", "[delaunay]") {
  SECTION("2D") {
    // Graph: a square frame of boundary points around an inner circle; queries fill the gap.
    std::vector<Vec<2>> nodes;
    for (int i = 0; i < 40; ++i) {
      const double t = 2.0 * std::numbers::pi * i / 40;
      nodes.emplace_back(0.3 * std::cos(t), 0.3 * std::sin(t));
      const double s = -1.0 + 2.0 * i / 40;
      nodes.emplace_back(s, -1.0);
      nodes.emplace_back(1.0, s);
      nodes.emplace_back(-s, 1.0);
      nodes.emplace_back(-1.0, -s);
    }
    Points<2> graph_points(2, static_cast<Index>(nodes.size()));
    for (std::size_t i = 0; i < nodes.size(); ++i)
      graph_points.col(static_cast<Index>(i)) = nodes[i];
    const auto graph = delaunay<2>(graph_points);
    const Points<2> queries = random_points<2>(3000, 23);
    const GraphMapping<2> mapping(graph, queries);
    CHECK(mapping.num_queries() == 3000);
    CHECK(mapping.num_outside() == 0);
    CHECK((mapping.map(graph_points) - queries).cwiseAbs().maxCoeff() < 1e-14);

    Eigen::Matrix2d a;
    a << 1.2, 0.3, -0.4, 0.9;
    const Vec<2> b(0.5, -2.0);
    const Points<2> moved = (a * graph_points).colwise() + b;
    const Points<2> expected = (a * queries).colwise() + b;
    CHECK((mapping.map(moved) - expected).cwiseAbs().maxCoeff() < 1e-13);
    CHECK(mapping.inverted_simplices(moved).empty());
    // Linear: displacements map like positions.
    const Points<2> displacement = moved - graph_points;
    CHECK((mapping.map(displacement) - (expected - queries)).cwiseAbs().maxCoeff() < 1e-13);

    // A reflection inverts everything; pushing one inner node across the circle inverts some.
    Points<2> mirrored = graph_points;
    mirrored.row(0) *= -1.0;
    CHECK(static_cast<Index>(mapping.inverted_simplices(mirrored).size()) == graph.num_simplices());
    Points<2> pushed = graph_points;
    pushed.col(0) = Vec<2>(-0.5, 0.0);
    CHECK_FALSE(mapping.inverted_simplices(pushed).empty());

    CHECK_THROWS_AS(mapping.map(Points<2>(2, 3)), InputError);
    Points<2> bad_query = queries.leftCols(5);
    bad_query(0, 2) = std::nan("");
    CHECK_THROWS_AS(GraphMapping<2>(graph, bad_query), InputError);
  }
  SECTION("3D, queries partly outside the hull") {
    const Points<3> graph_points = random_points<3>(300, 24);
    const auto graph = delaunay<3>(graph_points);
    const Points<3> queries = random_points<3>(2000, 25) * 1.2;
    const GraphMapping<3> mapping(graph, queries);
    CHECK(mapping.num_outside() > 0);
    Eigen::Matrix3d a;
    a << 1.0, 0.2, 0.0, -0.1, 0.8, 0.3, 0.05, 0.0, 1.1;
    const Vec<3> b(1.0, 2.0, 3.0);
    const Points<3> moved = (a * graph_points).colwise() + b;
    const Points<3> expected = (a * queries).colwise() + b;
    // Extrapolation outside the hull is affine too.
    CHECK((mapping.map(moved) - expected).cwiseAbs().maxCoeff() < 1e-12);
    CHECK(mapping.inverted_simplices(moved).empty());
  }
}

TEST_CASE("delaunay is invariant under power-of-two scaling", "[delaunay]") {
  // Coordinates near 1e120 would overflow the predicates' products unscaled (and near 1e-120
  // underflow); an exact power-of-two rescaling keeps the triangulation identical.
  const Points<3> p = random_points<3>(500, 26);
  const auto reference = delaunay<3>(p);
  for (int exponent : {400, -400, 40}) {
    const Points<3> scaled = p * std::ldexp(1.0, exponent);
    const auto dt = delaunay<3>(scaled);
    REQUIRE(dt.num_simplices() == reference.num_simplices());
    CHECK(dt.simplices() == reference.simplices());
  }
  const Points<2> q = random_points<2>(500, 27);
  const Points<2> huge = q * std::ldexp(1.0, 600);
  CHECK(delaunay<2>(huge).simplices() == delaunay<2>(q).simplices());
}

TEST_CASE("delaunay of exactly co-circular and co-spherical lattice points", "[delaunay]") {
  // Every lattice point of a circle/sphere: all on the hull and all on one circumsphere, so
  // every in-circle/in-sphere test of a finite simplex is exactly zero.
  SECTION("circle x^2 + y^2 = 5525 with its centre") {
    std::vector<Vec<2>> nodes{Vec<2>(0.0, 0.0)};
    for (int x = -75; x <= 75; ++x) {
      for (int y = -75; y <= 75; ++y) {
        if (x * x + y * y == 5525) nodes.emplace_back(x, y);
      }
    }
    REQUIRE(nodes.size() == 49);
    Points<2> p(2, static_cast<Index>(nodes.size()));
    for (std::size_t i = 0; i < nodes.size(); ++i) p.col(static_cast<Index>(i)) = nodes[i];
    const auto dt = delaunay<2>(p);
    check_delaunay(p, dt, true);
    CHECK(dt.num_simplices() == 48);
  }
  SECTION("sphere x^2 + y^2 + z^2 = 625") {
    std::vector<Vec<3>> nodes;
    for (int x = -25; x <= 25; ++x) {
      for (int y = -25; y <= 25; ++y) {
        for (int z = -25; z <= 25; ++z) {
          if (x * x + y * y + z * z == 625) nodes.emplace_back(x, y, z);
        }
      }
    }
    REQUIRE(nodes.size() > 100);
    Points<3> p(3, static_cast<Index>(nodes.size()));
    for (std::size_t i = 0; i < nodes.size(); ++i) p.col(static_cast<Index>(i)) = nodes[i];
    check_delaunay(p, delaunay<3>(p), true);
    DelaunayOptions unsorted;
    unsorted.spatial_sort = false;
    check_delaunay(p, delaunay<3>(p, unsorted), true);
  }
}
