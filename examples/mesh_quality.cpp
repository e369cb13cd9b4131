// mesh_quality: quality report of a mesh file (Knupp metrics and the certified scaled
// Jacobian), per metric and per element type; optionally a .vtu with the per-cell values and,
// for 2D meshes, an SVG picture coloured by the first metric. For an OpenFOAM case folder, also
// checkMesh's measures (non-orthogonality, skewness, aspect ratio, volumes) on its polyhedra.
//
//   mesh_quality wing.msh --metric shape --metric jacobian --svg q.svg --zoom 0.9,1.1,-0.05,0.05

#include "meshmotion/core/detail/atomic_file.hpp"
#include "meshmotion/core/json.hpp"
#include "meshmotion/io.hpp"
#include "meshmotion/quality.hpp"

#include "program.hpp"

#include <CLI/CLI.hpp>

#include <iostream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

using namespace meshmotion;

namespace {

struct Settings {
  std::string file;
  std::vector<std::string> metrics;
  bool json = false;
  std::string vtu, svg;
  std::vector<double> zoom;
  bool svg_no_markers = false;
  bool keep_orientation = false;
  int worst = 5;
};

template <int Dim>
int run(Mesh<Dim>& mesh, const Settings& s) {
  examples::handle_orientation(mesh, s.file, s.keep_orientation);
  std::vector<Metric> metrics;
  for (const auto& m : s.metrics) metrics.push_back(metric_from_name(m));
  if (metrics.empty()) metrics = {Metric::shape, Metric::skew, Metric::relative_size, Metric::scaled_jacobian};
  ReportOptions options;
  options.num_worst = s.worst;
  VtuFields fields;
  std::vector<QualityReport> reports;
  std::vector<double> first_values;
  for (Metric m : metrics) {
    const auto cells = evaluate_cells(mesh, m, options.quality);
    reports.push_back(make_report(mesh, m, cells, options));
    Eigen::MatrixXd column(1, static_cast<Index>(cells.size()));
    for (std::size_t i = 0; i < cells.size(); ++i) column(0, static_cast<Index>(i)) = cells[i].value;
    fields.cell_data.emplace_back(std::string(metric_name(m)), column);
    if (first_values.empty())
      for (const auto& c : cells) first_values.push_back(c.value);
  }
  // The .vtu and the picture are written as a set: both, or on an error neither.
  detail::OutputSet outputs;
  if (!s.vtu.empty()) outputs.stage(s.vtu, [&](const std::filesystem::path& file) { write_vtu(file, mesh, fields); });
  if (!s.svg.empty()) {
    if constexpr (Dim == 2) {
      SvgOptions svg;
      if (!s.zoom.empty()) {
        if (s.zoom.size() != 4) throw InputError("mesh_quality: --zoom needs xmin,xmax,ymin,ymax (got " + std::to_string(s.zoom.size()) + " numbers)");
        svg.zoom = std::array<double, 4>{s.zoom[0], s.zoom[1], s.zoom[2], s.zoom[3]};
      }
      svg.title = std::string(metric_name(metrics.front()));
      svg.mark_invalid = !s.svg_no_markers;
      outputs.stage(s.svg, [&](const std::filesystem::path& file) { write_svg(file, mesh, first_values, svg); });
    } else {
      std::cerr << "mesh_quality: --svg is for 2D meshes; " << s.file << " is 3D, no picture written\n";
    }
  }
  outputs.commit();
  // An OpenFOAM case: checkMesh's measures on its cells as they are (polyhedra included).
  std::optional<FoamQuality> foam;
  if (std::filesystem::is_directory(s.file)) foam = foam_quality(read_polymesh(s.file));
  if (s.json) {
    JsonWriter w(std::cout);
    w.begin_object().key("file").value(s.file).key("dim").value(Dim);
    w.key("nodes").value(mesh.num_nodes()).key("elements").value(mesh.num_cells());
    w.key("metrics").begin_object();
    for (const auto& r : reports) {
      w.key(metric_name(r.metric));
      write_json(w, r);
    }
    w.end_object();
    if (foam) {
      w.key("checkmesh");
      write_json(w, *foam);
    }
    w.end_object();
    std::cout << '\n';
  } else {
    std::cout << s.file << ": " << Dim << "D, " << mesh.num_nodes() << " nodes, " << mesh.num_cells() << " cells\n";
    for (const auto& r : reports) print_report(std::cout, r);
    if (foam) {
      std::cout << "checkMesh measures:\n";
      write_text(std::cout, *foam, 2);
      // checkMesh's verdict over these checks (its open-cell and topological ones are not here).
      const int failed = foam->failed_checks;
      if (failed == 0)
        std::cout << "Mesh OK (checkMesh's volume, face pyramid, non-orthogonality, skewness and aspect ratio checks)\n";
      else
        std::cout << "Failed " << failed << " mesh check" << (failed == 1 ? "" : "s")
                  << " (of checkMesh's volume, face pyramid, non-orthogonality, skewness and aspect ratio checks)\n";
    }
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  meshmotion::tune_process_memory(argc, argv);  // may restart the program once (core/process_memory.hpp)
  CLI::App app{"Mesh quality report: Knupp size/shape/skew metrics and the certified scaled Jacobian of P1/P2 cells"};
  examples::add_version_flag(app);
  Settings s;
  app.add_option("file", s.file, "mesh file (.msh, .su2, .cgns, .vtu) or OpenFOAM case folder")->required()->check(CLI::ExistingPath);
  app.add_option("--metric", s.metrics, "shape, skew, size, size-shape, size-skew or jacobian (repeatable; default shape, skew, size, jacobian)");
  app.add_flag("--json", s.json, "print one JSON object instead of the table");
  app.add_option("--vtu", s.vtu, "write the mesh with one cell array per metric");
  app.add_option("--svg", s.svg,
                 "write a picture of a 2D mesh coloured by the first metric on [0, 1]; cells with a value <= 0 are "
                 "magenta, ringed in red and counted in the legend");
  app.add_flag("--svg-no-markers", s.svg_no_markers, "SVG: no rings on invalid cells");
  app.add_option("--zoom", s.zoom, "picture box xmin,xmax,ymin,ymax")->delimiter(',');
  app.add_option("--worst", s.worst, "how many worst cells to list per metric");
  app.add_flag("--keep-orientation", s.keep_orientation,
               "refuse a mesh whose cells are all negatively oriented instead of reorienting it");
  examples::FoamSelection foam;
  examples::add_foam_options(app, foam);
  if (const auto rc = meshmotion::examples::parse_command_line(app, argc, argv)) return *rc;
  return examples::guarded(s.json, [&] {
    s.file = examples::foam_input(s.file, foam).string();
    if (!s.vtu.empty()) {
      check_mesh_output(s.vtu, 2);
      examples::check_side_output(s.vtu, {s.file});
    }
    if (!s.svg.empty()) examples::check_side_output(s.svg, {s.file}, {s.vtu});
    AnyMesh mesh = examples::read_input(s.file);
    return std::visit([&](auto& m) { return run(m, s); }, mesh);
  });
}
