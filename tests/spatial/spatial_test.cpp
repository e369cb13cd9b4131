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
