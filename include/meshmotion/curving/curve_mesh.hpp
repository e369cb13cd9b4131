#pragma once
/// \file
/// The curving pipeline (thesis chapter 3, issue 5): a linear mesh in, a certified curved
/// mesh of order 2 (default), 3 or 4 out.
///
/// 1. to_quadratic (convert_to_order past 2): the high-order nodes of every element type and
///    mixed meshes; linear nodes keep their numbers, high-order nodes are appended.
/// 2. snap_boundary: the facet nodes of every curved group go to the true boundary (2D
///    spline reconstruction by default; projection callbacks for analytic/CAD geometry, the
///    only way in 3D). Vertices already on the geometry stay.
/// 3. Regularization: the boundary displacements of step 2 are propagated into the domain by
///    a mover (the blending regularizer by default, RBF with Wendland C2, or any MeshMover):
///    curved groups are prescribed, other groups fixed or sliding. Only the nodes the mover
///    gives a nonzero displacement change. The motion may be split into `steps`, each a
///    fresh setup on the mesh moved so far (thesis table 4.2). The nodes inside faces and
///    cells it left straight then follow the curved edges (curving/inner_nodes.hpp).
/// 4. Certification: the certified scaled Jacobian (thesis eq. 3.3) of every cell; strict
///    mode throws InvalidMeshError when invalid cells remain, default mode reports them.
/// 5. Untangling of the cells below a threshold (curving/untangle.hpp).
/// 6. The geometric certificate: each curved wall's distance to the geometry it was curved
///    onto, sampled inside its facets (curving/geometry_distance.hpp); strict mode throws
///    InvalidMeshError when a facet is farther than geometry_tolerance × its size.
///
/// The blend's default length and the RBF's default support radius follow the boundary layer
/// (movers/boundary_layer.hpp): a factor × each curved wall's own layer thickness, or on a
/// wall without a layer a few of its node spacings at each node. docs/curving.md gives the
/// measured effect of other lengths and radii and of one radius for all walls.

#include "meshmotion/core/element.hpp"
#include "meshmotion/core/error.hpp"
#include "meshmotion/core/fields.hpp"
#include "meshmotion/core/mesh.hpp"
#include "meshmotion/core/orientation.hpp"
#include "meshmotion/core/topology.hpp"
#include "meshmotion/core/types.hpp"
#include "meshmotion/curving/boundary_snapping.hpp"
#include "meshmotion/curving/inner_nodes.hpp"
#include "meshmotion/curving/order_conversion.hpp"
#include "meshmotion/curving/p2_conversion.hpp"
#include "meshmotion/curving/untangle.hpp"
#include "meshmotion/movers/any_mover.hpp"
#include "meshmotion/movers/boundary.hpp"
#include "meshmotion/movers/boundary_layer.hpp"
#include "meshmotion/movers/detail/wall_distance.hpp"
#include "meshmotion/movers/mover.hpp"
#include "meshmotion/movers/registry.hpp"
#include "meshmotion/movers/rbf_kernels.hpp"
#include "meshmotion/movers/support_radius.hpp"
#include "meshmotion/quality/cell_quality.hpp"
#include "meshmotion/quality/quality_report.hpp"
#include "meshmotion/solvers/detail/stopwatch.hpp"
#include "meshmotion/spatial/kd_tree.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <memory>
#include <numbers>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <string_view>
#include <type_traits>
#include <unordered_map>
#include <utility>
#include <variant>
#include <vector>

namespace meshmotion {

/// Options of curve_mesh(). Their keys, types and one-line docs are in visit_options() below:
/// the programs' flags, Python's keywords, options files and docs/options.md come from there.
/// Measured effects of the defaults are in docs/curving.md.
template <int Dim>
struct CurveOptions {
  /// Order of the curved mesh: 2 (default), 3 or 4 (hexahedra, prisms and pyramids stop at 3;
  /// element_type()).
  int order = 2;
  /// Interior regularization: any registered method (mover_methods(), movers/registry.hpp).
  /// "blend" (wall-distance blending) is the default: it reached the best minimum on every
  /// case of curving_bench; "none" snaps the boundary alone, to show why the pipeline exists.
  std::string method = "blend";
  /// Typed options of `method` (its MoverOptions alternative); empty: the method's defaults.
  /// The pipeline sets what it measures in them, asking the options what they take: the
  /// support radius (and a radius per centre) of movers with one (TakesSupportRadius), the
  /// active region of those with one (TakesActiveRadius) unless these options set it, the
  /// layer recognition of those that blend over layers (TakesLayerOptions).
  std::optional<MoverOptions<Dim>> mover_options{};
  /// Movers with an active region (TakesActiveRadius: le, sle) solve only within this many
  /// support radii of the curved walls; 0: the whole mesh.
  double active_radius_factor = 4.0;
  /// Support radius of the movers that take one (TakesSupportRadius); 0:
  /// support_radius_factor × each wall's estimated layer (per_wall_radius), or × the thickest
  /// one (suggest_support_radius() with 3 wall node spacings when no wall has a layer).
  double support_radius = 0.0;
  /// 4 in 2D, 1 in 3D (a larger 3D support multiplies the factorization's cost).
  double support_radius_factor = Dim == 2 ? 4.0 : 1.0;
  /// With the default radius, each curved wall's centres get the radius of its own layer
  /// (walls without a layer: each node 2 node spacings of its own facets, half one where a
  /// facet is snapped away from its cell or hardly moves, local_spacing_radii()), and the
  /// other boundary centres the radius of the nearest moving
  /// wall node, so a thin layer is not overrun by the support of a thick one. false: the
  /// thickest layer's radius everywhere (the thesis's one radius). Differing radii make the
  /// RBF system nonsymmetric (sparse LU instead of Cholesky).
  bool per_wall_radius = true;
  /// A default radius is shrunk until a support holds at most this many boundary nodes on
  /// average around the moving ones; 0: no limit. 2D supports grow only linearly with the
  /// radius and are not limited by default.
  double max_support_nodes = Dim == 2 ? 0.0 : 100.0;
  /// Boundary nodes that stay put (fixed, sliding, or snapped with zero displacement) are RBF
  /// centres only within this many support radii of a node the snapping moved; 0 keeps every
  /// boundary node a centre (the thesis). A compact kernel couples centres only through
  /// overlapping supports, so farther ones barely change the interpolant.
  double centre_reach = 2.0;
  /// The regularization in this many increments, each re-based on the moved mesh.
  int steps = 1;
  /// After the regularization, the nodes inside the faces and cells of the cells touching a
  /// curved wall that it left where they were are placed from the nodes around them
  /// (curving/inner_nodes.hpp), as Gmsh places them from its curved edges. false: they stay.
  bool inner_nodes = true;
  /// After the regularization, the nodes inside the domain around cells below a threshold of
  /// the certified scaled Jacobian are optimized (curving/untangle.hpp); not for movers that
  /// leave the interior alone (method "none").
  UntangleOptions untangle{};
  /// Geometry per group name. Groups not listed: spline reconstruction in 2D when
  /// `spline_by_default`, straight otherwise; in 3D the WALF surface reconstruction for
  /// wall-named triangle groups (below), straight otherwise (give a projection callback or
  /// BoundaryGeometry::spline() for any other). Text: geometry_from_text().
  std::map<std::string, BoundaryGeometry<Dim>, std::less<>> geometry;
  bool spline_by_default = true;
  /// 3D: groups not listed whose name says they are walls (detail::looks_like_wall: "wall",
  /// "body", "wing", ...) and whose facets are triangles get the surface reconstruction;
  /// CurveResult::curved_groups says which. false: they stay straight.
  bool reconstruct_walls_by_default = true;
  /// Groups that slide in their plane (symmetry); other non-curved groups are fixed.
  std::vector<std::string> sliding;
  /// Groups given no geometry that lie in one plane (a line in 2D; planar_group_tags()) and
  /// are not named like walls stay straight, and those that meet a curved group slide in their plane: a symmetry
  /// plane or a flat side cut by a curved wall lets the cells at the cut follow the wall (the
  /// sphere on its STEP file at P3: minimum 0.61 with the plane fixed, 0.86 sliding).
  /// CurveResult::sliding_groups says which slid. false: only `sliding` slides.
  bool slide_planar_groups = true;
  /// Corners and midpoint rule of the spline; tolerance of "already on the geometry".
  SnapOptions snap{};
  BoundaryLayerOptions layer{};
  ReportOptions report{};
  /// A curved facet whose distance to its geometry (bounded by sampling, geometry_distance.hpp)
  /// exceeds this × its size is off the geometry: reported, and refused in strict mode. The
  /// facets of the data folder's cases are at most 0.004 of their size from a CAD model or a
  /// spline, 0.025 from a coarse 3D reconstruction; a node on the far side of a closed curve
  /// puts its facet at more than 1 (docs/curving.md, "What is certified").
  double geometry_tolerance = 0.1;
  /// Throw InvalidMeshError when invalid cells, facets off the geometry or cells turned over by
  /// the snapping remain (default: report them).
  bool strict = false;
  /// Called with a line of text before each stage.
  std::function<void(const std::string&)> progress{};
};

/// The keys of CurveOptions: every field text may set (`geometry` has its own text form,
/// geometry_from_text(); `mover_options` takes the keys of the method, MoverConfig).
template <int Dim, class F>
void visit_options(CurveOptions<Dim>& o, F&& f, const std::string& prefix = {}) {
  f(prefix + "order", o.order, "order of the curved mesh: 2, 3 or 4 (hexahedra, prisms and pyramids: 2 or 3)");
  f(prefix + "method", o.method, "interior regularization: a registered mover (its options are keys too)");
  f(prefix + "support_radius", o.support_radius, "support radius of the movers with one (0: from each wall's boundary layer)");
  f(prefix + "support_radius_factor", o.support_radius_factor, "default support radius = this x the wall's layer thickness");
  f(prefix + "per_wall_radius", o.per_wall_radius, "default radius: each wall its own (false: the thickest wall's for all)");
  f(prefix + "max_support_nodes", o.max_support_nodes, "shrink a default radius to this many boundary nodes per support (0: no limit)");
  f(prefix + "centre_reach", o.centre_reach, "RBF centres only within this x the radius of a moving node (0: every boundary node)");
  f(prefix + "active_radius_factor", o.active_radius_factor, "le/sle: solve within this x the support radius of the curved walls (0: whole mesh)");
  f(prefix + "steps", o.steps, "regularize in this many increments");
  f(prefix + "inner_nodes", o.inner_nodes, "re-place the nodes inside faces and cells next to a curved wall from the nodes around them");
  visit_options(o.untangle, f, prefix);
  f(prefix + "spline_by_default", o.spline_by_default, "2D: groups without a geometry get a spline");
  f(prefix + "reconstruct_walls_by_default", o.reconstruct_walls_by_default,
    "3D: wall-named triangle groups without a geometry get the surface reconstruction");
  f(prefix + "sliding", o.sliding, "groups sliding in their plane (symmetry), comma-separated");
  f(prefix + "slide_planar_groups", o.slide_planar_groups,
    "groups without a geometry lying in a plane (not named like walls) stay straight, and slide in it where they meet a curved group");
  visit_options(o.snap, f, prefix);
  visit_options(o.layer, f, prefix);
  visit_options(o.report, f, prefix);
  f(prefix + "geometry_tolerance", o.geometry_tolerance,
    "a curved facet farther than this x its size from its geometry is off it (reported; refused when strict)");
  f(prefix + "strict", o.strict, "write nothing when invalid cells, facets off the geometry or turned-over cells remain");
}

/// Wall-clock seconds of each stage.
struct CurveTimes {
  double cad = 0.0;  ///< reading a CAD file and matching it to the groups (by the caller: curve_mesh's --geometry FILE)
  double quadratic = 0.0;
  double snap = 0.0;
  double layer = 0.0;  ///< boundary-layer estimate for the default radius
  double regularize = 0.0;
  double untangle = 0.0;
  double certify = 0.0;
  double distance = 0.0;  ///< the geometric certificate
  double total = 0.0;
};

template <class F>
void visit_fields(const CurveTimes& t, F&& f) {
  f("cad", t.cad, "reading the CAD file, matching its entities to the groups and placing the curved nodes on them (the program's --geometry FILE)");
  f("quadratic", t.quadratic, "conversion to the curved order");
  f("snap", t.snap, "snapping the boundary to the geometry");
  f("layer", t.layer, "estimating the walls' boundary layers");
  f("regularize", t.regularize, "the mover's setup and moves");
  f("untangle", t.untangle, "optimizing the cells below the threshold");
  f("certify", t.certify, "certifying the scaled Jacobian");
  f("distance", t.distance, "measuring the curved walls' distance to their geometry");
  f("total", t.total, "the whole pipeline, with the CAD stage");
}

/// What curve_mesh() produced and measured.
template <int Dim>
struct CurveResult {
  Mesh<Dim> curved;                 ///< the curved mesh; nodes 0..num_linear_nodes-1 are the input's
  Index num_linear_nodes = 0;
  int order = 2;
  CurveTimes seconds;
  std::string method;
  double support_radius = 0.0;      ///< support radius given to the mover, the largest when per wall (0 for movers without one)
  std::vector<double> wall_support_radii;  ///< per wall of `layers` when each has its own radius (rbf default)
  bool support_radius_limited = false;  ///< the default radius was shrunk to max_support_nodes
  std::vector<std::string> curved_groups;  ///< the groups given a curved boundary (not straight)
  std::vector<std::string> sliding_groups;  ///< the groups that slid in their plane (given or planar)
  std::vector<WallLayer> layers;    ///< estimated layers of the curved walls (when estimated)
  Index snapped_nodes = 0;          ///< boundary nodes given a position on the true boundary
  Index moved_vertices = 0;         ///< linear vertices that were off the geometry
  /// Cells whose straight shape (their vertices) the snapping's vertex moves turned over: the
  /// validity certificate measures each cell against its orientation in the input, which such a
  /// cell no longer has even where its scaled Jacobian is positive.
  Index reversed_cells = 0;
  double max_boundary_displacement = 0.0;
  Index moved_nodes = 0;            ///< nodes not on the boundary that the regularization moved
  Index solver_iterations = 0;      ///< summed over steps
  std::vector<MoverStats> mover_steps;  ///< the mover's stats per step
  UntangleReport untangle;          ///< what the untangling did (cells_below = 0: nothing to do)
  QualityReport quality;            ///< certified scaled Jacobian
  std::vector<double> cell_quality;  ///< the certified scaled Jacobian of each cell, in cell order
  std::vector<GeometryDistance> geometry_distance;  ///< per curved group, the distance of its facets to its geometry
  [[nodiscard]] Index invalid() const noexcept { return quality.num_invalid; }
  /// Curved facets farther than CurveOptions::geometry_tolerance from their geometry.
  [[nodiscard]] Index off_geometry() const noexcept {
    Index n = 0;
    for (const GeometryDistance& w : geometry_distance) n += w.facets_off;
    return n;
  }
};

/// The report of CurveResult: every field but the mesh and the per-cell values.
template <int Dim, class F>
void visit_fields(const CurveResult<Dim>& r, F&& f) {
  f("method", r.method, "the mover that regularized the interior");
  f("order", r.order, "order of the curved mesh");
  f("num_linear_nodes", r.num_linear_nodes, "nodes of the input (numbered first in the curved mesh)");
  f("curved_groups", r.curved_groups, "groups given a curved boundary");
  f("sliding_groups", r.sliding_groups, "groups that slid in their plane: those given, and planar ones meeting a curved group");
  f("support_radius", r.support_radius, "support radius given to the mover (the largest when per wall; 0 without one)");
  f("wall_support_radii", r.wall_support_radii, "per wall of layers, when each has its own radius");
  f("support_radius_limited", r.support_radius_limited, "the default radius was shrunk to max_support_nodes");
  f("layers", r.layers, "estimated boundary layers of the curved walls");
  f("snapped_nodes", r.snapped_nodes, "boundary nodes given their place on the geometry");
  f("moved_vertices", r.moved_vertices, "linear vertices that were off the geometry");
  f("reversed_cells", r.reversed_cells, "cells whose straight shape the snapping's vertex moves turned over");
  f("max_boundary_displacement", r.max_boundary_displacement, "largest move of a boundary node");
  f("moved_nodes", r.moved_nodes, "nodes off the boundary that the regularization moved");
  f("solver_iterations", r.solver_iterations, "iterative solver iterations, summed over the steps");
  f("mover_steps", r.mover_steps, "the mover's stats per step");
  f("untangle", r.untangle, "what the untangling did");
  f("invalid", r.invalid(), "cells whose certified scaled Jacobian is not positive");
  f("quality", r.quality, "certified scaled Jacobian of the curved mesh");
  f("geometry_distance", r.geometry_distance, "per curved group: its facets' distance to the geometry it was curved onto");
  f("off_geometry", r.off_geometry(), "curved facets farther than geometry_tolerance x their size from their geometry");
  f("seconds", r.seconds, "wall-clock seconds per stage");
}

namespace detail {

/// "curve_mesh: " before the message of e, whose own "meshmotion: " prefix InputError adds again.
[[nodiscard]] inline std::string curve_mesh_message(const Error& e) {
  std::string_view message = e.what();
  constexpr std::string_view prefix = "meshmotion: ";
  if (message.starts_with(prefix)) message.remove_prefix(prefix.size());
  return "curve_mesh: " + std::string(message);
}

}  // namespace detail

/// Sets curve_mesh()'s options from text: its own keys (visit_options above), "method" first
/// wherever it stands, and every other key as an option of the method's mover
/// (MoverConfig::set). Throws InputError for a key neither takes (naming the known ones), a
/// malformed value, or an unknown method.
template <int Dim>
void set_curve_options(CurveOptions<Dim>& options, const KeyValues& values) {
  CurveOptions<Dim> o = options;  // `options` changes only when every value is taken
  const std::vector<std::string> own = option_keys(o);
  for (const auto& [key, text] : values)
    if (key == "method") parse_option_value(key, text, o.method);
  MoverConfig<Dim> config;
  try {
    config = mover_config<Dim>(o.method);
  } catch (const InputError& e) {
    throw InputError(detail::curve_mesh_message(e));
  }
  if (o.mover_options && o.mover_options->index() == config.options.index()) config.options = *o.mover_options;
  KeyValues mover;
  const std::vector<std::string> theirs = config.keys();
  for (const auto& [key, text] : values) {
    if (key == "method" || set_option(o, key, text)) continue;
    if (std::find(theirs.begin(), theirs.end(), key) == theirs.end()) {
      std::vector<std::string> known = own;
      known.insert(known.end(), theirs.begin(), theirs.end());
      throw InputError("curve_mesh: " + unknown_key_message("curve_mesh with method '" + o.method + "'", key, known));
    }
    mover.emplace_back(key, text);
  }
  config.set(mover);
  o.mover_options = config.options;
  options = std::move(o);
}

/// Every key of curve_mesh() with method `method`: its own, then the mover's, each with its
/// default as text and its doc line. The mover's keys that the pipeline's own shadow (the
/// support radius) are left out.
template <int Dim>
[[nodiscard]] std::vector<OptionDoc> curve_option_docs(const std::string& method) {
  CurveOptions<Dim> o;
  o.method = method;
  std::vector<OptionDoc> docs = option_docs(o);
  for (OptionDoc& d : mover_config<Dim>(method).docs())
    if (std::none_of(docs.begin(), docs.end(), [&](const OptionDoc& own) { return own.key == d.key; })) docs.push_back(std::move(d));
  return docs;
}

/// The tags of the facet groups (dim - 1) that lie in one plane, a line in 2D, to round-off
/// (PlaneFit::planar()): what CurveOptions::slide_planar_groups keeps straight.
template <int Dim>
[[nodiscard]] std::set<int> planar_group_tags(const Mesh<Dim>& mesh) {
  std::set<int> out;
  for (const auto& g : mesh.groups)
    if (g.dim == Dim - 1) {
      const std::vector<Index> nodes = mesh.group_nodes(g.tag);
      if (static_cast<Index>(nodes.size()) >= Dim && fit_plane(mesh.points, nodes).planar()) out.insert(g.tag);
    }
  return out;
}

namespace detail {

/// Whether a group's name says it is a solid wall: it holds "wall", or names a body
/// ("body", "airfoil", "wing", "blade", "hull", "sphere", "cylinder"), whatever the case.
[[nodiscard]] inline bool looks_like_wall(std::string name) {
  for (char& c : name) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  for (const char* word : {"wall", "body", "airfoil", "wing", "blade", "hull", "sphere", "cylinder"})
    if (name.find(word) != std::string::npos) return true;
  return false;
}

/// Whether every facet of group `tag` is a triangle (what the surface reconstruction takes).
template <int Dim>
[[nodiscard]] bool all_triangles(const Mesh<Dim>& mesh, int tag) {
  bool any = false;
  for (const auto& block : mesh.facets)
    for (const int t : block.tags)
      if (t == tag) {
        if (shape(block.type) != Shape::triangle) return false;
        any = true;
      }
  return any;
}

/// Group names and tags of the facet groups and the geometry each gets.
template <int Dim>
[[nodiscard]] std::map<int, BoundaryGeometry<Dim>> resolve_geometry(const Mesh<Dim>& mesh, const CurveOptions<Dim>& options,
                                                                    const std::set<int>& planar) {
  std::map<int, BoundaryGeometry<Dim>> out;
  for (const auto& [group, geo] : options.geometry) {
    const PhysicalGroup& g = mesh.group(group);
    if (g.dim != Dim - 1)
      throw InputError("curve_mesh: group '" + group + "' has dimension " + std::to_string(g.dim) + " (expected " +
                       std::to_string(Dim - 1) + ")");
    out[g.tag] = geo;
  }
  const auto is_sliding = [&](const std::string& n) {
    return std::find(options.sliding.begin(), options.sliding.end(), n) != options.sliding.end();
  };
  for (const auto& g : mesh.groups)
    if (g.dim == Dim - 1 && !out.count(g.tag)) {
      const bool by_default = Dim == 2 ? options.spline_by_default
                                       : options.reconstruct_walls_by_default && looks_like_wall(g.name) && all_triangles(mesh, g.tag);
      const bool flat = planar.count(g.tag) > 0 && !looks_like_wall(g.name);
      out[g.tag] = by_default && !is_sliding(g.name) && !flat ? BoundaryGeometry<Dim>::spline() : BoundaryGeometry<Dim>::straight();
    }
  return out;
}

/// The groups that slide: those given, then the planar groups (planar_group_tags()) that
/// are not `curved` and share a node with a `moving` wall.
template <int Dim>
[[nodiscard]] std::vector<std::string> sliding_groups(const Mesh<Dim>& mesh, const CurveOptions<Dim>& options,
                                                      const std::vector<std::string>& curved,
                                                      const std::vector<std::string>& moving, const std::set<int>& planar) {
  std::vector<std::string> out = options.sliding;
  if (planar.empty() || moving.empty()) return out;
  std::vector<char> on_wall(static_cast<std::size_t>(mesh.num_nodes()), 0);
  for (const std::string& w : moving)
    for (const Index v : mesh.group_nodes(std::string_view(w))) on_wall[static_cast<std::size_t>(v)] = 1;
  const auto listed = [](const std::vector<std::string>& list, const std::string& name) {
    return std::find(list.begin(), list.end(), name) != list.end();
  };
  for (const auto& g : mesh.groups) {
    if (g.dim != Dim - 1 || !planar.count(g.tag) || listed(curved, g.name) || listed(out, g.name)) continue;
    const std::vector<Index> nodes = mesh.group_nodes(g.tag);
    if (std::any_of(nodes.begin(), nodes.end(), [&](Index v) { return on_wall[static_cast<std::size_t>(v)] != 0; }))
      out.push_back(g.name);
  }
  return out;
}

/// Removes from `walls` the groups whose snapped nodes all moved less than the snapping's
/// on-geometry tolerance, and returns a flag per node: 1 for the nodes of those groups that
/// are on no remaining wall.
template <int Dim>
[[nodiscard]] std::vector<char> drop_unmoved_walls(const Mesh<Dim>& mesh, const SnappedBoundary<Dim>& snapped,
                                                   std::vector<std::string>& walls, const SnapOptions& snap) {
  std::vector<Index> slot(static_cast<std::size_t>(mesh.num_nodes()), -1);
  for (std::size_t k = 0; k < snapped.nodes.size(); ++k) slot[static_cast<std::size_t>(snapped.nodes[k])] = static_cast<Index>(k);
  const double tolerance =
      snap.on_geometry_tolerance * (mesh.points.rowwise().maxCoeff() - mesh.points.rowwise().minCoeff()).norm();
  std::vector<char> still(static_cast<std::size_t>(mesh.num_nodes()), 0), on_moving(still.size(), 0);
  std::vector<std::string> moving;
  for (const std::string& w : walls) {
    const std::vector<Index> nodes = mesh.group_nodes(std::string_view(w));
    const bool moves = std::any_of(nodes.begin(), nodes.end(), [&](Index v) {
      const Index k = slot[static_cast<std::size_t>(v)];
      return k >= 0 && snapped.displacements.col(k).norm() > tolerance;
    });
    for (const Index v : nodes) (moves ? on_moving : still)[static_cast<std::size_t>(v)] = 1;
    if (moves) moving.push_back(w);
  }
  for (std::size_t v = 0; v < still.size(); ++v) still[v] = still[v] && !on_moving[v];
  walls = std::move(moving);
  return still;
}

/// The boundary the mover sees: snapped nodes prescribed (but those flagged `still`), sliding
/// groups sliding, every other boundary node (tagged or not) fixed. `topology` is
/// unique_facets(mesh).
template <int Dim>
[[nodiscard]] ResolvedBoundary<Dim> curving_boundary(const Mesh<Dim>& mesh, const SnappedBoundary<Dim>& snapped,
                                                     const std::vector<char>& still, const std::vector<std::string>& sliding,
                                                     const FacetTopology& topology) {
  using Entry = BoundaryEntry<Dim>;
  BoundaryCollector<Dim> entries(mesh.num_nodes());
  for (std::size_t k = 0; k < snapped.nodes.size(); ++k)
    if (!still[static_cast<std::size_t>(snapped.nodes[k])])
      entries.add(snapped.nodes[k], Entry{BoundaryKind::prescribed, Vec<Dim>(snapped.displacements.col(static_cast<Index>(k)))});
  if (!sliding.empty()) {
    BoundarySpec<Dim> spec;
    for (const auto& g : sliding) spec.sliding(g);
    const ResolvedBoundary<Dim> slide = spec.resolve(mesh);
    for (Index k = 0; k < slide.size(); ++k)
      entries.add(slide.nodes[static_cast<std::size_t>(k)],
                  Entry{slide.kinds[static_cast<std::size_t>(k)], Vec<Dim>::Zero(), Vec<Dim>(slide.normals.col(k)),
                        Vec<Dim>(slide.directions.col(k))});
  }
  const auto fix = [&](const std::vector<ElementBlock>& blocks) {
    for (const auto& b : blocks)
      for (const Index v : b.connectivity) entries.add(v, Entry{BoundaryKind::fixed});
  };
  fix(mesh.facets);
  fix(boundary_facets(mesh, topology));
  return entries.resolve();
}

/// The nodes of `boundary` with a nonzero displacement.
template <int Dim>
[[nodiscard]] std::vector<Index> moving_nodes(const ResolvedBoundary<Dim>& boundary) {
  std::vector<Index> moving;
  for (Index k = 0; k < boundary.size(); ++k)
    if (boundary.displacements.col(k).squaredNorm() > 0.0) moving.push_back(boundary.nodes[static_cast<std::size_t>(k)]);
  return moving;
}

/// The entries of `boundary` within `reach` of an entry with a nonzero displacement. The RBF
/// system of a compact kernel couples centres only through overlapping supports, so the
/// coefficients of zero-displacement centres decay with their distance from the motion; those
/// beyond a couple of radii change the interpolant by a small fraction of the displacement.
template <int Dim>
[[nodiscard]] ResolvedBoundary<Dim> near_motion(const Mesh<Dim>& mesh, const ResolvedBoundary<Dim>& boundary, double reach) {
  const std::vector<Index> moving = moving_nodes(boundary);
  if (moving.empty()) return boundary;
  Points<Dim> at(Dim, static_cast<Index>(moving.size()));
  for (std::size_t k = 0; k < moving.size(); ++k) at.col(static_cast<Index>(k)) = mesh.points.col(moving[k]);
  const KdTree<Dim> tree(at);
  std::vector<Index> kept;  // entries of `boundary`, whose nodes ascend
  for (Index k = 0; k < boundary.size(); ++k) {
    const Vec<Dim> p = mesh.points.col(boundary.nodes[static_cast<std::size_t>(k)]);
    // Most boundary nodes (inflow, outflow, farfield) lie far outside the moving nodes' box.
    if (tree.box_squared_distance(p) <= reach * reach && tree.nearest(p).second <= reach * reach) kept.push_back(k);
  }
  return detail::collect_boundary<Dim>(static_cast<Index>(kept.size()), [&](auto&& add) {
    for (const Index k : kept)
      add(boundary.nodes[static_cast<std::size_t>(k)],
          BoundaryEntry<Dim>{boundary.kinds[static_cast<std::size_t>(k)], Vec<Dim>(boundary.displacements.col(k)),
                             Vec<Dim>(boundary.normals.col(k)), Vec<Dim>(boundary.directions.col(k))});
  });
}

/// The largest radius ≤ `radius` whose ball around a node of `moving` holds at most `budget`
/// nodes of `boundary` on average (a sample of up to 256 of them). Supports on a surface hold
/// ~r² nodes, on a curve ~r: a few rescaling rounds settle either.
template <int Dim>
[[nodiscard]] double limit_support_radius(const Mesh<Dim>& mesh, const ResolvedBoundary<Dim>& boundary,
                                          const std::vector<Index>& moving, double radius, double budget) {
  if (moving.empty() || !(budget > 0.0)) return radius;
  Points<Dim> at(Dim, boundary.size());
  for (Index k = 0; k < boundary.size(); ++k) at.col(k) = mesh.points.col(boundary.nodes[static_cast<std::size_t>(k)]);
  const KdTree<Dim> tree(at);
  const std::size_t stride = std::max<std::size_t>(1, moving.size() / 256);
  std::vector<Neighbor> found;
  for (int round = 0; round < 4; ++round) {
    double total = 0.0, samples = 0.0;
    for (std::size_t i = 0; i < moving.size(); i += stride, samples += 1.0)
      total += static_cast<double>(tree.radius_search(Vec<Dim>(mesh.points.col(moving[i])), radius, found));
    const double mean = total / samples;
    if (mean <= budget) break;
    radius *= std::sqrt(budget / mean);
  }
  return radius;
}

/// The wall (index into `walls`) of each node of the facets of the named groups; -1 for other
/// nodes. A node shared by two walls belongs to the first listed.
template <int Dim>
[[nodiscard]] std::vector<int> wall_of_nodes(const Mesh<Dim>& mesh, const std::vector<std::string>& walls) {
  std::vector<int> wall_of(static_cast<std::size_t>(mesh.num_nodes()), -1);
  for (std::size_t w = walls.size(); w-- > 0;) {
    const int tag = mesh.group(walls[w]).tag;
    for (const auto& block : mesh.facets)
      for (Index e = 0; e < block.size(); ++e)
        if (block.tags[static_cast<std::size_t>(e)] == tag)
          for (const Index v : block.element(e)) wall_of[static_cast<std::size_t>(v)] = static_cast<int>(w);
  }
  return wall_of;
}

/// Default support radii from the wall layers (see CurveOptions::support_radius).
struct DefaultRadii {
  double uniform = 0.0;          ///< one radius for every wall: the thickest layer's
  std::vector<double> per_wall;  ///< each wall's own: its layer's, or its largest local radius without a layer
  std::vector<double> per_node;  ///< nodes of walls without a layer: local_spacing_radii() (0 elsewhere)
  bool limited = false;          ///< some wall's layer radius was shrunk to max_support_nodes
};

/// For the nodes of the facets tagged `tag`: 2 × the node spacing of the largest facet holding
/// the node (its mean vertex-to-vertex edge length over the order), written into `radii`
/// (num_nodes entries). A wall without a boundary layer has nothing else to size its motion
/// by, and its spacing varies: on the RAE2822 the leading edge's cells are 0.007 wide where
/// the wall's median spacing gives a radius of 0.058, which spreads the leading edge's
/// displacement over many cells and lowers the snapped quality (0.79 to 0.61 at P2). With 2
/// the RBF raises it instead at orders 2 to 4; 1 leaves it as snapped, 4 lowers it
/// (docs/curving.md, "A radius per node on walls without a layer").
/// A facet snapped away from its cell (detail::bulging_away(): a farfield circle) only enlarges
/// it, and one that hardly moves has nothing to spread: they get half their spacing, which
/// reaches no other node, so their motion stays on them, as the blend leaves the first. At 2
/// spacings the 30P30N's farfield nodes took a radius of 1.03 and the RBF setup 2.5 s for the
/// minimum that a radius of 0.0022 gives in a tenth of the time.
template <int Dim>
void local_spacing_radii(const Mesh<Dim>& mesh, int tag, const SnappedBoundary<Dim>& snapped, std::vector<double>& radii) {
  const std::vector<WallFacet> wall = wall_facets(mesh, std::span<const int>(&tag, 1));
  const auto displacement = [&](Index v) -> Vec<Dim> {
    const auto it = std::lower_bound(snapped.nodes.begin(), snapped.nodes.end(), v);
    if (it == snapped.nodes.end() || *it != v) return Vec<Dim>::Zero();
    return snapped.displacements.col(static_cast<Index>(it - snapped.nodes.begin()));
  };
  const std::vector<char> away = bulging_away(mesh, wall, displacement);
  for (std::size_t i = 0; i < wall.size(); ++i) {
    const WallFacet& f = wall[i];
    const auto sides = edges(f.type);
    double length = 0.0;
    for (const auto& side : sides)
      length += (mesh.points.col(f.nodes[static_cast<std::size_t>(side[0])]) - mesh.points.col(f.nodes[static_cast<std::size_t>(side[1])])).norm();
    const double spacing = length / static_cast<double>(sides.size() * static_cast<std::size_t>(order(f.type)));
    // A facet moved by at most 2% of its spacing dents its cell by as little: the 30P30N
    // farfield's flat side has 49 such facets bulging inward where the spline meets its arc.
    const auto nodes = std::span<const Index>(f.nodes.data(), static_cast<std::size_t>(num_nodes(f.type)));
    const bool slight = std::all_of(nodes.begin(), nodes.end(), [&](Index v) { return displacement(v).norm() <= 0.02 * spacing; });
    const double radius = (away[i] != 0 || slight ? 0.5 : 2.0) * spacing;
    for (int k = 0; k < num_nodes(f.type); ++k) {
      double& r = radii[static_cast<std::size_t>(f.nodes[static_cast<std::size_t>(k)])];
      r = std::max(r, radius);
    }
  }
}

/// suggest_support_radius() over the snapped nodes for which keep(node) holds, with 3 wall
/// node spacings; 0 for fewer than two such nodes. Curving displacements are tiny, so the
/// spacing term decides. The motion default (10 spacings) spans the whole body on the sphere
/// test case (0.75 for radius 0.5) and gives 0.22, below snapping alone; 3 spacings give 0.64
/// (docs/curving.md).
template <int Dim, class Keep>
[[nodiscard]] double spacing_radius(const Mesh<Dim>& mesh, const SnappedBoundary<Dim>& snapped, Keep keep) {
  std::vector<Index> kept;
  for (std::size_t k = 0; k < snapped.nodes.size(); ++k)
    if (keep(snapped.nodes[k])) kept.push_back(static_cast<Index>(k));
  if (kept.size() < 2) return 0.0;
  Points<Dim> at(Dim, static_cast<Index>(kept.size())), moved(Dim, static_cast<Index>(kept.size()));
  for (std::size_t i = 0; i < kept.size(); ++i) {
    at.col(static_cast<Index>(i)) = mesh.points.col(snapped.nodes[static_cast<std::size_t>(kept[i])]);
    moved.col(static_cast<Index>(i)) = snapped.displacements.col(kept[i]);
  }
  SupportRadiusOptions wall_spacing;
  wall_spacing.spacing_factor = 3.0;
  return suggest_support_radius(at, moved, wall_spacing);
}

/// The default radii of the curved `walls` (wall_of: wall_of_nodes()): support_radius_factor ×
/// each wall's layer thickness, limited to max_support_nodes boundary nodes per support around
/// the wall's moving nodes; a wall without a layer gets a radius per node from its facets' node
/// spacing (local_spacing_radii(); per_wall: the largest of them).
/// The uniform radius is the largest layer radius, or spacing_radius() of every snapped node
/// when no wall has a layer.
template <int Dim>
[[nodiscard]] DefaultRadii default_support_radii(const Mesh<Dim>& mesh, const ResolvedBoundary<Dim>& boundary,
                                                 const SnappedBoundary<Dim>& snapped, const std::vector<WallLayer>& layers,
                                                 const std::vector<int>& wall_of, const CurveOptions<Dim>& options) {
  if (options.max_support_nodes < 0.0)
    throw InputError("curve_mesh: max_support_nodes must be non-negative (got " + std::to_string(options.max_support_nodes) + ")");
  DefaultRadii out;
  out.per_wall.assign(layers.size(), 0.0);
  std::vector<std::vector<Index>> moving(layers.size());
  for (const Index v : moving_nodes(boundary))
    if (const int w = wall_of[static_cast<std::size_t>(v)]; w >= 0) moving[static_cast<std::size_t>(w)].push_back(v);
  for (std::size_t w = 0; w < layers.size(); ++w) {
    if (!(layers[w].thickness > 0.0)) continue;
    const double full = options.support_radius_factor * layers[w].thickness;
    out.per_wall[w] = limit_support_radius(mesh, boundary, moving[w], full, options.max_support_nodes);
    out.limited = out.limited || out.per_wall[w] < full;
    out.uniform = std::max(out.uniform, out.per_wall[w]);
  }
  if (!(out.uniform > 0.0)) out.uniform = spacing_radius(mesh, snapped, [](Index) { return true; });
  if (!(out.uniform > 0.0)) out.uniform = 1.0;  // nothing moves: any radius
  for (std::size_t w = 0; w < layers.size(); ++w)
    if (!(out.per_wall[w] > 0.0)) {
      if (out.per_node.empty()) out.per_node.assign(static_cast<std::size_t>(mesh.num_nodes()), 0.0);
      local_spacing_radii(mesh, layers[w].tag, snapped, out.per_node);
      for (const Index v : moving[w]) out.per_wall[w] = std::max(out.per_wall[w], out.per_node[static_cast<std::size_t>(v)]);
      if (!(out.per_wall[w] > 0.0)) out.per_wall[w] = out.uniform;
    }
  return out;
}

/// The radius of each entry of `given`: its own (per_node, when positive) or its wall's, or
/// for a node on no curved wall (fixed, sliding) that of the nearest node that moves.
template <int Dim>
[[nodiscard]] std::vector<double> entry_radii(const Mesh<Dim>& mesh, const ResolvedBoundary<Dim>& given,
                                              const std::vector<int>& wall_of, const std::vector<double>& per_wall,
                                              const std::vector<double>& per_node) {
  const auto radius_of = [&](Index v) {
    if (!per_node.empty() && per_node[static_cast<std::size_t>(v)] > 0.0) return per_node[static_cast<std::size_t>(v)];
    return per_wall[static_cast<std::size_t>(wall_of[static_cast<std::size_t>(v)])];
  };
  std::vector<Index> moving;
  for (const Index v : moving_nodes(given))
    if (wall_of[static_cast<std::size_t>(v)] >= 0) moving.push_back(v);
  Points<Dim> at(Dim, static_cast<Index>(moving.size()));
  for (std::size_t k = 0; k < moving.size(); ++k) at.col(static_cast<Index>(k)) = mesh.points.col(moving[k]);
  const KdTree<Dim> tree(at);
  const double largest = *std::max_element(per_wall.begin(), per_wall.end());
  std::vector<double> radii(given.nodes.size(), largest);
  for (std::size_t k = 0; k < given.nodes.size(); ++k) {
    Index v = given.nodes[k];
    if (wall_of[static_cast<std::size_t>(v)] < 0 && !moving.empty()) v = moving[tree.nearest(Vec<Dim>(mesh.points.col(v))).first];
    if (wall_of[static_cast<std::size_t>(v)] >= 0) radii[k] = radius_of(v);
  }
  return radii;
}

/// The directions a sliding node searches: the columns of `basis` (an orthonormal basis of its
/// tangent line or plane) and, in a plane, their two diagonals (as the inside nodes search the
/// axes and diagonals).
template <int Dim, class Basis>
[[nodiscard]] std::vector<Vec<Dim>> tangent_directions(const Basis& basis) {
  std::vector<Vec<Dim>> out;
  for (Index c = 0; c < basis.cols(); ++c) out.emplace_back(basis.col(c));
  if (basis.cols() == 2) {
    out.emplace_back((basis.col(0) + basis.col(1)).normalized());
    out.emplace_back((basis.col(0) - basis.col(1)).normalized());
  }
  return out;
}

/// The wall nodes the untangling may slide along their geometry (untangle.hpp): every
/// high-order node of a facet of a group curved by projection (an analytic shape, a CAD model)
/// that lies inside its facet, or on an edge between two facets of that group whose straight
/// normals differ by at most `corner_angle` degrees. A node on a sharp edge (a trailing edge, a
/// wing's tip) or on the border with another group stays: sliding would take it off the edge.
/// Each projects through its facet (BoundaryGeometry::project_in_facet(): a CAD model's local
/// search from the facet's vertices) and searches its facets' tangent plane (in 2D, line).
/// `geometry` must outlive the result.
template <int Dim>
[[nodiscard]] SlidingNodes<Dim> wall_sliding_nodes(const Mesh<Dim>& mesh, const std::map<int, BoundaryGeometry<Dim>>& geometry,
                                                   double corner_angle) {
  struct Holder {
    std::size_t block;
    Index element;
    int local;
  };
  std::unordered_map<Index, std::vector<Holder>> holders;
  for (std::size_t b = 0; b < mesh.facets.size(); ++b) {
    const auto& block = mesh.facets[b];
    for (Index e = 0; e < block.size(); ++e) {
      const auto el = block.element(e);
      for (std::size_t k = static_cast<std::size_t>(num_vertices(block.type)); k < el.size(); ++k)
        holders[el[k]].push_back({b, e, static_cast<int>(k)});
    }
  }
  // A facet's straight normal (3D; in 2D its direction); whether it runs from vertex a to b.
  const auto normal = [&](const Holder& h) {
    const auto el = mesh.facets[h.block].element(h.element);
    const auto x = [&](int k) { return Vec<Dim>(mesh.points.col(el[static_cast<std::size_t>(k)])); };
    if constexpr (Dim == 2) {
      return Vec<2>((x(1) - x(0)).normalized());
    } else {
      const Vec<3> n = num_vertices(mesh.facets[h.block].type) == 4 ? Vec<3>((x(2) - x(0)).cross(x(3) - x(1))) : Vec<3>((x(1) - x(0)).cross(x(2) - x(0)));
      return Vec<3>(n.normalized());
    }
  };
  const auto runs = [&](const Holder& h, Index a, Index b) {
    const auto el = mesh.facets[h.block].element(h.element);
    const int nv = num_vertices(mesh.facets[h.block].type);
    for (int k = 0; k < nv; ++k)
      if (el[static_cast<std::size_t>(k)] == a) return el[static_cast<std::size_t>((k + 1) % nv)] == b;
    return false;
  };
  const double smooth = std::cos(corner_angle * std::numbers::pi / 180.0);
  SlidingNodes<Dim> out;
  for (const auto& [v, on] : holders) {
    const Holder& h = on.front();
    const auto& block = mesh.facets[h.block];
    const int tag = block.tags[static_cast<std::size_t>(h.element)];
    const auto geo = geometry.find(tag);
    if (geo == geometry.end() || geo->second.kind != BoundaryGeometry<Dim>::Kind::projection) continue;
    Vec<Dim> n = normal(h);
    if (on.size() == 2 && Dim == 3) {
      const Holder& g = on.back();
      if (mesh.facets[g.block].tags[static_cast<std::size_t>(g.element)] != tag) continue;
      // The two facets' common vertices are the edge's ends; facets oriented alike run along it in
      // opposite directions.
      std::vector<Index> common;
      const auto first = block.element(h.element), second = mesh.facets[g.block].element(g.element);
      for (int k = 0; k < num_vertices(block.type); ++k)
        if (const Index a = first[static_cast<std::size_t>(k)];
            std::find(second.begin(), second.begin() + num_vertices(mesh.facets[g.block].type), a) != second.begin() + num_vertices(mesh.facets[g.block].type))
          common.push_back(a);
      if (common.size() != 2) continue;
      Vec<Dim> m = normal(g);
      if (runs(h, common[0], common[1]) == runs(g, common[0], common[1])) m = -m;
      if (n.dot(m) < smooth) continue;
      n = (n + m).normalized();
    } else if (on.size() != 1 || (Dim == 3 && h.local < detail::first_inside_node(block.type))) {
      continue;  // on the border of its group (or of the tagged boundary)
    }
    const auto el = block.element(h.element);
    const int nv = num_vertices(block.type);
    std::array<Vec<Dim>, 4> vertices;
    for (int k = 0; k < nv; ++k) vertices[static_cast<std::size_t>(k)] = mesh.points.col(el[static_cast<std::size_t>(k)]);
    const std::vector<double> weights = detail::facet_node_weights(block.type).weights[static_cast<std::size_t>(h.local)];
    SlidingNode<Dim> node;
    if constexpr (Dim == 2) node.directions = {n};
    else node.directions = tangent_directions<3>(plane_basis<3>(n));
    node.project = [g = &geo->second, vertices, nv, weights](const Vec<Dim>& x) {
      return g->project_in_facet(std::span<const Vec<Dim>>(vertices.data(), static_cast<std::size_t>(nv)), weights, x);
    };
    out.emplace(v, std::move(node));
  }
  return out;
}

/// The sliding entries of `boundary` (symmetry planes, their lines), as nodes of `mesh` the
/// untangling may slide in their plane or line through where they are.
template <int Dim>
void add_sliding_entries(const Mesh<Dim>& mesh, const ResolvedBoundary<Dim>& boundary, SlidingNodes<Dim>& out) {
  for (Index k = 0; k < boundary.size(); ++k) {
    if (boundary.kinds[static_cast<std::size_t>(k)] != BoundaryKind::sliding) continue;
    const typename ResolvedBoundary<Dim>::Basis basis = boundary.sliding_basis(k);
    SlidingNode<Dim> node;
    node.directions = tangent_directions<Dim>(basis);
    const Index v = boundary.nodes[static_cast<std::size_t>(k)];
    node.project = [basis, origin = Vec<Dim>(mesh.points.col(v))](const Vec<Dim>& x) {
      return Vec<Dim>(origin + basis * (basis.transpose() * (x - origin)));
    };
    out.emplace(v, std::move(node));
  }
}

inline void report_progress(const std::function<void(const std::string&)>& progress, const std::string& line) {
  if (progress) progress(line);
}

/// A cell (block and element) and whether its straight shape's measure was positive.
struct CellSign {
  std::size_t block = 0;
  Index element = 0;
  bool positive = true;
};

/// The cells with a vertex that `snapped` moves, each with the sign of its straight measure now.
template <int Dim>
[[nodiscard]] std::vector<CellSign> cells_at_moved_vertices(const Mesh<Dim>& mesh, const SnappedBoundary<Dim>& snapped) {
  std::vector<CellSign> out;
  if (snapped.moved_vertices == 0) return out;
  std::vector<char> moved(static_cast<std::size_t>(mesh.num_nodes()), 0);
  for (std::size_t k = 0; k < snapped.nodes.size(); ++k)
    if (snapped.displacements.col(static_cast<Index>(k)).squaredNorm() > 0.0) moved[static_cast<std::size_t>(snapped.nodes[k])] = 1;
  for (std::size_t b = 0; b < mesh.cells.size(); ++b) {
    const ElementBlock& block = mesh.cells[b];
    const int nv = num_vertices(block.type);
    for (Index e = 0; e < block.size(); ++e) {
      const auto el = block.element(e);
      if (std::any_of(el.begin(), el.begin() + nv, [&](Index v) { return moved[static_cast<std::size_t>(v)] != 0; }))
        out.push_back({b, e, signed_measure(mesh, block.type, el) > 0.0});
    }
  }
  return out;
}

/// How many of `cells` have a straight measure of the other sign in `mesh`.
template <int Dim>
[[nodiscard]] Index count_reversed(const Mesh<Dim>& mesh, const std::vector<CellSign>& cells) {
  return static_cast<Index>(std::count_if(cells.begin(), cells.end(), [&](const CellSign& c) {
    const ElementBlock& block = mesh.cells[c.block];
    return (signed_measure(mesh, block.type, block.element(c.element)) > 0.0) != c.positive;
  }));
}

/// Throws InvalidMeshError when the snapping turned cells over (CurveResult::reversed_cells).
template <int Dim>
void refuse_reversed(const CurveResult<Dim>& result) {
  if (result.reversed_cells == 0) return;
  throw InvalidMeshError("curve_mesh: " + std::to_string(result.reversed_cells) + " cells were turned over by moving " +
                         std::to_string(result.moved_vertices) + " vertices onto the geometry (up to " +
                         format_option_value(result.max_boundary_displacement) +
                         "; the certificate measures a cell against its orientation in the input); expected none: the mesh does "
                         "not fit the geometry there");
}

/// Throws InvalidMeshError naming the count and the worst cell when `result` has invalid cells.
template <int Dim>
void refuse_invalid(const CurveResult<Dim>& result) {
  if (result.quality.num_invalid == 0) return;
  const WorstElement& w = result.quality.worst.front();
  std::ostringstream where;
  where << "(" << w.centroid[0] << ", " << w.centroid[1] << (Dim == 3 ? ", " + std::to_string(w.centroid[2]) : "") << ")";
  throw InvalidMeshError("curve_mesh: " + std::to_string(result.quality.num_invalid) + " of " +
                         std::to_string(result.quality.num_elements) + " cells are invalid after " + result.method +
                         " regularization (worst: " + std::string(name(w.type)) + " cell " + std::to_string(w.id) +
                         ", file id " + std::to_string(w.file_id) + ", at " + where.str() +
                         ", certified scaled Jacobian " + std::to_string(w.value) + "; expected > 0)");
}

/// Throws InvalidMeshError naming the count and the farthest facet when `result` has curved
/// facets off their geometry.
template <int Dim>
void refuse_off_geometry(const CurveResult<Dim>& result, double tolerance) {
  if (result.off_geometry() == 0) return;
  const auto worst = std::max_element(result.geometry_distance.begin(), result.geometry_distance.end(),
                                      [](const GeometryDistance& a, const GeometryDistance& b) {
                                        return a.max_relative_distance < b.max_relative_distance;
                                      });
  std::ostringstream where;
  where << "(" << worst->worst_at[0] << ", " << worst->worst_at[1];
  if (Dim == 3) where << ", " << worst->worst_at[2];
  where << ")";
  throw InvalidMeshError("curve_mesh: " + std::to_string(result.off_geometry()) + " curved facets are off their geometry (worst: group '" +
                         worst->group + "', a facet at " + where.str() + " up to " + format_option_value(worst->max_relative_distance) +
                         " x its size from its " + worst->geometry + "; expected at most geometry_tolerance " +
                         format_option_value(tolerance) + ")");
}

}  // namespace detail

/// Runs the regularization and certification on a P2 mesh whose boundary is already snapped
/// (`result.curved` straight, `boundary` from the snapping) with any MeshMover, in
/// `options.steps` increments. The mover sees `given`, a subset of `boundary` holding every
/// entry that moves; the other boundary nodes stay where they are, except that the untangling
/// slides the nodes `wall_sliding` gives (wall nodes along their geometry; called only when a
/// cell is below the untangling's threshold) and the sliding entries of `boundary` in their
/// planes. Fills the regularize/certify fields of `result`.
template <class Mover, int Dim>
void regularize_and_certify(Mover& mover, const ResolvedBoundary<Dim>& boundary, const ResolvedBoundary<Dim>& given,
                            const CurveOptions<Dim>& options, CurveResult<Dim>& result,
                            const std::type_identity_t<std::function<SlidingNodes<Dim>()>>& wall_sliding = {}) {
  static_assert(MeshMover<Mover> && Mover::dim == Dim, "regularize_and_certify: Mover must model MeshMover<Dim>");
  if (options.steps < 1)
    throw InputError("curve_mesh: steps must be at least 1 (got " + std::to_string(options.steps) + ")");
  Mesh<Dim>& mesh = result.curved;
  const detail::Stopwatch clock;
  ResolvedBoundary<Dim> step = given;
  step.displacements = given.displacements / static_cast<double>(options.steps);
  std::vector<char> pinned(static_cast<std::size_t>(mesh.num_nodes()), 0);
  for (const Index v : boundary.nodes) pinned[static_cast<std::size_t>(v)] = 1;
  for (const Index v : given.nodes) pinned[static_cast<std::size_t>(v)] = 0;
  std::vector<char> moved(static_cast<std::size_t>(mesh.num_nodes()), 0);
  for (int s = 0; s < options.steps; ++s) {
    detail::report_progress(options.progress, "regularizing (" + result.method + ", step " + std::to_string(s + 1) + "/" +
                                                  std::to_string(options.steps) + ")");
    mover.setup(mesh, step);
    const Points<Dim> u = mover.move(step.displacements);
    for (Index v = 0; v < mesh.num_nodes(); ++v)
      if (!pinned[static_cast<std::size_t>(v)] && u.col(v).squaredNorm() > 0.0) {
        mesh.points.col(v) += u.col(v);
        moved[static_cast<std::size_t>(v)] = 1;
      }
    result.mover_steps.push_back(mover.stats());
    result.solver_iterations += mover.stats().iterations;
  }
  if (options.inner_nodes) {
    // Faces on the boundary keep the nodes the snapping (or the sliding) gave them, and the
    // nodes the regularization moved keep its place: only what it left straight follows the
    // curved edges.
    std::vector<char> curved(static_cast<std::size_t>(mesh.num_nodes()), 0), kept = moved;
    for (std::size_t k = 0; k < boundary.nodes.size(); ++k) {
      const auto v = static_cast<std::size_t>(boundary.nodes[k]);
      kept[v] = 1;
      curved[v] = boundary.displacements.col(static_cast<Index>(k)).squaredNorm() > 0.0;
    }
    const Points<Dim> before = mesh.points;
    place_inner_nodes(mesh, curved, kept);
    for (Index v = 0; v < mesh.num_nodes(); ++v)
      if (mesh.points.col(v) != before.col(v)) moved[static_cast<std::size_t>(v)] = 1;
  }
  for (const Index v : boundary.nodes) moved[static_cast<std::size_t>(v)] = 0;
  result.moved_nodes = static_cast<Index>(std::count(moved.begin(), moved.end(), 1));
  result.seconds.regularize = clock.seconds();

  detail::report_progress(options.progress, "certifying " + std::to_string(mesh.num_cells()) + " cells (scaled Jacobian)");
  const detail::Stopwatch certify_clock;
  std::vector<CellQuality> cells = evaluate_cells(mesh, Metric::scaled_jacobian, options.report.quality);
  result.cell_quality.reserve(cells.size());
  for (const CellQuality& c : cells) result.cell_quality.push_back(c.value);
  result.seconds.certify = certify_clock.seconds();
  if (options.untangle.enabled) {
    const detail::Stopwatch untangle_clock;
    // Boundary nodes are on the geometry: they stay, or slide on it (`wall_sliding`, and the
    // entries sliding in a plane), asked for only when there is something to untangle.
    std::vector<char> fixed(static_cast<std::size_t>(mesh.num_nodes()), 0);
    for (const Index v : boundary.nodes) fixed[static_cast<std::size_t>(v)] = 1;
    SlidingNodes<Dim> sliding;
    if (std::any_of(result.cell_quality.begin(), result.cell_quality.end(), [&](double q) { return q < options.untangle.threshold; })) {
      detail::report_progress(options.progress, "untangling the cells below " + format_option_value(options.untangle.threshold));
      if (options.untangle.slide) {
        if (wall_sliding) sliding = wall_sliding();
        detail::add_sliding_entries(mesh, boundary, sliding);
      }
    }
    result.untangle = untangle(mesh, fixed, result.cell_quality, options.untangle, sliding);
    for (std::size_t c = 0; c < cells.size(); ++c) cells[c] = {result.cell_quality[c], result.cell_quality[c] > 0.0};
    result.seconds.untangle = untangle_clock.seconds();
  }
  result.quality = make_report(mesh, Metric::scaled_jacobian, cells, options.report);
  if (options.strict) detail::refuse_invalid(result);
}

/// regularize_and_certify() with the mover seeing the whole boundary.
template <class Mover, int Dim>
void regularize_and_certify(Mover& mover, const ResolvedBoundary<Dim>& boundary, const CurveOptions<Dim>& options,
                            CurveResult<Dim>& result) {
  regularize_and_certify(mover, boundary, boundary, options, result);
}

/// Curves a linear mesh (any element types, 2D or 3D) into a certified P2 mesh; see the file
/// comment for the stages. The input is not modified. Throws InputError for bad options
/// (unknown method or group, a spline in 3D, no curved group in 3D, steps < 1), what the
/// stages throw (SolverError from the RBF factorization), and InvalidMeshError in strict
/// mode when invalid cells remain (naming their count and the worst one).
template <int Dim>
[[nodiscard]] CurveResult<Dim> curve_mesh(const Mesh<Dim>& linear, const CurveOptions<Dim>& options = {}) {
  const detail::Stopwatch total;
  // The method and its options are checked before any work.
  MoverConfig<Dim> config;
  bool moves_interior = true;
  try {
    const MoverMethod<Dim>& method = mover_method<Dim>(options.method);
    config = MoverConfig<Dim>{options.method, options.mover_options ? *options.mover_options : method.defaults()};
    config.check();
    moves_interior = method.moves_interior;
  } catch (const InputError& e) {
    throw InputError(detail::curve_mesh_message(e));
  }
  if (!(options.active_radius_factor >= 0.0))
    throw InputError("curve_mesh: active_radius_factor must be non-negative (got " +
                     format_option_value(options.active_radius_factor) + ")");
  check_untangle_options(options.untangle);
  // The angle between two facets' directions: 0 to 180 degrees (720 is a slip, not a corner).
  if (!(options.snap.corner_angle >= 0.0 && options.snap.corner_angle <= 180.0))
    throw InputError("curve_mesh: corner_angle must be 0 to 180 degrees (got " + format_option_value(options.snap.corner_angle) + ")");
  if (!(options.geometry_tolerance > 0.0) || !std::isfinite(options.geometry_tolerance))
    throw InputError("curve_mesh: geometry_tolerance must be a positive number (got " + format_option_value(options.geometry_tolerance) +
                     ")");
  if (options.centre_reach < 0.0)
    throw InputError("curve_mesh: centre_reach must be non-negative (got " + format_option_value(options.centre_reach) + ")");
  CurveResult<Dim> result;
  result.method = options.method;
  result.order = options.order;
  if (options.order < 2 || options.order > max_element_order)
    throw InputError("curve_mesh: order must be 2 to " + std::to_string(max_element_order) + " (got " +
                     std::to_string(options.order) + ")");
  detail::report_progress(options.progress, "converting " + std::to_string(linear.num_cells()) + " cells to P" +
                                                std::to_string(options.order));
  detail::Stopwatch clock;
  if (options.order == 2) {
    QuadraticConversion<Dim> conversion = convert_to_quadratic(linear);
    result.curved = std::move(conversion.mesh);
    result.num_linear_nodes = conversion.num_linear_nodes;
  } else {
    for (const auto* list : {&linear.cells, &linear.facets, &linear.lower})
      for (const auto& b : *list)
        if (order(b.type) > 1)
          throw InputError("curve_mesh: the mesh already has " + std::string(name(b.type)) + " elements (expected a linear mesh)");
    OrderConversion<Dim> conversion = convert_to_order(linear, options.order);
    result.curved = std::move(conversion.mesh);
    result.num_linear_nodes = conversion.num_kept_nodes;
  }
  name_unnamed_facet_groups(result.curved);
  result.seconds.quadratic = clock.seconds();

  const std::set<int> planar = options.slide_planar_groups ? planar_group_tags(result.curved) : std::set<int>{};
  const std::map<int, BoundaryGeometry<Dim>> geometry = detail::resolve_geometry(result.curved, options, planar);
  std::vector<std::string> walls;
  for (const auto& g : result.curved.groups) {
    const auto it = geometry.find(g.tag);
    if (g.dim == Dim - 1 && it != geometry.end() && it->second.kind != BoundaryGeometry<Dim>::Kind::straight)
      walls.push_back(g.name);
  }
  result.curved_groups = walls;
  if (Dim == 3 && walls.empty())
    throw InputError("curve_mesh: no group to curve in 3D (no group named like a wall, and no projection callback or surface reconstruction "
                     "for at least one group)");

  detail::report_progress(options.progress, "snapping the boundary (" + std::to_string(walls.size()) + " curved groups)");
  clock = detail::Stopwatch{};
  const SnappedBoundary<Dim> snapped = snap_boundary(result.curved, geometry, options.snap);
  result.snapped_nodes = static_cast<Index>(snapped.nodes.size());
  result.moved_vertices = snapped.moved_vertices;
  result.max_boundary_displacement = snapped.max_displacement;
  // A curved group the snapping did not move (every node already on its geometry: a CAD
  // model's planar far field) is a fixed boundary, not a wall to blend from or size a layer by.
  const std::vector<char> still = detail::drop_unmoved_walls(result.curved, snapped, walls, options.snap);
  result.sliding_groups = detail::sliding_groups(result.curved, options, result.curved_groups, walls, planar);
  // Numbered once for the boundary's untagged facets and the layer estimate's cell walk (each
  // numbering of the 30P30N's P2 facets took 12 ms).
  const FacetTopology facet_topology = unique_facets(result.curved);
  const ResolvedBoundary<Dim> boundary =
      detail::curving_boundary(result.curved, snapped, still, result.sliding_groups, facet_topology);
  const std::vector<detail::CellSign> at_moved_vertices = detail::cells_at_moved_vertices(result.curved, snapped);
  result.seconds.snap = clock.seconds();

  // What the mover's options take decides what the pipeline measures for it: a support radius
  // and the centres near the motion, an active region, a blending length, the layers' test.
  const auto takes = [&](auto wants) { return std::visit([&]<class O>(const O&) { return wants.template operator()<O>(); }, config.options); };
  const bool radial = takes([]<class O>() { return TakesSupportRadius<O>; });
  const bool sized = radial || takes([]<class O>() { return TakesActiveRadius<O>; });
  const bool blends = takes([]<class O>() { return TakesBlendingLength<O>; });
  const bool default_length =
      blends && std::visit([]<class O>(const O& o) {
        if constexpr (TakesBlendingLength<O>) return o.blending_length <= 0.0;
        else return false;
      }, config.options);
  const bool estimate = !walls.empty() && ((sized && options.support_radius <= 0.0) || default_length);
  std::shared_ptr<const BoundaryLayerEstimate> layers;
  if (estimate) {
    detail::report_progress(options.progress, "estimating the boundary layer of the curved walls");
    clock = detail::Stopwatch{};
    layers = std::make_shared<const BoundaryLayerEstimate>(
        estimate_boundary_layer(result.curved, std::span<const std::string>(walls), options.layer, &facet_topology));
    result.layers = layers->walls;
    result.seconds.layer = clock.seconds();
  }
  std::vector<int> wall_of;
  std::vector<double> per_node;
  if (sized) {
    result.support_radius = options.support_radius;
    if (!(result.support_radius > 0.0)) {
      wall_of = detail::wall_of_nodes(result.curved, walls);
      const detail::DefaultRadii radii = detail::default_support_radii(result.curved, boundary, snapped, result.layers, wall_of, options);
      result.support_radius = radii.uniform;
      result.support_radius_limited = radii.limited;
      if (radial && options.per_wall_radius) {
        result.wall_support_radii = radii.per_wall;
        per_node = radii.per_node;
        if (!radii.per_wall.empty()) result.support_radius = *std::max_element(radii.per_wall.begin(), radii.per_wall.end());
      }
    }
  }
  const bool trim = radial && options.centre_reach > 0.0;
  const ResolvedBoundary<Dim> given =
      trim ? detail::near_motion(result.curved, boundary, options.centre_reach * result.support_radius) : boundary;
  const auto& per_wall = result.wall_support_radii;
  const bool varying =
      !per_node.empty() || std::any_of(per_wall.begin(), per_wall.end(), [&](double r) { return r != per_wall.front(); });
  std::visit(
      [&]<class O>(O& o) {
        if constexpr (TakesSupportRadius<O>) {
          o.support_radius = result.support_radius;
          o.support_radii = varying ? detail::entry_radii(result.curved, given, wall_of, per_wall, per_node) : std::vector<double>{};
        }
        if constexpr (TakesActiveRadius<O>)
          if (!(o.active_radius > 0.0)) o.active_radius = options.active_radius_factor * result.support_radius;
        if constexpr (TakesLayerOptions<O>) o.layer = options.layer;
        // The blend's walls are the moving facets, the estimate's the curved groups: the
        // mover checks they hold the same vertices. A later step would see a moved mesh.
        if constexpr (requires { o.layer_estimate = layers; })
          if (options.steps == 1) o.layer_estimate = layers;
      },
      config.options);
  AnyMover<Dim> mover = make_mover(config);
  // Strict mode refuses below, the geometry first: a wall in the wrong place explains invalid cells.
  CurveOptions<Dim> stage = options;
  stage.strict = false;
  if (!moves_interior) stage.untangle.enabled = false;
  regularize_and_certify(mover, boundary, given, stage, result,
                         [&] { return detail::wall_sliding_nodes(result.curved, geometry, options.snap.corner_angle); });
  result.reversed_cells = detail::count_reversed(result.curved, at_moved_vertices);
  detail::report_progress(options.progress, "measuring the curved walls' distance to their geometry");
  clock = detail::Stopwatch{};
  result.geometry_distance = measure_geometry_distance(result.curved, snapped.references, options.geometry_tolerance);
  result.seconds.distance = clock.seconds();
  if (options.strict) {
    detail::refuse_off_geometry(result, options.geometry_tolerance);
    detail::refuse_reversed(result);
    detail::refuse_invalid(result);
  }
  result.seconds.total = total.seconds();
  return result;
}

}  // namespace meshmotion

// The compiled library (target meshmotion::compiled, src/) holds these for Dim 2 and 3.
#ifdef MESHMOTION_COMPILED
namespace meshmotion {
extern template CurveResult<2> curve_mesh<2>(const Mesh<2>&, const CurveOptions<2>&);
extern template CurveResult<3> curve_mesh<3>(const Mesh<3>&, const CurveOptions<3>&);
}  // namespace meshmotion
#endif
