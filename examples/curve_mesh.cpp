// curve_mesh: a linear mesh in, a certified curved P2 mesh out (thesis chapter 3).
//
//   curve_mesh                       # built-in demo: boundary-layer O-mesh around a cylinder
//   curve_mesh in.su2 -o out.msh --group wall --geometry naca:0012 --svg out.svg
//   curve_mesh in.msh -o out.msh --group 7 --geometry sphere:0,0,0,0.5 --sliding 20 --json
//
// Writes OUTPUT (.msh/.cgns/.su2), OUTPUT's .vtu beside it (per-cell certified scaled Jacobian),
// and in 2D an SVG picture coloured by quality when --svg is given (always in the demo), with
// a red ring on every invalid cell (too thin to see at a zoom that shows the body).
// The input file is never modified. Exit codes: 0 curved, valid and on the geometry, 1 error
// (nothing written), 2 written with invalid cells or facets off the geometry (the last lines
// say so) or refused by --strict.

#include "meshmotion/core/detail/atomic_file.hpp"
#include "meshmotion/core/json.hpp"
#include "meshmotion/core/option_text.hpp"
#include "meshmotion/core/generators.hpp"
#include "meshmotion/curving/curve_mesh.hpp"
#include "meshmotion/curving/geometry_text.hpp"
#include "meshmotion/curving/reports.hpp"
#include "meshmotion/io/mesh_io.hpp"
#include "meshmotion/io/vtu_writer.hpp"
#include "meshmotion/movers/step_driver.hpp"
#include "meshmotion/parallel/parallel_options.hpp"
#include "meshmotion/quality/svg_picture.hpp"

#include "mover_arguments.hpp"
#include "program.hpp"

#ifdef MESHMOTION_HAVE_CAD
#include "meshmotion/cad/cad_model.hpp"
#endif

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cstdint>
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
  std::vector<std::string> geometry;
  double cad_tolerance = 0.0;  // 0: 1e-6 of the CAD model's diagonal
  std::vector<std::string> groups;
  bool json = false;
  bool overwrite = false;
  bool keep_orientation = false;
  std::string svg;
  std::vector<double> zoom;
  bool svg_no_markers = false;
  // curve_mesh()'s keys and the mover's, from their flags, --option and --options-file.
  examples::MoverArguments options;
};

// A --geometry naming a STEP, IGES or BREP file rather than an analytic shape.
bool cad_geometry(const Arguments& args) { return args.geometry.size() == 1 && is_cad_file(args.geometry.front()); }

// The options given, without the geometry (whose text needs the mesh's dimension).
template <int Dim>
CurveOptions<Dim> given_curve_options(const Arguments& args) {
  CurveOptions<Dim> options;
  set_curve_options(options, examples::given_options(args.options));
  // Each stage is named in an out-of-memory message; on stderr it is timed, unless --json.
  const std::string input = args.input.empty() ? "the demo mesh" : args.input;
  options.progress = [start = std::chrono::steady_clock::now(), input, quiet = args.json](const std::string& line) {
    examples::set_stage("curving " + input + ": " + line);
    if (quiet) return;
    const double t = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::fprintf(stderr, "[%7.3f s] %s\n", t, line.c_str());
  };
  return options;
}

template <int Dim>
CurveOptions<Dim> curve_options(const Arguments& args) {
  CurveOptions<Dim> options = given_curve_options<Dim>(args);
  if (cad_geometry(args)) return options;  // the groups come from the model (run())
  std::vector<std::string> groups = args.groups;
  if (groups.empty() && !args.geometry.empty()) groups.push_back("wall");
  if (!args.geometry.empty() && args.geometry.size() != 1 && args.geometry.size() != groups.size())
    throw InputError("--geometry: " + std::to_string(args.geometry.size()) + " geometries for " +
                     std::to_string(groups.size()) + " groups (expected one for all, or one per --group)");
  for (std::size_t g = 0; g < groups.size() && !args.geometry.empty(); ++g)
    options.geometry.insert_or_assign(groups[g], geometry_from_text<Dim>(args.geometry[args.geometry.size() == 1 ? 0 : g]));
  return options;
}

std::filesystem::path with_extension(const std::filesystem::path& file, const char* extension) {
  std::filesystem::path p = file;
  return p.replace_extension(extension);
}

template <int Dim>
int run(Mesh<Dim> linear, const Arguments& args) {
  if (!args.demo) examples::handle_orientation(linear, args.input, args.keep_orientation);
  CurveOptions<Dim> options = curve_options<Dim>(args);
  std::string cad_report;
  std::vector<std::string> on_model;  // the groups curved on the CAD file
  double cad_seconds = 0.0;
#ifdef MESHMOTION_HAVE_CAD
  // Kept for the whole run: the groups' geometry refers to it.
  static std::optional<CadModel> model;
  CadCurving cad;
#endif
  if (cad_geometry(args)) {
#ifdef MESHMOTION_HAVE_CAD
    const auto start = std::chrono::steady_clock::now();
    model.emplace(CadModel::read(args.geometry.front()));
    cad = geometry_on_cad(linear, *model, options, args.cad_tolerance, args.groups);
    cad_report = cad.report;
    on_model = cad.on_model;
    cad_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (!args.json) std::fprintf(stderr, "CAD model %s:\n%s", args.geometry.front().c_str(), cad_report.c_str());
#else
    throw InputError("--geometry " + args.geometry.front() + ": CAD files need the CAD component, which this build lacks "
                     "(install libocct-modeling-algorithms-dev libocct-data-exchange-dev and reconfigure)");
#endif
  }
  CurveResult<Dim> result = curve_mesh(linear, options);
#ifdef MESHMOTION_HAVE_CAD
  if (model) {
    // Each node's place on the model goes into the .msh, so the curved mesh goes back into
    // Gmsh's CAD-aware tools (and into this program again) tied to the model.
    const auto start = std::chrono::steady_clock::now();
    place_on_cad(result.curved, *model, cad.matches, args.cad_tolerance);
    cad_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
#endif
  result.seconds.cad = cad_seconds;
  result.seconds.total += cad_seconds;
  const std::vector<double>& values = result.cell_quality;
  // The mesh, its .vtu and the picture are written as a set: all of them, or on an error none.
  detail::OutputSet outputs;
  examples::set_stage("writing " + args.output);
  outputs.stage(args.output, [&](const std::filesystem::path& file) { write_mesh(file, result.curved); });
  const std::filesystem::path vtu = with_extension(args.output, ".vtu");
  VtuFields fields;
  fields.cell_data.emplace_back("scaled_jacobian",
                                Eigen::Map<const Eigen::MatrixXd>(values.data(), 1, static_cast<Index>(values.size())));
  examples::set_stage("writing " + vtu.string());
  outputs.stage(vtu, [&](const std::filesystem::path& file) { write_vtu(file, result.curved, fields); });
  if constexpr (Dim == 2) {
    if (!args.svg.empty()) {
      SvgOptions svg;
      char numbers[160];
      std::snprintf(numbers, sizeof numbers, "): min %.4g, mean %.4g, %lld of %lld cells invalid", result.quality.min,
                    result.quality.mean, static_cast<long long>(result.quality.num_invalid),
                    static_cast<long long>(result.quality.num_elements));
      svg.title = "certified scaled Jacobian of the P" + std::to_string(result.order) + " mesh (" + result.method + numbers;
      if (args.zoom.size() == 4) svg.zoom = std::array<double, 4>{args.zoom[0], args.zoom[1], args.zoom[2], args.zoom[3]};
      // Invalid cells are magenta and ringed: the scale keeps the valid range [0, 1] instead of
      // stretching down to the worst negative value (which left every valid cell one colour).
      svg.mark_invalid = !args.svg_no_markers;
      svg.value_min = svg.mark_invalid ? 0.0 : std::min(0.0, result.quality.min);
      examples::set_stage("writing " + args.svg);
      outputs.stage(args.svg, [&](const std::filesystem::path& file) { write_svg(file, result.curved, values, svg); });
    }
  }
  outputs.commit();
  const QualityReport& q = result.quality;
  if (args.json) {
    JsonWriter w(std::cout);
    w.begin_object();
    w.key("input").value(args.demo ? std::string("demo: boundary-layer O-mesh around a cylinder") : args.input);
    w.key("output").value(args.output).key("vtu").value(vtu.string());
    w.key("dim").value(Dim).key("nodes").value(result.curved.num_nodes()).key("cells").value(result.curved.num_cells());
    if (!cad_report.empty()) w.key("cad_groups").value(cad_report);
    w.key("min_scaled_jacobian").value(q.min).key("mean_scaled_jacobian").value(q.mean);
    write_json_fields(w, result);
    w.key("options").begin_object();
    for (const OptionDoc& d : option_docs(options)) w.key(d.key).value(d.value);
    for (const OptionDoc& d : MoverConfig<Dim>{options.method, *options.mover_options}.docs()) w.key(d.key).value(d.value);
    w.end_object();
    w.end_object();
    std::cout << "\n";
  } else {
    std::printf("curved %lld cells, %lld nodes (%lld linear) at order %d with %s\n",
                static_cast<long long>(result.curved.num_cells()), static_cast<long long>(result.curved.num_nodes()),
                static_cast<long long>(result.num_linear_nodes), result.order, result.method.c_str());
    write_text(std::cout, result, 2);
    std::cout.flush();
    // The last line says what each curved group was curved onto: a CAD file that fits only
    // some groups leaves the others to the reconstruction.
    std::string curved_on;
    for (const std::string& g : result.curved_groups) {
      if (!curved_on.empty()) curved_on += ", ";
      curved_on += "'";
      curved_on += g;
      curved_on += "' ";
      if (std::find(on_model.begin(), on_model.end(), g) != on_model.end())
        curved_on += "on " + std::filesystem::path(args.geometry.front()).filename().string();
      else if (options.geometry.count(g) > 0)
        curved_on += "on the given --geometry";
      else
        curved_on += Dim == 2 ? "by spline" : "by surface reconstruction";
    }
    std::string sliding;
    for (const std::string& g : result.sliding_groups) sliding.append(sliding.empty() ? "; sliding: '" : ", '").append(g).append("'");
    if (q.num_invalid == 0 && result.off_geometry() == 0 && result.reversed_cells == 0)
      std::printf("wrote %s, %s%s%s (curved: %s%s)\n", args.output.c_str(), vtu.string().c_str(), args.svg.empty() ? "" : ", ",
                  args.svg.c_str(), curved_on.empty() ? "none" : curved_on.c_str(), sliding.c_str());
  }
  if (q.num_invalid > 0 || result.off_geometry() > 0 || result.reversed_cells > 0) {
    std::fflush(stdout);
    if (q.num_invalid > 0)
      std::fprintf(stderr, "wrote %s WITH %lld INVALID CELLS of %lld\n", args.output.c_str(),
                   static_cast<long long>(q.num_invalid), static_cast<long long>(q.num_elements));
    // Valid cells in the wrong place: a wall taken the long way round, a model that fits badly.
    for (const GeometryDistance& w : result.geometry_distance)
      if (w.facets_off > 0)
        std::fprintf(stderr, "wrote %s WITH %lld FACETS OF '%s' OFF ITS GEOMETRY (up to %.3g x a facet's size, %.3g; tolerance %.3g)\n",
                     args.output.c_str(), static_cast<long long>(w.facets_off), w.group.c_str(), w.max_relative_distance,
                     w.max_distance, options.geometry_tolerance);
    if (result.reversed_cells > 0)
      std::fprintf(stderr, "wrote %s WITH %lld CELLS TURNED OVER BY MOVING %lld VERTICES ONTO THE GEOMETRY (up to %.3g)\n",
                   args.output.c_str(), static_cast<long long>(result.reversed_cells), static_cast<long long>(result.moved_vertices),
                   result.max_boundary_displacement);
    return examples::exit_invalid;
  }
  return examples::exit_ok;
}

// A table cell: '|' escaped, "(empty)" for nothing.
std::string cell(const std::string& text) {
  std::string out;
  for (const char c : text) {
    if (c == '|') out += '\\';
    out += c;
  }
  return out.empty() ? "(empty)" : out;
}

// An option's "what it does" cell: its whole description, or its line where that is all.
std::string what(const OptionDoc& d) { return d.details.empty() ? d.doc : d.details; }

// docs/options.md: every option and report field from the library's one description.
void print_options_markdown() {
  std::printf("# Options and results\n\n"
              "Generated by `curve_mesh --options-markdown` from the library's descriptions (`visit_options`,\n"
              "`visit_fields`); a test fails when this file and the descriptions differ. Each key is the\n"
              "command-line flag (`--key-with-dashes`; a bool also takes `--no-key`), the `--option KEY=VALUE`\n"
              "and options-file key, the Python keyword, and the JSON or Python dict key of a report.\n\n"
              "## curve_mesh\n\n`geometry` has its own text (`--geometry`, Python's `geometry={group: text}`); every key\n"
              "of the chosen `method`'s mover is a key of curve_mesh too (below).\n\n"
              "| key | type | default | what it does |\n|---|---|---|---|\n");
  const std::vector<OptionDoc> plane = option_docs(CurveOptions<2>{}), space = option_docs(CurveOptions<3>{});
  for (std::size_t k = 0; k < plane.size(); ++k) {
    const std::string value = plane[k].value == space[k].value ? cell(plane[k].value) : cell(plane[k].value) + " (3D: " + cell(space[k].value) + ")";
    std::printf("| `%s` | %s | %s | %s |\n", plane[k].key.c_str(), cell(plane[k].type).c_str(), value.c_str(), cell(what(plane[k])).c_str());
  }
  std::printf("\n## Movers (`--method`)\n");
  for (const auto& m : mover_methods<3>()) {
    std::printf("\n### %s\n%s.\n", std::string(m.name).c_str(), std::string(m.summary).c_str());
    const std::vector<OptionDoc> docs = mover_config<3>(std::string(m.name)).docs();
    if (docs.empty()) {
      std::printf("\nNo options.\n");
      continue;
    }
    std::printf("\n| key | type | default | what it does |\n|---|---|---|---|\n");
    for (const OptionDoc& d : docs)
      std::printf("| `%s` | %s | %s | %s |\n", d.key.c_str(), cell(d.type).c_str(), cell(d.value).c_str(), cell(what(d)).c_str());
  }
  std::printf("\n## Distributed solves\n\nThe keys of `move_mesh_mpi`, Python's `Warp(comm=...)` and the OpenFOAM plugin on a "
              "decomposed case, beside those of the method (rbf, le, sle).\n\n| key | type | default | what it does |\n|---|---|---|---|\n");
  for (const OptionDoc& d : option_docs(parallel::ParallelOptions{}))
    std::printf("| `%s` | %s | %s | %s |\n", d.key.c_str(), cell(d.type).c_str(), cell(d.value).c_str(), cell(what(d)).c_str());
  std::printf("\n## Reports\n");
  for_each_report([]<class Report>(std::string_view key, std::string_view heading, std::string_view what) {
    std::printf("\n### %s\n%s Its keys in Python: `report_fields(\"%s\")`.\n\n| key | what it is |\n|---|---|\n",
                std::string(heading).c_str(), std::string(what).c_str(), std::string(key).c_str());
    visit_fields(Report{}, [](std::string_view field, const auto&, std::string_view doc) {
      std::printf("| `%s` | %s |\n", std::string(field).c_str(), std::string(doc).c_str());
    });
  });
}

}  // namespace

int main(int argc, char** argv) {
  meshmotion::tune_process_memory(argc, argv);  // may restart the program once (core/process_memory.hpp)
  CLI::App app{"Curve a linear mesh into a certified P2 (to P8) mesh (spline or CAD boundary, RBF or blending interior)"};
  Arguments args;
  auto* input = app.add_option("input", args.input, "linear mesh (.msh, .su2, .cgns, .vtu); none: the built-in demo");
  app.add_option("-o,--output", args.output, "curved mesh to write (.msh, .cgns; .su2 for linear); a .vtu is written beside it");
  examples::add_version_flag(app);
  app.add_flag("--demo", args.demo, "curve the built-in boundary-layer mesh around a cylinder")->excludes(input);
  // Every key of curve_mesh() and of the movers is a flag (--list-options: those of --method).
  examples::add_option_flags(app, option_docs(CurveOptions<3>{}), args.options.given, "Curving options");
  // The flags of earlier versions, kept for their users' scripts.
  const auto alias = [&](const std::string& flag, const std::string& key, const std::string& value, const std::string& help) {
    if (value.empty())
      app.add_option_function<std::string>(flag, [&args, key](const std::string& v) { args.options.given.emplace_back(key, v); },
                                           "= --" + help)
          ->group("Curving options");
    else
      app.add_flag_function(flag, [&args, key, value](std::int64_t) { args.options.given.emplace_back(key, value); }, "= --" + help)
          ->group("Curving options");
  };
  alias("--active-factor", "active_radius_factor", "", "active-radius-factor");
  alias("--support-factor", "support_radius_factor", "", "support-radius-factor");
  alias("--single-radius", "per_wall_radius", "false", "no-per-wall-radius");
  alias("--mover-inner-nodes", "inner_nodes", "false", "no-inner-nodes");
  alias("--parameter-midpoint", "midpoint", "parameter", "midpoint parameter");
  examples::add_mover_options(app, args.options, "", false);
  app.add_option("--geometry", args.geometry,
                 "true boundary: spline | reconstruct | straight | bump | circle:X,Y,R | naca:XXXX[,CHORD,X0,Y0] | sphere:X,Y,Z,R "
                 "(one for all --group, or one per group), or a CAD file (.step, .stp, .iges, .igs, .brep) for every group it fits");
  app.add_option("--group", args.groups,
                 "groups the --geometry applies to (default: wall; with a CAD file, every group the model fits)");
  app.add_option("--cad-tolerance", args.cad_tolerance,
                 "CAD file: how far a vertex may be from the model (default: 1e-6 of the model's diagonal)");
  app.add_flag("--overwrite", args.overwrite, "allow the output to be the input file");
  app.add_flag("--keep-orientation", args.keep_orientation,
               "refuse a mesh whose cells are all negatively oriented instead of reorienting it");
  app.add_flag("--json", args.json, "print one JSON object");
  bool markdown = false;
  app.add_flag("--options-markdown", markdown, "print docs/options.md (every option and report field) and exit");
  app.add_option("--svg", args.svg, "2D: write an SVG picture coloured by quality");
  app.add_option("--zoom", args.zoom, "SVG zoom box x0,x1,y0,y1 (only cells reaching into it are written)")
      ->delimiter(',')
      ->expected(4);
  app.add_flag("--svg-no-markers", args.svg_no_markers,
               "SVG: do not ring invalid cells (by default each cell with scaled Jacobian <= 0 gets a red ring, "
               "the legend counts them and the colour scale spans [0, 1]); the scale then reaches down to the minimum");
  if (const auto rc = meshmotion::examples::parse_command_line(app, argc, argv)) return *rc;

  args.demo = args.demo || args.input.empty();
  return examples::guarded(args.json, [&] {
    if (markdown) {
      print_options_markdown();
      return examples::exit_ok;
    }
    if (args.options.list_options) {
      const CurveOptions<3> options = given_curve_options<3>(args);
      examples::print_option_docs("curve_mesh with method " + options.method + ": " +
                                      std::string(mover_method<3>(options.method).summary),
                                  curve_option_docs<3>(options.method));
      return examples::exit_ok;
    }
    if (args.demo) {
      if (args.output.empty()) args.output = "cylinder_p" + std::to_string(given_curve_options<3>(args).order) + ".msh";
      if (args.svg.empty()) args.svg = with_extension(args.output, ".svg").string();
      if (args.zoom.empty()) args.zoom = {0.47, 0.53, -0.03, 0.03};
      if (args.geometry.empty()) {
        args.groups = {"wall"};
        args.geometry = {"circle:0,0,0.5"};
      }
      examples::check_output({}, args.output, given_curve_options<3>(args).order, args.overwrite);
      examples::check_side_output(args.svg, {args.options.options_file}, {args.output, with_extension(args.output, ".vtu")});
      return run(o_mesh({}), args);  // 128 x 64 quads, first cell 1e-5 for a 0.025 wall spacing
    }
    if (args.output.empty()) throw InputError("curve_mesh: no output file (expected -o OUTPUT)");
    // The curved mesh is of order --order, and a .vtu goes beside it: both are checked before any work.
    const int order = given_curve_options<3>(args).order;
    examples::check_output(args.input, args.output, order, args.overwrite);
    // The pictures never replace what the run reads, whatever --overwrite allows the mesh.
    const std::filesystem::path vtu = with_extension(args.output, ".vtu"), options_file = args.options.options_file,
                                geometry = cad_geometry(args) ? std::filesystem::path(args.geometry.front()) : std::filesystem::path();
    check_mesh_output(vtu, order);
    examples::check_side_output(vtu, {args.input, geometry, options_file}, {args.output});
    if (!args.svg.empty()) examples::check_side_output(args.svg, {args.input, geometry, options_file}, {args.output, vtu});
    AnyMesh mesh = examples::read_input(args.input);
    return std::visit([&](auto& m) { return run(std::move(m), args); }, mesh);
  });
}
