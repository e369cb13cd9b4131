#pragma once
/// \file
/// Distance from a point to a set of straight boundary facets (a wall), with the facet and
/// the reference coordinates of the closest point, so that a field given at the facet's
/// nodes (P1 or P2) can be interpolated there. Shared by the boundary-layer estimate and the
/// blending regularizer.
///
/// Candidate facets are those incident to the `candidates` wall vertices nearest to the
/// query (k-d tree): exact for every point whose closest facet has one of those vertices,
/// which holds for all but strongly curved walls sampled far coarser than their distance.

#include "meshmotion/core/element.hpp"
#include "meshmotion/core/error.hpp"
#include "meshmotion/core/mesh.hpp"
#include "meshmotion/core/shape_functions.hpp"
#include "meshmotion/core/types.hpp"
#include "meshmotion/spatial/kd_tree.hpp"

#include <Eigen/Cholesky>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <tuple>
#include <unordered_map>
#include <utility>
#include <vector>

namespace meshmotion::detail {

/// One wall facet: its element type (line2/3, tri3/6, quad4/8/9) and all its nodes.
struct WallFacet {
  ElementType type = ElementType::line2;
  std::array<Index, max_facet_nodes> nodes{};
};

/// The wall facets of the groups tagged `tags` (facet blocks of a mesh).
template <int Dim>
[[nodiscard]] std::vector<WallFacet> wall_facets(const Mesh<Dim>& mesh, std::span<const int> tags) {
  std::vector<WallFacet> out;
  for (const auto& block : mesh.facets)
    for (Index e = 0; e < block.size(); ++e) {
      if (std::find(tags.begin(), tags.end(), block.tags[static_cast<std::size_t>(e)]) == tags.end()) continue;
      WallFacet f{block.type, {}};
      const auto el = block.element(e);
      std::copy(el.begin(), el.end(), f.nodes.begin());
      out.push_back(f);
    }
  return out;
}

/// For each facet of a wall, the direction from its centroid to that of the cell holding it
/// (zero when no cell holds it).
template <int Dim>
[[nodiscard]] std::vector<Vec<Dim>> inward_directions(const Mesh<Dim>& mesh, const std::vector<WallFacet>& wall) {
  std::unordered_map<Index, std::vector<std::pair<std::size_t, Index>>> cells_at;  // wall vertex -> (block, cell)
  for (const auto& f : wall)
    for (int j = 0; j < num_vertices(f.type); ++j) cells_at.try_emplace(f.nodes[static_cast<std::size_t>(j)]);
  for (std::size_t blk = 0; blk < mesh.cells.size(); ++blk) {
    const ElementBlock& block = mesh.cells[blk];
    for (Index c = 0; c < block.size(); ++c) {
      const auto el = block.element(c);
      for (int j = 0; j < num_vertices(block.type); ++j)
        if (const auto it = cells_at.find(el[static_cast<std::size_t>(j)]); it != cells_at.end()) it->second.emplace_back(blk, c);
    }
  }
  const auto centroid = [&](const ElementType type, const auto& nodes) {
    Vec<Dim> x = Vec<Dim>::Zero();
    for (int j = 0; j < num_vertices(type); ++j) x += mesh.points.col(nodes[static_cast<std::size_t>(j)]);
    return Vec<Dim>(x / num_vertices(type));
  };
  std::vector<Vec<Dim>> out(wall.size(), Vec<Dim>::Zero());
  for (std::size_t i = 0; i < wall.size(); ++i) {
    const WallFacet& f = wall[i];
    for (const auto& [blk, c] : cells_at[f.nodes[0]]) {
      const auto el = mesh.cells[blk].element(c);
      const int nv = num_vertices(mesh.cells[blk].type);
      const bool holds = std::all_of(f.nodes.begin(), f.nodes.begin() + num_vertices(f.type), [&](Index v) {
        return std::find(el.begin(), el.begin() + nv, v) != el.begin() + nv;
      });
      if (holds) {
        out[i] = centroid(mesh.cells[blk].type, el) - centroid(f.type, f.nodes);
        break;
      }
    }
  }
  return out;
}

/// Whether each facet bulges away from the cell holding it: the displacements of its nodes
/// beyond its vertices (displacement(node), a Dim-vector) point, summed, against the facet's
/// inward direction. Such a facet only enlarges its cell (a farfield circle snapped outward):
/// the snapped cell is better left alone than its motion spread into the interior.
template <int Dim, class Displacement>
[[nodiscard]] std::vector<char> bulging_away(const Mesh<Dim>& mesh, const std::vector<WallFacet>& wall, const Displacement& displacement) {
  const std::vector<Vec<Dim>> inward = inward_directions(mesh, wall);
  std::vector<char> away(wall.size(), 0);
  for (std::size_t i = 0; i < wall.size(); ++i) {
    const WallFacet& f = wall[i];
    Vec<Dim> bulge = Vec<Dim>::Zero();
    for (int j = num_vertices(f.type); j < num_nodes(f.type); ++j) bulge += displacement(f.nodes[static_cast<std::size_t>(j)]);
    away[i] = bulge.dot(inward[i]) < 0.0 ? 1 : 0;
  }
  return away;
}

/// Closest point on a wall: facet index, reference coordinates there, point and distance.
template <int Dim>
struct WallPoint {
  Index facet = -1;
  RefPoint xi{0.0, 0.0, 0.0};
  Vec<Dim> point = Vec<Dim>::Zero();
  double distance = std::numeric_limits<double>::infinity();
};

/// Closest point of segment a-b to p: parameter t in [0, 1].
template <int Dim>
[[nodiscard]] double closest_on_segment(const Vec<Dim>& p, const Vec<Dim>& a, const Vec<Dim>& b) {
  const Vec<Dim> ab = b - a;
  const double length2 = ab.squaredNorm();
  return length2 > 0.0 ? std::clamp((p - a).dot(ab) / length2, 0.0, 1.0) : 0.0;
}

/// Closest point of triangle abc to p (Ericson, Real-Time Collision Detection, 5.1.5):
/// barycentric weights (of b, of c) of the point.
[[nodiscard]] inline std::array<double, 2> closest_on_triangle(const Vec<3>& p, const Vec<3>& a, const Vec<3>& b,
                                                               const Vec<3>& c) {
  const Vec<3> ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0.0 && d2 <= 0.0) return {0.0, 0.0};
  const Vec<3> bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0.0 && d4 <= d3) return {1.0, 0.0};
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) return {d1 / (d1 - d3), 0.0};
  const Vec<3> cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0.0 && d5 <= d6) return {0.0, 1.0};
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) return {0.0, d2 / (d2 - d6)};
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return {1.0 - w, w};
  }
  const double denominator = 1.0 / (va + vb + vc);
  return {vb * denominator, vc * denominator};
}

/// Closest point of the quadrilateral x0 x1 x2 x3 to p: that of the triangles 012 and 023,
/// mapped back to the bilinear reference square [-1, 1]^2 by Gauss-Newton (exact for planar
/// parallelograms, close for the gently warped faces of real meshes). Returns (xi, point).
// A template so that its Gauss-Newton solve is compiled only where WallDistance<3> is.
template <int = 0>
[[nodiscard]] std::pair<RefPoint, Vec<3>> closest_on_quadrilateral(const Vec<3>& p, const Vec<3>& x0,
                                                                         const Vec<3>& x1, const Vec<3>& x2,
                                                                         const Vec<3>& x3) {
  const auto [u1, v1] = closest_on_triangle(p, x0, x1, x2);
  const Vec<3> q1 = x0 + u1 * (x1 - x0) + v1 * (x2 - x0);
  const auto [u2, v2] = closest_on_triangle(p, x0, x2, x3);
  const Vec<3> q2 = x0 + u2 * (x2 - x0) + v2 * (x3 - x0);
  const Vec<3> q = (p - q1).squaredNorm() <= (p - q2).squaredNorm() ? q1 : q2;
  Eigen::Matrix<double, 3, 4> corners;
  corners << x0, x1, x2, x3;
  RefPoint xi{0.0, 0.0, 0.0};
  for (int iteration = 0; iteration < 8; ++iteration) {
    const Vec<3> r = q - map_to_physical(ElementType::quad4, corners, xi);
    const Eigen::Matrix<double, 3, 2> jac = jacobian(ElementType::quad4, corners, xi);
    const Eigen::Vector2d step = (jac.transpose() * jac).ldlt().solve(jac.transpose() * r);
    xi[0] = std::clamp(xi[0] + step[0], -1.0, 1.0);
    xi[1] = std::clamp(xi[1] + step[1], -1.0, 1.0);
    if (step.norm() < 1e-14) break;
  }
  return {xi, map_to_physical(ElementType::quad4, corners, xi)};
}

/// Closest points on a fixed set of straight wall facets. Reads `points` in place: they must
/// outlive the object and not move while it is used.
template <int Dim>
class WallDistance {
 public:
  WallDistance() = default;

  /// `points`: Dim × n_nodes; `facets` index its columns. `candidates`: nearest wall vertices
  /// whose incident facets are searched. Throws InputError for a facet node out of range.
  WallDistance(const Points<Dim>& points, std::vector<WallFacet> facets, Index candidates = 4)
      : points_(&points), facets_(std::move(facets)), candidates_(candidates) {
    if (candidates < 1 || static_cast<std::size_t>(candidates) > KdTree<Dim>::max_within)
      throw InputError("WallDistance: " + std::to_string(candidates) + " candidate vertices (expected 1 to " +
                       std::to_string(KdTree<Dim>::max_within) + ")");
    for (const WallFacet& f : facets_)
      for (int k = 0; k < num_nodes(f.type); ++k) {
        const Index v = f.nodes[static_cast<std::size_t>(k)];
        if (v < 0 || v >= points.cols())
          throw InputError("WallDistance: wall facet refers to node " + std::to_string(v) + " (expected 0 to " +
                           std::to_string(points.cols() - 1) + ")");
        if (k < num_vertices(f.type)) vertices_.push_back(v);
      }
    std::sort(vertices_.begin(), vertices_.end());
    vertices_.erase(std::unique(vertices_.begin(), vertices_.end()), vertices_.end());
    vertex_points_.resize(Dim, static_cast<Index>(vertices_.size()));
    for (std::size_t i = 0; i < vertices_.size(); ++i) vertex_points_.col(static_cast<Index>(i)) = points.col(vertices_[i]);
    tree_.build(vertex_points_);
    // Vertex -> incident facets, compressed rows over the sorted vertex list.
    offsets_.assign(vertices_.size() + 1, 0);
    const auto slot = [&](Index v) {
      return static_cast<std::size_t>(std::lower_bound(vertices_.begin(), vertices_.end(), v) - vertices_.begin());
    };
    for (const WallFacet& f : facets_)
      for (int k = 0; k < num_vertices(f.type); ++k) ++offsets_[slot(f.nodes[static_cast<std::size_t>(k)]) + 1];
    for (std::size_t i = 1; i < offsets_.size(); ++i) offsets_[i] += offsets_[i - 1];
    incident_.resize(static_cast<std::size_t>(offsets_.back()));
    std::vector<Index> fill(offsets_.begin(), offsets_.end() - 1);
    for (std::size_t f = 0; f < facets_.size(); ++f)
      for (int k = 0; k < num_vertices(facets_[f].type); ++k)
        incident_[static_cast<std::size_t>(fill[slot(facets_[f].nodes[static_cast<std::size_t>(k)])]++)] = static_cast<Index>(f);
  }

  [[nodiscard]] bool empty() const noexcept { return facets_.empty(); }
  [[nodiscard]] const std::vector<WallFacet>& facets() const noexcept { return facets_; }
  /// Sorted unique wall vertices.
  [[nodiscard]] const std::vector<Index>& vertices() const noexcept { return vertices_; }

  /// The wall vertex nearest to p (a mesh node index) and its distance.
  [[nodiscard]] std::pair<Index, double> nearest_vertex(const Vec<Dim>& p) const {
    const Neighbor n = tree_.nearest(p);
    return {vertices_[n.first], std::sqrt(n.second)};
  }

  /// Closest point of the wall to p. Throws InputError when the wall has no facet.
  [[nodiscard]] WallPoint<Dim> closest(const Vec<Dim>& p) const {
    if (facets_.empty()) throw InputError("WallDistance::closest: the wall has no facet");
    return *closest_within(p, std::numeric_limits<double>::infinity());
  }

  /// closest(p) when a wall vertex lies strictly closer than `reach` to p, none otherwise: one
  /// search pruned by the reach, far from the wall much cheaper than closest(). Candidate
  /// vertices beyond the reach are left out, so a facet with a point within (reach − its
  /// length) of p is always among those searched.
  [[nodiscard]] std::optional<WallPoint<Dim>> closest_within(const Vec<Dim>& p, double reach) const {
    std::array<Neighbor, KdTree<Dim>::max_within> near{};
    const Index found = tree_.nearest_within(p, reach, std::span<Neighbor>(near.data(), static_cast<std::size_t>(candidates_)));
    if (found == 0) return std::nullopt;
    WallPoint<Dim> best;
    for (Index i = 0; i < found; ++i) {
      const std::size_t vertex = near[static_cast<std::size_t>(i)].first;
      for (Index k = offsets_[vertex]; k < offsets_[vertex + 1]; ++k) {
        const WallPoint<Dim> c = closest_on_facet(p, incident_[static_cast<std::size_t>(k)]);
        if (c.distance < best.distance) best = c;
      }
    }
    return best;
  }

  /// Value at the wall point w of a field given per node (`values`: rows × n_nodes), by the
  /// facet's own (P1 or P2) shape functions.
  template <int Rows>
  [[nodiscard]] Eigen::Matrix<double, Rows, 1> interpolate(const Eigen::Matrix<double, Rows, Eigen::Dynamic>& values,
                                                           const WallPoint<Dim>& w) const {
    const WallFacet& f = facets_[static_cast<std::size_t>(w.facet)];
    std::array<double, max_facet_nodes> shape{};
    shape_functions(f.type, w.xi, std::span<double>(shape.data(), static_cast<std::size_t>(num_nodes(f.type))));
    Eigen::Matrix<double, Rows, 1> out = Eigen::Matrix<double, Rows, 1>::Zero(values.rows());
    for (int k = 0; k < num_nodes(f.type); ++k) out += shape[static_cast<std::size_t>(k)] * values.col(f.nodes[static_cast<std::size_t>(k)]);
    return out;
  }

 private:
  [[nodiscard]] WallPoint<Dim> closest_on_facet(const Vec<Dim>& p, Index f) const {
    const WallFacet& facet = facets_[static_cast<std::size_t>(f)];
    const auto x = [&](int k) -> Vec<Dim> { return points_->col(facet.nodes[static_cast<std::size_t>(k)]); };
    WallPoint<Dim> out;
    out.facet = f;
    if (shape(facet.type) == Shape::line) {
      const double t = closest_on_segment<Dim>(p, x(0), x(1));
      out.xi = {2.0 * t - 1.0, 0.0, 0.0};  // the reference line is [-1, 1]
      out.point = x(0) + t * (x(1) - x(0));
    } else if constexpr (Dim == 3) {
      if (shape(facet.type) == Shape::triangle) {
        const auto [u, v] = closest_on_triangle(p, x(0), x(1), x(2));
        out.xi = {u, v, 0.0};
        out.point = x(0) + u * (x(1) - x(0)) + v * (x(2) - x(0));
      } else {
        std::tie(out.xi, out.point) = closest_on_quadrilateral(p, x(0), x(1), x(2), x(3));
      }
    }
    out.distance = (p - out.point).norm();
    return out;
  }

  const Points<Dim>* points_ = nullptr;
  std::vector<WallFacet> facets_;
  Index candidates_ = 4;
  std::vector<Index> vertices_;
  Points<Dim> vertex_points_;
  KdTree<Dim> tree_;
  std::vector<Index> offsets_;
  std::vector<Index> incident_;
};

}  // namespace meshmotion::detail
