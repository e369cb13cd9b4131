// curve_mesh: a linear mesh in, a certified curved P2 mesh out (thesis chapter 3).
//
//   curve_mesh                       # built-in demo: boundary-layer O-mesh around a cylinder
//   curve_mesh in.su2 -o out.msh --group wall --geometry naca:0012 --svg out.svg
//   curve_mesh in.msh -o out.msh --group 7 --geometry sphere:0,0,0,0.5 --sliding 20 --json
//
// Writes OUTPUT (.msh/.cgns/.su2), OUTPUT's .vtu beside it (per-cell certified scaled Jacobian),
// and in 2D an SVG picture coloured by quality when --svg is given (always in the demo), with
// a red ring on every invalid cell (too thin to see at a zoom that shows the body).
// The input file is never modified. Exit codes: 0 curved and valid, 1 error (nothing
// written), 2 written with invalid cells (the last line says so) or refused by --strict.

#include "meshmotion/core/json.hpp"
#include "meshmotion/core/option_text.hpp"
#include "meshmotion/core/generators.hpp"
#include "meshmotion/curving/curve_mesh.hpp"
#include "meshmotion/curving/geometry_text.hpp"
#include "meshmotion/io/mesh_io.hpp"
#include "meshmotion/io/vtu_writer.hpp"
#include "meshmotion/quality/svg_picture.hpp"

#include "mover_arguments.hpp"
#include "program.hpp"

#ifdef MESHMOTION_HAVE_CAD
#include "meshmotion/cad/cad_model.hpp"
#endif

#include <CLI/CLI.hpp>

#include <cctype>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <optional>
#include <string>
#include <variant>
#include <vector>

namespace {

using namespace meshmotion;

struct Arguments {
  std::string input;
  std::string output;
  bool demo = false;
  double support_radius = 0.0;
  std::optional<double> active_factor;
  bool single_radius = false;
  double support_factor = 0.0;  // unset: the library's default for the dimension
  double blending_length = 0.0;
  double blending_factor = 0.0;  // unset: the library's default for the dimension
  int steps = 1;
  int order = 2;
  bool no_untangle = false;
  bool mover_inner_nodes = false;
  double untangle_threshold = 0.1;
  int raise_rounds = UntangleOptions{}.raise_rounds;
  std::vector<std::string> geometry;
  double cad_tolerance = 0.0;  // 0: 1e-6 of the CAD model's diagonal
  std::vector<std::string> groups;
  std::vector<std::string> sliding;
  double corner_angle = 30.0;
  bool parameter_midpoint = false;
  bool strict = false;
  bool json = false;
  bool overwrite = false;
  bool keep_orientation = false;
  std::string svg;
  std::vector<double> zoom;
  bool svg_no_markers = false;
  examples::MoverArguments mover;
};

// A --geometry naming a STEP, IGES or BREP file (any case) rather than an analytic shape.
bool is_cad_file(const std::string& text) {
  std::string ext = std::filesystem::path(text).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".step" || ext == ".stp" || ext == ".iges" || ext == ".igs" || ext == ".brep";
}

bool cad_geometry(const Arguments& args) { return args.geometry.size() == 1 && is_cad_file(args.geometry.front()); }

template <int Dim>
CurveOptions<Dim> curve_options(const Arguments& args) {
  CurveOptions<Dim> options;
  options.method = args.mover.method;
  const KeyValues given = examples::given_options(args.mover);
  if (options.method == "blend" || options.method == "none") {
    if (!given.empty())
      throw InputError("curve_mesh: method '" + options.method + "' takes no mover option (got '" + given.front().first + "')");
  } else {
    options.mover_options = mover_config<Dim>(options.method, given).options;
  }
  if (args.active_factor) options.active_radius_factor = *args.active_factor;
  options.support_radius = args.support_radius;
  options.per_wall_radius = !args.single_radius;
  if (args.support_factor > 0.0) options.support_radius_factor = args.support_factor;
  options.blending_length = args.blending_length;
  if (args.blending_factor > 0.0) options.blending_factor = args.blending_factor;
  options.steps = args.steps;
  options.order = args.order;
  options.untangle.enabled = !args.no_untangle;
  options.inner_nodes = !args.mover_inner_nodes;
  options.untangle.threshold = args.untangle_threshold;
  options.untangle.raise_rounds = args.raise_rounds;
  options.sliding = args.sliding;
  options.strict = args.strict;
  options.snap.corner_angle = args.corner_angle;
  options.snap.midpoint = args.parameter_midpoint ? SplineMidpoint::parameter : SplineMidpoint::arc_length;
  if (cad_geometry(args)) return options;  // the groups come from the model (run())
  std::vector<std::string> groups = args.groups;
  if (groups.empty() && !args.geometry.empty()) groups.push_back("wall");
  if (!args.geometry.empty() && args.geometry.size() != 1 && args.geometry.size() != groups.size())
    throw InputError("--geometry: " + std::to_string(args.geometry.size()) + " geometries for " +
                     std::to_string(groups.size()) + " groups (expected one for all, or one per --group)");
  for (std::size_t g = 0; g < groups.size() && !args.geometry.empty(); ++g)
    options.geometry.insert_or_assign(groups[g], geometry_from_text<Dim>(args.geometry[args.geometry.size() == 1 ? 0 : g]));
  if (!args.json)
    options.progress = [start = std::chrono::steady_clock::now()](const std::string& line) {
      const double t = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      std::fprintf(stderr, "[%7.3f s] %s\n", t, line.c_str());
    };
  return options;
}

std::filesystem::path with_extension(const std::filesystem::path& file, const char* extension) {
  std::filesystem::path p = file;
  return p.replace_extension(extension);
}

template <int Dim>
void print_summary(const CurveResult<Dim>& result, const Arguments& args, const std::filesystem::path& vtu);

template <int Dim>
int run(Mesh<Dim> linear, const Arguments& args) {
  if (!args.demo) examples::handle_orientation(linear, args.input, args.keep_orientation);
  CurveOptions<Dim> options = curve_options<Dim>(args);
  std::string cad_report;
  if (cad_geometry(args)) {
#ifdef MESHMOTION_HAVE_CAD
    // Kept for the whole run: the groups' geometry refers to it.
    static std::optional<CadModel> model;
    model.emplace(CadModel::read(args.geometry.front()));
    const std::vector<CadGroupMatch> matches = match_cad_groups(linear, *model, args.cad_tolerance, args.groups);
    for (const CadGroupMatch& m : matches)
      if (m.matched()) options.geometry.insert_or_assign(m.group, cad_boundary<Dim>(*model, m, args.cad_tolerance));
    cad_report = describe_cad_matches(matches);
    if (!args.json) std::fprintf(stderr, "CAD model %s:\n%s", args.geometry.front().c_str(), cad_report.c_str());
#else
    throw InputError("--geometry " + args.geometry.front() + ": CAD files need the CAD component, which this build lacks "
                     "(install libocct-modeling-algorithms-dev libocct-data-exchange-dev and reconfigure)");
#endif
  }
  const CurveResult<Dim> result = curve_mesh(linear, options);
  const std::vector<double>& values = result.cell_quality;
  write_mesh(args.output, result.curved);
  const std::filesystem::path vtu = with_extension(args.output, ".vtu");
  VtuFields fields;
  fields.cell_data.emplace_back("scaled_jacobian",
                                Eigen::Map<const Eigen::MatrixXd>(values.data(), 1, static_cast<Index>(values.size())));
  write_vtu(vtu, result.curved, fields);
  if constexpr (Dim == 2) {
    if (!args.svg.empty()) {
      SvgOptions svg;
      char numbers[160];
      std::snprintf(numbers, sizeof numbers, "): min %.4g, mean %.4g, %lld of %lld cells invalid", result.quality.min,
                    result.quality.mean, static_cast<long long>(result.quality.num_invalid),
                    static_cast<long long>(result.quality.num_elements));
      svg.title = "certified scaled Jacobian of the P" + std::to_string(args.order) + " mesh (" + result.method + numbers;
      if (args.zoom.size() == 4) svg.zoom = std::array<double, 4>{args.zoom[0], args.zoom[1], args.zoom[2], args.zoom[3]};
      // Invalid cells are magenta and ringed: the scale keeps the valid range [0, 1] instead of
      // stretching down to the worst negative value (which left every valid cell one colour).
      svg.mark_invalid = !args.svg_no_markers;
      svg.value_min = svg.mark_invalid ? 0.0 : std::min(0.0, result.quality.min);
      write_svg(args.svg, result.curved, values, svg);
    }
  }
  const QualityReport& q = result.quality;
  if (args.json) {
    JsonWriter w(std::cout);
    w.begin_object();
    w.key("input").value(args.demo ? std::string("demo: boundary-layer O-mesh around a cylinder") : args.input);
    w.key("output").value(args.output).key("vtu").value(vtu.string());
    w.key("dim").value(Dim).key("nodes").value(result.curved.num_nodes()).key("cells").value(result.curved.num_cells());
    w.key("method").value(result.method).key("steps").value(args.steps).key("support_radius").value(result.support_radius);
    w.key("support_radius_limited").value(result.support_radius_limited);
    w.key("order").value(args.order);
    w.key("curved_groups").begin_array();
    for (const auto& g : result.curved_groups) w.value(g);
    w.end_array();
    if (!cad_report.empty()) w.key("cad_groups").value(cad_report);
    w.key("walls").begin_array();
    for (std::size_t k = 0; k < result.layers.size(); ++k) {
      w.begin_object().key("group").value(result.layers[k].group).key("layer_thickness").value(result.layers[k].thickness);
      if (!result.wall_support_radii.empty()) w.key("support_radius").value(result.wall_support_radii[k]);
      w.end_object();
    }
    w.end_array();
    w.key("seconds").begin_object();
    w.key("quadratic").value(result.seconds.quadratic).key("snap").value(result.seconds.snap);
    w.key("layer").value(result.seconds.layer).key("regularize").value(result.seconds.regularize);
    w.key("untangle").value(result.seconds.untangle);
    w.key("certify").value(result.seconds.certify).key("total").value(result.seconds.total);
    w.end_object();
    w.key("solver_iterations").value(result.solver_iterations);
    w.key("snapped_nodes").value(result.snapped_nodes).key("moved_vertices").value(result.moved_vertices);
    w.key("moved_nodes").value(result.moved_nodes);
    const UntangleReport& u = result.untangle;
    w.key("untangle").begin_object().key("cells_below").value(u.cells_below).key("invalid_before").value(u.invalid_before);
    w.key("invalid_after").value(u.invalid_after).key("min_before").value(u.min_before).key("min_after").value(u.min_after);
    w.key("patch_cells").value(u.patch_cells).key("free_nodes").value(u.free_nodes).key("sweeps").value(u.sweeps);
    w.key("raise_rounds").value(u.raise_rounds).end_object();
    w.key("min_scaled_jacobian").value(q.min).key("mean_scaled_jacobian").value(q.mean).key("invalid").value(q.num_invalid);
    w.key("quality");
    write_json(w, q);
    w.end_object();
    std::cout << "\n";
  } else {
    print_summary(result, args, vtu);
  }
  if (q.num_invalid > 0) {
    std::fflush(stdout);
    std::fprintf(stderr, "wrote %s WITH %lld INVALID CELLS of %lld\n", args.output.c_str(),
                 static_cast<long long>(q.num_invalid), static_cast<long long>(q.num_elements));
    return examples::exit_invalid;
  }
  return examples::exit_ok;
}

template <int Dim>
void print_summary(const CurveResult<Dim>& result, const Arguments& args, const std::filesystem::path& vtu) {
  const QualityReport& q = result.quality;
  std::printf("curved %lld cells, %lld nodes (%lld linear) with %s", static_cast<long long>(result.curved.num_cells()),
              static_cast<long long>(result.curved.num_nodes()), static_cast<long long>(result.num_linear_nodes),
              result.method.c_str());
  if (!result.wall_support_radii.empty())
    std::printf(", a support radius per wall%s", result.support_radius_limited ? " (limited to keep the system sparse)" : "");
  else if (result.support_radius > 0.0)
    std::printf(", support radius %.4g%s", result.support_radius,
                result.support_radius_limited ? " (limited to keep the system sparse)" : "");
  std::printf(", %d step(s), order %d\n", args.steps, args.order);
  std::printf("  curved groups:");
  for (const auto& g : result.curved_groups) std::printf(" %s", g.c_str());
  std::printf("\n");
  for (std::size_t k = 0; k < result.layers.size(); ++k) {
    const auto& layer = result.layers[k];
    std::printf("  wall '%s': boundary layer %.4g thick (max %.4g)", layer.group.c_str(), layer.thickness, layer.max_thickness);
    if (!result.wall_support_radii.empty()) std::printf(", support radius %.4g", result.wall_support_radii[k]);
    std::printf("\n");
  }
  std::printf("  boundary: %lld nodes snapped, %lld vertices moved onto the geometry, largest move %.3g\n",
              static_cast<long long>(result.snapped_nodes), static_cast<long long>(result.moved_vertices),
              result.max_boundary_displacement);
  std::printf("  interior nodes moved: %lld, solver iterations: %lld\n", static_cast<long long>(result.moved_nodes),
              static_cast<long long>(result.solver_iterations));
  if (result.untangle.cells_below > 0 || result.untangle.raise_rounds > 0) {
    const UntangleReport& u = result.untangle;
    std::printf("  untangling: %lld cells below the threshold (%lld invalid), %d rounds raising the worst, min %.4f -> %.4f, "
                "%lld invalid after (%lld cells, %lld free nodes, %d sweeps)\n",
                static_cast<long long>(u.cells_below), static_cast<long long>(u.invalid_before), u.raise_rounds, u.min_before,
                u.min_after, static_cast<long long>(u.invalid_after), static_cast<long long>(u.patch_cells),
                static_cast<long long>(u.free_nodes), u.sweeps);
  }
  std::printf("  certified scaled Jacobian: min %.4f, mean %.4f, invalid %lld of %lld\n", q.min, q.mean,
              static_cast<long long>(q.num_invalid), static_cast<long long>(q.num_elements));
  if (!q.worst.empty())
    std::printf("  worst cell: %s %lld at (%.4g, %.4g, %.4g): %.4f\n", std::string(name(q.worst[0].type)).c_str(),
                static_cast<long long>(q.worst[0].file_id), q.worst[0].centroid[0], q.worst[0].centroid[1],
                q.worst[0].centroid[2], q.worst[0].value);
  std::printf("  seconds: P%d %.3f, snap %.3f, layer %.3f, regularize %.3f, certify %.3f, untangle %.3f, total %.3f\n",
              args.order, result.seconds.quadratic, result.seconds.snap, result.seconds.layer, result.seconds.regularize,
              result.seconds.certify, result.seconds.untangle, result.seconds.total);
  if (q.num_invalid == 0)
    std::printf("wrote %s, %s%s%s\n", args.output.c_str(), vtu.string().c_str(), args.svg.empty() ? "" : ", ",
                args.svg.c_str());
}

}  // namespace

int main(int argc, char** argv) {
  meshmotion::tune_process_memory(argc, argv);  // may restart the program once (core/process_memory.hpp)
  CLI::App app{"Curve a linear mesh into a certified P2 (P3, P4) mesh (spline or CAD boundary, RBF or blending interior)"};
  Arguments args;
  app.add_option("input", args.input, "linear mesh (.msh, .su2, .cgns, .vtu); none: the built-in demo");
  app.add_option("-o,--output", args.output, "curved mesh to write (.msh, .cgns; .su2 for linear); a .vtu is written beside it");
  examples::add_version_flag(app);
  app.add_flag("--demo", args.demo, "curve the built-in boundary-layer mesh around a cylinder");
  args.mover.method = "blend";  // curve_mesh()'s default (CurveOptions::method)
  examples::add_mover_options(app, args.mover, "interior regularization (default blend): blend, none, or ");
  app.add_option("--support-radius", args.support_radius,
                 "support radius of the movers with one (rbf; 0: from the boundary-layer thickness)");
  app.add_option("--active-factor", args.active_factor,
                 "le/sle: solve within this x the support radius of the curved walls (default 4; 0: whole mesh)");
  const auto positive = [](const std::string& value) {
    char* end = nullptr;
    const double x = std::strtod(value.c_str(), &end);
    return end != value.c_str() && *end == '\0' && x > 0.0 ? std::string() : "must be a number > 0 (got " + value + ")";
  };
  app.add_option("--support-factor", args.support_factor,
                 "default radius = this x the thickest wall layer (default: 4 in 2D, 1 in 3D)")
      ->check(positive);
  app.add_option("--blending-length", args.blending_length, "blend: length (0: --blending-factor x each wall's layer thickness)");
  app.add_option("--blending-factor", args.blending_factor, "blend: default length = this x each wall's layer (default 6)")
      ->check(positive);
  app.add_option("--steps", args.steps, "regularize in this many increments")->capture_default_str();
  app.add_flag("--mover-inner-nodes", args.mover_inner_nodes,
               "keep the regularization's nodes inside the faces and cells next to a curved wall (default: re-placed from "
               "the nodes around them)");
  app.add_flag("--no-untangle", args.no_untangle, "leave the regularized mesh as it is (no optimization of the cells below the threshold)");
  app.add_option("--untangle-threshold", args.untangle_threshold,
                 "optimize the high-order nodes around cells whose certified scaled Jacobian is below this")
      ->capture_default_str();
  app.add_option("--raise-rounds", args.raise_rounds,
                 "then raise the worst cells: rounds of optimization around them while the minimum rises (0: none)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--order", args.order, "order of the curved mesh: 2, 3 or 4 (hexahedra, prisms and pyramids: 2 or 3)")
      ->capture_default_str();
  app.add_option("--geometry", args.geometry,
                 "true boundary: spline | reconstruct | straight | bump | circle:X,Y,R | naca:XXXX[,CHORD,X0,Y0] | sphere:X,Y,Z,R "
                 "(one for all --group, or one per group), or a CAD file (.step, .stp, .iges, .igs, .brep) for every group it fits");
  app.add_option("--group", args.groups,
                 "groups the --geometry applies to (default: wall; with a CAD file, every group the model fits)");
  app.add_option("--cad-tolerance", args.cad_tolerance,
                 "CAD file: how far a vertex may be from the model (default: 1e-6 of the model's diagonal)");
  app.add_option("--sliding", args.sliding, "groups sliding in their plane (symmetry)");
  app.add_option("--corner-angle", args.corner_angle, "spline corners above this angle (degrees)")->capture_default_str();
  app.add_flag("--parameter-midpoint", args.parameter_midpoint,
               "spline: nodes at fractions of the facet's parameter (the thesis) instead of its arc length");
  app.add_flag("--single-radius", args.single_radius,
               "rbf default radius: the thickest wall layer's for every wall, not each wall's own");
  app.add_flag("--strict", args.strict, "write nothing when invalid cells remain (exit 2)");
  app.add_flag("--overwrite", args.overwrite, "allow the output to be the input file");
  app.add_flag("--keep-orientation", args.keep_orientation,
               "refuse a mesh whose cells are all negatively oriented instead of reorienting it");
  app.add_flag("--json", args.json, "print one JSON object");
  app.add_option("--svg", args.svg, "2D: write an SVG picture coloured by quality");
  app.add_option("--zoom", args.zoom, "SVG zoom box x0,x1,y0,y1 (only cells reaching into it are written)")
      ->delimiter(',')
      ->expected(4);
  app.add_flag("--svg-no-markers", args.svg_no_markers,
               "SVG: do not ring invalid cells (by default each cell with scaled Jacobian <= 0 gets a red ring, "
               "the legend counts them and the colour scale spans [0, 1]); the scale then reaches down to the minimum");
  CLI11_PARSE(app, argc, argv);

  args.demo = args.demo || args.input.empty();
  return examples::guarded(args.json, [&] {
    if (args.mover.method != "blend" && args.mover.method != "none" && examples::list_options<2>(args.mover))
      return examples::exit_ok;
    if (args.demo) {
      if (args.output.empty()) args.output = "cylinder_p" + std::to_string(args.order) + ".msh";
      if (args.svg.empty()) args.svg = with_extension(args.output, ".svg").string();
      if (args.zoom.empty()) args.zoom = {0.47, 0.53, -0.03, 0.03};
      if (args.geometry.empty()) {
        args.groups = {"wall"};
        args.geometry = {"circle:0,0,0.5"};
      }
      examples::check_output({}, args.output, args.order, args.overwrite);
      return run(o_mesh({}), args);  // 128 x 64 quads, first cell 1e-5 for a 0.025 wall spacing
    }
    if (args.output.empty()) throw InputError("curve_mesh: no output file (expected -o OUTPUT)");
    // The curved mesh is of order --order, and a .vtu goes beside it: both are checked before any work.
    examples::check_output(args.input, args.output, args.order, args.overwrite);
    examples::check_output(args.input, with_extension(args.output, ".vtu"), args.order, args.overwrite);
    AnyMesh mesh = read_mesh(args.input);
    return std::visit([&](auto& m) { return run(std::move(m), args); }, mesh);
  });
}
