// mesh_info: prints what a mesh file holds (element counts per type, boundary groups,
// bounding box, edge lengths, orientation), as text or as one JSON object. It shows the file
// as it is: a reversed or mixed orientation is reported, never changed.

#include "meshmotion/core/json.hpp"
#include "meshmotion/io.hpp"

#include "program.hpp"

#include <CLI/CLI.hpp>

#include <iostream>
#include <string>
#include <variant>

int main(int argc, char** argv) {
  meshmotion::tune_process_memory(argc, argv);  // may restart the program once (core/process_memory.hpp)
  using namespace meshmotion;
  CLI::App app{"Print the contents of a mesh file (.msh, .su2, .cgns or .vtu) or OpenFOAM case"};
  examples::add_version_flag(app);
  std::string file;
  bool json = false;
  app.add_option("file", file, "mesh file (.msh Gmsh 2.2/4.1, .su2, .cgns) or OpenFOAM case folder")->required();
  app.add_flag("--json", json, "print one JSON object instead of text");
  if (const auto rc = meshmotion::examples::parse_command_line(app, argc, argv)) return *rc;
  return examples::guarded(json, [&] {
    const AnyMesh mesh = examples::read_input(file);
    const auto summary = std::visit([](const auto& m) { return summarize(m); }, mesh);
    if (json) {
      JsonWriter w(std::cout);
      w.begin_object().key("file").value(file).key("mesh");
      write_json(w, summary);
      w.end_object();
      std::cout << "\n";
    } else {
      std::cout << file << ":\n";
      write_text(std::cout, summary, 2);
    }
    return examples::exit_ok;
  });
}
