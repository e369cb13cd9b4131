// What the readers make of inputs that used to read wrong or not at all (issue 17): a
// consistently reversed mesh, a mixed one, a UTF-8 byte-order mark; output checks; the
// worst cell's id as the written file gives it.

#include "meshmotion/core/generators.hpp"
#include "meshmotion/core/orientation.hpp"
#include "meshmotion/io.hpp"
#include "meshmotion/quality/quality_report.hpp"
#include "meshmotion/quality/svg_picture.hpp"

#include "test_data.hpp"

#include "messages.hpp"

#include <catch2/catch.hpp>

#include <sys/stat.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

using namespace meshmotion;
namespace fs = std::filesystem;

namespace {

void write_file(const fs::path& file, const std::string& text) {
  std::ofstream out(file, std::ios::binary);
  out << text;
}

// A unit square of two triangles, both listed clockwise (or the second one counterclockwise).
std::string square_su2(bool mixed) {
  return std::string("NDIME= 2\nNELEM= 2\n5 0 2 1 0\n") + (mixed ? "5 0 2 3 1\n" : "5 0 3 2 1\n") +
         "NPOIN= 4\n0 0 0\n1 0 1\n1 1 2\n0 1 3\nNMARK= 1\nMARKER_TAG= wall\nMARKER_ELEMS= 1\n3 0 1\n";
}

template <class F>
std::string input_error_of(F&& f) {
  return test::message_of<InputError>(std::forward<F>(f));
}

}  // namespace

TEST_CASE("orientation at read time: reversed meshes fixed or refused, mixed ones named", "[io][orientation]") {
  const fs::path reversed = test::scratch_path("reversed.su2");
  write_file(reversed, square_su2(false));
  CHECK(orientation_report(read_mesh_as<2>(reversed)).num_negative == 2);  // keep: as the file lists them
  const Mesh<2> fixed = read_mesh_as<2>(reversed, {ReadOrientation::fix_reversed});
  CHECK(orientation_report(fixed).num_negative == 0);
  CHECK(quality_report(fixed, Metric::scaled_jacobian).num_invalid == 0);
  CHECK_THAT(input_error_of([&] { (void)read_mesh(reversed, {ReadOrientation::require_positive}); }),
             Catch::Contains("every cell") && Catch::Contains("element"));

  const fs::path mixed = test::scratch_path("mixed.su2");
  write_file(mixed, square_su2(true));
  Mesh<2> m = read_mesh_as<2>(mixed, {ReadOrientation::fix_reversed});
  CHECK(orientation_report(m).num_negative == 1);  // a mixed mesh is not "fixed" behind the user's back
  const OrientationFix fix = orient_consistently(m);
  CHECK(fix.found == OrientationFix::Found::mixed);
  CHECK(fix.reoriented == 0);
  CHECK(name(fix.found) == "mixed");
  CHECK_THAT(input_error_of([&] { (void)read_mesh(mixed, {ReadOrientation::require_positive}); }),
             Catch::Contains("mixed orientation"));
  CHECK(to_json(summarize(m)).find("\"orientation\":\"mixed\"") != std::string::npos);
}

TEST_CASE("orientation at read time: the clockwise SU2 test mesh", "[io][orientation]") {
  MESHMOTION_REQUIRE_DATA(file, "su2_naca64a010_aeroelastic_hybrid.su2");
  const Mesh<2> as_is = read_mesh_as<2>(file);
  const OrientationReport before = orientation_report(as_is);
  CHECK(before.num_negative == before.num_cells);
  const Mesh<2> fixed = read_mesh_as<2>(file, {ReadOrientation::fix_reversed});
  CHECK(orientation_report(fixed).num_negative == 0);
  CHECK(quality_report(fixed, Metric::scaled_jacobian).num_invalid == 0);
  CHECK(fixed.points == as_is.points);  // numbering kept
}

TEST_CASE("a UTF-8 byte-order mark is skipped", "[io]") {
  const std::string bom = "\xEF\xBB\xBF";
  const fs::path su2 = test::scratch_path("bom.su2");
  write_file(su2, bom + square_su2(false));
  CHECK(read_mesh_as<2>(su2).num_nodes() == 4);
  const fs::path msh = test::scratch_path("bom.msh");
  write_file(msh, bom + "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n3\n1 0 0 0\n2 1 0 0\n3 0 1 0\n$EndNodes\n"
                        "$Elements\n1\n1 2 2 0 1 1 2 3\n$EndElements\n");
  CHECK(read_mesh_as<2>(msh).num_cells() == 1);
}

TEST_CASE("outputs are checked before any work", "[io]") {
  CHECK_NOTHROW(check_mesh_output(test::scratch_path("a.msh"), 2));
  CHECK_NOTHROW(check_mesh_output(test::scratch_path("a.su2"), 1));
  CHECK_NOTHROW(check_mesh_output(test::scratch_path("a.su2"), 4));  // SU2's DG-FEM format
  CHECK_THAT(input_error_of([] { check_mesh_output(test::scratch_path("a.cgns"), 5); }),
             Catch::Contains("up to order 4") || Catch::Contains("needs the CGNS library"));
  CHECK_THAT(input_error_of([] { check_mesh_output(test::scratch_path("a.vtk"), 1); }), Catch::Contains(".vtk"));
  if (have_cgns) CHECK_NOTHROW(check_mesh_output(test::scratch_path("a.cgns"), 4));
  CHECK_THAT(input_error_of([] { check_mesh_output(test::scratch_path("no/such/folder/a.msh"), 1); }),
             Catch::Contains("does not exist"));
}

TEST_CASE("the worst cell is named by the id the written .msh gives it", "[io][quality]") {
  Mesh<2> mesh = rectangle_mesh({});
  const ElementBlock& quads = mesh.cells.front();
  const Index bad = 37;
  mesh.points.col(quads.element(bad)[2]) = mesh.points.col(quads.element(bad)[0]);  // collapse a cell
  const QualityReport q = quality_report(mesh, Metric::scaled_jacobian);
  REQUIRE(!q.worst.empty());
  const fs::path file = test::scratch_path("worst.msh");
  write_mesh(file, mesh, WriteOptions{MshVersion::v2_2});
  // Read the element line of that id back and find the cell's nodes on it.
  std::ifstream in(file);
  std::string line;
  bool found = false;
  while (std::getline(in, line))
    if (line.rfind(std::to_string(q.worst[0].file_id) + " 3 ", 0) == 0) {
      found = true;
      std::istringstream s(line);
      std::int64_t id = 0, type = 0, ntags = 0, tag = 0, entity = 0;
      s >> id >> type >> ntags >> tag >> entity;
      std::vector<std::int64_t> nodes(4);
      for (auto& n : nodes) s >> n;
      const auto cell = mesh.cells.front().element(q.worst[0].id);
      for (int k = 0; k < 4; ++k) CHECK(nodes[static_cast<std::size_t>(k)] == msh_node_id(mesh, cell[static_cast<std::size_t>(k)]));
    }
  CHECK(found);
  CHECK(q.worst[0].file_id == static_cast<std::int64_t>(mesh.num_facets()) + q.worst[0].id + 1);
}

TEST_CASE("SU2 prisms are in VTK's order: the base turns away from the top (issue 21)", "[io][orientation]") {
  // One prism as SU2 (VTK) lists it: base (0,1,2) clockwise seen from the top triangle (3,4,5).
  const std::string prism = "NDIME= 3\nNELEM= 1\n13 0 1 2 3 4 5 0\nNPOIN= 6\n"
                            "0 0 0 0\n0 1 0 1\n1 0 0 2\n0 0 1 3\n0 1 1 4\n1 0 1 5\n"
                            "NMARK= 1\nMARKER_TAG= bottom\nMARKER_ELEMS= 1\n5 0 1 2\n";
  const fs::path file = test::scratch_path("vtk_prism.su2");
  write_file(file, prism);
  const Mesh<3> mesh = read_mesh_as<3>(file);
  CHECK(orientation_report(mesh).num_negative == 0);
  CHECK(quality_report(mesh, Metric::scaled_jacobian).num_invalid == 0);

  // Every type of a positive mixed mesh keeps its orientation and numbering through a file.
  for (const auto cells : {BoxCells::prism6, BoxCells::tet_pyramid_prism, BoxCells::hex_prism}) {
    const Mesh<3> box = box_mesh({.nx = 3, .ny = 2, .nz = 2, .cells = cells});
    REQUIRE(orientation_report(box).num_negative == 0);
    const fs::path out = test::scratch_path("box_prisms.su2");
    write_mesh(out, box);
    const Mesh<3> back = read_mesh_as<3>(out);
    CHECK(orientation_report(back).num_negative == 0);
    for (std::size_t b = 0; b < box.cells.size(); ++b) CHECK(back.cells[b].connectivity == box.cells[b].connectivity);
  }
  // The writer lists a prism in VTK's order, as SU2 reads it.
  const std::string text = format_su2(box_mesh({.nx = 1, .ny = 1, .nz = 1, .cells = BoxCells::prism6}));
  const Mesh<3> one = box_mesh({.nx = 1, .ny = 1, .nz = 1, .cells = BoxCells::prism6});
  const auto p = one.cells.front().element(0);
  std::ostringstream line;
  line << "\n13\t" << p[0] << '\t' << p[2] << '\t' << p[1] << '\t' << p[3] << '\t' << p[5] << '\t' << p[4] << "\t0\n";
  CHECK(text.find(line.str()) != std::string::npos);
}

TEST_CASE("SU2 sections after the markers (periodic transformations, FFD boxes) are read past", "[io]") {
  const std::string extra = "NPERIODIC= 1\nPERIODIC_INDEX= 0\n0 0 0\n0 0 0\n0 0 0\n"
                            "FFD_NBOX= 1\nFFD_NLEVEL= 1\nFFD_TAG= BOX\nFFD_LEVEL= 0\nFFD_DEGREE_I= 1\nFFD_DEGREE_J= 1\n"
                            "FFD_BLENDING= BEZIER\nFFD_PARENTS= 0\nFFD_CHILDREN= 0\nFFD_CORNER_POINTS= 4\n"
                            "-0.1\t-0.1\n1.1\t-0.1\n1.1\t1.1\n-0.1\t1.1\nFFD_CONTROL_POINTS= 2\n0\t0\t0\t-0.1\t-0.1\t-0.5\n"
                            "1\t0\t0\t1.1\t-0.1\t-0.5\nFFD_SURFACE_POINTS= 1\nwall\t1\t0.5\t0.5\t0.5\n";
  const fs::path file = test::scratch_path("ffd.su2");
  write_file(file, square_su2(false) + extra);
  const Mesh<2> mesh = read_mesh_as<2>(file);
  CHECK(mesh.num_nodes() == 4);
  CHECK(mesh.num_cells() == 2);
  CHECK(mesh.group_nodes("wall") == std::vector<Index>{0, 1});
  // A keyword line after the skipped data is still read: a marker section after an FFD box.
  write_file(file, "NDIME= 2\nFFD_NBOX= 1\nFFD_CORNER_POINTS= 1\n0 0\n" + square_su2(false).substr(9));
  CHECK(read_mesh_as<2>(file).num_cells() == 2);
}

TEST_CASE("SU2 lines that say something else than their element, and markers beyond NMARK, are refused", "[io]") {
  const fs::path file = test::scratch_path("hostile.su2");
  const auto parse_error = [&](const std::string& text) {
    write_file(file, text);
    return test::message_of<ParseError>([&] { (void)read_mesh(file); });
  };
  // A quadrilateral's line given the triangle's type code: four nodes and an index.
  CHECK_THAT(parse_error("NDIME= 2\nNELEM= 1\n5 0 1 2 3 0\nNPOIN= 4\n0 0 0\n1 0 1\n1 1 2\n0 1 3\n"),
             Catch::Contains("hostile.su2:3:") && Catch::Contains("tri3 element with more numbers than its 3 nodes"));
  // One number after the nodes is SU2's element index, so the same line without its index
  // reads as a triangle: the type code alone cannot tell.
  write_file(file, "NDIME= 2\nNELEM= 1\n5 0 1 2 3\nNPOIN= 4\n0 0 0\n1 0 1\n1 1 2\n0 1 3\n");
  CHECK(read_mesh_as<2>(file).num_cells() == 1);
  CHECK_THAT(parse_error(square_su2(false) + "MARKER_TAG= far\nMARKER_ELEMS= 1\n3 1 2\n"),
             Catch::Contains("MARKER_TAG= of a marker beyond NMARK="));
}

TEST_CASE("a group name given to two groups is refused where it is looked up, naming both", "[io]") {
  const fs::path file = test::scratch_path("twice.su2");
  write_file(file, "NDIME= 2\nNELEM= 2\n5 0 1 2 0\n5 0 2 3 1\nNPOIN= 4\n0 0 0\n1 0 1\n1 1 2\n0 1 3\nNMARK= 2\n"
                   "MARKER_TAG= wall\nMARKER_ELEMS= 1\n3 0 1\nMARKER_TAG= wall\nMARKER_ELEMS= 1\n3 2 3\n");
  const Mesh<2> mesh = read_mesh_as<2>(file);
  CHECK_THAT(input_error_of([&] { (void)mesh.group("wall"); }),
             Catch::Contains("'wall' names two groups (tag 1 of dimension 1 and tag 2 of dimension 1)"));
}

TEST_CASE("node ids are each format's own: from 0 in SU2 and VTU, from 1 in a written .msh", "[io]") {
  const fs::path su2 = test::scratch_path("numbering.su2");
  write_file(su2, square_su2(false));
  const Mesh<2> from_su2 = read_mesh_as<2>(su2);
  CHECK(from_su2.first_node_id == 0);
  CHECK(from_su2.node_indices(std::vector<std::int64_t>{0, 3}) == std::vector<Index>{0, 3});
  CHECK_THAT(input_error_of([&] { (void)from_su2.node_indices(std::vector<std::int64_t>{4}); }),
             Catch::Contains("no node has id 4") && Catch::Contains("numbers its nodes 0 to 3"));
  const fs::path vtu = test::scratch_path("numbering.vtu");
  write_mesh(vtu, from_su2);
  CHECK(read_mesh_as<2>(vtu).node_indices(std::vector<std::int64_t>{0}) == std::vector<Index>{0});
  // Written as .msh, the same node is 1: Gmsh numbers from 1.
  const fs::path msh = test::scratch_path("numbering.msh");
  write_mesh(msh, from_su2);
  const Mesh<2> from_msh = read_mesh_as<2>(msh);
  CHECK(from_msh.node_indices(std::vector<std::int64_t>{1, 4}) == std::vector<Index>{0, 3});
  CHECK_THROWS_AS(from_msh.node_indices(std::vector<std::int64_t>{0}), InputError);
}

namespace {

/// A msh 4.1 square: one line on curve 1 ("wall"), two triangles on surface 1 ("fluid").
/// `elements` replaces its $Elements body.
std::string square_msh41(const std::string& elements = "2 3 1 3\n1 1 1 1\n1 1 2\n2 1 2 2\n2 1 2 3\n3 1 3 4\n",
                         bool entities = true) {
  return std::string("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$PhysicalNames\n2\n1 1 \"wall\"\n2 2 \"fluid\"\n$EndPhysicalNames\n") +
         (entities ? "$Entities\n0 1 1 0\n1 0 0 0 1 0 0 1 1 0\n1 0 0 0 1 1 0 1 2 0\n$EndEntities\n" : "") +
         "$Nodes\n1 4 1 4\n2 1 0 4\n1\n2\n3\n4\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n$EndNodes\n$Elements\n" + elements + "$EndElements\n";
}

}  // namespace

TEST_CASE("Gmsh 4.1: element blocks must sit on declared entities of their dimension, in one $Elements section", "[io]") {
  const fs::path file = test::scratch_path("hostile.msh");
  const auto parse_error = [&](const std::string& text) {
    write_file(file, text);
    return test::message_of<ParseError>([&] { (void)read_mesh(file); });
  };
  write_file(file, square_msh41());
  const Mesh<2> square = read_mesh_as<2>(file);
  CHECK(square.num_cells() == 2);
  CHECK(square.group_nodes("wall") == std::vector<Index>{0, 1});
  CHECK(square.group_nodes("fluid").size() == 4);
  // Each of these once read as a mesh whose groups had lost their elements, or held them twice.
  CHECK_THAT(parse_error(square_msh41("2 3 1 3\n1 1 1 1\n1 1 2\n2 7 2 2\n2 1 2 3\n3 1 3 4\n")),
             Catch::Contains("hostile.msh:") && Catch::Contains("element block on entity 7 of dimension 2, which $Entities does not declare"));
  CHECK_THAT(parse_error(square_msh41("2 3 1 3\n1 1 1 1\n1 1 2\n1 1 2 2\n2 1 2 3\n3 1 3 4\n")),
             Catch::Contains("element block of tri3 (dimension 2) on an entity of dimension 1"));
  std::string twice = square_msh41();
  twice += twice.substr(twice.find("$Elements"));
  CHECK_THAT(parse_error(twice), Catch::Contains("a second $Elements section"));
  CHECK_THAT(parse_error(square_msh41("2 3 1 3\n1 1 1 1\n1 1 2\n2 1 2 2\n2 1 2 3\n3 1 3 4\n", false)),
             Catch::Contains("physical groups are named but there is no $Entities section"));
  std::string entity_twice = square_msh41();
  entity_twice.replace(entity_twice.find("0 1 1 0\n"), 8, "0 2 1 0\n1 0 0 0 1 0 0 1 1 0\n");
  CHECK_THAT(parse_error(entity_twice), Catch::Contains("entity 1 of dimension 1 declared twice"));
  // Types beyond those read are named with what is read.
  CHECK_THAT(parse_error(square_msh41("1 1 1 1\n1 1 65 1\n1 1 2 3 4 1 2 3 4 1 2\n")),
             Catch::Contains("unsupported Gmsh element type 65 (expected"));  // line10, order 9
}

TEST_CASE("a cell or facet through one node twice is refused by the SU2 and Gmsh readers, naming file, line and node", "[io]") {
  const fs::path su2 = test::scratch_path("twice_node.su2"), msh = test::scratch_path("twice_node.msh");
  write_file(su2, "NDIME= 2\nNELEM= 2\n5 0 1 2 0\n5 0 2 2 1\nNPOIN= 4\n0 0 0\n1 0 1\n1 1 2\n0 1 3\n");
  CHECK_THAT(test::message_of<ParseError>([&] { (void)read_mesh(su2); }),
             Catch::Contains("twice_node.su2:4:") && Catch::Contains("tri3 element lists node 2 twice"));
  write_file(su2, "NDIME= 2\nNELEM= 2\n5 0 2 1 0\n5 0 3 2 1\nNPOIN= 4\n0 0 0\n1 0 1\n1 1 2\n0 1 3\nNMARK= 1\n"
                  "MARKER_TAG= wall\nMARKER_ELEMS= 1\n3 1 1\n");
  CHECK_THAT(test::message_of<ParseError>([&] { (void)read_mesh(su2); }), Catch::Contains("line2 element lists node 1 twice"));
  write_file(msh, square_msh41("2 3 1 3\n1 1 1 1\n1 1 2\n2 1 2 2\n2 1 2 3\n3 1 4 4\n"));
  CHECK_THAT(test::message_of<ParseError>([&] { (void)read_mesh(msh); }),
             Catch::Contains("twice_node.msh:32:") && Catch::Contains("element 3 (tri3) lists node 4 twice"));
  write_file(msh, "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n3\n1 0 0 0\n2 1 0 0\n5 0 1 0\n$EndNodes\n$Elements\n1\n"
                  "7 2 2 0 1 1 5 1\n$EndElements\n");
  CHECK_THAT(test::message_of<ParseError>([&] { (void)read_mesh(msh); }),
             Catch::Contains("twice_node.msh:12:") && Catch::Contains("element 7 (tri3) lists node 1 twice"));
}

TEST_CASE("SU2: a multi-zone file is refused as such, not as a second NELEM section", "[io]") {
  const fs::path file = test::scratch_path("zones.su2");
  write_file(file, "NZONE= 2\nIZONE= 1\n" + square_su2(false) + "IZONE= 2\n" + square_su2(false));
  CHECK_THAT(test::message_of<ParseError>([&] { (void)read_mesh(file); }),
             Catch::Contains("zones.su2:1:") && Catch::Contains("NZONE= 2: a multi-zone SU2 file"));
  write_file(file, "NZONE= 1\n" + square_su2(false));
  CHECK(read_mesh_as<2>(file).num_cells() > 0);
}

TEST_CASE("the outputs of one run are written as a set: all of them, or on an error none and the old files kept", "[io]") {
  const fs::path dir = test::scratch_path("output_set");
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path mesh_file = dir / "out.msh", picture = dir / "out.svg";
  write_file(picture, "old picture");
  const Mesh<2> square = rectangle_mesh();
  const auto files = [&] {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
  };
  {
    detail::OutputSet outputs;
    outputs.stage(mesh_file, [&](const fs::path& file) {
      CHECK(file.extension() == ".msh");  // the writer chooses the format by it
      write_mesh(file, square);
    });
    CHECK_THROWS_WITH(outputs.stage(picture, [](const fs::path& file) { throw IoError(file.string() + ": write failed (disk full?)"); }),
                      "meshmotion: " + picture.string() + ": write failed (disk full?)");  // the output's name, not the temporary's
  }
  CHECK(files() == std::vector<std::string>{"out.svg"});
  std::ifstream old(picture);
  CHECK(std::string(std::istreambuf_iterator<char>(old), {}) == "old picture");
  {
    detail::OutputSet outputs;
    outputs.stage(mesh_file, [&](const fs::path& file) { write_mesh(file, square); });
    outputs.stage(picture, [&](const fs::path& file) { write_svg(file, square, std::vector<double>(static_cast<std::size_t>(square.num_cells()), 1.0)); });
    CHECK(files().size() == 3);  // the old picture and two temporaries, until the commit
    outputs.commit();
  }
  CHECK(files() == std::vector<std::string>{"out.msh", "out.svg"});
  CHECK(read_mesh_as<2>(mesh_file).num_cells() == square.num_cells());
}

TEST_CASE("a path that is no regular file is refused naming why: a loop of links, a link to nothing, a pipe", "[io]") {
  const fs::path dir = test::scratch_path("odd_paths");
  fs::remove_all(dir);
  fs::create_directories(dir);
  const auto io_error = [](const fs::path& file) { return test::message_of<IoError>([&] { (void)read_mesh(file); }); };
  fs::create_symlink("b.msh", dir / "a.msh");
  fs::create_symlink("a.msh", dir / "b.msh");
  CHECK_THAT(io_error(dir / "a.msh"), Catch::Contains("a.msh: cannot read: Too many levels of symbolic links"));
  fs::create_symlink("gone.su2", dir / "link.su2");
  CHECK_THAT(io_error(dir / "link.su2"), Catch::Contains("link.su2: a symbolic link to nothing (gone.su2)"));
  CHECK_THAT(io_error(dir / "none.su2"), Catch::Contains("none.su2: no such file"));
  REQUIRE(mkfifo((dir / "pipe.su2").c_str(), 0600) == 0);
  CHECK_THAT(io_error(dir / "pipe.su2"), Catch::Contains("pipe.su2: cannot read: not a regular file (a device, pipe or socket)"));
  if (have_cgns) {
    REQUIRE(mkfifo((dir / "pipe.cgns").c_str(), 0600) == 0);
    CHECK_THAT(io_error(dir / "pipe.cgns"), Catch::Contains("pipe.cgns: cannot read: not a regular file (a device, pipe or socket)"));
    CHECK_THAT(io_error(dir / "a.cgns"), Catch::Contains("a.cgns: no such file"));
  }
}
