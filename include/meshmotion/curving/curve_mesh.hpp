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

#include "meshmotion/curving/curve_options.hpp"
#include "meshmotion/curving/curve_report.hpp"
#include "meshmotion/curving/detail/curving_certificate.hpp"
#include "meshmotion/curving/detail/curving_groups.hpp"
#include "meshmotion/curving/detail/curving_radii.hpp"
#include "meshmotion/curving/detail/curving_sliding.hpp"
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
  if (options.untangle.untangle) {
    const detail::Stopwatch untangle_clock;
    // Boundary nodes are on the geometry: they stay, or slide on it (`wall_sliding`, and the
    // entries sliding in a plane), asked for only when there is something to untangle.
    std::vector<char> fixed(static_cast<std::size_t>(mesh.num_nodes()), 0);
    for (const Index v : boundary.nodes) fixed[static_cast<std::size_t>(v)] = 1;
    SlidingNodes<Dim> sliding;
    if (std::any_of(result.cell_quality.begin(), result.cell_quality.end(), [&](double q) { return q < options.untangle.untangle_threshold; })) {
      detail::report_progress(options.progress, "untangling the cells below " + format_option_value(options.untangle.untangle_threshold));
      if (options.untangle.untangle_slide) {
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
  try {
    check_option_ranges(options);
  } catch (const InputError& e) {
    throw InputError(detail::curve_mesh_message(e));
  }
  CurveResult<Dim> result;
  result.method = options.method;
  result.order = options.order;
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
  if (!moves_interior) stage.untangle.untangle = false;
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
