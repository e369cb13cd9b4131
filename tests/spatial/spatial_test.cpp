#include "meshmotion/spatial.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <span>
#include <type_traits>
#include <utility>

using namespace meshmotion;

namespace {

template <int Dim>
void check_against_brute_force(Index n) {
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Points<Dim> points(Dim, n);
  for (Index i = 0; i < n; ++i)
    for (int d = 0; d < Dim; ++d) points(d, i) = u(rng);
  const KdTree<Dim> tree(points);
  REQUIRE(tree.size() == n);
  std::vector<Neighbor> found;
  for (int q = 0; q < 50; ++q) {
    Vec<Dim> query;
    for (int d = 0; d < Dim; ++d) query[d] = 1.2 * u(rng);
    const double radius = 0.05 + 0.5 * (q % 5) / 4.0;
    tree.radius_search(query, radius, found);
    std::vector<std::size_t> got;
    for (const auto& [i, d2] : found) {
      got.push_back(i);
      CHECK(d2 == Approx((points.col(static_cast<Index>(i)) - query).squaredNorm()));
    }
    std::sort(got.begin(), got.end());
    std::vector<std::size_t> expected;
    std::vector<std::pair<double, std::size_t>> all;
    for (Index i = 0; i < n; ++i) {
      const double d2 = (points.col(i) - query).squaredNorm();
      if (d2 < radius * radius) expected.push_back(static_cast<std::size_t>(i));
      all.emplace_back(d2, static_cast<std::size_t>(i));
    }
    CHECK(got == expected);
    std::sort(all.begin(), all.end());
    const auto knn = tree.nearest(query, 7);
    REQUIRE(knn.size() == 7);
    for (std::size_t k = 0; k < 7; ++k) CHECK(knn[k].second == Approx(all[k].first));
    CHECK(tree.nearest(query).first == all[0].second);
    // The nearest point strictly within the radius, or none.
    const auto within = tree.nearest_within(query, radius);
    REQUIRE(within.has_value() == (all[0].first < radius * radius));
    if (within) CHECK(within->first == all[0].second);
    if (within) CHECK(within->second == Approx(all[0].first));
    // The k nearest within the radius: the front of the sorted distances below it.
    std::array<Neighbor, 5> near{};
    const Index count = tree.nearest_within(query, radius, std::span<Neighbor>(near));
    const auto inside = static_cast<Index>(std::count_if(all.begin(), all.end(), [&](const auto& a) { return a.first < radius * radius; }));
    REQUIRE(count == std::min<Index>(5, inside));
    for (Index k = 0; k < count; ++k) {
      CHECK(near[static_cast<std::size_t>(k)].first == all[static_cast<std::size_t>(k)].second);
      CHECK(near[static_cast<std::size_t>(k)].second == Approx(all[static_cast<std::size_t>(k)].first));
    }
  }
}

}  // namespace

// The nanoflann switch picks the installed version's result type (1.4: std::pair; 1.5+: its
// ResultItem, renamed with SearchParameters).
#if NANOFLANN_VERSION >= 0x150
static_assert(std::is_same_v<meshmotion::Neighbor, nanoflann::ResultItem<std::size_t, double>>);
#else
static_assert(std::is_same_v<meshmotion::Neighbor, std::pair<std::size_t, double>>);
#endif

TEST_CASE("k-d tree radius and k-nearest queries match brute force", "[spatial]") {
  check_against_brute_force<2>(500);
  check_against_brute_force<3>(800);
}

TEST_CASE("k-d tree reads the matrix in place and handles edge cases", "[spatial]") {
  Points<2> points(2, 3);
  points << 0, 1, 2, 0, 0, 0;
  const KdTree<2> tree(points);
  CHECK(tree.radius_search(Vec<2>(0.9, 0.0), 0.2).size() == 1);
  // Queries outside the points' bounding box: found exactly when strictly within the radius,
  // across a side and past a corner.
  CHECK(tree.radius_search(Vec<2>(2.5, 0.0), 0.5).empty());
  CHECK(tree.radius_search(Vec<2>(2.5, 0.0), 0.5001).size() == 1);
  CHECK(tree.radius_search(Vec<2>(1.0, 0.3), 0.31).size() == 1);
  CHECK(tree.radius_search(Vec<2>(1.0, 0.3), 0.29).empty());
  CHECK(tree.radius_search(Vec<2>(3.0, 4.0), 4.2).size() == 1);
  CHECK(tree.radius_search(Vec<2>(3.0, 4.0), 4.1).empty());
  const KdTree<2> empty(Points<2>(2, 0));
  CHECK(empty.radius_search(Vec<2>(0.0, 0.0), 1.0).empty());
  CHECK(empty.nearest(Vec<2>(0.0, 0.0), 3).empty());
  CHECK_THROWS_AS(empty.nearest(Vec<2>(0.0, 0.0)), InputError);
  CHECK_FALSE(empty.nearest_within(Vec<2>(0.0, 0.0), 1.0).has_value());
  // From the centre of points on a circle every point is at one distance: a radius below it
  // finds none, one above finds the nearest.
  Points<2> circle(2, 64);
  for (Index i = 0; i < 64; ++i) circle.col(i) = Vec<2>(std::cos(0.1 * static_cast<double>(i)), std::sin(0.1 * static_cast<double>(i)));
  const KdTree<2> ring(circle);
  CHECK_FALSE(ring.nearest_within(Vec<2>(0.0, 0.0), 0.99).has_value());
  CHECK(ring.nearest_within(Vec<2>(0.9, 0.0), 0.2)->first == 0);
  std::array<Neighbor, KdTree<2>::max_within + 1> too_many{};
  CHECK_THROWS_WITH(ring.nearest_within(Vec<2>(0.0, 0.0), 2.0, std::span<Neighbor>(too_many)), Catch::Contains("17 neighbours asked"));
  CHECK(ring.nearest_within(Vec<2>(0.0, 0.0), 2.0, std::span<Neighbor>(too_many.data(), KdTree<2>::max_within)) == 16);
  CHECK(tree.nearest(Vec<2>(5.0, 0.0), 10).size() == 3);
  points(0, 1) = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_AS(KdTree<2>(points), InputError);
}

namespace {

// Every point in a ball is covered; most points outside every ball by more than a cell are not.
template <int Dim>
void check_ball_cover(const std::vector<double>& radius_spread) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const Index n = 300;
  Points<Dim> centres(Dim, n);
  std::vector<double> radii(static_cast<std::size_t>(n));
  for (Index i = 0; i < n; ++i) {
    for (int d = 0; d < Dim; ++d) centres(d, i) = d == 0 ? u(rng) : 0.1 * u(rng);  // a thin wall-like strip
    radii[static_cast<std::size_t>(i)] = 0.002 * radius_spread[static_cast<std::size_t>(i) % radius_spread.size()];
  }
  radii[5] = 0.0;  // no ball
  const BallCover<Dim> cover(centres, radii);
  const auto inside = [&](const Vec<Dim>& p, double grow) {
    for (Index i = 0; i < n; ++i)
      if (radii[static_cast<std::size_t>(i)] > 0.0 && (p - centres.col(i)).norm() <= radii[static_cast<std::size_t>(i)] + grow) return true;
    return false;
  };
  Index covered_far = 0, far = 0;
  for (int q = 0; q < 4000; ++q) {
    // points near a centre (inside its ball or just outside) and anywhere around the strip
    Vec<Dim> p;
    if (q % 2 == 0) {
      const Index i = static_cast<Index>(q / 2) % n;
      Vec<Dim> direction;
      for (int d = 0; d < Dim; ++d) direction[d] = u(rng) - 0.5;
      p = centres.col(i) + direction.normalized() * radii[static_cast<std::size_t>(i)] * 1.2 * u(rng);
    } else {
      for (int d = 0; d < Dim; ++d) p[d] = 1.4 * u(rng) - 0.2;
    }
    if (inside(p, 0.0)) {
      REQUIRE(cover.contains(p));
    } else if (!inside(p, 0.05)) {
      ++far;
      covered_far += cover.contains(p) ? 1 : 0;
    }
  }
  CHECK(far > 500);
  CHECK(covered_far == 0);
  CHECK(!cover.contains(Vec<Dim>::Constant(5.0)));
}

}  // namespace

TEST_CASE("BallCover: every point of a ball is covered, points far from all balls are not", "[spatial]") {
  check_ball_cover<2>({1.0});
  check_ball_cover<3>({1.0});
  check_ball_cover<2>({0.5, 1.0, 3.0, 14.0});  // the 30P30N's spread of facet sizes
  check_ball_cover<3>({0.5, 1.0, 3.0, 14.0});
}

TEST_CASE("BallCover: no ball covers nothing, bad input is refused", "[spatial]") {
  const Points<2> centres = Points<2>::Zero(2, 2);
  const std::vector<double> none{0.0, -1.0};
  CHECK(!BallCover<2>(centres, none).contains(Vec<2>::Zero()));
  CHECK(!BallCover<2>().contains(Vec<2>::Zero()));
  const std::vector<double> one{1.0};
  CHECK_THROWS_WITH(BallCover<2>(centres, one), Catch::Contains("1 radii for 2 centres"));
  const std::vector<double> nan{1.0, std::nan("")};
  CHECK_THROWS_WITH(BallCover<2>(centres, nan), Catch::Contains("ball 1"));
  // radii over many orders of magnitude: the cover keeps the box and is still never wrong
  Points<2> spread(2, 3);
  spread << 0.0, 1.0, 1000.0, 0.0, 0.0, 0.0;
  const std::vector<double> radii{1e-6, 1e-6, 500.0};
  const BallCover<2> coarse(spread, radii);
  CHECK(coarse.contains(Vec<2>(1.0, 0.0)));
  CHECK(coarse.contains(Vec<2>(700.0, 10.0)));
  CHECK(!coarse.contains(Vec<2>(0.0, 600.0)));
}
