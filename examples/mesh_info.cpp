// mesh_info: prints what a mesh file holds (element counts per type, boundary groups,
// bounding box, edge lengths, orientation), as text or as one JSON object. It shows the file
// as it is: a reversed or mixed orientation is reported, never changed. An OpenFOAM case is
// also shown as checkMesh shows it: its points, faces and cells, the cells by shape
// (polyhedra, not the tetrahedra the library cuts them into) and its patches with their types.
// --compare OTHER reports the largest distance between the two files' points, node by node
// (a run on several ranks against the serial run, a moved mesh against a solver's), and
// exits 2 when it exceeds --tolerance of the bounding box's diagonal.

#include "meshmotion/core/fields.hpp"
#include "meshmotion/core/json.hpp"
#include "meshmotion/io.hpp"
#include "meshmotion/io/foam_case_summary.hpp"

#include "program.hpp"

#include <CLI/CLI.hpp>

#include <cmath>
#include <filesystem>
#include <iostream>
#include <optional>
#include <string>
#include <variant>

using namespace meshmotion;

namespace {

struct Comparison {
  std::string file;
  double max_difference = 0.0;  // largest distance between a node's two positions
  double relative = 0.0;        // max_difference over the bounding box's diagonal
  double tolerance = 0.0;
  bool within = true;
};

template <class F>
void visit_fields(const Comparison& c, F&& f) {
  f("file", c.file, "the mesh compared with");
  f("max_difference", c.max_difference, "largest distance between a node's two positions");
  f("relative", c.relative, "max_difference over the bounding box's diagonal");
  f("tolerance", c.tolerance, "largest relative difference allowed");
  f("within", c.within, "relative <= tolerance");
}

Comparison compare(const AnyMesh& mesh, const std::string& other_file, double tolerance) {
  const AnyMesh other = examples::read_input(other_file);
  if (mesh.index() != other.index())
    throw InputError("mesh_info --compare: " + other_file + " is " + std::to_string(other.index() + 2) + "D, the mesh " +
                     std::to_string(mesh.index() + 2) + "D");
  return std::visit(
      [&](const auto& a) {
        const auto& b = std::get<std::decay_t<decltype(a)>>(other);
        if (a.num_nodes() != b.num_nodes())
          throw InputError("mesh_info --compare: " + other_file + " has " + std::to_string(b.num_nodes()) + " nodes, the mesh " +
                           std::to_string(a.num_nodes()) + " (expected the same nodes)");
        Comparison c{other_file, 0.0, 0.0, tolerance, true};
        if (a.num_nodes() == 0) return c;
        c.max_difference = (a.points - b.points).colwise().norm().maxCoeff();
        const double diagonal = (a.points.rowwise().maxCoeff() - a.points.rowwise().minCoeff()).norm();
        c.relative = diagonal > 0.0 ? c.max_difference / diagonal : c.max_difference;
        c.within = c.relative <= tolerance;  // false for a NaN
        return c;
      },
      mesh);
}

}  // namespace

int main(int argc, char** argv) {
  meshmotion::tune_process_memory(argc, argv);  // may restart the program once (core/process_memory.hpp)
  CLI::App app{"Print the contents of a mesh file (.msh, .su2, .cgns or .vtu) or OpenFOAM case"};
  examples::add_version_flag(app);
  std::string file;
  bool json = false;
  app.add_option("file", file, "mesh file (.msh Gmsh 2.2/4.1, .su2, .cgns) or OpenFOAM case folder")->required();
  app.add_flag("--json", json, "print one JSON object instead of text");
  std::string other;
  double tolerance = 1e-10;
  app.add_option("--compare", other, "another file of the same nodes: report the largest distance between their points");
  app.add_option("--tolerance", tolerance, "with --compare, the largest difference allowed relative to the bounding box's "
                 "diagonal (exit 2 beyond it; default 1e-10)")->check(CLI::NonNegativeNumber);
  examples::FoamSelection foam;
  examples::add_foam_options(app, foam);
  if (const auto rc = meshmotion::examples::parse_command_line(app, argc, argv)) return *rc;
  return examples::guarded(json, [&] {
    file = examples::foam_input(file, foam).string();
    const AnyMesh mesh = examples::read_input(file);
    const auto summary = std::visit([](const auto& m) { return summarize(m); }, mesh);
    std::error_code ec;
    const std::optional<PolyMesh> poly =
        std::filesystem::is_directory(file, ec) ? std::optional<PolyMesh>(read_polymesh(file)) : std::nullopt;
    const std::optional<FoamCaseSummary> foam_case = poly ? std::optional(summarize(*poly)) : std::nullopt;
    const std::optional<Comparison> compared =
        other.empty() ? std::nullopt : std::optional(compare(mesh, examples::foam_input(other, foam).string(), tolerance));
    if (json) {
      JsonWriter w(std::cout);
      w.begin_object().key("file").value(file).key("mesh");
      write_json(w, summary);
      if (foam_case) {
        w.key("openfoam");
        write_json(w, *foam_case);
      }
      if (compared) {
        w.key("compared");
        write_json(w, *compared);
      }
      w.end_object();
      std::cout << "\n";
    } else {
      std::cout << file << ":\n";
      write_text(std::cout, summary, 2);
      if (foam_case) {
        std::cout << "  the OpenFOAM case, as checkMesh counts it:\n";
        write_text(std::cout, *foam_case, 4);
      }
      if (compared) {
        std::cout << "  compared with " << compared->file << ":\n";
        write_text(std::cout, *compared, 4);
      }
    }
    return compared && !compared->within ? examples::exit_invalid : examples::exit_ok;
  });
}
