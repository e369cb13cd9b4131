// mesh_info: prints what a mesh file holds (element counts per type, boundary groups,
// bounding box, edge lengths, orientation), as text or as one JSON object. It shows the file
// as it is: a reversed or mixed orientation is reported, never changed. An OpenFOAM case is
// also shown as checkMesh shows it: its points, faces and cells, the cells by shape
// (polyhedra, not the tetrahedra the library cuts them into) and its patches with their types.

#include "meshmotion/core/json.hpp"
#include "meshmotion/io.hpp"

#include "program.hpp"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <array>
#include <filesystem>
#include <iostream>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

namespace {

using namespace meshmotion;

// checkMesh's cell shapes, by the faces' vertex counts and the cell's vertex count.
constexpr std::array<const char*, 5> shape_names{"hexahedra", "prisms", "pyramids", "tetrahedra", "polyhedra"};

std::array<Index, 5> cell_shapes(const PolyMesh& poly) {
  const auto nc = static_cast<std::size_t>(poly.num_cells);
  std::vector<std::array<int, 3>> faces(nc, {0, 0, 0});  // triangles, quadrilaterals, others
  std::vector<std::vector<Index>> vertices(nc);
  const auto add = [&](Index cell, Index f) {
    const auto v = poly.face(f);
    auto& count = faces[static_cast<std::size_t>(cell)];
    ++count[v.size() == 3 ? 0 : v.size() == 4 ? 1 : 2];
    vertices[static_cast<std::size_t>(cell)].insert(vertices[static_cast<std::size_t>(cell)].end(), v.begin(), v.end());
  };
  for (Index f = 0; f < poly.num_faces(); ++f) {
    add(poly.owner[static_cast<std::size_t>(f)], f);
    if (f < poly.num_internal_faces()) add(poly.neighbour[static_cast<std::size_t>(f)], f);
  }
  std::array<Index, 5> out{};
  for (std::size_t c = 0; c < nc; ++c) {
    std::vector<Index>& v = vertices[c];
    std::sort(v.begin(), v.end());
    const auto points = std::unique(v.begin(), v.end()) - v.begin();
    const auto [tris, quads, others] = faces[c];
    int shape = 4;
    if (others == 0 && tris == 0 && quads == 6 && points == 8) shape = 0;
    if (others == 0 && tris == 2 && quads == 3 && points == 6) shape = 1;
    if (others == 0 && tris == 4 && quads == 1 && points == 5) shape = 2;
    if (others == 0 && tris == 4 && quads == 0 && points == 4) shape = 3;
    ++out[static_cast<std::size_t>(shape)];
  }
  return out;
}

// Cell zones, then face zones, then point zones, as OpenFOAM lists them: f("cellZone", zone).
template <class F>
void for_each_zone(const PolyMesh& poly, F&& f) {
  for (const auto& z : poly.cell_zones) f("cellZone", z);
  for (const auto& z : poly.face_zones) f("faceZone", z);
  for (const auto& z : poly.point_zones) f("pointZone", z);
}

void write_case_json(JsonWriter& w, const PolyMesh& poly) {
  w.key("openfoam").begin_object();
  w.key("points").value(poly.points.cols()).key("faces").value(poly.num_faces());
  w.key("internal_faces").value(poly.num_internal_faces()).key("cells").value(poly.num_cells);
  const std::array<Index, 5> shapes = cell_shapes(poly);
  w.key("cell_shapes").begin_object();
  for (std::size_t k = 0; k < shapes.size(); ++k) w.key(shape_names[k]).value(shapes[k]);
  w.end_object();
  w.key("patches").begin_array();
  for (const auto& p : poly.patches) {
    w.begin_object().key("name").value(p.name).key("type").value(p.type).key("faces").value(p.size);
    w.key("in_groups").array(p.groups);
    w.end_object();
  }
  w.end_array();
  w.key("zones").begin_array();
  for_each_zone(poly, [&](const char* kind, const PolyMesh::Zone& z) {
    w.begin_object().key("name").value(z.name).key("kind").value(kind).key("size").value(static_cast<Index>(z.labels.size())).end_object();
  });
  w.end_array().end_object();
}

void write_case_text(std::ostream& out, const PolyMesh& poly) {
  out << "  OpenFOAM case: " << poly.points.cols() << " points, " << poly.num_faces() << " faces (" << poly.num_internal_faces()
      << " internal), " << poly.num_cells << " cells\n    cells:";
  const std::array<Index, 5> shapes = cell_shapes(poly);
  for (std::size_t k = 0; k < shapes.size(); ++k) out << " " << shape_names[k] << " " << shapes[k] << (k + 1 < shapes.size() ? "," : "\n");
  for (const auto& p : poly.patches) {
    out << "    patch " << p.name << ": " << p.type << ", " << p.size << " faces";
    for (std::size_t g = 0; g < p.groups.size(); ++g) out << (g == 0 ? ", in groups " : " ") << p.groups[g];
    out << "\n";
  }
  for_each_zone(poly, [&](const char* kind, const PolyMesh::Zone& z) {
    out << "    " << kind << " " << z.name << ": " << z.labels.size() << " " << std::string_view(kind).substr(0, std::string_view(kind).size() - 4)
        << (z.labels.size() == 1 ? "" : "s") << "\n";
  });
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
    if (json) {
      JsonWriter w(std::cout);
      w.begin_object().key("file").value(file).key("mesh");
      write_json(w, summary);
      if (poly) write_case_json(w, *poly);
      w.end_object();
      std::cout << "\n";
    } else {
      std::cout << file << ":\n";
      write_text(std::cout, summary, 2);
      if (poly) write_case_text(std::cout, *poly);
    }
    return examples::exit_ok;
  });
}
