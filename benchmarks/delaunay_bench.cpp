// Delaunay triangulation (2D) and tetrahedralization (3D) of uniformly random points, and of
// regular grids (massively co-circular/co-spherical: exact predicates decide most tests):
// seconds and points per second for meshmotion::delaunay, with CGAL's Delaunay_triangulation_2/3
// (Epick kernel, range insertion with its own spatial sort) on the same points in the same run
// as the reference when CGAL is installed. Also times locate() of as many random queries,
// each hinted with the previous answer after a Hilbert sort (the DGM access pattern).
// Usage: delaunay_bench [n ...]   (default 100000 1000000; 3D grids have n/10 points)

#include "bench_memory.hpp"
#include "meshmotion/delaunay.hpp"
#include "meshmotion/delaunay/detail/spatial_sort.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#if __has_include(<CGAL/Delaunay_triangulation_2.h>) && defined(MESHMOTION_BENCH_HAVE_CGAL)
#define MESHMOTION_BENCH_CGAL 1
#include <CGAL/Delaunay_triangulation_2.h>
#include <CGAL/Delaunay_triangulation_3.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#endif

using namespace meshmotion;

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

template <int Dim>
Points<Dim> random_points(Index n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Points<Dim> p(Dim, n);
  for (Index i = 0; i < n; ++i) {
    for (int d = 0; d < Dim; ++d) p(d, i) = u(rng);
  }
  return p;
}

/// CGAL's time on the same points, or a negative value when CGAL is absent.
template <int Dim>
double cgal_seconds(const Points<Dim>& points, std::size_t& n_cells) {
#ifdef MESHMOTION_BENCH_CGAL
  using K = CGAL::Exact_predicates_inexact_constructions_kernel;
  if constexpr (Dim == 2) {
    std::vector<K::Point_2> pts;
    pts.reserve(static_cast<std::size_t>(points.cols()));
    for (Index i = 0; i < points.cols(); ++i) pts.emplace_back(points(0, i), points(1, i));
    const auto start = Clock::now();
    CGAL::Delaunay_triangulation_2<K> dt(pts.begin(), pts.end());
    const double t = seconds_since(start);
    n_cells = dt.number_of_faces();
    return t;
  } else {
    std::vector<K::Point_3> pts;
    pts.reserve(static_cast<std::size_t>(points.cols()));
    for (Index i = 0; i < points.cols(); ++i) {
      pts.emplace_back(points(0, i), points(1, i), points(2, i));
    }
    const auto start = Clock::now();
    CGAL::Delaunay_triangulation_3<K> dt(pts.begin(), pts.end());
    const double t = seconds_since(start);
    n_cells = dt.number_of_finite_cells();
    return t;
  }
#else
  (void)points;
  n_cells = 0;
  return -1.0;
#endif
}

/// About n points on a regular grid of spacing 0.1 (not a power of two: not dyadic).
template <int Dim>
Points<Dim> grid_points(Index n) {
  const auto m = static_cast<Index>(std::round(std::pow(static_cast<double>(n), 1.0 / Dim)));
  const Index total = Dim == 2 ? m * m : m * m * m;
  Points<Dim> p(Dim, total);
  for (Index i = 0; i < total; ++i) {
    Index rest = i;
    for (int d = 0; d < Dim; ++d) {
      p(d, i) = 0.1 * static_cast<double>(rest % m);
      rest /= m;
    }
  }
  return p;
}

template <int Dim>
void run(const std::string& kind, const Points<Dim>& points) {
  const Index n = points.cols();
  auto start = Clock::now();
  const DelaunayTriangulation<Dim> dt = delaunay<Dim>(points);
  const double ours = seconds_since(start);

  // Locate as many random queries in Hilbert order, each hinted by the previous answer.
  const Points<Dim> queries = random_points<Dim>(n, 7 + Dim);
  const std::vector<Index> order = detail::brio_order<Dim>(queries, 1, queries.cols());
  start = Clock::now();
  Index hint = -1;
  double checksum = 0.0;
  for (Index q : order) {
    const LocateResult<Dim> r = dt.locate(queries.col(q), hint);
    hint = r.simplex;
    checksum += r.barycentric(0);
  }
  const double locate = seconds_since(start);

  std::size_t cgal_cells = 0;
  const double cgal = cgal_seconds<Dim>(points, cgal_cells);
  const double ratio = cgal > 0.0 ? ours / cgal : -1.0;
  std::printf("%-6s %dD %9lld points  %8.3f s  %8.2e points/s  %9lld simplices  locate %7.3f s",
              kind.c_str(), Dim, static_cast<long long>(n), ours, static_cast<double>(n) / ours,
              static_cast<long long>(dt.num_simplices()), locate);
  if (cgal > 0.0) {
    std::printf("  | CGAL %8.3f s (%zu cells)  ours/CGAL %.2f\n", cgal, cgal_cells, ratio);
  } else {
    std::printf("  | CGAL not available\n");
  }
  std::printf(
      "{\"benchmark\":\"delaunay\",\"input\":\"%s\",\"dim\":%d,\"points\":%lld,\"seconds\":%.6f,"
      "\"points_per_second\":%.1f,\"simplices\":%lld,\"locate_seconds\":%.6f,"
      "\"cgal_seconds\":%.6f,\"cgal_cells\":%zu,\"ratio_to_cgal\":%.4f,\"checksum\":%.6g}\n",
      kind.c_str(), Dim, static_cast<long long>(n), ours, static_cast<double>(n) / ours,
      static_cast<long long>(dt.num_simplices()), locate, cgal, cgal_cells, ratio, checksum);
}

}  // namespace

int main(int argc, char** argv) {
  bench::tune_memory(argc, argv);
  std::vector<Index> sizes;
  for (int a = 1; a < argc; ++a) sizes.push_back(std::atoll(argv[a]));
  if (sizes.empty()) sizes = {100000, 1000000};
  std::printf(
      "Delaunay of random points in the unit box and of regular grids (no thesis figure; CGAL "
      "is the reference, target ratio <= 2)\n");
  for (Index n : sizes) {
    run<2>("random", random_points<2>(n, 44));
    run<3>("random", random_points<3>(n, 45));
  }
  for (Index n : sizes) {
    run<2>("grid", grid_points<2>(n));
    run<3>("grid", grid_points<3>(n / 10));  // 3D grids: co-spherical cubes are slow for all
  }
  return 0;
}
