#pragma once
/// \file
/// BlendMover: wall-distance blending, a regularizer for curved boundary-layer meshes that
/// needs no linear solve (beyond the thesis; issue 5, method "blend", the curving pipeline's
/// default). Like every mover it propagates prescribed boundary displacements; its walls are
/// the connected sets of prescribed facets.
///
/// The prescribed (moving) boundary nodes are split into walls: connected sets of facets
/// whose nodes are all prescribed. Every other node x takes
///   u(x) = Σ_b φ(d_b / L_b) Π_{c ≠ b} (1 - φ(d_c / min(L_c, d_b + d_c))) u_b(p_b(x)),
/// where p_b(x) is the closest point of wall b (its straight facets in the reference
/// configuration), u_b the wall's displacement interpolated there by the facet's own P1/P2
/// shape functions, d_b = |x - p_b(x)|, L_b the wall's blending length and φ Wendland's C2
/// function φ(r) = (1 - r)^4 (4 r + 1) for r < 1, 0 beyond. φ is flat at the wall, so the
/// first cells follow the wall almost rigidly and the curvature is extruded through the
/// layer, as boundary-layer meshes want; the product makes each wall's field vanish on the
/// other walls, over the width of the gap between them where that is shorter than L. Fixed
/// boundary nodes stay, sliding ones keep the in-plane part of the blend.
///
/// Linear in the displacements: setup stores the sparse operator (per node, the weights of
/// the wall nodes of its closest facets), move is one sparse product. Setup: a k-d tree per
/// wall and a closest-facet query per node within reach, O(n log m), over the threads
/// (core/threads.hpp); move: O(nonzeros).

#include "meshmotion/movers/blend_options.hpp"
#include "meshmotion/core/element.hpp"
#include "meshmotion/core/error.hpp"
#include "meshmotion/core/mesh.hpp"
#include "meshmotion/core/shape_functions.hpp"
#include "meshmotion/core/threads.hpp"
#include "meshmotion/core/types.hpp"
#include "meshmotion/movers/boundary_layer.hpp"
#include "meshmotion/movers/detail/wall_distance.hpp"
#include "meshmotion/movers/boundary.hpp"
#include "meshmotion/movers/mover.hpp"
#include "meshmotion/movers/rbf_kernels.hpp"
#include "meshmotion/solvers/detail/stopwatch.hpp"
#include "meshmotion/spatial/ball_cover.hpp"

#include <Eigen/SparseCore>

#ifdef _OPENMP
#include <omp.h>
#endif

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <numeric>
#include <span>
#include <utility>
#include <string>
#include <vector>

namespace meshmotion {

/// Wall-distance blending mover (models MeshMover).
template <int Dim>
class BlendMover {
 public:
  static constexpr int dim = Dim;

  explicit BlendMover(BlendOptions options = {}) : options_(std::move(options)) {}

  /// Builds the blending operator on the reference mesh. `boundary` as ResolvedBoundary.
  /// Throws InputError for a negative blending length, a boundary node out of range, or
  /// prescribed nodes that belong to no facet of mesh.facets (a wall must be made of facets).
  void setup(const Mesh<Dim>& mesh, const ResolvedBoundary<Dim>& boundary) {
    const detail::Stopwatch clock;
    if (!(options_.blending_length >= 0.0))
      throw InputError("BlendMover::setup: negative blending length (got " + std::to_string(options_.blending_length) + ")");
    if (!(options_.blending_factor > 0.0))
      throw InputError("BlendMover::setup: blending factor " + std::to_string(options_.blending_factor) + " (expected > 0)");
    const Index n = mesh.num_nodes();
    const Index m = boundary.size();
    boundary_ = boundary;
    slot_.assign(static_cast<std::size_t>(n), -1);
    for (Index k = 0; k < m; ++k) {
      const Index v = boundary.nodes[static_cast<std::size_t>(k)];
      if (v < 0 || v >= n)
        throw InputError("BlendMover::setup: boundary node " + std::to_string(v) + " out of range (expected 0 to " +
                         std::to_string(n - 1) + ")");
      slot_[static_cast<std::size_t>(v)] = k;
    }
    const std::vector<std::vector<detail::WallFacet>> walls = split_walls(mesh);
    lengths_ = wall_lengths(mesh, walls);

    // A wall whose every facet has length 0 (all bulge away from their cells: a farfield
    // circle) gives no node a weight; querying it for each node of the mesh cost the 30P30N's
    // curving half its time.
    std::vector<detail::WallDistance<Dim>> distance;
    std::vector<double> reach;  // beyond this nearest-vertex distance no facet is within L
    std::vector<std::size_t> active;
    distance.reserve(walls.size());
    for (std::size_t b = 0; b < walls.size(); ++b) {
      reach.push_back(lengths_[b] + largest_facet(mesh.points, walls[b]));
      distance.emplace_back(mesh.points, walls[b]);
      if (lengths_[b] > 0.0) active.push_back(b);
    }
    const auto length_at = [&](std::size_t b, Index facet) {
      return facet_lengths_[b].empty() ? lengths_[b] : facet_lengths_[b][static_cast<std::size_t>(facet)];
    };
    // A node is weighted by wall b only within L_f of a facet f, so within L_f + diam f of one
    // of its vertices. The k-d search prunes by the wall's largest such reach; the cover of each
    // vertex's own reach skips, in constant time, the nodes beyond them all: on the 30P30N,
    // where the largest facet is 14 times the median, 40% of the nodes the search would visit.
    std::vector<BallCover<Dim>> near_wall(walls.size());
    for (const std::size_t b : active) near_wall[b] = vertex_reach_cover(mesh.points, distance[b], [&](Index f) { return length_at(b, f); });
    // Nodes in chunks over the threads, each thread its own triplets: no two walls share a
    // node and no node is written twice, so the operator does not depend on the order.
    std::vector<std::vector<Eigen::Triplet<double, Index>>> lists(static_cast<std::size_t>(num_threads()));
    Index evaluated = 0;
    detail::RegionErrors errors;
#pragma omp parallel num_threads(static_cast<int>(lists.size())) reduction(+ : evaluated)
    {
#ifdef _OPENMP
      std::vector<Eigen::Triplet<double, Index>>& triplets = lists[static_cast<std::size_t>(omp_get_thread_num())];
#else
      std::vector<Eigen::Triplet<double, Index>>& triplets = lists[0];
#endif
      std::array<double, max_facet_nodes> shape{};
      std::vector<detail::WallPoint<Dim>> closest;
      std::vector<double> phi;
      errors.run([&] {
        closest.resize(walls.size());
        phi.assign(walls.size(), 0.0);
      });
      // Nodes near a wall cost a closest-facet search, the others a pruned search per wall.
#pragma omp for schedule(dynamic, 1024)
      for (Index v = 0; v < n; ++v)
        errors.run([&] {
          const Index k = slot_[static_cast<std::size_t>(v)];
          if (k >= 0 && boundary.kinds[static_cast<std::size_t>(k)] == BoundaryKind::prescribed) {
            triplets.emplace_back(k, v, 1.0);
            return;
          }
          if (k >= 0 && boundary.kinds[static_cast<std::size_t>(k)] == BoundaryKind::fixed) return;
          const Vec<Dim> x = mesh.points.col(v);
          bool any = false;
          for (const std::size_t b : active) {
            phi[b] = 0.0;
            if (!near_wall[b].contains(x)) continue;
            const std::optional<detail::WallPoint<Dim>> near = distance[b].closest_within(x, reach[b]);
            if (!near) continue;
            closest[b] = *near;
            const double length = length_at(b, closest[b].facet);
            phi[b] = length > 0.0 ? rbf_value(RbfKernel::wendland2, closest[b].distance, length) : 0.0;
            any = any || phi[b] > 0.0;
          }
          if (!any) return;
          ++evaluated;
          for (const std::size_t b : active) {
            if (phi[b] == 0.0) continue;
            // Another wall c within reach damps b's share to zero on c. In a gap narrower than
            // L_c the damping runs over the gap's width d_b + d_c instead: over L_c it would
            // suppress b's share already at b's own first cells (the 30P30N flap gap folded).
            double weight = phi[b];
            for (const std::size_t c : active)
              if (c != b && phi[c] > 0.0)
                weight *= 1.0 - rbf_value(RbfKernel::wendland2, closest[c].distance,
                                          std::min(length_at(c, closest[c].facet), closest[b].distance + closest[c].distance));
            const detail::WallFacet& f = distance[b].facets()[static_cast<std::size_t>(closest[b].facet)];
            shape_functions(f.type, closest[b].xi, std::span<double>(shape.data(), static_cast<std::size_t>(num_nodes(f.type))));
            for (int j = 0; j < num_nodes(f.type); ++j)
              if (weight * shape[static_cast<std::size_t>(j)] != 0.0)
                triplets.emplace_back(slot_[static_cast<std::size_t>(f.nodes[static_cast<std::size_t>(j)])], v,
                                      weight * shape[static_cast<std::size_t>(j)]);
          }
        });
    }
    errors.rethrow();
    evaluated_ = evaluated;
    fill_operator(m, n, lists);
    stats_ = MoverStats{};
    stats_.setup_seconds = clock.seconds();
    stats_.factorizations = 0;
    stats_.boundary_nodes = m;
    stats_.evaluated_nodes = evaluated_;
    stats_.nonzeros = operator_.nonZeros();
  }

  /// Displacement of every node (Dim × n_nodes) for boundary displacements `d`
  /// (Dim × boundary.size(), columns in boundary.nodes order; entries of fixed and sliding
  /// nodes are ignored). Throws InputError for a wrong shape, a non-finite entry, or a call
  /// before setup.
  [[nodiscard]] Points<Dim> move(PointsView<Dim> d) {
    Points<Dim> out;
    move_into(d, out);
    return out;
  }

  /// move() into caller storage.
  void move_into(PointsView<Dim> d, Points<Dim>& out) {
    const detail::Stopwatch clock;
    if (d.cols() != operator_.rows() || slot_.empty())
      throw InputError("BlendMover::move: " + std::to_string(d.cols()) + " displacements (expected " +
                       std::to_string(operator_.rows()) + ", one per boundary node, after setup)");
    if (!d.allFinite()) throw InputError("BlendMover::move: non-finite displacement");
    check_covered("move", d);
    Points<Dim> given = d;
    for (Index k = 0; k < boundary_.size(); ++k)
      if (boundary_.kinds[static_cast<std::size_t>(k)] != BoundaryKind::prescribed) given.col(k).setZero();
    out.noalias() = given * operator_;
    for (Index k = 0; k < boundary_.size(); ++k)
      if (boundary_.kinds[static_cast<std::size_t>(k)] == BoundaryKind::sliding) {
        auto u = out.col(boundary_.nodes[static_cast<std::size_t>(k)]);
        u = boundary_.project(k, u);
      }
    ++stats_.moves;
    stats_.move_seconds = clock.seconds();
  }

  [[nodiscard]] const MoverStats& stats() const noexcept { return stats_; }
  /// Blending length of each wall of the last setup.
  [[nodiscard]] const std::vector<double>& blending_lengths() const noexcept { return lengths_; }

 private:
  // Facets (of mesh.facets) whose nodes are all prescribed, grouped into connected walls; the
  // prescribed nodes on none kept in uncovered_.
  [[nodiscard]] std::vector<std::vector<detail::WallFacet>> split_walls(const Mesh<Dim>& mesh) {
    std::vector<detail::WallFacet> facets;
    for (const auto& block : mesh.facets)
      for (Index e = 0; e < block.size(); ++e) {
        const auto el = block.element(e);
        const bool moving = std::all_of(el.begin(), el.end(), [&](Index v) {
          const Index k = slot_[static_cast<std::size_t>(v)];
          return k >= 0 && boundary_.kinds[static_cast<std::size_t>(k)] == BoundaryKind::prescribed;
        });
        if (!moving) continue;
        detail::WallFacet f{block.type, {}};
        std::copy(el.begin(), el.end(), f.nodes.begin());
        facets.push_back(f);
      }
    // Union-find over the boundary slots of the facets' vertices.
    std::vector<Index> parent(static_cast<std::size_t>(boundary_.size()));
    std::iota(parent.begin(), parent.end(), Index{0});
    const auto root = [&](Index a) {
      while (parent[static_cast<std::size_t>(a)] != a) a = parent[static_cast<std::size_t>(a)] = parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(a)])];
      return a;
    };
    const auto slot = [&](const detail::WallFacet& f, int j) { return slot_[static_cast<std::size_t>(f.nodes[static_cast<std::size_t>(j)])]; };
    for (const auto& f : facets)
      for (int j = 1; j < num_nodes(f.type); ++j) parent[static_cast<std::size_t>(root(slot(f, j)))] = root(slot(f, 0));
    std::vector<Index> wall_of_root(parent.size(), -1);
    std::vector<std::vector<detail::WallFacet>> walls;
    for (const auto& f : facets) {
      Index& w = wall_of_root[static_cast<std::size_t>(root(slot(f, 0)))];
      if (w < 0) {
        w = static_cast<Index>(walls.size());
        walls.emplace_back();
      }
      walls[static_cast<std::size_t>(w)].push_back(f);
    }
    std::vector<char> covered(parent.size(), 0);
    for (const auto& f : facets)
      for (int j = 0; j < num_nodes(f.type); ++j) covered[static_cast<std::size_t>(slot(f, j))] = 1;
    uncovered_.clear();
    for (Index k = 0; k < boundary_.size(); ++k)
      if (boundary_.kinds[static_cast<std::size_t>(k)] == BoundaryKind::prescribed && !covered[static_cast<std::size_t>(k)])
        uncovered_.push_back(k);
    check_covered("setup", boundary_.displacements);
    return walls;
  }

  // A prescribed node on no wall facet carries nothing into the volume: refused when it moves,
  // at setup or (for a mover set up at rest) at the move that first moves it.
  void check_covered(const char* where, PointsView<Dim> d) const {
    for (const Index k : uncovered_)
      if (d.col(k).squaredNorm() > 0.0)
        throw InputError(std::string("BlendMover::") + where + ": moving boundary node " +
                         std::to_string(boundary_.nodes[static_cast<std::size_t>(k)]) +
                         " lies on no facet whose nodes all move (expected walls made of mesh.facets)");
  }

  // The operator's columns (nodes) straight from the threads' entries, each column sorted by
  // row: setFromTriplets' sort and merge of every entry was a sixth of the 30P30N's setup. A
  // node's entries are one thread's, on rows of distinct wall nodes (no two walls share one).
  void fill_operator(Index m, Index n, const std::vector<std::vector<Eigen::Triplet<double, Index>>>& lists) {
    operator_.resize(m, n);
    std::size_t nonzeros = 0;
    for (const auto& list : lists) nonzeros += list.size();
    operator_.resizeNonZeros(static_cast<Index>(nonzeros));
    Index* outer = operator_.outerIndexPtr();
    for (const auto& list : lists)
      for (const auto& t : list) ++outer[t.col() + 1];
    for (Index v = 0; v < n; ++v) outer[v + 1] += outer[v];
    std::vector<Index> next(outer, outer + n);
    Index* inner = operator_.innerIndexPtr();
    double* values = operator_.valuePtr();
    for (const auto& list : lists)
      for (const auto& t : list) {
        const Index at = next[static_cast<std::size_t>(t.col())]++;
        inner[at] = t.row();
        values[at] = t.value();
      }
    for (Index v = 0; v < n; ++v)  // a few entries per column: insertion sort
      for (Index i = outer[v] + 1; i < outer[v + 1]; ++i)
        for (Index j = i; j > outer[v] && inner[j - 1] > inner[j]; --j) {
          std::swap(inner[j - 1], inner[j]);
          std::swap(values[j - 1], values[j]);
        }
  }

  // Largest distance between two vertices of the facet.
  [[nodiscard]] static double diameter(const Points<Dim>& points, const detail::WallFacet& f) {
    double largest = 0.0;
    for (int a = 0; a < num_vertices(f.type); ++a)
      for (int b = a + 1; b < num_vertices(f.type); ++b)
        largest = std::max(largest, (points.col(f.nodes[static_cast<std::size_t>(a)]) -
                                     points.col(f.nodes[static_cast<std::size_t>(b)])).norm());
    return largest;
  }

  [[nodiscard]] static double largest_facet(const Points<Dim>& points, const std::vector<detail::WallFacet>& wall) {
    double largest = 0.0;
    for (const auto& f : wall) largest = std::max(largest, diameter(points, f));
    return largest;
  }

  // Balls around the wall's vertices holding every point within a facet's blending length of
  // the facet: each vertex's radius is the largest L_f + diam f of its facets (none for facets
  // of length 0, which weigh nothing).
  template <class LengthOf>
  [[nodiscard]] static BallCover<Dim> vertex_reach_cover(const Points<Dim>& points, const detail::WallDistance<Dim>& wall,
                                                         LengthOf&& length_of) {
    const std::vector<Index>& vertices = wall.vertices();
    Points<Dim> centres(Dim, static_cast<Index>(vertices.size()));
    for (std::size_t i = 0; i < vertices.size(); ++i) centres.col(static_cast<Index>(i)) = points.col(vertices[i]);
    std::vector<double> radii(vertices.size(), 0.0);
    for (std::size_t f = 0; f < wall.facets().size(); ++f) {
      const detail::WallFacet& facet = wall.facets()[f];
      const double length = length_of(static_cast<Index>(f));
      if (!(length > 0.0)) continue;
      const double radius = length + diameter(points, facet);
      for (int k = 0; k < num_vertices(facet.type); ++k) {
        const auto at = std::lower_bound(vertices.begin(), vertices.end(), facet.nodes[static_cast<std::size_t>(k)]);
        double& r = radii[static_cast<std::size_t>(at - vertices.begin())];
        r = std::max(r, radius);
      }
    }
    return BallCover<Dim>(centres, radii);
  }

  // Each wall's length (for a wall without a layer: the largest of its facets' lengths, which
  // facet_lengths_ holds).
  [[nodiscard]] std::vector<double> wall_lengths(const Mesh<Dim>& mesh, const std::vector<std::vector<detail::WallFacet>>& walls) {
    std::vector<double> lengths(walls.size(), options_.blending_length);
    facet_lengths_.assign(walls.size(), {});
    if (options_.blending_length > 0.0) return lengths;
    std::vector<double> thickness;
    if (options_.layer_estimate) thickness = detail::regrouped_thickness(*options_.layer_estimate, walls);
    if (thickness.empty())
      for (const WallLayer& w : estimate_boundary_layer(mesh, walls, options_.layer).walls) thickness.push_back(w.thickness);
    for (std::size_t b = 0; b < walls.size(); ++b) {
      lengths[b] = options_.blending_factor * thickness[b];
      if (lengths[b] > 0.0) continue;
      // A facet bulging away from its cell is left alone (the NACA0012's farfield circle:
      // 0.9964 as snapped, 0.978 blended over one facet).
      const std::vector<char> away = detail::bulging_away(mesh, walls[b], [&](Index v) {
        return boundary_.displacements.col(slot_[static_cast<std::size_t>(v)]);
      });
      for (std::size_t i = 0; i < walls[b].size(); ++i) {
        const detail::WallFacet& f = walls[b][i];
        const auto sides = edges(f.type);
        double size = 0.0;
        for (const auto& side : sides)
          size += (mesh.points.col(f.nodes[static_cast<std::size_t>(side[0])]) - mesh.points.col(f.nodes[static_cast<std::size_t>(side[1])])).norm();
        facet_lengths_[b].push_back(!away[i] ? options_.fallback_spacings * size / static_cast<double>(sides.size()) : 0.0);
        lengths[b] = std::max(lengths[b], facet_lengths_[b].back());
      }
    }
    return lengths;
  }

  BlendOptions options_;
  ResolvedBoundary<Dim> boundary_;
  std::vector<Index> slot_;  // node -> boundary index, -1 inside
  std::vector<Index> uncovered_;  // prescribed boundary indices on no wall facet
  std::vector<double> lengths_;
  std::vector<std::vector<double>> facet_lengths_;  // per facet of each wall without a layer
  Eigen::SparseMatrix<double, Eigen::ColMajor, Index> operator_;  // boundary × nodes
  Index evaluated_ = 0;
  MoverStats stats_;
};

static_assert(MeshMover<BlendMover<2>> && MeshMover<BlendMover<3>>);

}  // namespace meshmotion

// The compiled library (target meshmotion::compiled, src/) holds these for Dim 2 and 3.
#ifdef MESHMOTION_COMPILED
namespace meshmotion {
extern template class BlendMover<2>;
extern template class BlendMover<3>;
}  // namespace meshmotion
#endif
