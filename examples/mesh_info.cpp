// mesh_info: prints what a mesh file holds (element counts per type, boundary groups,
// bounding box, edge lengths, inverted cells), as text or as one JSON object.

#include "meshmotion/io.hpp"

#include <CLI/CLI.hpp>

#include <iostream>
#include <string>
#include <variant>

int main(int argc, char** argv) {
  CLI::App app{"Print the contents of a mesh file (.msh or .su2)"};
  std::string file;
  bool json = false;
  app.add_option("file", file, "mesh file (.msh Gmsh 2.2/4.1, .su2)")->required();
  app.add_flag("--json", json, "print one JSON object instead of text");
  CLI11_PARSE(app, argc, argv);
  try {
    const meshmotion::AnyMesh mesh = meshmotion::read_mesh(file);
    const auto summary = std::visit([](const auto& m) { return meshmotion::summarize(m); }, mesh);
    if (json) std::cout << "{\"file\":" << meshmotion::detail::json_string(file) << ",\"mesh\":" << meshmotion::to_json(summary) << "}\n";
    else std::cout << file << ": " << meshmotion::to_text(summary);
  } catch (const meshmotion::Error& e) {
    if (json) std::cout << "{\"file\":" << meshmotion::detail::json_string(file) << ",\"error\":" << meshmotion::detail::json_string(e.what()) << "}\n";
    std::cerr << e.what() << "\n";
    return 1;
  }
  return 0;
}
