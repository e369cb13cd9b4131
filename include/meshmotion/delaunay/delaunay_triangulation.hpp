#pragma once
/// \file
/// The result of delaunay(): simplices, their neighbours, duplicate-point bookkeeping and
/// point location with barycentric coordinates (the query of the Delaunay graph mapping,
/// thesis section 2.2.1).

#include "meshmotion/core/error.hpp"
#include "meshmotion/core/types.hpp"
#include "meshmotion/delaunay/detail/bowyer_watson_kernel.hpp"

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>
#include <vector>

namespace meshmotion {

/// Where a point lies in a triangulation.
template <int Dim>
struct LocateResult {
  /// The containing simplex; for a point outside the convex hull, the simplex with a hull
  /// facet nearest to the point.
  Index simplex = -1;
  /// Barycentric coordinates with respect to the simplex's vertices (in the order of the
  /// simplex's column); they sum to 1 and reproduce the point. Some are negative when
  /// `outside` (extrapolation).
  Eigen::Matrix<double, Dim + 1, 1> barycentric = Eigen::Matrix<double, Dim + 1, 1>::Zero();
  /// The point is strictly outside the convex hull of the triangulated points.
  bool outside = false;
};

namespace detail {

/// Determinant of a 2×2 or 3×3 matrix (without pulling in Eigen's LU module).
template <int Dim>
[[nodiscard]] inline double small_determinant(const Eigen::Matrix<double, Dim, Dim>& m) {
  if constexpr (Dim == 2) {
    return m(0, 0) * m(1, 1) - m(0, 1) * m(1, 0);
  } else {
    return m(0, 0) * (m(1, 1) * m(2, 2) - m(1, 2) * m(2, 1)) -
           m(0, 1) * (m(1, 0) * m(2, 2) - m(1, 2) * m(2, 0)) +
           m(0, 2) * (m(1, 0) * m(2, 1) - m(1, 1) * m(2, 0));
  }
}

}  // namespace detail

/// Barycentric coordinates of q in the simplex with vertex columns `corners` (Dim × Dim+1),
/// by Cramer's rule on the edge vectors from vertex 0; they sum to 1 and reproduce q up to
/// rounding. Precondition: a non-degenerate simplex.
template <int Dim>
[[nodiscard]] Eigen::Matrix<double, Dim + 1, 1> barycentric_coordinates(
    const Eigen::Matrix<double, Dim, Dim + 1>& corners, const Vec<Dim>& q) {
  Eigen::Matrix<double, Dim, Dim> edges;
  for (int k = 0; k < Dim; ++k) edges.col(k) = corners.col(k + 1) - corners.col(0);
  const double volume = detail::small_determinant<Dim>(edges);
  const Vec<Dim> relative = q - corners.col(0);
  Eigen::Matrix<double, Dim + 1, 1> lambda;
  for (int k = 0; k < Dim; ++k) {
    Eigen::Matrix<double, Dim, Dim> replaced = edges;
    replaced.col(k) = relative;
    lambda(k + 1) = detail::small_determinant<Dim>(replaced) / volume;
  }
  lambda(0) = 1.0 - lambda.template tail<Dim>().sum();
  return lambda;
}

/// A Delaunay triangulation (Dim = 2) or tetrahedralization (Dim = 3) of a point set.
template <int Dim>
class DelaunayTriangulation {
 public:
  static constexpr int corners = Dim + 1;
  /// (Dim+1) × n_simplices vertex indices, or neighbour indices.
  using SimplexArray = Eigen::Matrix<Index, Dim + 1, Eigen::Dynamic>;

  /// Built by delaunay(); `simplices` must be positively oriented, `neighbours(j, s)` is the
  /// simplex across the facet opposite vertex j of s (-1 on the convex hull), and
  /// `representatives[i]` is the input point that point i duplicates (i when unique).
  DelaunayTriangulation(Points<Dim> points, SimplexArray simplices, SimplexArray neighbours,
                        std::vector<Index> representatives)
      : points_(std::move(points)),
        simplices_(std::move(simplices)),
        neighbours_(std::move(neighbours)),
        representatives_(std::move(representatives)),
        vertex_simplex_(static_cast<std::size_t>(points_.cols()), -1) {
    for (Index s = 0; s < simplices_.cols(); ++s) {
      for (int j = 0; j < corners; ++j) {
        vertex_simplex_[static_cast<std::size_t>(simplices_(j, s))] = s;
        if (neighbours_(j, s) < 0) hull_facets_.emplace_back(s, j);
      }
    }
    for (std::size_t i = 0; i < representatives_.size(); ++i) {
      if (representatives_[i] != static_cast<Index>(i)) ++num_duplicates_;
    }
  }

  /// The input points, Dim × n_points (duplicates included).
  [[nodiscard]] const Points<Dim>& points() const noexcept { return points_; }
  /// Vertex indices into points(), (Dim+1) × n_simplices, each column positively oriented.
  [[nodiscard]] const SimplexArray& simplices() const noexcept { return simplices_; }
  /// neighbours()(j, s): the simplex sharing the facet opposite vertex j of s, or -1.
  [[nodiscard]] const SimplexArray& neighbours() const noexcept { return neighbours_; }
  [[nodiscard]] Index num_simplices() const noexcept { return simplices_.cols(); }
  /// The point that input point i duplicates (equal coordinates), or i for a unique point.
  /// Every representative is a vertex of the triangulation, every duplicate is not.
  [[nodiscard]] Index representative(Index i) const {
    return representatives_[static_cast<std::size_t>(i)];
  }
  [[nodiscard]] Index num_duplicates() const noexcept { return num_duplicates_; }
  /// A simplex having vertex representative(i) (a good locate() hint near point i).
  [[nodiscard]] Index vertex_simplex(Index i) const {
    return vertex_simplex_[static_cast<std::size_t>(representative(i))];
  }
  /// Convex-hull facets as (simplex, local index of the opposite vertex).
  [[nodiscard]] const std::vector<std::pair<Index, int>>& hull_facets() const noexcept {
    return hull_facets_;
  }

  /// Vertex columns of simplex s, Dim × (Dim+1).
  [[nodiscard]] Eigen::Matrix<double, Dim, Dim + 1> corner_points(Index s) const {
    Eigen::Matrix<double, Dim, Dim + 1> c;
    for (int j = 0; j < corners; ++j) c.col(j) = points_.col(simplices_(j, s));
    return c;
  }

  /// Locates q by a visibility walk (exact orientation tests) from `hint` (a simplex index;
  /// -1 or out of range starts from simplex 0). Outside the convex hull, returns the simplex
  /// whose hull facet is nearest to q, flagged `outside`, with extrapolating barycentric
  /// coordinates (found by a scan of the hull facets: an outside query costs O(hull size)).
  /// The exact orientation tests assume coordinates of magnitude between about 1e-60 and 1e60
  /// (no overflow in their products). Throws InputError for a non-finite q.
  [[nodiscard]] LocateResult<Dim> locate(const Vec<Dim>& q, Index hint = -1) const {
    if (!q.allFinite()) {
      throw InputError("DelaunayTriangulation::locate: point has a non-finite coordinate");
    }
    LocateResult<Dim> result;
    Index s = (hint >= 0 && hint < num_simplices()) ? hint : 0;
    Index previous = -1;
    std::uint64_t state = 0x9E3779B97F4A7C15ull ^ static_cast<std::uint64_t>(s);
    const Index max_steps = 64 + 4 * num_simplices();
    bool found = false;
    for (Index step = 0; step < max_steps && !found; ++step) {
      state ^= state << 13;
      state ^= state >> 7;
      state ^= state << 17;
      const int start = static_cast<int>(state % corners);
      Index next = -1;
      bool leaves_hull = false;
      for (int k = 0; k < corners; ++k) {
        const int j = (start + k) % corners;
        const Index across = neighbours_(j, s);
        if (across == previous && across >= 0) continue;
        if (orientation_with(s, j, q) < 0) {
          next = across;
          leaves_hull = across < 0;
          break;
        }
      }
      if (leaves_hull) {
        result.outside = true;
        s = nearest_hull_simplex(q);
        found = true;
      } else if (next < 0) {
        found = true;
      } else {
        previous = s;
        s = next;
      }
    }
    if (!found) s = locate_exhaustively(q, result.outside);
    if (flat(s)) s = solid_simplex_near(s, q);
    result.simplex = s;
    result.barycentric = barycentric_coordinates<Dim>(corner_points(s), q);
    return result;
  }

 private:
  [[nodiscard]] int orientation_with(Index s, int j, const Vec<Dim>& q) const {
    const double* p[corners];
    for (int k = 0; k < corners; ++k) {
      p[k] = k == j ? q.data() : points_.col(simplices_(k, s)).data();
    }
    return detail::orientation<Dim>(p);
  }

  [[nodiscard]] Index locate_exhaustively(const Vec<Dim>& q, bool& outside) const {
    for (Index s = 0; s < num_simplices(); ++s) {
      bool inside = true;
      for (int j = 0; j < corners && inside; ++j) inside = orientation_with(s, j, q) >= 0;
      if (inside) return s;
    }
    outside = true;
    return nearest_hull_simplex(q);
  }

  /// Whether simplex s is flat to rounding: Dim! × its volume below 1e-8 × its longest edge to
  /// the power Dim. Nodes on a plane that is not aligned with the axes are coplanar only to
  /// rounding, and the exact predicates close the hull over them with slivers that thin: the
  /// barycentric coordinates of a point in one are rounding noise, or 0/0 (a tilted symmetry
  /// plane gave NaN coordinates for a zero displacement).
  [[nodiscard]] bool flat(Index s) const {
    const Eigen::Matrix<double, Dim, Dim + 1> c = corner_points(s);
    Eigen::Matrix<double, Dim, Dim> edges;
    double longest = 0.0;
    for (int k = 0; k < Dim; ++k) edges.col(k) = c.col(k + 1) - c.col(0);
    for (int a = 0; a < corners; ++a)
      for (int b = a + 1; b < corners; ++b) longest = std::max(longest, (c.col(a) - c.col(b)).norm());
    return !(std::abs(detail::small_determinant<Dim>(edges)) > 1e-8 * std::pow(longest, Dim));
  }

  /// From the flat simplex s, the simplex that is not flat, among the 256 nearest to s through
  /// their neighbours, in which q's smallest barycentric coordinate is largest (q inside it
  /// when it lies inside any of them); s when all are flat.
  [[nodiscard]] Index solid_simplex_near(Index s, const Vec<Dim>& q) const {
    std::vector<Index> seen{s};
    Index best = s;
    double best_lowest = -std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < seen.size() && seen.size() < 256; ++i) {
      for (int j = 0; j < corners; ++j) {
        const Index next = neighbours_(j, seen[i]);
        if (next < 0 || std::find(seen.begin(), seen.end(), next) != seen.end()) continue;
        seen.push_back(next);
        if (flat(next)) continue;
        const double lowest = barycentric_coordinates<Dim>(corner_points(next), q).minCoeff();
        if (lowest > best_lowest) {
          best_lowest = lowest;
          best = next;
        }
      }
    }
    return best;
  }

  /// Distance from q to the hull facet opposite vertex j of s.
  [[nodiscard]] double facet_distance(Index s, int j, const Vec<Dim>& q) const {
    Vec<Dim> c[Dim];
    for (int k = 0, m = 0; k < corners; ++k) {
      if (k != j) c[m++] = points_.col(simplices_(k, s));
    }
    if constexpr (Dim == 2) {
      const Vec<2> e = c[1] - c[0];
      const double t = std::clamp(e.dot(q - c[0]) / e.squaredNorm(), 0.0, 1.0);
      return (c[0] + t * e - q).norm();
    } else {
      return (closest_on_triangle(q, c[0], c[1], c[2]) - q).norm();
    }
  }

  /// Closest point to p on triangle abc (Ericson, Real-Time Collision Detection, 5.1.5).
  [[nodiscard]] static Vec<3> closest_on_triangle(const Vec<3>& p, const Vec<3>& a, const Vec<3>& b,
                                                  const Vec<3>& c) {
    const Vec<3> ab = b - a, ac = c - a, ap = p - a;
    const double d1 = ab.dot(ap), d2 = ac.dot(ap);
    if (d1 <= 0.0 && d2 <= 0.0) return a;
    const Vec<3> bp = p - b;
    const double d3 = ab.dot(bp), d4 = ac.dot(bp);
    if (d3 >= 0.0 && d4 <= d3) return b;
    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) return a + d1 / (d1 - d3) * ab;
    const Vec<3> cp = p - c;
    const double d5 = ab.dot(cp), d6 = ac.dot(cp);
    if (d6 >= 0.0 && d5 <= d6) return c;
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) return a + d2 / (d2 - d6) * ac;
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
      return b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b);
    }
    const double denominator = 1.0 / (va + vb + vc);
    return a + ab * (vb * denominator) + ac * (vc * denominator);
  }

  [[nodiscard]] Index nearest_hull_simplex(const Vec<Dim>& q) const {
    Index best = -1;
    double best_distance = std::numeric_limits<double>::infinity();
    for (const auto& [s, j] : hull_facets_) {
      const double d = facet_distance(s, j, q);
      if (d < best_distance) {
        best_distance = d;
        best = s;
      }
    }
    return best;
  }

  Points<Dim> points_;
  SimplexArray simplices_;
  SimplexArray neighbours_;
  std::vector<Index> representatives_;
  std::vector<Index> vertex_simplex_;
  std::vector<std::pair<Index, int>> hull_facets_;
  Index num_duplicates_ = 0;
};

}  // namespace meshmotion
