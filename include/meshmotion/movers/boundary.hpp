#pragma once
/// \file
/// Boundary specification for the movers: named groups (Gmsh physical groups, SU2 markers)
/// each prescribed (a per-node displacement array or a rigid Motion), fixed, or sliding in a
/// plane (or, where two sliding planes meet in 3D, along their line); resolved against a mesh into the node lists and target displacements a mover's
/// setup/move take.
///
/// \code
/// BoundarySpec<2> spec;
/// spec.moving("wall", Rotation2D{{0.0, 0.0}, radians(60.0)});
/// spec.fixed("farfield");
/// spec.sliding("symmetry");                 // plane normal estimated from the group's nodes
/// const ResolvedBoundary<2> b = spec.resolve(mesh);
/// \endcode

#include "meshmotion/core/error.hpp"
#include "meshmotion/core/mesh.hpp"
#include "meshmotion/core/name_pattern.hpp"
#include "meshmotion/core/types.hpp"
#include "meshmotion/movers/motion.hpp"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace meshmotion {

/// How the nodes of a group move.
enum class BoundaryKind {
  prescribed,  ///< displacement given (array or rigid motion)
  fixed,       ///< zero displacement
  sliding,     ///< free to move in a plane, zero displacement along its normal
};

[[nodiscard]] inline std::string_view name(BoundaryKind k) {
  return k == BoundaryKind::prescribed ? "prescribed" : k == BoundaryKind::fixed ? "fixed" : "sliding";
}

/// An orthonormal basis of the plane normal to the unit vector n (Dim × (Dim − 1)).
template <int Dim>
[[nodiscard]] Eigen::Matrix<double, Dim, Dim - 1> plane_basis(const Vec<Dim>& n) {
  Eigen::Matrix<double, Dim, Dim - 1> t;
  if constexpr (Dim == 2) {
    t.col(0) = Vec<2>(-n(1), n(0));
  } else {
    // Start from the axis least aligned with n.
    Eigen::Index axis = 0;
    n.cwiseAbs().minCoeff(&axis);
    Vec<3> e = Vec<3>::Zero();
    e(axis) = 1.0;
    t.col(0) = (e - n.dot(e) * n).normalized();
    t.col(1) = n.cross(Vec<3>(t.col(0)));
  }
  return t;
}

/// A boundary resolved to nodes: what a mover's setup and move take.
///
/// `nodes` are sorted, unique mesh node indices; `displacements` (Dim × nodes.size()) are
/// their targets (zero for fixed and sliding nodes); `kinds[k]` tells how node nodes[k]
/// moves. A sliding node moves in a plane or, in 3D, along a line:
/// - `normals` (Dim × nodes.size()) holds the unit normal of a plane the node stays in
///   (zero columns for other kinds);
/// - `directions` (Dim × nodes.size(), or empty when no node slides along a line) holds the
///   unit direction of the line of a node on two non-parallel sliding planes (the edge where
///   two symmetry planes meet moves along it); zero columns for nodes sliding in a plane.
///
/// A node in several groups takes the strongest condition: prescribed over fixed over
/// sliding. Sliding in parallel planes stays a plane; two non-parallel planes leave their
/// line of intersection in 3D and a point (fixed) in 2D; a third plane not containing that
/// line fixes the node.
template <int Dim>
struct ResolvedBoundary {
  using Basis = Eigen::Matrix<double, Dim, Eigen::Dynamic, 0, Dim, Dim - 1>;

  std::vector<Index> nodes;
  std::vector<BoundaryKind> kinds;
  Points<Dim> displacements;
  Points<Dim> normals;
  Points<Dim> directions;

  [[nodiscard]] Index size() const noexcept { return static_cast<Index>(nodes.size()); }
  [[nodiscard]] bool has_sliding() const {
    return std::find(kinds.begin(), kinds.end(), BoundaryKind::sliding) != kinds.end();
  }
  /// True when entry k slides along a line (directions.col(k) is set).
  [[nodiscard]] bool slides_on_line(Index k) const {
    return directions.cols() > k && directions.col(k).squaredNorm() > 0.0;
  }
  /// Orthonormal basis (Dim × 1 for a line, Dim × (Dim − 1) for a plane) of the directions
  /// sliding entry k may move in. Precondition: kinds[k] is sliding.
  [[nodiscard]] Basis sliding_basis(Index k) const {
    if (slides_on_line(k)) return Basis(directions.col(k));
    return Basis(plane_basis<Dim>(Vec<Dim>(normals.col(k))));
  }
  /// The column of `node` in move()'s input (its entry in `nodes`). Throws InputError when
  /// the node is not on this boundary.
  [[nodiscard]] Index column(Index node) const {
    const auto it = std::lower_bound(nodes.begin(), nodes.end(), node);
    if (it == nodes.end() || *it != node)
      throw InputError("ResolvedBoundary::column: node " + std::to_string(node) + " is not a boundary node");
    return static_cast<Index>(it - nodes.begin());
  }
  /// Writes `values.col(k)` into the column of node `node_list[k]` of `d` (Dim × size(),
  /// move()'s input; sized and zeroed when its shape differs), in any node order. Throws
  /// InputError naming the node for one not on the boundary, one that is fixed or sliding
  /// (its displacement is not free), one given twice, or a non-finite value.
  void scatter(const std::vector<Index>& node_list, const Points<Dim>& values, Points<Dim>& d) const {
    if (static_cast<Index>(node_list.size()) != values.cols())
      throw InputError("ResolvedBoundary::scatter: " + std::to_string(node_list.size()) + " nodes for " +
                       std::to_string(values.cols()) + " displacements (expected one per node)");
    if (d.cols() != size()) d.setZero(Dim, size());
    std::vector<char> seen(nodes.size(), 0);
    for (std::size_t k = 0; k < node_list.size(); ++k) {
      const Index c = column(node_list[k]);
      const auto slot = static_cast<std::size_t>(c);
      if (kinds[slot] != BoundaryKind::prescribed)
        throw InputError("ResolvedBoundary::scatter: node " + std::to_string(node_list[k]) + " is " +
                         (kinds[slot] == BoundaryKind::fixed ? "fixed" : "sliding") + " (expected a prescribed node)");
      if (seen[slot]) throw InputError("ResolvedBoundary::scatter: node " + std::to_string(node_list[k]) + " given twice");
      if (!values.col(static_cast<Index>(k)).allFinite())
        throw InputError("ResolvedBoundary::scatter: node " + std::to_string(node_list[k]) + " has a non-finite displacement");
      seen[slot] = 1;
      d.col(c) = values.col(static_cast<Index>(k));
    }
  }
  /// The part of u that entry k may take: u projected on its line or plane when it slides,
  /// u itself otherwise.
  [[nodiscard]] Vec<Dim> project(Index k, const Vec<Dim>& u) const {
    if (kinds[static_cast<std::size_t>(k)] != BoundaryKind::sliding) return u;
    if (slides_on_line(k)) {
      const Vec<Dim> t = directions.col(k);
      return t.dot(u) * t;
    }
    const Vec<Dim> n = normals.col(k);
    return u - n.dot(u) * n;
  }
};

/// The least-squares plane (a line in 2D) through some nodes, and how far they are from it.
template <int Dim>
struct PlaneFit {
  Vec<Dim> normal = Vec<Dim>::Zero();    ///< unit normal
  Vec<Dim> centroid = Vec<Dim>::Zero();
  double off_plane = 0.0;  ///< largest distance of a node to the plane
  double extent = 0.0;     ///< largest distance of a node to the centroid
  /// The nodes lie in the plane to round-off: 1e-8 of their extent, the tolerance a sliding
  /// group is held to (a mesh generator's planar faces are within 1e-15 of it).
  [[nodiscard]] bool planar() const noexcept { return off_plane <= 1e-8 * std::max(extent, 1e-300); }
};

/// The plane through `points` of the nodes `list` (at least one): the eigenvector of the
/// smallest eigenvalue of their scatter matrix is the normal.
template <int Dim>
[[nodiscard]] PlaneFit<Dim> fit_plane(const Points<Dim>& points, std::span<const Index> list) {
  PlaneFit<Dim> fit;
  for (const Index v : list) fit.centroid += points.col(v);
  fit.centroid /= static_cast<double>(std::max<std::size_t>(list.size(), 1));
  Eigen::Matrix<double, Dim, Dim> scatter = Eigen::Matrix<double, Dim, Dim>::Zero();
  for (const Index v : list) {
    const Vec<Dim> r = points.col(v) - fit.centroid;
    scatter += r * r.transpose();
    fit.extent = std::max(fit.extent, r.norm());
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, Dim, Dim>> eig(scatter);
  fit.normal = eig.eigenvectors().col(0);
  for (const Index v : list) fit.off_plane = std::max(fit.off_plane, std::abs(fit.normal.dot(points.col(v) - fit.centroid)));
  return fit;
}

/// The normal of sliding group `group` from the plane fitted through its `count` nodes;
/// throws InputError when they are too few for a plane or do not lie in one (PlaneFit::planar),
/// asking for the normal. One message wherever the nodes are (one mesh, or spread over ranks).
template <int Dim>
[[nodiscard]] Vec<Dim> sliding_plane_normal(const std::string& group, Index count, const PlaneFit<Dim>& fit) {
  if (count < Dim)
    throw InputError("BoundarySpec::resolve: sliding group '" + group + "' has " + std::to_string(count) +
                     " nodes, too few to fit a plane (give the normal)");
  if (!fit.planar())
    throw InputError("BoundarySpec::resolve: sliding group '" + group + "' is not planar (a node lies " +
                     std::to_string(fit.off_plane) + " off the fitted plane, expected 0; give the normal)");
  return fit.normal;
}

/// One node's condition, as BoundarySpec (and other builders of a ResolvedBoundary) collect them.
template <int Dim>
struct BoundaryEntry {
  BoundaryKind kind = BoundaryKind::fixed;
  Vec<Dim> displacement = Vec<Dim>::Zero();
  Vec<Dim> normal = Vec<Dim>::Zero();
  Vec<Dim> direction = Vec<Dim>::Zero();  ///< line of a node on two sliding planes (3D)
};

namespace detail {

// A ResolvedBoundary of `count` conditions, which visit(add) passes to add(node, entry) in
// ascending node order.
template <int Dim, class Visit>
[[nodiscard]] ResolvedBoundary<Dim> collect_boundary(Index count, Visit&& visit) {
  ResolvedBoundary<Dim> out;
  out.nodes.reserve(static_cast<std::size_t>(count));
  out.kinds.reserve(static_cast<std::size_t>(count));
  out.displacements.setZero(Dim, count);
  out.normals.setZero(Dim, count);
  out.directions.setZero(Dim, count);
  Index k = 0;
  visit([&](Index node, const BoundaryEntry<Dim>& e) {
    out.nodes.push_back(node);
    out.kinds.push_back(e.kind);
    out.displacements.col(k) = e.displacement;
    out.normals.col(k) = e.normal;
    out.directions.col(k) = e.direction;
    ++k;
  });
  return out;
}

}  // namespace detail

/// Conditions of a whole mesh's boundary collected by node in a dense table: a map's node
/// allocations cost more than the rest of a 3D curving boundary's setup. The first condition
/// given to a node stays.
template <int Dim>
class BoundaryCollector {
 public:
  explicit BoundaryCollector(Index num_nodes) : slot_(static_cast<std::size_t>(num_nodes), -1) {}
  /// Gives `node` the condition `entry` unless it has one already.
  void add(Index node, const BoundaryEntry<Dim>& entry) {
    int& s = slot_[static_cast<std::size_t>(node)];
    if (s >= 0) return;
    s = static_cast<int>(entries_.size());
    entries_.push_back(entry);
  }
  /// The condition of `node`, or nullptr when it has none yet.
  [[nodiscard]] BoundaryEntry<Dim>* find(Index node) {
    const int s = slot_[static_cast<std::size_t>(node)];
    return s >= 0 ? &entries_[static_cast<std::size_t>(s)] : nullptr;
  }
  /// The collected conditions, nodes ascending.
  [[nodiscard]] ResolvedBoundary<Dim> resolve() const {
    return detail::collect_boundary<Dim>(static_cast<Index>(entries_.size()), [&](auto&& add) {
      for (std::size_t v = 0; v < slot_.size(); ++v)
        if (slot_[v] >= 0) add(static_cast<Index>(v), entries_[static_cast<std::size_t>(slot_[v])]);
    });
  }

 private:
  std::vector<int> slot_;
  std::vector<BoundaryEntry<Dim>> entries_;
};

/// Node lists by group name, for meshes without named groups (any MeshLike).
using GroupNodes = std::map<std::string, std::vector<Index>, std::less<>>;

/// Named-group boundary conditions, resolved against a mesh by resolve().
template <int Dim>
class BoundarySpec {
 public:
  /// The group moves rigidly with `motion` (evaluated on the group's reference positions).
  BoundarySpec& moving(std::string group, Motion<Dim> motion) {
    groups_.push_back({std::move(group), BoundaryKind::prescribed, std::move(motion), {}, {}, {}, false});
    return *this;
  }
  /// The group moves by `displacements`: Dim × (number of group nodes), columns in the order
  /// of the group's sorted node indices. A solver's own order is easy to get wrong here: prefer
  /// the overload with node indices.
  BoundarySpec& moving(std::string group, Points<Dim> displacements) {
    groups_.push_back({std::move(group), BoundaryKind::prescribed, std::nullopt, std::move(displacements), {}, {}, false});
    return *this;
  }
  /// The group moves by displacements given with their nodes: node `nodes[k]` (a mesh node
  /// index, 0-based, any order) moves by `displacements.col(k)`. resolve() throws InputError
  /// naming the node for one outside the mesh, one not in the group, one given twice, and for
  /// a group node without a displacement.
  BoundarySpec& moving(std::string group, std::vector<Index> nodes, Points<Dim> displacements) {
    if (static_cast<Index>(nodes.size()) != displacements.cols())
      throw InputError("BoundarySpec::moving: group '" + group + "': " + std::to_string(nodes.size()) + " nodes for " +
                       std::to_string(displacements.cols()) + " displacements (expected one per node)");
    groups_.push_back({std::move(group), BoundaryKind::prescribed, std::nullopt, std::move(displacements), {},
                       std::move(nodes), false});
    return *this;
  }
  /// The group is prescribed, its displacements given later in move()'s input (columns by
  /// ResolvedBoundary::column or scatter); resolve() gives it zero displacements.
  BoundarySpec& prescribed(std::string group) {
    groups_.push_back({std::move(group), BoundaryKind::prescribed, std::nullopt, {}, {}, {}, true});
    return *this;
  }
  /// The group does not move.
  BoundarySpec& fixed(std::string group) {
    groups_.push_back({std::move(group), BoundaryKind::fixed, std::nullopt, {}, {}, {}, false});
    return *this;
  }
  /// The group slides in its plane; the normal is fitted to the group's nodes (least squares)
  /// when not given. Throws at resolve() when the nodes are not coplanar.
  BoundarySpec& sliding(std::string group, std::optional<Vec<Dim>> normal = std::nullopt) {
    groups_.push_back({std::move(group), BoundaryKind::sliding, std::nullopt, {}, normal, {}, false});
    return *this;
  }

  [[nodiscard]] bool empty() const noexcept { return groups_.empty(); }

  /// Nodes that two groups of different kinds share, and which condition they take (the
  /// strongest: prescribed over fixed over sliding; see ResolvedBoundary). A flap touching a
  /// fixed wing moves its shared nodes with the flap: this says how many, so a program can
  /// tell its user.
  struct Overlap {
    std::string winner, other;            ///< group names
    BoundaryKind winner_kind, other_kind;
    Index nodes = 0;                      ///< shared nodes
  };
  [[nodiscard]] std::vector<Overlap> overlaps(const Mesh<Dim>& mesh) const {
    std::vector<Overlap> out;
    const std::vector<Group> groups = expand(mesh);
    for (std::size_t i = 0; i < groups.size(); ++i)
      for (std::size_t j = i + 1; j < groups.size(); ++j) {
        const Group *a = &groups[i], *b = &groups[j];
        if (a->kind == b->kind) continue;
        if (static_cast<int>(b->kind) < static_cast<int>(a->kind)) std::swap(a, b);
        const std::vector<Index> na = mesh.group_nodes(a->name), nb = mesh.group_nodes(b->name);
        std::vector<Index> shared;
        std::set_intersection(na.begin(), na.end(), nb.begin(), nb.end(), std::back_inserter(shared));
        if (!shared.empty()) out.push_back({a->name, b->name, a->kind, b->kind, static_cast<Index>(shared.size())});
      }
    return out;
  }

  /// Resolves against a Mesh<Dim> (groups by name, reference positions mesh.points).
  /// Displacements are those between fractions `from` and `to` of the motions (arrays scale
  /// linearly), so a driver can split the motion into steps. A name that is not a group's
  /// names, as in OpenFOAM, every facet group of that set (PhysicalGroup::in_groups: `wall`,
  /// an `inGroups` entry) or, when it is a pattern (core/name_pattern.hpp: `"(inlet|outlet)"`),
  /// every facet group whose name or set matches it: each takes the condition on its own (each
  /// sliding group its own plane). Throws InputError for an unknown group (listing the known
  /// ones), a malformed pattern, a displacement array given to a name of several groups, a
  /// wrong-sized or non-finite displacement array, or a non-planar sliding group.
  /// Displacements given by node need not name a polyhedral mesh's auxiliary centres: each
  /// left out takes the mean of its face's or cell's nodes (derive_auxiliary()).
  /// Messages name a node by its index and, where the file numbers it otherwise, its id there.
  [[nodiscard]] ResolvedBoundary<Dim> resolve(const Mesh<Dim>& mesh, double to = 1.0, double from = 0.0) const {
    const std::vector<Group> groups = expand(mesh);
    GroupNodes nodes;
    for (const auto& g : groups) nodes.emplace(g.name, mesh.group_nodes(g.name));
    return resolve_nodes(groups, mesh.points, nodes, to, from, &mesh);
  }

  /// Resolves with explicit node lists per group name (for MeshLike meshes without groups).
  /// `points` (Dim × n_nodes) are the reference positions. Throws InputError as above and for
  /// node indices outside [0, n_nodes).
  [[nodiscard]] ResolvedBoundary<Dim> resolve(const Points<Dim>& points, const GroupNodes& group_nodes,
                                              double to = 1.0, double from = 0.0) const {
    return resolve_nodes(groups_, points, group_nodes, to, from, nullptr);
  }

 private:
  struct Group {
    std::string name;
    BoundaryKind kind;
    std::optional<Motion<Dim>> motion;
    Points<Dim> displacements;
    std::optional<Vec<Dim>> normal;
    std::vector<Index> node_order{};  ///< nodes of `displacements`' columns; empty: the sorted group
    bool later = false;               ///< prescribed, displacements given to move()
  };
  using Entry = BoundaryEntry<Dim>;

  /// How messages name node v: with the file's id when the nodes come from a mesh.
  struct NodeNames {
    const Mesh<Dim>* mesh = nullptr;
    [[nodiscard]] std::string operator()(Index v) const { return mesh ? mesh->describe_node(v) : "node " + std::to_string(v); }
  };

  /// The conditions with each name that is not one of the mesh's groups replaced by the facet
  /// groups it names (see resolve()); an unmatched name stays, for resolve's message.
  [[nodiscard]] std::vector<Group> expand(const Mesh<Dim>& mesh) const {
    std::vector<Group> out;
    for (const Group& g : groups_) {
      if (mesh.find_group(g.name) != nullptr) {
        out.push_back(g);
        continue;
      }
      const auto in_set = [&](const PhysicalGroup& m, auto&& named) {
        return std::any_of(m.in_groups.begin(), m.in_groups.end(), named);
      };
      std::vector<std::string> names;
      for (const PhysicalGroup& m : mesh.groups)
        if (m.dim == Dim - 1 && in_set(m, [&](const std::string& s) { return s == g.name; })) names.push_back(m.name);
      if (names.empty() && NamePattern::is_pattern(g.name)) {
        const NamePattern pattern(g.name);
        const auto match = [&](const std::string& s) { return pattern.matches(s); };
        for (const PhysicalGroup& m : mesh.groups)
          if (m.dim == Dim - 1 && (match(m.name) || in_set(m, match))) names.push_back(m.name);
      }
      if (names.size() > 1 && (g.displacements.size() > 0 || !g.node_order.empty()))
        throw InputError("BoundarySpec::resolve: '" + g.name + "' names " + std::to_string(names.size()) +
                         " groups but is given one displacement array (give it one group's name)");
      if (names.empty()) names.push_back(g.name);
      for (std::string& name : names) {
        out.push_back(g);
        out.back().name = std::move(name);
      }
    }
    return out;
  }

  [[nodiscard]] ResolvedBoundary<Dim> resolve_nodes(const std::vector<Group>& groups, const Points<Dim>& points,
                                                    const GroupNodes& group_nodes, double to, double from,
                                                    const Mesh<Dim>* mesh) const {
    const NodeNames node_name{mesh};
    BoundaryCollector<Dim> entries(points.cols());
    for (auto g = groups.begin(); g != groups.end(); ++g)
      for (auto h = groups.begin(); h != g; ++h)
        if (h->name == g->name)
          throw InputError("BoundarySpec::resolve: group '" + g->name + "' is given twice (" + std::string(name(h->kind)) + " and " +
                           std::string(name(g->kind)) + "): give each group one condition");
    for (const auto& g : groups) {
      const auto found = group_nodes.find(g.name);
      if (found == group_nodes.end()) {
        std::string known;
        for (const auto& [name, list] : group_nodes) known += (known.empty() ? "" : ", ") + name;
        throw InputError("BoundarySpec::resolve: no group named '" + g.name + "' (known: " +
                         (known.empty() ? std::string("none") : known) + ")");
      }
      std::vector<Index> list = found->second;
      for (const Index v : list)
        if (v < 0 || v >= points.cols())
          throw InputError("BoundarySpec::resolve: group '" + g.name + "' refers to " + node_name(v) +
                           " (expected 0 to " + std::to_string(points.cols() - 1) + ")");
      std::sort(list.begin(), list.end());
      list.erase(std::unique(list.begin(), list.end()), list.end());
      add_group(g, list, points, to, from, node_name, entries);
    }
    return entries.resolve();
  }

  /// Sine of the angle below which two plane normals count as parallel (and a line as lying
  /// in a plane).
  static constexpr double parallel_tolerance = 1e-5;

  /// Adds the sliding plane `normal` to a sliding entry: parallel planes keep the plane, two
  /// planes leave their line (3D) or a point (2D), a plane not containing the line fixes it.
  static void intersect(Entry& e, const Vec<Dim>& normal) {
    const Entry fixed{BoundaryKind::fixed, Vec<Dim>::Zero(), Vec<Dim>::Zero()};
    if (e.direction.squaredNorm() > 0.0) {
      if (std::abs(e.direction.dot(normal)) > parallel_tolerance) e = fixed;
      return;
    }
    if constexpr (Dim == 3) {
      const Vec<3> line = e.normal.cross(normal);
      if (line.norm() > parallel_tolerance) e.direction = line.normalized();
    } else {
      if (std::abs(e.normal(0) * normal(1) - e.normal(1) * normal(0)) > parallel_tolerance) e = fixed;
    }
  }

  static Vec<Dim> plane_normal(const Group& g, const std::vector<Index>& list, const Points<Dim>& points) {
    if (g.normal) {
      const double length = g.normal->norm();
      if (!(length > 0.0) || !std::isfinite(length))
        throw InputError("BoundarySpec::resolve: sliding group '" + g.name + "' has a zero or non-finite normal");
      return *g.normal / length;
    }
    const auto count = static_cast<Index>(list.size());
    return sliding_plane_normal<Dim>(g.name, count, count < Dim ? PlaneFit<Dim>{} : fit_plane(points, list));
  }

  // The auxiliary nodes of a polyhedral mesh (the centres to_mesh() cuts its cells around) are
  // the library's, not the user's: one the displacements leave out takes the mean of the
  // displacements of the nodes it is the centre of (those of its face, or of its cell: the
  // other nodes of the elements around it), exact for a rigid or affine motion, as the centre
  // is their mean. Left missing when one of those has no displacement either.
  static void derive_auxiliary(const Mesh<Dim>& mesh, const std::vector<Index>& list, const std::vector<Index>& slot,
                               std::vector<char>& given, Points<Dim>& out) {
    const Index first_auxiliary = mesh.num_nodes() - mesh.num_auxiliary_nodes;
    std::vector<std::vector<Index>> around(list.size());
    bool any = false;
    for (std::size_t s = 0; s < list.size(); ++s) any = any || (!given[s] && list[s] >= first_auxiliary);
    if (!any) return;
    for (const auto& b : mesh.cells)
      for (Index e = 0; e < b.size(); ++e) {
        const auto nodes = b.element(e);
        for (const Index v : nodes) {
          const Index s = v < first_auxiliary ? -1 : slot[static_cast<std::size_t>(v)];
          if (s < 0 || given[static_cast<std::size_t>(s)]) continue;
          for (const Index u : nodes)
            if (u < first_auxiliary) around[static_cast<std::size_t>(s)].push_back(u);
        }
      }
    for (std::size_t s = 0; s < list.size(); ++s) {
      std::vector<Index>& centre_of = around[s];
      std::sort(centre_of.begin(), centre_of.end());
      centre_of.erase(std::unique(centre_of.begin(), centre_of.end()), centre_of.end());
      const bool known = !centre_of.empty() && std::all_of(centre_of.begin(), centre_of.end(), [&](Index u) {
        const Index t = slot[static_cast<std::size_t>(u)];
        return t >= 0 && given[static_cast<std::size_t>(t)] != 0;
      });
      if (!known) continue;
      Vec<Dim> mean = Vec<Dim>::Zero();
      for (const Index u : centre_of) mean += out.col(slot[static_cast<std::size_t>(u)]);
      out.col(static_cast<Index>(s)) = mean / static_cast<double>(centre_of.size());
      given[s] = 2;
    }
  }

  // The displacements of a group given with their nodes, in the order of the sorted `list`.
  static Points<Dim> by_node(const Group& g, const std::vector<Index>& list, Index num_nodes, const NodeNames& node_name) {
    std::vector<Index> slot(static_cast<std::size_t>(num_nodes), -1);
    for (std::size_t k = 0; k < list.size(); ++k) slot[static_cast<std::size_t>(list[k])] = static_cast<Index>(k);
    Points<Dim> out(Dim, static_cast<Index>(list.size()));
    std::vector<char> given(list.size(), 0);
    const std::string where = "BoundarySpec::resolve: group '" + g.name + "': ";
    for (std::size_t k = 0; k < g.node_order.size(); ++k) {
      const Index v = g.node_order[k];
      if (v < 0 || v >= num_nodes)
        throw InputError(where + "node " + std::to_string(v) + " is not a node of the mesh (expected 0 to " +
                         std::to_string(num_nodes - 1) + ")");
      const Index s = slot[static_cast<std::size_t>(v)];
      if (s < 0) throw InputError(where + node_name(v) + " is not in the group");
      if (given[static_cast<std::size_t>(s)]) throw InputError(where + node_name(v) + " is given twice");
      if (!g.displacements.col(static_cast<Index>(k)).allFinite())
        throw InputError(where + node_name(v) + " has a non-finite displacement");
      given[static_cast<std::size_t>(s)] = 1;
      out.col(s) = g.displacements.col(static_cast<Index>(k));
    }
    if (node_name.mesh != nullptr) derive_auxiliary(*node_name.mesh, list, slot, given, out);
    const auto missing = std::find(given.begin(), given.end(), 0);
    if (missing != given.end())
      throw InputError(where + node_name(list[static_cast<std::size_t>(missing - given.begin())]) +
                       " has no displacement (" + std::to_string(std::count(given.begin(), given.end(), 0)) + " of " +
                       std::to_string(list.size()) + " group nodes missing)");
    return out;
  }

  static void add_group(const Group& g, const std::vector<Index>& list, const Points<Dim>& points, double to,
                        double from, const NodeNames& node_name, BoundaryCollector<Dim>& entries) {
    const auto n = static_cast<Index>(list.size());
    Points<Dim> targets = Points<Dim>::Zero(Dim, n);
    if (g.kind == BoundaryKind::prescribed) {
      if (g.motion) {
        for (Index k = 0; k < n; ++k) targets.col(k) = g.motion->displacement(points.col(list[k]), to, from);
      } else if (g.later) {
        // zero until move()'s input says otherwise
      } else if (!g.node_order.empty()) {
        targets = (to - from) * by_node(g, list, points.cols(), node_name);
      } else {
        if (g.displacements.cols() != n)
          throw InputError("BoundarySpec::resolve: group '" + g.name + "' has " + std::to_string(n) +
                           " nodes (got " + std::to_string(g.displacements.cols()) + " displacements)");
        if (!g.displacements.allFinite())
          throw InputError("BoundarySpec::resolve: group '" + g.name + "' has a non-finite displacement");
        targets = (to - from) * g.displacements;
      }
    }
    const Vec<Dim> normal = g.kind == BoundaryKind::sliding ? plane_normal(g, list, points) : Vec<Dim>::Zero();
    for (Index k = 0; k < n; ++k) {
      const Entry incoming{g.kind, targets.col(k), normal};
      Entry* existing = entries.find(list[k]);
      if (!existing) {
        entries.add(list[k], incoming);
        continue;
      }
      Entry& e = *existing;
      if (e.kind == BoundaryKind::prescribed && g.kind == BoundaryKind::prescribed) {
        const double scale = std::max({1.0, e.displacement.norm(), incoming.displacement.norm()});
        if ((e.displacement - incoming.displacement).norm() > 1e-12 * scale)
          throw InputError("BoundarySpec::resolve: " + node_name(list[k]) +
                           " gets two different displacements (group '" + g.name + "' conflicts with an earlier group)");
      } else if (g.kind == BoundaryKind::sliding && e.kind == BoundaryKind::sliding) {
        intersect(e, normal);
      } else if (static_cast<int>(g.kind) < static_cast<int>(e.kind)) {
        e = incoming;
      }
    }
  }

  std::vector<Group> groups_;
};

}  // namespace meshmotion

// The compiled library (target meshmotion::compiled, src/core.cpp) holds these for Dim 2 and 3.
#ifdef MESHMOTION_COMPILED
namespace meshmotion {
extern template PlaneFit<2> fit_plane<2>(const Points<2>&, std::span<const Index>);
extern template PlaneFit<3> fit_plane<3>(const Points<3>&, std::span<const Index>);
extern template class BoundaryCollector<2>;
extern template class BoundaryCollector<3>;
extern template class BoundarySpec<2>;
extern template class BoundarySpec<3>;
}  // namespace meshmotion
#endif
