// mesh_info: prints what a mesh file holds (element counts per type, boundary groups,
// bounding box, edge lengths, orientation), as text or as one JSON object. It shows the file
// as it is: a reversed or mixed orientation is reported, never changed. An OpenFOAM case is
// also shown as checkMesh shows it: its points, faces and cells, the cells by shape
// (polyhedra, not the tetrahedra the library cuts them into) and its patches with their types.

#include "meshmotion/core/json.hpp"
#include "meshmotion/io.hpp"
#include "meshmotion/io/foam_case_summary.hpp"

#include "program.hpp"

#include <CLI/CLI.hpp>

#include <filesystem>
#include <iostream>
#include <optional>
#include <string>
#include <variant>

using namespace meshmotion;

int main(int argc, char** argv) {
  meshmotion::tune_process_memory(argc, argv);  // may restart the program once (core/process_memory.hpp)
  CLI::App app{"Print the contents of a mesh file (.msh, .su2, .cgns or .vtu) or OpenFOAM case"};
  examples::add_version_flag(app);
  std::string file;
  bool json = false;
  app.add_option("file", file, "mesh file (.msh Gmsh 2.2/4.1, .su2, .cgns) or OpenFOAM case folder")->required();
  app.add_flag("--json", json, "print one JSON object instead of text");
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
    if (json) {
      JsonWriter w(std::cout);
      w.begin_object().key("file").value(file).key("mesh");
      write_json(w, summary);
      if (foam_case) {
        w.key("openfoam");
        write_json(w, *foam_case);
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
    }
    return examples::exit_ok;
  });
}
