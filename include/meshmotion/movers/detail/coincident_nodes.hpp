#pragma once
/// \file
/// Detection of coincident boundary nodes (periodic seams, groups sharing corners), which make
/// an RBF matrix singular: they are merged into one centre.

#include "meshmotion/core/types.hpp"
#include "meshmotion/spatial/kd_tree.hpp"

#include <vector>

namespace meshmotion::detail {

/// For each of the m columns of `points`, the lowest-numbered column within `tolerance`
/// of it (itself when none), following chains so that every group has one representative.
template <int Dim>
[[nodiscard]] std::vector<Index> coincident_representatives(const Points<Dim>& points, double tolerance) {
  const Index m = points.cols();
  std::vector<Index> rep(static_cast<std::size_t>(m));
  for (Index i = 0; i < m; ++i) rep[static_cast<std::size_t>(i)] = i;
  if (m == 0) return rep;
  const KdTree<Dim> tree(points);
  std::vector<Neighbor> found;
  for (Index i = 0; i < m; ++i) {
    tree.radius_search(points.col(i), tolerance, found);
    for (const auto& [j, d2] : found) {
      auto& r = rep[static_cast<std::size_t>(i)];
      r = std::min(r, rep[j]);
    }
  }
  for (Index i = 0; i < m; ++i) rep[static_cast<std::size_t>(i)] = rep[static_cast<std::size_t>(rep[static_cast<std::size_t>(i)])];
  return rep;
}

}  // namespace meshmotion::detail
