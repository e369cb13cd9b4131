#pragma once
/// \file
/// curve_mesh()'s options (CurveOptions) with their one description, and their text form:
/// set_curve_options() (its own keys, then the method's mover's through the registry) and
/// curve_option_docs().

#include "meshmotion/core/element.hpp"
#include "meshmotion/core/error.hpp"
#include "meshmotion/core/fields.hpp"
#include "meshmotion/core/mesh.hpp"
#include "meshmotion/core/option_text.hpp"
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
#include "meshmotion/movers/rbf_kernels.hpp"
#include "meshmotion/movers/registry.hpp"
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
  int order = 2;
  std::string method = "blend";
  /// Typed options of `method` (its MoverOptions alternative); empty: the method's defaults.
  /// The pipeline sets what it measures in them, asking the options what they take: the
  /// support radius (and a radius per centre) of movers with one (TakesSupportRadius), the
  /// active region of those with one (TakesActiveRadius) unless these options set it, the
  /// layer recognition of those that blend over layers (TakesLayerOptions).
  std::optional<MoverOptions<Dim>> mover_options{};
  double active_radius_factor = 4.0;
  double support_radius = 0.0;
  double support_radius_factor = Dim == 2 ? 4.0 : 1.0;
  bool per_wall_radius = true;
  double max_support_nodes = Dim == 2 ? 0.0 : 100.0;
  double centre_reach = 2.0;
  int steps = 1;
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
  bool reconstruct_walls_by_default = true;
  std::vector<std::string> sliding;
  bool slide_planar_groups = true;
  /// Corners and midpoint rule of the spline; tolerance of "already on the geometry".
  SnapOptions snap{};
  BoundaryLayerOptions layer{};
  ReportOptions report{};
  double geometry_tolerance = 0.1;
  bool strict = false;
  /// Called with a line of text before each stage.
  std::function<void(const std::string&)> progress{};
};

/// The keys of CurveOptions: every field text may set (`geometry` has its own text form,
/// geometry_from_text(); `mover_options` takes the keys of the method, MoverConfig).
template <int Dim, class F>
void visit_options(CurveOptions<Dim>& o, F&& f, const std::string& prefix = {}) {
  f(prefix + "order", o.order, OptionHelp{"order of the curved mesh: 2 to 8", range::between(2, max_element_order)});
  f(prefix + "method", o.method, OptionHelp{"interior regularization: a registered mover (its options are keys too)", {},
      "Interior regularization: any registered method (mover_methods(), movers/registry.hpp). \"blend\" "
      "(wall-distance blending) is the default: it reached the best minimum on every case of curving_bench; "
      "\"none\" snaps the boundary alone, to show why the pipeline exists."});
  f(prefix + "support_radius", o.support_radius, OptionHelp{"support radius of the movers with one (0: from each wall's boundary layer)", range::non_negative,
      "Support radius of the movers that take one (TakesSupportRadius); 0: support_radius_factor × each "
      "wall's estimated layer (per_wall_radius), or × the thickest one (suggest_support_radius() with 3 wall "
      "node spacings when no wall has a layer)."});
  f(prefix + "support_radius_factor", o.support_radius_factor, OptionHelp{"default support radius = this x the wall's layer thickness", range::positive,
      "The default support radius is this × each wall's estimated layer thickness: 4 in 2D, 1 in 3D (a "
      "larger 3D support multiplies the factorization's cost)."});
  f(prefix + "per_wall_radius", o.per_wall_radius, OptionHelp{"default radius: each wall its own (false: the thickest wall's for all)", {},
      "With the default radius, each curved wall's centres get the radius of its own layer (walls without a "
      "layer: each node 2 node spacings of its own facets, half one where a facet is snapped away from its "
      "cell or hardly moves, local_spacing_radii()), and the other boundary centres the radius of the nearest "
      "moving wall node, so a thin layer is not overrun by the support of a thick one. false: the thickest "
      "layer's radius everywhere (the thesis's one radius). Differing radii make the RBF system nonsymmetric "
      "(sparse LU instead of Cholesky)."});
  f(prefix + "max_support_nodes", o.max_support_nodes, OptionHelp{"shrink a default radius to this many boundary nodes per support (0: no limit)", range::non_negative,
      "A default radius is shrunk until a support holds at most this many boundary nodes on average around "
      "the moving ones; 0: no limit. 2D supports grow only linearly with the radius and are not limited by "
      "default."});
  f(prefix + "centre_reach", o.centre_reach, OptionHelp{"RBF centres only within this x the radius of a moving node (0: every boundary node)", range::non_negative,
      "Boundary nodes that stay put (fixed, sliding, or snapped with zero displacement) are RBF centres only "
      "within this many support radii of a node the snapping moved; 0 keeps every boundary node a centre (the "
      "thesis). A compact kernel couples centres only through overlapping supports, so farther ones barely "
      "change the interpolant."});
  f(prefix + "active_radius_factor", o.active_radius_factor, OptionHelp{"le/sle: solve within this x the support radius of the curved walls (0: whole mesh)", range::non_negative});
  f(prefix + "steps", o.steps, OptionHelp{"regularize in this many increments", range::at_least(1)});
  f(prefix + "inner_nodes", o.inner_nodes, OptionHelp{"re-place the nodes inside faces and cells next to a curved wall from the nodes around them", {},
      "After the regularization, the nodes inside the faces and cells of the cells touching a curved wall "
      "that it left where they were are placed from the nodes around them (curving/inner_nodes.hpp), as Gmsh "
      "places them from its curved edges. false: they stay."});
  visit_options(o.untangle, f, prefix);
  f(prefix + "spline_by_default", o.spline_by_default, "2D: groups without a geometry get a spline");
  f(prefix + "reconstruct_walls_by_default", o.reconstruct_walls_by_default,
    OptionHelp{"3D: wall-named triangle groups without a geometry get the surface reconstruction", {},
      "3D: groups not listed whose name says they are walls (detail::looks_like_wall: \"wall\", \"body\", \"wing\", "
      "...) and whose facets are triangles get the surface reconstruction; CurveResult::curved_groups says "
      "which. false: they stay straight."});
  f(prefix + "sliding", o.sliding, "groups sliding in their plane (symmetry), comma-separated");
  f(prefix + "slide_planar_groups", o.slide_planar_groups,
    OptionHelp{"groups without a geometry lying in a plane (not named like walls) stay straight, and slide in it where they meet a curved group", {},
      "Groups given no geometry that lie in one plane (a line in 2D; planar_group_tags()) and are not named "
      "like walls stay straight, and those that meet a curved group slide in their plane: a symmetry plane or "
      "a flat side cut by a curved wall lets the cells at the cut follow the wall (the sphere on its STEP "
      "file at P3: minimum 0.61 with the plane fixed, 0.86 sliding). CurveResult::sliding_groups says which "
      "slid. false: only `sliding` slides."});
  visit_options(o.snap, f, prefix);
  visit_options(o.layer, f, prefix);
  visit_options(o.report, f, prefix);
  f(prefix + "geometry_tolerance", o.geometry_tolerance,
    OptionHelp{"a curved facet farther than this x its size from its geometry is off it (reported; refused when strict)", range::positive,
      "A curved facet whose distance to its geometry (bounded by sampling, geometry_distance.hpp) exceeds "
      "this × its size is off the geometry: reported, and refused in strict mode. The facets of the data "
      "folder's cases are at most 0.004 of their size from a CAD model or a spline, 0.025 from a coarse 3D "
      "reconstruction; a node on the far side of a closed curve puts its facet at more than 1 "
      "(docs/curving.md, \"What is certified\")."});
  f(prefix + "strict", o.strict, "write nothing when invalid cells, facets off the geometry or turned-over cells remain");
}

namespace detail {

/// "curve_mesh: " before the message of e (without the "meshmotion: " InputError adds again).
[[nodiscard]] inline std::string curve_mesh_message(const Error& e) { return "curve_mesh: " + e.message(); }

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

}  // namespace meshmotion
