#pragma once
/// \file
/// delaunay(): Bowyer–Watson Delaunay triangulation (2D) and tetrahedralization (3D) of a
/// point set, thesis appendix A (see detail/bowyer_watson_kernel.hpp for the kernel and its
/// departures from the appendix).

#include "meshmotion/core/error.hpp"
#include "meshmotion/core/types.hpp"
#include "meshmotion/delaunay/delaunay_triangulation.hpp"
#include "meshmotion/delaunay/detail/bowyer_watson_kernel.hpp"
#include "meshmotion/delaunay/detail/spatial_sort.hpp"
#include "meshmotion/delaunay/predicates.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <string>
#include <vector>

namespace meshmotion {

/// Options of delaunay().
struct DelaunayOptions {
  /// Insert in a biased randomized order with Hilbert-sorted rounds (fast); false inserts in
  /// input order (quadratic worst case, for tests).
  bool spatial_sort = true;
  /// Seed of the insertion order and of the stochastic walk: the result is deterministic for
  /// a given seed (and unique up to co-circular/co-spherical ties).
  std::uint64_t seed = 20240607;
};

namespace detail {

/// Moves to the front of `order` the first Dim + 1 affinely independent points it meets.
/// Returns false when there are none (all points collinear in 2D / coplanar in 3D).
template <int Dim>
[[nodiscard]] bool move_first_simplex_to_front(const Points<Dim>& points,
                                               std::vector<Index>& order) {
  std::vector<std::size_t> chosen{0};
  auto p = [&](std::size_t k) { return points.col(order[k]).data(); };
  auto independent = [&](std::size_t k) {
    if (chosen.size() == 1) {
      return !std::equal(p(k), p(k) + Dim, p(chosen[0]));
    }
    if (chosen.size() == 2) {
      if constexpr (Dim == 2) {
        return orient2d(p(chosen[0]), p(chosen[1]), p(k)) != 0;
      } else {
        // Collinear in 3D iff collinear in all three coordinate-plane projections.
        for (int axis = 0; axis < 3; ++axis) {
          double a[2], b[2], c[2];
          for (int m = 0; m < 2; ++m) {
            const int d = (axis + 1 + m) % 3;
            a[m] = p(chosen[0])[d];
            b[m] = p(chosen[1])[d];
            c[m] = p(k)[d];
          }
          if (orient2d(a, b, c) != 0) return true;
        }
        return false;
      }
    }
    if constexpr (Dim == 3) {
      return orient3d(p(chosen[0]), p(chosen[1]), p(chosen[2]), p(k)) != 0;
    }
    return false;
  };
  for (std::size_t k = 1; k < order.size() && chosen.size() < Dim + 1; ++k) {
    if (independent(k)) chosen.push_back(k);
  }
  if (chosen.size() < Dim + 1) return false;
  std::vector<Index> front;
  for (std::size_t k : chosen) front.push_back(order[k]);
  for (auto it = chosen.rbegin(); it != chosen.rend(); ++it) {
    order.erase(order.begin() + static_cast<std::ptrdiff_t>(*it));
  }
  order.insert(order.begin(), front.begin(), front.end());
  return true;
}

/// The exponent e such that scaling the points by 2^-e brings the largest coordinate near 1,
/// or 0 when no scaling is needed (|e| <= 64) or when it would not be exact (a coordinate
/// would underflow).
template <int Dim>
[[nodiscard]] int safe_scale_exponent(const Points<Dim>& points) {
  const double largest = points.cwiseAbs().maxCoeff();
  if (largest == 0.0) return 0;
  const int exponent = std::ilogb(largest);
  if (exponent >= -64 && exponent <= 64) return 0;
  for (Index i = 0; i < points.size(); ++i) {
    const double x = points.data()[i];
    if (std::ldexp(std::ldexp(x, -exponent), exponent) != x) return 0;
  }
  return exponent;
}

}  // namespace detail

/// Delaunay triangulation (Dim = 2, triangles) or tetrahedralization (Dim = 3) of `points`
/// (Dim × n, a column per point) by Bowyer–Watson insertion, thesis appendix A.
///
/// The result is exactly Delaunay for the given coordinates (exact predicates): no point is
/// strictly inside any simplex's circumcircle/circumsphere, the simplices cover the convex
/// hull and are positively oriented. Points with equal coordinates are triangulated once:
/// the lowest input index of each group is the vertex, and represents the others
/// (DelaunayTriangulation::representative).
/// Coordinates of any magnitude are handled (an exact power-of-two rescaling guards the
/// predicates against overflow). Expected cost O(n log n); see benchmarks/delaunay_bench.cpp.
///
/// Throws InputError when a coordinate is not finite, when there are fewer than Dim + 1
/// distinct points, or when all points are collinear (2D) / coplanar (3D).
template <int Dim>
[[nodiscard]] DelaunayTriangulation<Dim> delaunay(const Points<Dim>& points,
                                                  const DelaunayOptions& options = {}) {
  static_assert(Dim == 2 || Dim == 3, "delaunay: Dim must be 2 or 3");
  using Id = typename detail::BowyerWatsonKernel<Dim>::Id;
  const Index n = points.cols();
  const std::string where = "delaunay<" + std::to_string(Dim) + ">";
  if (n < Dim + 1) {
    throw InputError(where + ": too few points (got " + std::to_string(n) + ", expected at least " +
                     std::to_string(Dim + 1) + ")");
  }
  if (n >= std::numeric_limits<Id>::max() / 8) {
    throw InputError(where + ": too many points for 32-bit simplex indices (got " +
                     std::to_string(n) + ")");
  }
  for (Index i = 0; i < n; ++i) {
    if (!points.col(i).allFinite()) {
      throw InputError(where + ": point " + std::to_string(i) +
                       " has a non-finite coordinate (expected finite coordinates)");
    }
  }
  // Very large or very small coordinates are scaled by a power of two, which is exact and
  // keeps every predicate's sign, so that the predicates' products cannot overflow/underflow.
  const int exponent = detail::safe_scale_exponent(points);
  Points<Dim> rescaled;
  if (exponent != 0) {
    rescaled = points.unaryExpr([&](double x) { return std::ldexp(x, -exponent); });
  }
  const Points<Dim>& work = exponent != 0 ? rescaled : points;
  std::vector<Index> order;
  if (options.spatial_sort) {
    order = detail::brio_order<Dim>(work, options.seed);
  } else {
    order.resize(static_cast<std::size_t>(n));
    std::iota(order.begin(), order.end(), Index{0});
  }
  if (!detail::move_first_simplex_to_front<Dim>(work, order)) {
    throw InputError(where + ": all " + std::to_string(n) + " points are " +
                     (Dim == 2 ? "collinear" : "coplanar") + " (expected at least " +
                     std::to_string(Dim + 1) + " affinely independent points)");
  }
  // Coordinates in insertion order: the kernel then reads memory in the order it walks.
  std::vector<double> sorted(static_cast<std::size_t>(n) * Dim);
  for (Index k = 0; k < n; ++k) {
    for (int d = 0; d < Dim; ++d) sorted[static_cast<std::size_t>(k) * Dim + d] = work(d, order[k]);
  }
  detail::BowyerWatsonKernel<Dim> kernel(sorted.data(), static_cast<Id>(n), options.seed);
  kernel.run();

  std::vector<Index> output_index(static_cast<std::size_t>(kernel.num_slots()), -1);
  Index n_simplices = 0;
  for (Id s = 0; s < kernel.num_slots(); ++s) {
    if (!kernel.is_dead(s) && !kernel.is_ghost(s)) output_index[s] = n_simplices++;
  }
  typename DelaunayTriangulation<Dim>::SimplexArray simplices(Dim + 1, n_simplices);
  typename DelaunayTriangulation<Dim>::SimplexArray neighbours(Dim + 1, n_simplices);
  for (Id s = 0; s < kernel.num_slots(); ++s) {
    const Index out = output_index[s];
    if (out < 0) continue;
    for (int j = 0; j <= Dim; ++j) {
      simplices(j, out) = order[kernel.vertex(s, j)];
      neighbours(j, out) = output_index[kernel.neighbour(s, j)];
    }
  }
  // Each group of equal points is represented by its lowest input index.
  std::vector<Index> representatives(static_cast<std::size_t>(n));
  std::vector<Index> lowest(static_cast<std::size_t>(n));
  for (Index k = 0; k < n; ++k) {
    representatives[order[k]] = order[kernel.representative(static_cast<Id>(k))];
    lowest[order[k]] = order[k];
  }
  for (Index i = 0; i < n; ++i) {
    Index& low = lowest[representatives[i]];
    low = std::min(low, i);
  }
  for (Index i = 0; i < n; ++i) representatives[i] = lowest[representatives[i]];
  for (Index s = 0; s < n_simplices; ++s) {
    for (int j = 0; j <= Dim; ++j) simplices(j, s) = representatives[simplices(j, s)];
  }
  return DelaunayTriangulation<Dim>(points, std::move(simplices), std::move(neighbours),
                                    std::move(representatives));
}

}  // namespace meshmotion
