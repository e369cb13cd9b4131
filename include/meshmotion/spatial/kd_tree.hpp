#pragma once
/// \file
/// KdTree<Dim>: a nanoflann (1.4, or 1.5+ with its renamed types) k-d tree over the columns of a Dim × n point matrix, read in
/// place (no copy), with radius and k-nearest queries. Distances returned are squared
/// Euclidean distances, as nanoflann's L2 metric gives them.

#include "meshmotion/core/error.hpp"
#include "meshmotion/core/types.hpp"

#include <nanoflann.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

namespace meshmotion {

/// One neighbour found by a query: point index (column of the indexed matrix) and squared
/// distance to the query point.
#if NANOFLANN_VERSION >= 0x150
// nanoflann 1.5 returns its own (first, second) struct and renamed SearchParams.
using Neighbor = nanoflann::ResultItem<std::size_t, double>;
namespace detail {
using RadiusSearchParameters = nanoflann::SearchParameters;
}
#else
using Neighbor = std::pair<std::size_t, double>;
namespace detail {
using RadiusSearchParameters = nanoflann::SearchParams;
}
#endif

namespace detail {

/// nanoflann dataset adaptor over column-major Dim × n storage it does not own.
template <int Dim>
struct ColumnPointsAdaptor {
  const double* data = nullptr;
  std::size_t count = 0;

  [[nodiscard]] std::size_t kdtree_get_point_count() const { return count; }
  [[nodiscard]] double kdtree_get_pt(std::size_t idx, std::size_t axis) const {
    return data[idx * static_cast<std::size_t>(Dim) + axis];
  }
  template <class BBox>
  bool kdtree_get_bbox(BBox& /*unused*/) const {
    return false;
  }
};

}  // namespace detail

/// Options of a KdTree.
struct KdTreeOptions {
  std::size_t leaf_max_size = 16;  ///< points per leaf: larger builds faster, queries slower
};

/// A static k-d tree over the n columns of a Dim × n point matrix.
///
/// The tree reads the matrix in place: the matrix must outlive the tree and must not be
/// resized or modified while the tree is used (rebuild after moving the points). Queries are
/// const and thread-safe. Movable, not copyable.
template <int Dim>
class KdTree {
  using Adaptor = detail::ColumnPointsAdaptor<Dim>;
  using Tree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Adaptor<double, Adaptor>, Adaptor, Dim,
                                                   std::size_t>;

 public:
  KdTree() = default;

  /// Builds the tree over `points` (Dim × n; n may be 0). Throws InputError on a non-finite
  /// coordinate.
  explicit KdTree(const Points<Dim>& points, KdTreeOptions options = {}) { build(points, options); }
  /// Same, over any column-major Dim × n storage (an Eigen::Map, a solver's array).
  KdTree(const double* data, Index n, KdTreeOptions options = {}) { build(data, n, options); }

  void build(const Points<Dim>& points, KdTreeOptions options = {}) {
    build(points.data(), points.cols(), options);
  }
  void build(const double* data, Index n, KdTreeOptions options = {}) {
    if (n < 0) throw InputError("KdTree::build: negative point count (got " + std::to_string(n) + ")");
    for (Index k = 0; k < n * Dim; ++k)
      if (!std::isfinite(data[k]))
        throw InputError("KdTree::build: point " + std::to_string(k / Dim) + " has a non-finite coordinate");
    lower_.setConstant(std::numeric_limits<double>::infinity());
    upper_.setConstant(-std::numeric_limits<double>::infinity());
    for (Index k = 0; k < n; ++k) {
      const Eigen::Map<const Vec<Dim>> p(data + k * Dim);
      lower_ = lower_.cwiseMin(p);
      upper_ = upper_.cwiseMax(p);
    }
    adaptor_ = std::make_unique<Adaptor>(Adaptor{data, static_cast<std::size_t>(n)});
    tree_ = std::make_unique<Tree>(Dim, *adaptor_, nanoflann::KDTreeSingleIndexAdaptorParams(options.leaf_max_size));
    if (n > 0) tree_->buildIndex();
  }

  /// Number of indexed points.
  [[nodiscard]] Index size() const noexcept { return adaptor_ ? static_cast<Index>(adaptor_->count) : 0; }

  /// All points strictly closer than `radius` to `query`, written to `out` (cleared first) as
  /// (index, squared distance), sorted by distance when `sorted`. Returns their number.
  /// Reusing `out` across queries avoids allocation.
  Index radius_search(const Vec<Dim>& query, double radius, std::vector<Neighbor>& out, bool sorted = false) const {
    out.clear();
    // A query farther than `radius` from the points' bounding box finds nothing: most nodes of
    // a mesh asking for centres on a small wall. nanoflann would still descend to a leaf.
    if (size() == 0 || box_squared_distance(query) >= radius * radius) return 0;
    detail::RadiusSearchParameters params;
    params.sorted = sorted;
    return static_cast<Index>(tree_->radiusSearch(query.data(), radius * radius, out, params));
  }
  [[nodiscard]] std::vector<Neighbor> radius_search(const Vec<Dim>& query, double radius, bool sorted = true) const {
    std::vector<Neighbor> out;
    radius_search(query, radius, out, sorted);
    return out;
  }

  /// Squared distance from `query` to the points' bounding box: 0 inside it, a lower bound of
  /// every point's squared distance, infinite for an empty tree. A cheap rejection test.
  [[nodiscard]] double box_squared_distance(const Vec<Dim>& query) const {
    return (lower_ - query).cwiseMax(query - upper_).cwiseMax(0.0).squaredNorm();
  }
  /// The k nearest points to `query`, nearest first, as (index, squared distance); fewer when
  /// the tree holds fewer than k points.
  [[nodiscard]] std::vector<Neighbor> nearest(const Vec<Dim>& query, Index k) const {
    std::vector<Neighbor> out;
    if (size() == 0 || k <= 0) return out;
    const auto count = static_cast<std::size_t>(std::min(k, size()));
    std::vector<std::size_t> indices(count);
    std::vector<double> distances(count);
    const std::size_t found = tree_->knnSearch(query.data(), count, indices.data(), distances.data());
    out.reserve(found);
    for (std::size_t i = 0; i < found; ++i) out.emplace_back(indices[i], distances[i]);
    return out;
  }

  /// Most neighbours one nearest_within() call returns.
  static constexpr std::size_t max_within = 16;

  /// The out.size() (at most max_within) nearest points strictly closer than `radius` to
  /// `query`, nearest first, written to the front of `out`; returns their number. The search is
  /// pruned by the radius from its start and allocates nothing: points at about one distance
  /// all around the query (a farfield circle seen from inside it) make an unpruned search visit
  /// nearly every one of them. An infinite radius gives the plain k nearest.
  Index nearest_within(const Vec<Dim>& query, double radius, std::span<Neighbor> out) const {
    if (out.size() > max_within)
      throw InputError("KdTree::nearest_within: " + std::to_string(out.size()) + " neighbours asked (at most " +
                       std::to_string(max_within) + ")");
    if (out.empty() || size() == 0 || box_squared_distance(query) >= radius * radius) return 0;
    std::array<std::size_t, max_within> indices{};
    std::array<double, max_within> distances{};
    nanoflann::KNNResultSet<double, std::size_t, std::size_t> result(out.size());
    result.init(indices.data(), distances.data());
    distances[out.size() - 1] = radius * radius;  // the worst distance the search accepts
    tree_->findNeighbors(result, query.data(), detail::RadiusSearchParameters{});
    for (std::size_t i = 0; i < result.size(); ++i) out[i] = Neighbor{indices[i], distances[i]};
    return static_cast<Index>(result.size());
  }
  /// The nearest point strictly closer than `radius` to `query`, or none.
  [[nodiscard]] std::optional<Neighbor> nearest_within(const Vec<Dim>& query, double radius) const {
    Neighbor found{};
    if (nearest_within(query, radius, std::span<Neighbor>(&found, 1)) == 0) return std::nullopt;
    return found;
  }

  /// The nearest point to `query` as (index, squared distance). Throws InputError on an empty tree.
  [[nodiscard]] Neighbor nearest(const Vec<Dim>& query) const {
    if (size() == 0) throw InputError("KdTree::nearest: the tree is empty");
    std::size_t index = 0;
    double distance = 0.0;
    tree_->knnSearch(query.data(), 1, &index, &distance);
    return {index, distance};
  }

 private:
  std::unique_ptr<Adaptor> adaptor_;
  std::unique_ptr<Tree> tree_;
  // Bounding box of the points (empty: lower above upper).
  Vec<Dim> lower_ = Vec<Dim>::Constant(std::numeric_limits<double>::infinity());
  Vec<Dim> upper_ = Vec<Dim>::Constant(-std::numeric_limits<double>::infinity());
};

}  // namespace meshmotion
