#pragma once
/// \file
/// Repair of the linear cells a move folded (RbfOptions::repair). A smooth map can be valid
/// everywhere and still fold a mesh's linear cells: a body turned a half turn inside held walls
/// twists the space between by a shear of θ / ln(R1/r0), and a twist's vertices, joined by
/// straight edges, flip the mesh's slivers (the plate of docs/interpolation.md: 102 of
/// 120,287 tetrahedra at 180°, the map's determinant 1 everywhere). No choice of the map's
/// weights helps there (measured: profiles in the distance, in the distance to the axis, by
/// superellipse norms, harmonic on the mesh: 79–160 folded); moving the nodes around the
/// folded cells does.
///
/// After the move, the cells valid at the reference whose corner determinants (Knupp's corner
/// Jacobians, quality/knupp.hpp; one corner for simplices, the base corners for pyramids; for
/// hexahedra and prisms also det J at the centre) are no longer all of the reference's sign are
/// folded: exact for simplices and quadrilaterals (whose det J is affine in each coordinate),
/// a check at nine points for hexahedra (a certified bound costs 0.8 µs a cell, every move),
/// which a cell folded only between them passes. Inside the patch hexahedra, prisms and
/// pyramids are judged by their certified scaled Jacobian too, so what the repair leaves is
/// what quality_report() finds. Their nodes and `repair_layers` rings of
/// neighbours around them form the patch; its nodes that no boundary entry holds are free, and
/// its sliding nodes move in their plane or along their line. Each of them in turn (by ascending
/// global id) takes, by a pattern search along the axes (or its plane's or line's directions)
/// with a halving step, the place that lowers the squared shortfall of its cells' signed corner
/// shapes below repair_target; sweeps repeat while a node moves (at most repair_sweeps). A move
/// that folds nothing costs one pass of corner determinants over the cells and changes nothing;
/// a cell of several corners skips them when its vertices moved relative to each other by less
/// than the margin prepare() computed (detail::sign_margin_squared).
///
/// Over MPI the patch is gathered: the folded cells' nodes, the rings and then the patch's
/// cells and owned nodes go to every rank (allgathers of the patch alone), which repairs the
/// same patch in the same order as one process does: the serial result, to the rounding of the
/// displacements the ranks were given.
///
/// Only meshes whose cells are all linear are repaired (a high-order cell's inner nodes would be
/// left behind by its vertices; curving's untangle() repairs curved cells). The repaired
/// nodes' derivatives and velocities are those of the map before the repair: the repair is a
/// search, not a smooth function of the motion (docs/interpolation.md).

#include "meshmotion/core/element.hpp"
#include "meshmotion/core/mesh_like.hpp"
#include "meshmotion/core/threads.hpp"
#include "meshmotion/core/types.hpp"
#include "meshmotion/movers/boundary.hpp"
#include "meshmotion/quality/knupp.hpp"
#include "meshmotion/quality/scaled_jacobian.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

namespace meshmotion {

/// The signed corner shape the repair raises a folded cell's corners towards.
inline constexpr double repair_target = 0.1;
/// Rings of neighbours around the folded cells' nodes that the repair may move.
inline constexpr int repair_layers = 2;
/// Most sweeps over the free nodes.
inline constexpr int repair_sweeps = 10;

/// What the last repair found and did (the same on every process).
struct RepairReport {
  Index folded = 0;       ///< cells the move folded
  Index moved_nodes = 0;  ///< nodes the repair moved
  Index left_folded = 0;  ///< cells still folded after it
};

/// The gathers of one process: every process's values are its own.
struct LocalGather {
  template <class T>
  [[nodiscard]] std::vector<T> all(std::vector<T> mine) const {
    return mine;
  }
};

namespace detail {

/// `sign` × the corner determinant of corner `c` of a linear cell of shape table `t` whose
/// vertices' positions `at(k)` gives, and its signed corner shape (Knupp's, −1 when degenerate).
template <int Dim, class At>
[[nodiscard]] std::pair<double, double> signed_corner(const KnuppCorner& c, double sign, const At& at) {
  Eigen::Matrix<double, Dim, Dim> a;
  const Vec<Dim> origin = at(c.vertex);
  for (int d = 0; d < Dim; ++d) a.col(d) = at(c.neighbours[static_cast<std::size_t>(d)]) - origin;
  const double det = sign * a.determinant();
  const Eigen::Matrix<double, Dim, Dim> t = a * c.ideal_inverse.template topLeftCorner<Dim, Dim>();
  const double frob2 = t.squaredNorm();
  if (!(frob2 > 0.0) || !std::isfinite(det)) return {det, -1.0};
  const double tdet = std::abs(sign * t.determinant());
  const double size = Dim == 2 ? tdet : std::cbrt(tdet * tdet);
  return {det, std::copysign(Dim * size / frob2, det)};
}

/// J at the centre of a linear hexahedron or prism whose vertices' positions `at(k)` gives
/// (Gmsh's order; columns scaled alike, the ideal cell's first corner matrix for the ideal
/// cell); the identity for other shapes, judged at their corners alone.
template <class At>
[[nodiscard]] Eigen::Matrix3d centre_jacobian(Shape s, const At& at) {
  Eigen::Matrix3d j = Eigen::Matrix3d::Identity();
  if (s == Shape::hexahedron) {
    j.col(0) = (at(1) - at(0) + at(2) - at(3) + at(5) - at(4) + at(6) - at(7)) / 4.0;
    j.col(1) = (at(3) - at(0) + at(2) - at(1) + at(7) - at(4) + at(6) - at(5)) / 4.0;
    j.col(2) = (at(4) - at(0) + at(5) - at(1) + at(6) - at(2) + at(7) - at(3)) / 4.0;
  } else if (s == Shape::prism) {
    j.col(0) = (at(1) - at(0) + at(4) - at(3)) / 2.0;
    j.col(1) = (at(2) - at(0) + at(5) - at(3)) / 2.0;
    j.col(2) = (at(3) - at(0) + at(4) - at(1) + at(5) - at(2)) / 3.0;
  }
  return j;
}

/// f(A) for the corner matrices of a linear cell of shape `s` at its vertices `p` (for
/// hexahedra and prisms also J at the centre) while f returns true; whether it always did.
/// Each matrix's columns are differences of two vertices, or (the centre's) a quarter or
/// half or third of sums of as many such differences: a column moves by at most 2ρ when no
/// vertex moves more than ρ relative to the first.
template <int Dim, class F>
[[nodiscard]] bool all_corner_matrices(Shape s, const Vec<Dim>* p, F&& f) {
  for (const KnuppCorner& corner : knupp_table(s).corners) {
    Eigen::Matrix<double, Dim, Dim> a;
    for (int d = 0; d < Dim; ++d) a.col(d) = p[corner.neighbours[static_cast<std::size_t>(d)]] - p[corner.vertex];
    if (!f(a)) return false;
  }
  if constexpr (Dim == 3)
    if (s == Shape::hexahedron || s == Shape::prism) return f(centre_jacobian(s, [&](int k) { return p[k]; }));
  return true;
}

/// Whether every corner determinant (all_corner_matrices) is positive once multiplied by
/// `sign`: the determinants alone, the pass a move makes over the cells it cannot skip.
template <int Dim>
[[nodiscard]] bool corners_keep_sign(Shape s, double sign, const Vec<Dim>* p) {
  return all_corner_matrices<Dim>(s, p, [&](const Eigen::Matrix<double, Dim, Dim>& a) { return sign * a.determinant() > 0.0; });
}

/// The squared largest ρ such that no vertex of the cell moving by at most ρ relative to its
/// first vertex can change a corner determinant's sign: a corner matrix A keeps its sign under
/// any change of spectral norm below σ_min(A), the change is at most 2ρ√Dim in Frobenius norm
/// (all_corner_matrices), and σ_min(A) ≥ |det A| / ‖A‖_F (2D), 2 |det A| / ‖A‖_F² (3D: σ1σ2 ≤
/// (σ1² + σ2²) / 2). A hundredth off for the rounding of the determinants the check would compute.
template <int Dim>
[[nodiscard]] double sign_margin_squared(Shape s, const Vec<Dim>* p) {
  double smallest = std::numeric_limits<double>::infinity();
  (void)all_corner_matrices<Dim>(s, p, [&](const Eigen::Matrix<double, Dim, Dim>& a) {
    const double frob2 = a.squaredNorm(), det = std::abs(a.determinant());
    smallest = std::min(smallest, frob2 > 0.0 ? (Dim == 2 ? det / std::sqrt(frob2) : 2.0 * det / frob2) : 0.0);
    return true;
  });
  const double rho = 0.99 * smallest / (2.0 * std::sqrt(double(Dim)));
  return rho * rho;
}

}  // namespace detail

/// The linear cells of a mesh (or of one process's part of it) and the repair of what a move
/// folded in them (the file comment).
template <int Dim>
class LinearRepair {
 public:
  /// Keeps `mesh`'s cells, when they are all linear (otherwise the repair stays inactive), and
  /// which nodes `boundary` holds. `ids` (per node; empty: the node's index) are the nodes'
  /// global ids, `owned` (per node; empty: every node) those this process owns.
  template <MeshLike M>
    requires(mesh_dim<M> == Dim)
  void prepare(const M& mesh, const ResolvedBoundary<Dim>& boundary, std::vector<std::int64_t> ids = {},
               std::vector<char> owned = {}) {
    using T = MeshTraits<M>;
    *this = LinearRepair{};
    const Index n = T::num_nodes(mesh);
    if (n > std::numeric_limits<std::int32_t>::max()) return;
    offsets_.push_back(0);
    for (Index b = 0; b < T::num_cell_blocks(mesh); ++b) {
      const ElementType type = T::cell_type(mesh, b);
      if (dimension(type) != Dim) continue;
      if (order(type) != 1) {
        *this = LinearRepair{};
        return;
      }
      const int nv = num_vertices(type);
      for (Index c = 0; c < T::num_cells(mesh, b); ++c) {
        shapes_.push_back(shape(type));
        for (int k = 0; k < nv; ++k) nodes_.push_back(static_cast<std::int32_t>(T::cell_node(mesh, b, c, k)));
        offsets_.push_back(static_cast<Index>(nodes_.size()));
      }
    }
    reference_.resize(Dim, n);
    for (Index v = 0; v < n; ++v)
      for (int a = 0; a < Dim; ++a) reference_(a, v) = T::coordinate(mesh, v, a);
    signs_.assign(shapes_.size(), 0);
    margins_.assign(shapes_.size(), 0.0f);
    const auto cells = static_cast<Index>(shapes_.size());
#pragma omp parallel for num_threads(::meshmotion::num_threads()) schedule(static)
    for (Index i = 0; i < cells; ++i) {
      const auto c = static_cast<std::size_t>(i);
      const auto p = vertices(i, Points<Dim>::Zero(Dim, n));
      const Shape s = shapes_[c];
      signs_[c] = detail::corners_keep_sign<Dim>(s, 1.0, p.data()) ? 1 : detail::corners_keep_sign<Dim>(s, -1.0, p.data()) ? -1 : 0;
      // A cell folded at the reference is left alone; a simplex's one determinant is cheaper than its margin.
      if (signs_[c] != 0 && num_vertices(element_type(s, 1)) > Dim + 1)
        margins_[c] = static_cast<float>(detail::sign_margin_squared<Dim>(s, p.data()) * (1.0 - 1e-6));
    }
    freedom_.assign(static_cast<std::size_t>(n), Dim);
    first_direction_.assign(static_cast<std::size_t>(n), -1);
    for (Index k = 0; k < boundary.size(); ++k) {
      const Index v = boundary.nodes[static_cast<std::size_t>(k)];
      if (v < 0 || v >= n) continue;
      if (boundary.kinds[static_cast<std::size_t>(k)] != BoundaryKind::sliding) {
        freedom_[static_cast<std::size_t>(v)] = 0;
        continue;
      }
      const auto basis = boundary.sliding_basis(k);
      freedom_[static_cast<std::size_t>(v)] = static_cast<int>(basis.cols());
      first_direction_[static_cast<std::size_t>(v)] = static_cast<Index>(directions_.size());
      for (Index j = 0; j < basis.cols(); ++j) directions_.push_back(basis.col(j));
    }
    ids_ = std::move(ids);
    owned_ = std::move(owned);
    active_ = true;
  }

  /// prepare() kept cells (all linear; over MPI every process must agree, see disable()).
  [[nodiscard]] bool active() const noexcept { return active_; }
  /// No repair (a process whose part has cells of higher order).
  void disable() { *this = LinearRepair{}; }

  /// Repairs the displacements `out` (Dim × nodes, added to the reference prepare() was given)
  /// in place. Collective through `gather` (LocalGather for one process).
  template <class Out, class Gather = LocalGather>
  RepairReport repair(Out& out, const Gather& gather = {}) const {
    if (!active()) return {};
    // The check reads every vertex of every cell each move: through contiguous columns, as a
    // map whose stride the compiler knows (a caller's Eigen::Ref, its stride known at run time
    // only, made the check 70% slower: Python's move_into 0.6 ms on a 40³ box).
    if (out.outerStride() != Dim) {
      Points<Dim> copy = out;
      const RepairReport report = repair(copy, gather);
      out = copy;
      return report;
    }
    Eigen::Map<Points<Dim>> contiguous(out.data(), Dim, out.cols());
    return repair_contiguous(contiguous, gather);
  }

 private:
  template <class Gather>
  RepairReport repair_contiguous(Eigen::Map<Points<Dim>>& out, const Gather& gather) const {
    RepairReport report;
    const auto cells = static_cast<Index>(shapes_.size());
    std::vector<char> folded(shapes_.size(), 0);
#pragma omp parallel for num_threads(::meshmotion::num_threads()) schedule(static)
    for (Index c = 0; c < cells; ++c)
      if (const int sign = signs_[static_cast<std::size_t>(c)]; sign != 0) folded[static_cast<std::size_t>(c)] = is_folded(c, sign, out) ? 1 : 0;
    std::vector<std::int64_t> seeds, count{0};
    for (Index c = 0; c < cells; ++c)
      if (folded[static_cast<std::size_t>(c)] != 0) {
        ++count[0];
        for (Index k = offsets_[static_cast<std::size_t>(c)]; k < offsets_[static_cast<std::size_t>(c) + 1]; ++k)
          seeds.push_back(id(nodes_[static_cast<std::size_t>(k)]));
      }
    for (const std::int64_t f : gather.all(count)) report.folded += f;
    if (report.folded == 0) return report;

    // The patch's nodes: the folded cells' and repair_layers rings around them.
    std::vector<std::int64_t> patch = sorted_union(gather.all(std::move(seeds)));
    for (int layer = 0; layer < repair_layers; ++layer) {
      std::vector<std::int64_t> ring;
      for_cells_touching(patch, [&](Index c) {
        for (Index k = offsets_[static_cast<std::size_t>(c)]; k < offsets_[static_cast<std::size_t>(c) + 1]; ++k)
          ring.push_back(id(nodes_[static_cast<std::size_t>(k)]));
      });
      patch = sorted_union(gather.all(std::move(ring)));
    }
    // Every cell touching the patch, as (shape, sign, vertices' ids), and their nodes, from
    // their owners: the same patch on every process.
    std::vector<std::int64_t> cell_rows;
    for_cells_touching(patch, [&](Index c) {
      cell_rows.push_back(static_cast<std::int64_t>(shapes_[static_cast<std::size_t>(c)]));
      cell_rows.push_back(signs_[static_cast<std::size_t>(c)]);
      for (Index k = offsets_[static_cast<std::size_t>(c)]; k < offsets_[static_cast<std::size_t>(c) + 1]; ++k)
        cell_rows.push_back(id(nodes_[static_cast<std::size_t>(k)]));
    });
    Patch p = patch_cells(gather.all(std::move(cell_rows)));
    std::vector<std::int64_t> node_rows;
    std::vector<double> node_values;
    // Per node: id and freedom; position, then a sliding node's directions.
    for (Index v = 0; v < static_cast<Index>(freedom_.size()); ++v) {
      if (!owns(v) || !std::binary_search(p.ids.begin(), p.ids.end(), id(v))) continue;
      const int freedom = freedom_[static_cast<std::size_t>(v)];
      node_rows.push_back(id(v));
      node_rows.push_back(freedom);
      for (int a = 0; a < Dim; ++a) node_values.push_back(reference_(a, v) + out(a, v));
      for (int j = 0; j < (freedom < Dim ? freedom : 0); ++j)
        for (int a = 0; a < Dim; ++a)
          node_values.push_back(directions_[static_cast<std::size_t>(first_direction_[static_cast<std::size_t>(v)] + j)](a));
    }
    const std::vector<std::int64_t> rows = gather.all(std::move(node_rows));
    const std::vector<double> values = gather.all(std::move(node_values));
    p.x.resize(Dim, static_cast<Index>(p.ids.size()));
    p.directions.assign(p.ids.size(), {});
    for (std::size_t r = 0, next = 0; r < rows.size() / 2; ++r) {
      const auto i = static_cast<std::size_t>(std::lower_bound(p.ids.begin(), p.ids.end(), rows[2 * r]) - p.ids.begin());
      for (int a = 0; a < Dim; ++a) p.x(a, static_cast<Index>(i)) = values[next++];
      const auto freedom = static_cast<int>(rows[2 * r + 1]);
      const bool ringed = std::binary_search(patch.begin(), patch.end(), rows[2 * r]);
      for (int j = 0; j < freedom; ++j) {
        Vec<Dim> u = Vec<Dim>::Unit(j);
        if (freedom < Dim)
          for (int a = 0; a < Dim; ++a) u(a) = values[next++];
        if (ringed) p.directions[i].push_back(u);
      }
    }
    report.moved_nodes = optimize(p);
    for (Index c = 0; c < static_cast<Index>(p.shapes.size()); ++c)
      if (p.signs[static_cast<std::size_t>(c)] != 0 && p.is_folded(c)) ++report.left_folded;

    for (Index v = 0; v < static_cast<Index>(freedom_.size()); ++v) {
      const auto it = std::lower_bound(p.ids.begin(), p.ids.end(), id(v));
      if (it == p.ids.end() || *it != id(v) || p.directions[static_cast<std::size_t>(it - p.ids.begin())].empty()) continue;
      out.col(v) = p.x.col(it - p.ids.begin()) - reference_.col(v);
    }
    return report;
  }

  /// The gathered patch: its nodes by ascending id, its cells in a canonical order.
  struct Patch {
    std::vector<std::int64_t> ids;
    Points<Dim> x;
    std::vector<std::vector<Vec<Dim>>> directions;  ///< per node: those it may move in (none: held)
    std::vector<Shape> shapes;
    std::vector<int> signs;
    std::vector<Index> offsets{0}, nodes;      // cells' vertices (patch indices)
    std::vector<Index> node_offsets, node_cells;  // each node's cells

    /// f(det, shape) for each corner of cell c, and for a hexahedron or prism at its centre too;
    /// with `only` ≥ 0, the corners whose matrix holds the cell's vertex `only` alone.
    template <class F>
    void for_corners(Index c, F&& f, int only = -1) const {
      const Index* vertex = nodes.data() + offsets[static_cast<std::size_t>(c)];
      const auto at = [&](int k) { return Vec<Dim>(x.col(vertex[k])); };
      const Shape s = shapes[static_cast<std::size_t>(c)];
      const int sign = signs[static_cast<std::size_t>(c)];
      const auto& corners = detail::knupp_table(s).corners;
      for (const detail::KnuppCorner& corner : corners) {
        if (only >= 0 && corner.vertex != only &&
            std::find(corner.neighbours.begin(), corner.neighbours.begin() + Dim, only) == corner.neighbours.begin() + Dim)
          continue;
        const auto [det, q] = detail::signed_corner<Dim>(corner, sign, at);
        f(det, q);
      }
      if constexpr (Dim == 3)
        if (s == Shape::hexahedron || s == Shape::prism) {
          // The centre's Jacobian against the ideal cell's, which is its first corner's there.
          const Eigen::Matrix3d j = detail::centre_jacobian(s, at);
          const Eigen::Matrix3d t = j * corners.front().ideal_inverse;
          const double det = sign * j.determinant(), frob2 = t.squaredNorm(), tdet = std::abs(t.determinant());
          f(det, frob2 > 0.0 ? std::copysign(3.0 * std::cbrt(tdet * tdet) / frob2, det) : -1.0);
        }
    }
    /// Folded: a corner or the centre left the reference's sign, or for a hexahedron, prism or
    /// pyramid (whose det J is not smallest at those points) its certified scaled Jacobian
    /// (quality/scaled_jacobian.hpp) is not positive: the verdict of quality_report().
    [[nodiscard]] bool is_folded(Index c) const {
      bool folded = false;
      for_corners(c, [&](double det, double) { folded = folded || !(det > 0.0); });
      const Shape s = shapes[static_cast<std::size_t>(c)];
      if (folded || Dim == 2 || s == Shape::tetrahedron) return folded;
      const ElementType type = element_type(s, 1);
      Eigen::Matrix<double, Dim, Eigen::Dynamic> coords(Dim, num_vertices(type));
      for (int k = 0; k < num_vertices(type); ++k) coords.col(k) = x.col(nodes[static_cast<std::size_t>(offsets[static_cast<std::size_t>(c)] + k)]);
      const ScaledJacobian m = scaled_jacobian(type, coords);
      return !(signs[static_cast<std::size_t>(c)] > 0 ? m.certified_min > 0.0 : m.certified_max < 0.0);
    }
    /// The squared shortfall below repair_target of the corner shapes node i moves (a corner it
    /// is not part of would add a constant whose rounding decides between equal trials).
    [[nodiscard]] double shortfall(Index i) const {
      double sum = 0.0;
      for (Index k = node_offsets[static_cast<std::size_t>(i)]; k < node_offsets[static_cast<std::size_t>(i) + 1]; ++k) {
        const Index c = node_cells[static_cast<std::size_t>(k)];
        if (signs[static_cast<std::size_t>(c)] == 0) continue;
        const Index first = offsets[static_cast<std::size_t>(c)];
        const auto local = static_cast<int>(std::find(nodes.begin() + first, nodes.begin() + offsets[static_cast<std::size_t>(c) + 1], i) -
                                            (nodes.begin() + first));
        for_corners(c, [&](double, double q) { sum += q < repair_target ? (repair_target - q) * (repair_target - q) : 0.0; }, local);
      }
      return sum;
    }
  };

  [[nodiscard]] std::int64_t id(Index v) const { return ids_.empty() ? v : ids_[static_cast<std::size_t>(v)]; }
  [[nodiscard]] bool owns(Index v) const { return owned_.empty() || owned_[static_cast<std::size_t>(v)] != 0; }

  /// Cell c's vertices at the reference plus `out`, read once for all its corners.
  template <class Out>
  [[nodiscard]] std::array<Vec<Dim>, 8> vertices(Index c, const Out& out) const {
    const std::int32_t* vertex = nodes_.data() + offsets_[static_cast<std::size_t>(c)];
    std::array<Vec<Dim>, 8> p;
    for (Index k = 0; k < offsets_[static_cast<std::size_t>(c) + 1] - offsets_[static_cast<std::size_t>(c)]; ++k)
      p[static_cast<std::size_t>(k)] = reference_.col(vertex[k]) + out.col(vertex[k]);
    return p;
  }
  /// Whether cell c, its vertices at the reference plus `out`, has left orientation `sign`:
  /// not when no vertex moved relative to the first by more than the cell's margin (its
  /// determinants then cannot have changed sign), else by its determinants.
  [[nodiscard]] bool is_folded(Index c, int sign, const Eigen::Map<Points<Dim>>& out) const {
    if (const float margin = margins_[static_cast<std::size_t>(c)]; margin > 0.0f) {
      const std::int32_t* vertex = nodes_.data() + offsets_[static_cast<std::size_t>(c)];
      const Vec<Dim> first = out.col(vertex[0]);
      double rho2 = 0.0;
      for (Index k = 1; k < offsets_[static_cast<std::size_t>(c) + 1] - offsets_[static_cast<std::size_t>(c)]; ++k)
        rho2 = std::max(rho2, (Vec<Dim>(out.col(vertex[k])) - first).squaredNorm());
      if (rho2 < margin) return false;
    }
    return !detail::corners_keep_sign<Dim>(shapes_[static_cast<std::size_t>(c)], sign, vertices(c, out).data());
  }
  /// f(c) for every local cell with a node whose id is in `ids` (sorted).
  template <class F>
  void for_cells_touching(const std::vector<std::int64_t>& ids, F&& f) const {
    for (Index c = 0; c < static_cast<Index>(shapes_.size()); ++c)
      for (Index k = offsets_[static_cast<std::size_t>(c)]; k < offsets_[static_cast<std::size_t>(c) + 1]; ++k)
        if (std::binary_search(ids.begin(), ids.end(), id(nodes_[static_cast<std::size_t>(k)]))) {
          f(c);
          break;
        }
  }
  [[nodiscard]] static std::vector<std::int64_t> sorted_union(std::vector<std::int64_t> ids) {
    std::sort(ids.begin(), ids.end());
    ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
    return ids;
  }

  /// The patch of the gathered cell rows (a cell held by two processes counted once).
  [[nodiscard]] static Patch patch_cells(const std::vector<std::int64_t>& rows) {
    std::vector<std::vector<std::int64_t>> cells;
    for (std::size_t r = 0; r < rows.size();) {
      const auto s = static_cast<Shape>(rows[r]);
      const std::size_t length = 2 + static_cast<std::size_t>(num_vertices(element_type(s, 1)));
      cells.emplace_back(rows.begin() + static_cast<std::ptrdiff_t>(r), rows.begin() + static_cast<std::ptrdiff_t>(r + length));
      r += length;
    }
    std::sort(cells.begin(), cells.end(), [](const auto& a, const auto& b) {
      return std::lexicographical_compare(a.begin() + 2, a.end(), b.begin() + 2, b.end());
    });
    cells.erase(std::unique(cells.begin(), cells.end()), cells.end());
    Patch p;
    for (const auto& cell : cells) p.ids.insert(p.ids.end(), cell.begin() + 2, cell.end());
    p.ids = sorted_union(std::move(p.ids));
    std::vector<Index> degree(p.ids.size() + 1, 0);
    for (const auto& cell : cells) {
      p.shapes.push_back(static_cast<Shape>(cell[0]));
      p.signs.push_back(static_cast<int>(cell[1]));
      for (auto it = cell.begin() + 2; it != cell.end(); ++it) {
        const auto i = static_cast<Index>(std::lower_bound(p.ids.begin(), p.ids.end(), *it) - p.ids.begin());
        p.nodes.push_back(i);
        ++degree[static_cast<std::size_t>(i) + 1];
      }
      p.offsets.push_back(static_cast<Index>(p.nodes.size()));
    }
    p.node_offsets.assign(degree.size(), 0);
    for (std::size_t i = 1; i < degree.size(); ++i) p.node_offsets[i] = p.node_offsets[i - 1] + degree[i];
    p.node_cells.resize(p.nodes.size());
    std::vector<Index> next(p.node_offsets.begin(), p.node_offsets.end() - 1);
    for (Index c = 0; c < static_cast<Index>(p.shapes.size()); ++c)
      for (Index k = p.offsets[static_cast<std::size_t>(c)]; k < p.offsets[static_cast<std::size_t>(c) + 1]; ++k)
        p.node_cells[static_cast<std::size_t>(next[static_cast<std::size_t>(p.nodes[static_cast<std::size_t>(k)])]++)] = c;
    return p;
  }

  /// The sweeps over the patch's nodes that may move; the nodes moved. Each node stays within its
  /// nearest cell's reach at the start from where the move put it: a shape measure alone
  /// rewards a node sent far away (its cells flatten towards 0 from below).
  [[nodiscard]] static Index optimize(Patch& p) {
    const auto n = static_cast<Index>(p.ids.size());
    std::vector<double> limit(static_cast<std::size_t>(n), 0.0);
    for (Index i = 0; i < n; ++i) {
      if (p.directions[static_cast<std::size_t>(i)].empty()) continue;
      double reach = std::numeric_limits<double>::infinity();
      for (Index k = p.node_offsets[static_cast<std::size_t>(i)]; k < p.node_offsets[static_cast<std::size_t>(i) + 1]; ++k) {
        const Index c = p.node_cells[static_cast<std::size_t>(k)];
        double far = 0.0;
        for (Index j = p.offsets[static_cast<std::size_t>(c)]; j < p.offsets[static_cast<std::size_t>(c) + 1]; ++j)
          far = std::max(far, (p.x.col(p.nodes[static_cast<std::size_t>(j)]) - p.x.col(i)).norm());
        reach = std::min(reach, far);
      }
      limit[static_cast<std::size_t>(i)] = reach;
    }
    const Points<Dim> start = p.x;
    std::vector<char> moved(p.ids.size(), 0);
    for (int sweep = 0; sweep < repair_sweeps; ++sweep) {
      bool any = false;
      for (Index i = 0; i < n; ++i) {
        const std::vector<Vec<Dim>>& along = p.directions[static_cast<std::size_t>(i)];
        if (along.empty()) continue;
        // Shortfalls within rounding of the target (squared, 1e-12: corners within 1e-6 of it)
        // count as met, and a trial must gain more than rounding, and stay clear of the trust
        // region's edge (four first steps reach it exactly): one process and several given the
        // same motion to its last digits take the same path.
        constexpr double met = 1e-12;
        double best = p.shortfall(i);
        if (best <= met) continue;
        const double reach = limit[static_cast<std::size_t>(i)], first = 0.25 * reach;
        int steps = 0;  // a node's moves a sweep: the next sweep goes on after its neighbours moved
        for (double step = first; step > 1e-3 * first && best > met && steps < 64;) {
          bool better = false;
          for (std::size_t a = 0; a < along.size() && !better; ++a)
            for (const double s : {step, -step}) {
              const Vec<Dim> from = p.x.col(i), to = from + s * along[a];
              if ((to - start.col(i)).norm() > 0.97 * reach) continue;
              p.x.col(i) = to;
              const double trial = p.shortfall(i);
              if (trial < best * (1.0 - 1e-9)) {
                best = trial;
                better = true;
                break;
              }
              p.x.col(i) = from;
            }
          if (better) {
            ++steps;
            moved[static_cast<std::size_t>(i)] = 1;
            any = true;
          } else {
            step *= 0.5;
          }
        }
      }
      if (!any) break;
    }
    return static_cast<Index>(std::count(moved.begin(), moved.end(), 1));
  }

  std::vector<Shape> shapes_;
  std::vector<std::int8_t> signs_;    ///< per cell: its orientation at the reference (0: folded there)
  std::vector<float> margins_;        ///< per cell: sign_margin_squared() (0: none, check the determinants)
  std::vector<Index> offsets_;        ///< cells' first vertex in nodes_
  std::vector<std::int32_t> nodes_;   ///< cells' vertices (a mesh of 2^31 nodes or more is not repaired)
  Points<Dim> reference_;
  std::vector<int> freedom_;          ///< per node: directions it may move in (0: held; Dim: free)
  std::vector<Index> first_direction_;  ///< per sliding node: its first in directions_ (else −1)
  std::vector<Vec<Dim>> directions_;  ///< the sliding nodes' planes' or lines' orthonormal bases
  std::vector<std::int64_t> ids_;
  std::vector<char> owned_;
  bool active_ = false;
};

}  // namespace meshmotion
