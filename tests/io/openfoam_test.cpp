// Tests of OpenFOAM polyMesh reading and in-place point writing (io/openfoam.hpp): the shared
// airFoil2D case with its documented counts, a case with a polyhedral cell (a hanging node)
// cut into tetrahedra, ASCII, binary and compressed files alike, moved points written into the
// case or a time folder and read back, and the error for each kind of bad file.

#include "meshmotion/core/generators.hpp"
#include "meshmotion/core/orientation.hpp"
#include "meshmotion/io.hpp"
#include "meshmotion/quality/foam_quality.hpp"
#include "meshmotion/movers.hpp"
#include "meshmotion/quality.hpp"

#include "io_support.hpp"
#include "messages.hpp"
#include "test_data.hpp"

#include <catch2/catch.hpp>

#include <sys/resource.h>

#include <algorithm>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#ifdef MESHMOTION_HAVE_ZLIB
#include <zlib.h>
#endif

using namespace meshmotion;
namespace fs = std::filesystem;

namespace {

std::string read_text(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

enum class Format { ascii, binary, compressed };

void write_case(const fs::path& case_dir, const PolyMesh& mesh, Format format = Format::ascii) {
  fs::remove_all(case_dir);
  write_polymesh(case_dir, mesh, PolyMeshWriteOptions{format == Format::binary, format == Format::compressed});
  // What OpenFOAM's checkMesh reads beside the mesh.
  fs::create_directories(case_dir / "system");
  const auto dictionary = [&](const std::string& object, const std::string& body) {
    std::ofstream(case_dir / "system" / object) << "FoamFile\n{\n    version 2.0;\n    format ascii;\n    class dictionary;\n    object "
                                                << object << ";\n}\n" << body;
  };
  dictionary("controlDict", "application simpleFoam;\nstartFrom startTime;\nstartTime 0;\nstopAt endTime;\nendTime 1;\n"
                            "deltaT 1;\nwriteControl timeStep;\nwriteInterval 1;\n");
  dictionary("fvSchemes", "ddtSchemes { default steadyState; }\ngradSchemes { default Gauss linear; }\ndivSchemes { default none; }\n"
                          "laplacianSchemes { default Gauss linear corrected; }\ninterpolationSchemes { default linear; }\n"
                          "snGradSchemes { default corrected; }\n");
  dictionary("fvSolution", "solvers {}\n");
}

std::vector<Format> formats() {
#ifdef MESHMOTION_HAVE_ZLIB
  return {Format::ascii, Format::binary, Format::compressed};
#else
  return {Format::ascii, Format::binary};
#endif
}

// Three cells: a polyhedron x in [0,1], y in [0,2] (its +x side split in two faces, its z = 0
// and z = 1 sides pentagons through the hanging node (1,1)), and two hexahedra beside it.
PolyMesh hanging_node_case() {
  PolyMesh c;
  const double xy[8][2] = {{0, 0}, {1, 0}, {2, 0}, {1, 1}, {2, 1}, {0, 2}, {1, 2}, {2, 2}};
  c.points.resize(3, 16);
  for (int z = 0; z < 2; ++z)
    for (int k = 0; k < 8; ++k) c.points.col(8 * z + k) << xy[k][0], xy[k][1], double(z);
  const std::vector<std::vector<Index>> faces{
      {1, 3, 11, 9},     {3, 6, 14, 11},   {3, 11, 12, 4},                   // internal
      {0, 8, 13, 5},                                                         // wall
      {2, 4, 12, 10},    {4, 7, 15, 12},                                     // outlet
      {0, 1, 9, 8},      {1, 2, 10, 9},    {5, 13, 14, 6}, {6, 14, 15, 7},   // y sides
      {0, 5, 6, 3, 1},   {1, 3, 4, 2},     {3, 6, 7, 4},                     // z = 0
      {8, 9, 11, 14, 13}, {9, 10, 12, 11}, {11, 12, 15, 14}};                // z = 1
  for (const auto& f : faces) {
    c.face_nodes.insert(c.face_nodes.end(), f.begin(), f.end());
    c.face_offsets.push_back(static_cast<Index>(c.face_nodes.size()));
  }
  c.owner = {0, 0, 1, 0, 1, 2, 0, 1, 0, 2, 0, 1, 2, 0, 1, 2};
  c.neighbour = {1, 2, 2};
  c.patches = {{"wall", "wall", 3, 1}, {"outlet", "patch", 4, 2}, {"sides", "patch", 6, 4}, {"frontAndBack", "empty", 10, 6}};
  c.num_cells = 3;
  return c;
}

// checkMesh's output on a case, or empty when OpenFOAM is not installed (Debian's openfoam
// keeps its etc folder in /usr/share/openfoam).
std::string check_mesh(const fs::path& case_dir) {
  if (std::system("command -v checkMesh > /dev/null 2>&1") != 0) return {};
  const fs::path log = case_dir / "checkMesh.log";
  std::string env;
  if (fs::exists("/usr/share/openfoam/etc/controlDict")) env = "WM_PROJECT_DIR=/usr/share/openfoam FOAM_ETC=/usr/share/openfoam/etc ";
  const std::string command = env + "checkMesh -case " + case_dir.string() + " > " + log.string() + " 2>&1";
  (void)std::system(command.c_str());
  return read_text(log);
}

// The number after `label` in checkMesh's report.
double reported(const std::string& report, const std::string& label) {
  const std::size_t at = report.find(label);
  if (at == std::string::npos) FAIL("checkMesh does not report '" << label << "'");
  return std::stod(report.substr(at + label.size()));
}

// Our measures against checkMesh's report (6 significant digits there).
void require_checkmesh_values(const FoamQuality& q, const std::string& report) {
  INFO(report);
  CHECK(q.max_aspect_ratio == Approx(reported(report, "Max aspect ratio = ")).epsilon(1e-5));
  if (report.find("Minimum negative volume: ") != std::string::npos) {
    CHECK(q.min_volume == Approx(reported(report, "Minimum negative volume: ")).epsilon(1e-5));
    CHECK(q.num_nonpositive_volumes == static_cast<Index>(reported(report, "Number of negative volume cells: ")));
  } else {
    CHECK(q.num_nonpositive_volumes == 0);
    CHECK(q.min_volume == Approx(reported(report, "Min volume = ")).epsilon(1e-5));
    CHECK(q.max_volume == Approx(reported(report, "Max volume = ")).epsilon(1e-5));
    CHECK(q.total_volume == Approx(reported(report, "Total volume = ")).epsilon(1e-5));
  }
  CHECK(q.max_non_orthogonality == Approx(reported(report, "non-orthogonality Max: ")).epsilon(1e-5));
  CHECK(q.average_non_orthogonality == Approx(reported(report, "average: ")).epsilon(1e-5));
  CHECK(q.max_skewness == Approx(reported(report, "Max skewness = ")).epsilon(1e-5));
  const bool severe = report.find("severely non-orthogonal") != std::string::npos;
  CHECK(severe == (q.num_severely_non_orthogonal > 0));
  if (severe) CHECK(q.num_severely_non_orthogonal == static_cast<Index>(reported(report, "Number of severely non-orthogonal (> 70 degrees) faces: ")));
  // " ***Max skewness = S, N highly skew faces detected ..."
  const std::size_t skew_count = report.find(" highly skew faces");
  CHECK((skew_count != std::string::npos) == (q.num_highly_skewed > 0));
  if (skew_count != std::string::npos) {
    const std::size_t from = report.rfind(", ", skew_count) + 2;
    CHECK(q.num_highly_skewed == std::stol(report.substr(from, skew_count - from)));
  }
  const bool errors = report.find("non-orthogonality errors") != std::string::npos;
  CHECK(errors == (q.num_non_orthogonality_errors > 0));
  if (errors) CHECK(q.num_non_orthogonality_errors == static_cast<Index>(reported(report, "Number of non-orthogonality errors: ")));
  // " ***Error in face pyramids: N faces are incorrectly oriented."
  const bool pyramids = report.find("Error in face pyramids: ") != std::string::npos;
  CHECK(pyramids == (q.num_wrong_face_pyramids > 0));
  if (pyramids) CHECK(q.num_wrong_face_pyramids == static_cast<Index>(reported(report, "Error in face pyramids: ")));
  // The verdict over the geometric checks: each failed one prints a "***" line after
  // "Checking geometry..." (the topological ones before it are not ours).
  const std::size_t geometry = report.find("Checking geometry...");
  REQUIRE(geometry != std::string::npos);
  int failed = 0;
  for (std::size_t at = report.find("***", geometry); at != std::string::npos; at = report.find("***", at + 3)) ++failed;
  CHECK(q.failed_checks == failed);
}

double total_volume(const Mesh<3>& mesh) {
  double v = 0;
  for (const auto& b : mesh.cells)
    for (Index e = 0; e < b.size(); ++e) v += signed_measure(mesh, b.type, b.element(e));
  return v;
}

}  // namespace

TEST_CASE("OpenFOAM: the airFoil2D case reads with checkMesh's counts, all hexahedra", "[io][openfoam]") {
  MESHMOTION_REQUIRE_DATA(file, "openfoam_airFoil2D_polyMesh");
  const PolyMesh poly = read_polymesh(file);
  CHECK(poly.points.cols() == 21812);
  CHECK(poly.num_faces() == 43066);
  CHECK(poly.num_internal_faces() == 21254);
  CHECK(poly.num_cells == 10720);
  REQUIRE(poly.patches.size() == 4);
  CHECK(poly.patches[2].name == "walls");
  CHECK(poly.patches[2].type == "wall");
  CHECK(poly.patches[3].size == 21440);
  const Mesh<3> mesh = std::get<Mesh<3>>(read_mesh(file));
  CHECK(mesh.num_auxiliary_nodes == 0);
  CHECK(mesh.num_nodes() == 21812);
  REQUIRE(mesh.cells.size() == 1);
  CHECK(mesh.cells.front().type == ElementType::hex8);
  CHECK(mesh.cells.front().size() == 10720);
  CHECK(orientation_report(mesh).num_negative == 0);
  CHECK(test::group_size(mesh, "walls") == 78);
  CHECK(test::group_size(mesh, "frontAndBack") == 21440);
  CHECK(mesh.points == poly.points);
}

TEST_CASE("OpenFOAM: a polyhedral cell is cut into tetrahedra around auxiliary centres", "[io][openfoam]") {
  const PolyMesh c = hanging_node_case();
  for (const auto format : formats()) {
    INFO("format " << static_cast<int>(format));
    const fs::path dir = test::scratch_path("foam_hanging");
    write_case(dir, c, format);
    const PolyMesh poly = read_polymesh(dir);
    CHECK(poly.num_cells == 3);
    CHECK(poly.face(10).size() == 5);
    const Mesh<3> mesh = read_openfoam(dir);
    // 16 points, then a centre per face of 4 or 5 vertices (16) and per cell (3).
    CHECK(mesh.num_auxiliary_nodes == 19);
    CHECK(mesh.num_nodes() == 35);
    REQUIRE(mesh.cells.size() == 1);
    CHECK(mesh.cells.front().size() == 30 + 24 + 24);
    CHECK(orientation_report(mesh).num_negative == 0);
    CHECK(total_volume(mesh) == Approx(4.0).epsilon(1e-12));
    CHECK(quality_report(mesh, Metric::scaled_jacobian).num_invalid == 0);
    // The wall quad becomes 4 triangles around its centre, a patch's facets.
    CHECK(test::group_size(mesh, "wall") == 4);
    CHECK(test::group_size(mesh, "sides") == 4 * 4);
    CHECK(test::group_size(mesh, "frontAndBack") == 2 * 5 + 4 * 4);
    CHECK(mesh.points.leftCols(16) == c.points);
  }
  // OpenFOAM's own checkMesh reads the case we wrote: 3 cells, one of them a polyhedron.
  const fs::path dir = test::scratch_path("foam_checkmesh");
  write_case(dir, c);
  const std::string report = check_mesh(dir);
  if (report.empty()) {
    WARN("checkMesh not installed (Debian openfoam): the written case was not checked by OpenFOAM");
    return;
  }
  INFO(report);
  CHECK_THAT(report, Catch::Contains("cells:            3") && Catch::Contains("polyhedra:     1") && Catch::Contains("Mesh OK."));
}

TEST_CASE("OpenFOAM: patch groups and types name sets of patches, as in OpenFOAM's dictionaries", "[io][openfoam]") {
  PolyMesh c = hanging_node_case();
  c.patches[0].groups = {"body"};
  const fs::path dir = test::scratch_path("foam_groups");
  write_case(dir, c);
  const PolyMesh poly = read_polymesh(dir);
  CHECK(poly.patches[0].groups == std::vector<std::string>{"body"});
  CHECK(poly.patches[1].groups.empty());
  const Mesh<3> mesh = read_openfoam(dir);
  // The type joins the set as OpenFOAM adds it; the generic `patch` does not.
  CHECK(mesh.group("wall").in_groups == std::vector<std::string>{"body", "wall"});
  CHECK(mesh.group("outlet").in_groups.empty());
  CHECK(mesh.group("frontAndBack").in_groups == std::vector<std::string>{"empty"});
  const ResolvedBoundary<3> by_set = BoundarySpec<3>{}.fixed("body").resolve(mesh);
  CHECK(by_set.nodes == mesh.group_nodes("wall"));
  const ResolvedBoundary<3> by_pattern = BoundarySpec<3>{}.fixed("(wall|outlet)").resolve(mesh);
  const ResolvedBoundary<3> by_names = BoundarySpec<3>{}.fixed("wall").fixed("outlet").resolve(mesh);
  CHECK(by_pattern.nodes == by_names.nodes);
}

TEST_CASE("OpenFOAM: cells of standard shapes are cut into tetrahedra on request, as polyhedra are", "[io][openfoam]") {
  // A rank of a decomposed case holding only hexahedra cuts them when another rank holds
  // polyhedra (the plugin's distributed elasticity), so both must give the same volume.
  const PolyMesh poly = to_polymesh(box_mesh({.nx = 3, .ny = 2, .nz = 2}));
  const Mesh<3> kept = to_mesh(poly);
  CHECK(kept.num_auxiliary_nodes == 0);
  REQUIRE(kept.cells.size() == 1);
  CHECK(kept.cells.front().type == ElementType::hex8);
  const Mesh<3> cut = to_mesh(poly, true);
  // A centre per face (every face a quadrilateral) and per cell; 4 tetrahedra per face of a cell.
  CHECK(cut.num_auxiliary_nodes == poly.num_faces() + 12);
  REQUIRE(cut.cells.size() == 1);
  CHECK(cut.cells.front().type == ElementType::tet4);
  CHECK(cut.cells.front().size() == 12 * 6 * 4);
  CHECK(orientation_report(cut).num_negative == 0);
  CHECK(total_volume(cut) == Approx(total_volume(kept)).epsilon(1e-12));
  CHECK(cut.points.leftCols(poly.points.cols()) == poly.points);
}

TEST_CASE("OpenFOAM: moved points go into the case or a time folder, in the case's format", "[io][openfoam]") {
  const PolyMesh c = hanging_node_case();
  for (const auto format : formats()) {
    INFO("format " << static_cast<int>(format));
    const fs::path dir = test::scratch_path("foam_moved");
    write_case(dir, c, format);
    const fs::path poly_dir = dir / "constant" / "polyMesh";
    const std::string suffix = format == Format::compressed ? ".gz" : "";
    const std::string faces_before = read_text(poly_dir / ("faces" + suffix));
    const std::string points_before = read_text(poly_dir / ("points" + suffix));
    Mesh<3> mesh = read_openfoam(dir);
    for (Index i = 0; i < mesh.num_nodes(); ++i) mesh.points.col(i) += Vec<3>(0.1, 1.0 / 3.0, 0.0) * (1.0 + mesh.points(0, i));

    // A time folder: created, the constant mesh left alone.
    CHECK(is_openfoam_target(dir / "0.5"));
    write_mesh(dir / "0.5", mesh);
    CHECK(read_text(poly_dir / ("points" + suffix)) == points_before);
    const Points<3> at_time = detail::read_foam_points(dir / "0.5" / "polyMesh" / "points");
    CHECK(at_time == mesh.points.leftCols(16));  // every digit kept
    CHECK(detail::read_foam_file(dir / "0.5" / "polyMesh" / "points").find("\"0.5/polyMesh\"") != std::string::npos);
    // Read back from the time folder, as OpenFOAM's -time 0.5: those points on the constant
    // faces; a time folder without points gives the constant ones.
    const Mesh<3> at_half = read_openfoam(dir / "0.5");
    CHECK(at_half.points.leftCols(16) == mesh.points.leftCols(16));
    CHECK(at_half.cells.front().connectivity == mesh.cells.front().connectivity);
    fs::create_directories(dir / "0.25");
    CHECK(read_polymesh(dir / "0.25").points == c.points);
    CHECK_THROWS_AS(read_polymesh(dir / "0.125"), IoError);  // no such time

    // In place: only the points change.
    write_mesh(dir, mesh);
    CHECK(read_text(poly_dir / ("faces" + suffix)) == faces_before);
    const Mesh<3> back = read_openfoam(dir);
    CHECK(back.points.leftCols(16) == mesh.points.leftCols(16));
    CHECK(back.cells.front().connectivity == mesh.cells.front().connectivity);
    std::size_t files = 0;
    for ([[maybe_unused]] const auto& e : fs::directory_iterator(poly_dir)) ++files;
    CHECK(files == 5);  // no temporary left, no second points file
    if (format == Format::ascii) {
      const std::string report = check_mesh(dir);
      INFO(report);
      if (!report.empty()) CHECK_THAT(report, Catch::Contains("Mesh OK."));
    }
  }
}

TEST_CASE("OpenFOAM: moved points are written with the case's writePrecision, as OpenFOAM writes them", "[io][openfoam]") {
  const PolyMesh c = hanging_node_case();
  const fs::path dir = test::scratch_path("foam_precision");
  write_case(dir, c);
  Mesh<3> mesh = read_openfoam(dir);
  for (Index i = 0; i < mesh.num_nodes(); ++i) mesh.points.col(i) += Vec<3>(0.1, 1.0 / 3.0, 0.0) * (1.0 + mesh.points(0, i));
  fs::create_directories(dir / "system");
  {
    // A writePrecision inside a sub-dictionary (a function object's) is not the case's.
    std::ofstream out(dir / "system" / "controlDict");
    out << "FoamFile { version 2.0; format ascii; class dictionary; object controlDict; }\n"
           "functions { probes { writePrecision 12; } }\n// writePrecision 3;\nwritePrecision 6;\n";
  }
  write_mesh(dir / "0.5", mesh);
  const std::string text = detail::read_foam_file(dir / "0.5" / "polyMesh" / "points");
  CHECK(text.find("(0.1 0.333333 0)") != std::string::npos);  // point 0 moved, six digits
  const Points<3> back = detail::read_foam_points(dir / "0.5" / "polyMesh" / "points");
  CHECK((back - mesh.points.leftCols(16)).cwiseAbs().maxCoeff() < 5e-6 * mesh.points.cwiseAbs().maxCoeff());
  CHECK(back != mesh.points.leftCols(16));
  // Without a writePrecision every digit is kept.
  fs::remove(dir / "system" / "controlDict");
  write_mesh(dir / "0.5", mesh);
  CHECK(detail::read_foam_points(dir / "0.5" / "polyMesh" / "points") == mesh.points.leftCols(16));
}

TEST_CASE("OpenFOAM: each kind of bad case gets a clear error and nothing is written", "[io][openfoam]") {
  const fs::path dir = test::scratch_path("foam_bad");
  const auto message = [&](PolyMesh c) {
    write_case(dir, c);
    return test::message_of<InputError>([&] { (void)read_openfoam(dir); });
  };
  {
    // An owner list one short (the writer wants one per face: cut the file instead).
    write_case(dir, hanging_node_case());
    const fs::path owner = dir / "constant" / "polyMesh" / "owner";
    std::string text = read_text(owner);
    text.replace(text.find("\n16\n"), 4, "\n15\n");
    text.erase(text.rfind("2\n)"), 2);
    std::ofstream(owner, std::ios::binary) << text;
    CHECK_THAT(test::message_of<InputError>([&] { (void)read_openfoam(dir); }), Catch::Contains("owner") && Catch::Contains("15 entries for 16 faces"));
  }
  {
    PolyMesh c = hanging_node_case();
    c.face_nodes[static_cast<std::size_t>(c.face_offsets[5]) + 2] = 99;
    CHECK_THAT(message(c), Catch::Contains("faces") && Catch::Contains("face 5 has vertex 99"));
  }
  {
    write_case(dir, hanging_node_case());
    const fs::path boundary = dir / "constant" / "polyMesh" / "boundary";
    std::string text = read_text(boundary);
    text.replace(text.rfind("nFaces          6;"), 18, "nFaces          5;");
    std::ofstream(boundary, std::ios::binary) << text;
    CHECK_THAT(test::message_of<InputError>([&] { (void)read_openfoam(dir); }),
               Catch::Contains("boundary") && Catch::Contains("the patches end at face 15"));
  }
  {
    PolyMesh c = hanging_node_case();
    c.neighbour[1] = 0;
    CHECK_THAT(message(c), Catch::Contains("internal face 1 has neighbour 0 (owner 0,"));
  }
  {
    // A truncated list: the file and line of the end.
    write_case(dir, hanging_node_case());
    const fs::path faces = dir / "constant" / "polyMesh" / "faces";
    std::string text = read_text(faces);
    std::ofstream(faces, std::ios::binary) << text.substr(0, text.rfind(')') - 3);
    const std::string m = test::message_of<ParseError>([&] { (void)read_openfoam(dir); });
    CHECK_THAT(m, Catch::Contains("faces:") && Catch::Contains("unexpected end of file"));
  }
  {
    // A binary list shorter than its count says: refused by its count, before it is read.
    write_case(dir, hanging_node_case(), Format::binary);
    const fs::path owner = dir / "constant" / "polyMesh" / "owner";
    std::string text = read_text(owner);
    std::ofstream(owner, std::ios::binary) << text.substr(0, text.rfind(')') - 30);
    CHECK_THAT(test::message_of<ParseError>([&] { (void)read_openfoam(dir); }),
               Catch::Contains("owner:") && Catch::Contains("owner count 16 is more than the 34 bytes left"));
  }
  CHECK_THAT(test::message_of<IoError>([&] { (void)read_mesh(test::scratch_path("")); }), Catch::Contains("not an OpenFOAM case"));

  // Another mesh's points are refused, and the case keeps its own.
  write_case(dir, hanging_node_case());
  const fs::path points = dir / "constant" / "polyMesh" / "points";
  const std::string before = read_text(points);
  Mesh<3> other = read_openfoam(dir);
  other.points.conservativeResize(3, other.num_nodes() + 1);
  other.points.col(other.num_nodes() - 1).setZero();
  CHECK_THAT(test::message_of<InputError>([&] { write_mesh(dir, other); }), Catch::Contains("the mesh has 17 points, the case 16"));
  CHECK(read_text(points) == before);
  CHECK_THROWS_AS(check_mesh_output(dir, 2), InputError);
  CHECK_NOTHROW(check_mesh_output(dir, 1));
  CHECK_NOTHROW(check_mesh_output(dir / "0.25", 1));
}

TEST_CASE("OpenFOAM: corrupt counts, labels and classes are refused before anything is allocated for them", "[io][openfoam]") {
  const fs::path dir = test::scratch_path("foam_hostile");
  const fs::path mesh_dir = dir / "constant" / "polyMesh";
  // Rewrites one file of a freshly written case; returns the message read_openfoam() throws.
  const auto edited = [&](const std::string& file, Format format, const auto& edit) {
    write_case(dir, hanging_node_case(), format);
    std::string text = read_text(mesh_dir / file);
    edit(text);
    std::ofstream(mesh_dir / file, std::ios::binary) << text;
    try {
      (void)read_openfoam(dir);
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  // One owner label of 2^31 - 1: it names the face instead of sizing a cell list by it.
  CHECK_THAT(edited("owner", Format::ascii, [](std::string& t) { t.replace(t.find("\n(\n") + 3, 1, "2147483647"); }),
             Catch::Contains("owner") && Catch::Contains("face 0 has owner 2147483647") && Catch::Contains("at most 8 cells"));
  // A list count of 2^31 in a file of a few hundred bytes.
  CHECK_THAT(edited("points", Format::ascii, [](std::string& t) { t.replace(t.find("\n16\n"), 4, "\n2147483648\n"); }),
             Catch::Contains("points:") && Catch::Contains("point count 2147483648 is more than"));
  CHECK_THAT(edited("owner", Format::ascii, [](std::string& t) { t.replace(t.find("\n16\n"), t.rfind(')') - t.find("\n16\n") + 1, "\n2147483648{0}"); }),
             Catch::Contains("owner:") && Catch::Contains("uniform owner list of 2147483648 entries (at most 16 here)"));
  // One flipped byte in a binary neighbour list: the last label's high byte.
  CHECK_THAT(edited("neighbour", Format::binary, [](std::string& t) { t[t.rfind(')') - 1] = '\x40'; }),
             Catch::Contains("neighbour") && Catch::Contains("internal face 2 has neighbour 1073741826"));
  // A file declaring another class than its own, as OpenFOAM refuses it.
  CHECK_THAT(edited("points", Format::ascii, [](std::string& t) { t.replace(t.find("vectorField"), 11, "faceList"); }),
             Catch::Contains("points:") && Catch::Contains("FoamFile class 'faceList' (expected vectorField)"));
  // A face through one vertex twice.
  CHECK_THAT(edited("faces", Format::ascii, [](std::string& t) { t.replace(t.find("4(1 3 11 9)"), 11, "4(1 3 11 1)"); }),
             Catch::Contains("face 0 lists vertex 1 twice"));
  // A face relabelled to a cell of its own: a cell of one face.
  CHECK_THAT(edited("owner", Format::ascii, [](std::string& t) { t.replace(t.rfind("\n2\n"), 3, "\n3\n"); }),
             Catch::Contains("owner") && Catch::Contains("cell 3 is bounded by 1 face in the owner and neighbour lists"));
  // The vector area of a face: a unit square in z = 0 points along +z; no vertex, no area.
  PolyMesh square;
  square.points = Points<3>::Zero(3, 4);
  square.points.row(0) << 0, 1, 1, 0;
  square.points.row(1) << 0, 0, 1, 1;
  square.face_nodes = {0, 1, 2, 3};
  square.face_offsets = {0, 4, 4};
  CHECK(square.face_area(0) == Vec<3>(0, 0, 1));
  CHECK(square.face_area(1) == Vec<3>::Zero());
  // An owner/neighbour pair relabelled: the face would turn into the other cell.
  CHECK_THAT(edited("neighbour", Format::ascii, [](std::string& t) { t.replace(t.rfind("2\n)"), 3, "0\n)"); }),
             Catch::Contains("neighbour") && Catch::Contains("internal face 2 has owner 1 and neighbour 0"));
  // A face listed the wrong way round, internal or on the boundary: its cell is open.
  CHECK_THAT(edited("faces", Format::ascii, [](std::string& t) { t.replace(t.find("4(3 11 12 4)"), 12, "4(4 12 11 3)"); }),
             Catch::Contains("faces") && Catch::Contains("cell 1 is open") && Catch::Contains("face 2 points into it"));
  CHECK_THAT(edited("faces", Format::binary, [](std::string& t) {
               // Binary faces: the compact list's labels, 4 bytes each; swap face 3's 2nd and 4th.
               const std::string label8("\x08\0\0\0\x0d\0\0\0\x05\0\0\0", 12);
               const auto at = t.find(label8);
               std::swap_ranges(t.begin() + static_cast<std::ptrdiff_t>(at), t.begin() + static_cast<std::ptrdiff_t>(at) + 4,
                                t.begin() + static_cast<std::ptrdiff_t>(at) + 8);
             }),
             Catch::Contains("cell 0 is open") && Catch::Contains("face 3 points into it"));
}

TEST_CASE("OpenFOAM: bytes after a list are refused, and a compressed file is decompressed no further than its list needs",
          "[io][openfoam]") {
  const fs::path dir = test::scratch_path("foam_appended");
  const fs::path mesh_dir = dir / "constant" / "polyMesh";
  const auto message = [&] {
    try {
      (void)read_openfoam(dir);
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  write_case(dir, hanging_node_case());
  std::ofstream(mesh_dir / "owner", std::ios::app) << "\n// the end\n3 4 5\n";
  CHECK_THAT(message(), Catch::Contains("owner:") && Catch::Contains("unexpected content after the owner list ('3')"));
  write_case(dir, hanging_node_case(), Format::binary);
  std::ofstream(mesh_dir / "points", std::ios::app | std::ios::binary) << std::string(100, '\0');
  CHECK_THAT(message(), Catch::Contains("points: byte") && Catch::Contains("after the point list (a NUL byte)"));
#ifdef MESHMOTION_HAVE_ZLIB
  // A list, then 64 MiB of NUL bytes: 64 kB compressed. Decompression stops 64 KiB past the
  // list instead of holding it all.
  const auto padded = [&](const std::string& file, bool binary, std::size_t pad) {
    write_polymesh(dir, hanging_node_case(), PolyMeshWriteOptions{binary, true});
    std::string text = detail::read_foam_file(mesh_dir / file);
    const std::size_t length = text.size();
    text.append(pad, '\0');
    gzFile out = gzopen((mesh_dir / (file + ".gz")).c_str(), "wb");
    REQUIRE(out != nullptr);
    REQUIRE(gzwrite(out, text.data(), static_cast<unsigned>(text.size())) == static_cast<int>(text.size()));
    gzclose(out);
    return length;
  };
  for (const bool binary : {false, true}) {
    fs::remove_all(dir);
    const std::size_t length = padded("points", binary, std::size_t{64} << 20);
    CHECK(fs::file_size(mesh_dir / "points.gz") < (std::size_t{1} << 20));
    const std::string what = message();
    CHECK_THAT(what, Catch::Contains("points.gz: byte ") && Catch::Contains("decompresses to more than its list needs (") &&
                         Catch::Contains("bytes after the list"));
    // The list ends before the file's closing comment line: within 65 kB of the file's end.
    const std::size_t at = std::stoul(what.substr(what.find(": byte ") + 7));
    CHECK(at > 65536);
    CHECK(at <= length + 65536);
  }
  // A few NUL bytes inside the tail: read, then refused as content after the list.
  (void)padded("owner", false, 10);
  CHECK_THAT(message(), Catch::Contains("owner:") && Catch::Contains("after the owner list (a NUL byte)"));
  // The untouched compressed case reads.
  write_polymesh(dir, hanging_node_case(), PolyMeshWriteOptions{false, true});
  CHECK(message() == "no error");
#endif
}

TEST_CASE("OpenFOAM: points that cannot be written whole (a full disk) leave the case as it was, no empty time folder",
          "[io][openfoam]") {
  const fs::path dir = test::scratch_path("foam_full_disk");
  for (const auto format : formats()) {
    INFO("format " << static_cast<int>(format));
    write_case(dir, hanging_node_case(), format);
    const std::string suffix = format == Format::compressed ? ".gz" : "";
    const fs::path points = dir / "constant" / "polyMesh" / ("points" + suffix);
    const std::string before = read_text(points);
    Mesh<3> mesh = read_openfoam(dir);
    mesh.points *= 2.0;
    // The disk is full: no file may grow past 64 bytes (RLIMIT_FSIZE, its signal ignored: a
    // write fails with EFBIG, as on a full disk with ENOSPC).
    const auto written_on_full_disk = [&](const fs::path& target) {
      rlimit old{};
      REQUIRE(getrlimit(RLIMIT_FSIZE, &old) == 0);
      rlimit tiny = old;
      tiny.rlim_cur = 64;
      const auto previous = std::signal(SIGXFSZ, SIG_IGN);
      REQUIRE(setrlimit(RLIMIT_FSIZE, &tiny) == 0);
      std::string what = "no error";
      try {
        write_mesh(target, mesh);
      } catch (const Error& e) {
        what = e.what();
      }
      setrlimit(RLIMIT_FSIZE, &old);
      std::signal(SIGXFSZ, previous);
      return what;
    };
    CHECK_THAT(written_on_full_disk(dir / "0.5"), Catch::Contains("points"));
    CHECK_FALSE(fs::exists(dir / "0.5"));  // once an empty 0.5/polyMesh, which -latestTime took
    CHECK_THAT(written_on_full_disk(dir), Catch::Contains("points"));
    CHECK(read_text(points) == before);
    std::size_t files = 0;
    for ([[maybe_unused]] const auto& e : fs::directory_iterator(points.parent_path())) ++files;
    CHECK(files == 5);  // no temporary left behind
    write_mesh(dir / "0.5", mesh);
    CHECK(read_openfoam(dir / "0.5").points.leftCols(16) == mesh.points.leftCols(16));
  }
}

TEST_CASE("OpenFOAM: checkMesh's measures agree with checkMesh on the shared case, a moved one and a polyhedral one",
          "[io][openfoam][quality]") {
  // The polyhedral case: volumes are exact (planar faces).
  const PolyMesh hanging = hanging_node_case();
  const FoamQuality h = foam_quality(hanging);
  CHECK(h.solution_directions == 2);  // its z sides are an empty patch
  CHECK(h.min_volume == Approx(1.0).epsilon(1e-14));
  CHECK(h.max_volume == Approx(2.0).epsilon(1e-14));
  CHECK(h.total_volume == Approx(4.0).epsilon(1e-14));
  CHECK(h.num_nonpositive_volumes == 0);
  CHECK(h.num_wrong_face_pyramids == 0);
  CHECK(h.num_invalid_cells == 0);
  CHECK(h.failed_checks == 0);
  // mesh_quality's "checkmesh" object and text come from the description: every field in both.
  std::ostringstream json, text;
  JsonWriter w(json);
  write_json(w, h);
  write_text(text, h);
  for (const std::string& key : field_keys(h)) {
    INFO(key);
    CHECK(json.str().find("\"" + key + "\":") != std::string::npos);
    CHECK(text.str().find(key + ": ") != std::string::npos);
  }
  CHECK(json.str().find("\"solution_directions\":2,") != std::string::npos);
  const fs::path dir = test::scratch_path("foam_quality");
  write_case(dir, hanging);
  if (const std::string report = check_mesh(dir); !report.empty()) require_checkmesh_values(h, report);
  else WARN("checkMesh not installed (Debian openfoam): compared with exact values only");
  // The same cells in 3D (no empty patch): all three directions count.
  PolyMesh solid = hanging;
  solid.patches.back().type = "wall";
  const FoamQuality h3 = foam_quality(solid);
  CHECK(h3.solution_directions == 3);
  write_case(dir, solid);
  if (const std::string report = check_mesh(dir); !report.empty()) require_checkmesh_values(h3, report);

  const auto shared = test::shared_data("openfoam_airFoil2D_polyMesh");
  if (!shared) {
    WARN("skipped: openfoam_airFoil2D_polyMesh not found (../shared/data is absent here)");
    return;
  }
  PolyMesh poly = read_polymesh(*shared);
  const FoamQuality q = foam_quality(poly);
  // checkMesh (OpenFOAM 1912) on this case printed these.
  CHECK(q.solution_directions == 2);
  CHECK(q.max_aspect_ratio == Approx(98.7681).epsilon(1e-5));
  CHECK(q.min_volume == Approx(0.00085511).epsilon(1e-5));
  CHECK(q.max_volume == Approx(35.4259).epsilon(1e-5));
  CHECK(q.total_volume == Approx(10564.5).epsilon(1e-5));
  CHECK(q.max_non_orthogonality == Approx(41.6237).epsilon(1e-5));
  CHECK(q.average_non_orthogonality == Approx(7.52805).epsilon(1e-5));
  CHECK(q.max_skewness == Approx(0.983306).epsilon(1e-5));
  write_case(dir, poly);
  if (const std::string report = check_mesh(dir); !report.empty()) require_checkmesh_values(q, report);

  // Moved: a swirl around the airfoil that fades with distance, strong enough to fold cells.
  for (Index i = 0; i < poly.points.cols(); ++i) {
    const double x = poly.points(0, i), y = poly.points(1, i);  // the airfoil spans x in [-17.5, 17.5]
    const double turn = 8.0 * std::exp(-(x * x + y * y) / 100.0);
    const double c = std::cos(turn), sn = std::sin(turn);
    poly.points(0, i) = c * x - sn * y;
    poly.points(1, i) = sn * x + c * y;
  }
  const FoamQuality moved = foam_quality(poly);
  CHECK(moved.num_severely_non_orthogonal > 0);
  CHECK(moved.num_non_orthogonality_errors > 0);
  CHECK(moved.num_nonpositive_volumes > 0);
  CHECK(moved.num_highly_skewed > 0);
  CHECK(moved.num_wrong_face_pyramids > 0);
  CHECK(moved.num_invalid_cells >= moved.num_nonpositive_volumes);
  CHECK(moved.failed_checks >= 4);
  write_case(dir, poly);
  if (const std::string report = check_mesh(dir); !report.empty()) require_checkmesh_values(moved, report);
}

TEST_CASE("OpenFOAM: a wedge case's aspect ratio is taken in its geometric directions, as checkMesh takes it",
          "[io][openfoam][quality]") {
  // An axisymmetric wedge of 5 degrees about the x axis: a 2D grid in x, y (y the radius),
  // its front and back at z = -/+ y tan(2.5 degrees).
  Mesh<3> box = box_mesh({.nx = 6, .ny = 4, .nz = 1, .y_min = 0.1, .z_min = -1.0, .z_max = 1.0});
  for (Index i = 0; i < box.num_nodes(); ++i) box.points(2, i) *= box.points(1, i) * std::tan(2.5 * std::numbers::pi / 180.0);
  PolyMesh wedge = to_polymesh(box);
  for (auto& p : wedge.patches)
    if (p.name == "bottom" || p.name == "top") p.type = "wedge";
  const FoamQuality q = foam_quality(wedge);
  CHECK(q.solution_directions == 3);
  CHECK(q.geometric_directions == 2);
  PolyMesh flat = wedge;
  for (auto& p : flat.patches) p.type = "patch";
  const FoamQuality in_3d = foam_quality(flat);
  CHECK(in_3d.geometric_directions == 3);
  CHECK(q.max_aspect_ratio < in_3d.max_aspect_ratio);  // the thin direction no longer counts
  const fs::path dir = test::scratch_path("foam_wedge");
  fs::remove_all(dir);
  write_case(dir, wedge);
  if (const std::string report = check_mesh(dir); !report.empty()) require_checkmesh_values(q, report);
  else WARN("checkMesh not installed (Debian openfoam): the wedge case was not compared");
}

TEST_CASE("OpenFOAM: a mixed mesh written as a new case reads back cell by cell and passes checkMesh", "[io][openfoam]") {
  for (const auto cells : {BoxCells::tet_pyramid_prism, BoxCells::hex_prism, BoxCells::pyramid5, BoxCells::tet4}) {
    INFO("box cells " << static_cast<int>(cells));
    const Mesh<3> box = box_mesh({.nx = 4, .ny = 3, .nz = 2, .cells = cells});
    const fs::path dir = test::scratch_path("foam_new_case");
    fs::remove_all(dir);
    CHECK(is_new_openfoam_case(dir));
    write_mesh(dir, box);
    CHECK(is_openfoam_target(dir));
    const Mesh<3> back = read_openfoam(dir);
    CHECK(back.num_auxiliary_nodes == 0);
    CHECK(back.points == box.points);
    CHECK(orientation_report(back).num_negative == 0);
    // Cell by cell (OpenFOAM's cell c is the mesh's c-th cell): the same type and vertices.
    const auto by_cell = [](const Mesh<3>& m, bool use_ids) {
      std::vector<std::pair<ElementType, std::vector<Index>>> out(static_cast<std::size_t>(m.num_cells()));
      Index position = 0;
      for (const auto& b : m.cells)
        for (Index e = 0; e < b.size(); ++e, ++position) {
          const auto nodes = b.element(e);
          std::vector<Index> sorted(nodes.begin(), nodes.end());
          std::sort(sorted.begin(), sorted.end());
          out[static_cast<std::size_t>(use_ids ? b.ids[static_cast<std::size_t>(e)] - 1 : position)] = {b.type, sorted};
        }
      return out;
    };
    CHECK(by_cell(back, true) == by_cell(box, false));
    for (const auto& g : box.groups)
      if (g.dim == 2) CHECK(back.group_nodes(back.group(g.name).tag) == box.group_nodes(g.tag));
    if (const std::string report = check_mesh(dir); !report.empty()) {
      write_case(dir, read_polymesh(dir));  // the same case with the dictionaries checkMesh wants
      const std::string full = check_mesh(dir);
      INFO(full);
      CHECK_THAT(full, Catch::Contains("Mesh OK."));
      require_checkmesh_values(foam_quality(read_polymesh(dir)), full);
    }
  }
  // A new case only where there is nothing to lose.
  const fs::path file = test::scratch_path("foam_not_empty");
  fs::remove_all(file);
  fs::create_directories(file);
  std::ofstream(file / "keep.txt") << "x";
  CHECK_FALSE(is_new_openfoam_case(file));
  CHECK_THROWS_AS(write_mesh(file, box_mesh({})), InputError);
  CHECK(fs::exists(file / "keep.txt"));
}

TEST_CASE("OpenFOAM: a new case appears whole or not at all, and never over a folder that holds something", "[io][openfoam]") {
  const fs::path parent = test::scratch_path("foam_atomic");
  fs::remove_all(parent);
  fs::create_directories(parent / "empty");
  const Mesh<3> box = box_mesh({.nx = 2, .ny = 1, .nz = 1});
  write_mesh(parent / "fresh", box);
  write_mesh(parent / "empty/", box);  // an existing empty folder, named with a trailing slash
  CHECK(read_openfoam(parent / "fresh").points == box.points);
  CHECK(read_openfoam(parent / "empty").points == box.points);
  // Nothing but the two cases: the temporary folders were renamed into place.
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(parent)) names.push_back(entry.path().filename().string());
  std::sort(names.begin(), names.end());
  CHECK(names == std::vector<std::string>{"empty", "fresh"});
  // A folder that holds a file is not a place for a new case: refused, and left as it was.
  fs::create_directories(parent / "busy");
  std::ofstream(parent / "busy" / "notes.txt") << "keep";
  CHECK_THAT(test::message_of<InputError>([&] { write_new_polymesh_case(parent / "busy", to_polymesh(box)); }),
             Catch::Contains("not empty"));
  CHECK(fs::exists(parent / "busy" / "notes.txt"));
  CHECK(std::distance(fs::directory_iterator(parent), fs::directory_iterator{}) == 3);
}

TEST_CASE("OpenFOAM: cell, face and point zones come back as written and name groups of their nodes", "[io][openfoam]") {
  PolyMesh c = hanging_node_case();
  c.cell_zones = {{"body", {0}}, {"right", {1, 2}}};
  c.face_zones = {{"cut", {1, 2}, {0, 1}}};
  c.point_zones = {{"wall", {0, 5}}};  // a patch's name: its group is qualified
  for (const auto format : formats()) {
    INFO("format " << static_cast<int>(format));
    const fs::path dir = test::scratch_path("foam_zones");
    write_case(dir, c, format);
    const PolyMesh back = read_polymesh(dir);
    for (const auto& [read, written] : {std::pair{&back.cell_zones, &c.cell_zones}, std::pair{&back.face_zones, &c.face_zones},
                                        std::pair{&back.point_zones, &c.point_zones}}) {
      REQUIRE(read->size() == written->size());
      for (std::size_t z = 0; z < read->size(); ++z) {
        CHECK((*read)[z].name == (*written)[z].name);
        CHECK((*read)[z].labels == (*written)[z].labels);
        CHECK((*read)[z].flip == (*written)[z].flip);
      }
    }
    const Mesh<3> mesh = read_openfoam(dir);
    for (const char* name : {"body", "right", "cut", "pointZone:wall"}) CHECK(mesh.group(name).dim == 0);
    CHECK(mesh.group("wall").dim == 2);
    // Cell 0: its 10 vertices, the centres of its 7 faces (none a triangle) and its own.
    const std::vector<Index> body = mesh.group_nodes("body");
    REQUIRE(body.size() == 18);
    CHECK(body[9] == 14);
    CHECK(body[10] >= 16);
    // The faces 1 and 2: 6 vertices and 2 centres; the points as listed.
    CHECK(mesh.group_nodes("cut").size() == 8);
    CHECK(mesh.group_nodes("pointZone:wall") == std::vector<Index>{0, 5});
    // A zone moved as a body: each of its nodes, auxiliary ones included, takes the motion.
    BoundarySpec<3> spec;
    spec.moving("right", Translation<3>{Vec<3>(0.0, 0.0, 0.25)}).fixed("wall");
    const ResolvedBoundary<3> r = spec.resolve(mesh);
    const std::vector<Index> right = mesh.group_nodes("right");
    for (const Index v : right) CHECK(r.displacements.col(r.column(v)) == Vec<3>(0.0, 0.0, 0.25));
    if (format == Format::ascii) {
      const std::string report = check_mesh(dir);
      INFO(report);
      if (!report.empty()) {
        CHECK_THAT(report, Catch::Contains("Mesh OK."));
        // OpenFOAM reads the zones as written.
        CHECK(reported(report, "cell zones:") == 2);
        CHECK(reported(report, "face zones:") == 1);
        CHECK(reported(report, "point zones:") == 1);
      }
    }
  }
}

TEST_CASE("OpenFOAM: a zone file in binary reads as in ASCII", "[io][openfoam]") {
  const fs::path dir = test::scratch_path("foam_zones_binary");
  write_case(dir, hanging_node_case());
  std::string text = "FoamFile\n{\n    version 2.0;\n    format binary;\n    arch \"LSB;label=32;scalar=64\";\n    class regIOobject;\n"
                     "    object faceZones;\n}\n1\n(\ncut\n{\n    type faceZone;\n    faceLabels List<label> 2(";
  for (const std::int32_t f : {1, 2}) text.append(reinterpret_cast<const char*>(&f), 4);
  text += ");\n    flipMap List<bool> 2(";
  text += std::string("\0\1", 2);
  text += ");\n}\n)\n";
  std::ofstream(dir / "constant/polyMesh/faceZones", std::ios::binary) << text;
  const PolyMesh poly = read_polymesh(dir);
  REQUIRE(poly.face_zones.size() == 1);
  CHECK(poly.face_zones[0].labels == std::vector<Index>{1, 2});
  CHECK(poly.face_zones[0].flip == std::vector<char>{0, 1});
}

TEST_CASE("OpenFOAM: a zone that names what the mesh lacks, or is malformed, is refused naming the zone", "[io][openfoam]") {
  const fs::path dir = test::scratch_path("foam_zones_bad");
  const auto zones_file = [&](const std::string& object, const std::string& body) {
    write_case(dir, hanging_node_case());
    std::ofstream(dir / "constant/polyMesh" / object) << "FoamFile { version 2.0; format ascii; class regIOobject; object " << object
                                                       << "; }\n" << body;
  };
  zones_file("cellZones", "1\n(\nbody\n{\n    type cellZone;\n    cellLabels List<label> 2(0 3);\n}\n)\n");
  CHECK_THAT(test::message_of<InputError>([&] { (void)read_polymesh(dir); }),
             Catch::Contains("cellZones") && Catch::Contains("cell zone 'body' holds cell 3") && Catch::Contains("3 cells"));
  zones_file("pointZones", "1\n(\ntip\n{\n    type pointZone;\n    pointLabels List<label> 1(-1);\n}\n)\n");
  CHECK_THAT(test::message_of<InputError>([&] { (void)read_polymesh(dir); }), Catch::Contains("point zone 'tip' holds point -1"));
  zones_file("faceZones", "1\n(\ncut\n{\n    type faceZone;\n    flipMap List<bool> 1(0);\n}\n)\n");
  CHECK_THAT(test::message_of<ParseError>([&] { (void)read_polymesh(dir); }), Catch::Contains("lacks faceLabels"));
  zones_file("faceZones", "1\n(\ncut\n{\n    type faceZone;\n    faceLabels List<label> 2(1 2);\n    flipMap List<bool> 1(0);\n}\n)\n");
  CHECK_THAT(test::message_of<ParseError>([&] { (void)read_polymesh(dir); }), Catch::Contains("1 flipMap entries for 2 faces"));
  // A count no file of this size holds allocates nothing.
  zones_file("cellZones", "1\n(\nbody\n{\n    type cellZone;\n    cellLabels List<label> 2000000000(0);\n}\n)\n");
  CHECK_THAT(test::message_of<ParseError>([&] { (void)read_polymesh(dir); }), Catch::Contains("bytes left in the file"));
  zones_file("faceZones", "1\n(\ncut\n{\n    type faceZone;\n    faceLabels List<label> 1(1);\n    flipMap List<bool> 2000000000{0};\n}\n)\n");
  CHECK_THAT(test::message_of<ParseError>([&] { (void)read_polymesh(dir); }), Catch::Contains("uniform flipMap of 2000000000 entries"));
}

TEST_CASE("OpenFOAM: a region's mesh and a time's points are read and written as OpenFOAM's -region and -time address them", "[io][openfoam]") {
  const fs::path dir = test::scratch_path("foam_region");
  const PolyMesh fluid = hanging_node_case();
  write_case(dir, fluid);
  // A second region: a box, in constant/solid/polyMesh.
  const PolyMesh solid = to_polymesh(box_mesh({.nx = 2, .ny = 1, .nz = 1}));
  write_polymesh(dir / "solid_case", solid);
  fs::create_directories(dir / "constant/solid");
  fs::rename(dir / "solid_case/constant/polyMesh", dir / "constant/solid/polyMesh");
  fs::remove_all(dir / "solid_case");
  CHECK(read_polymesh(dir / "constant/solid/polyMesh").num_cells == solid.num_cells);

  // Moved points of the region at 0.5: in 0.5/solid/polyMesh, located there.
  Mesh<3> moved = read_openfoam(dir / "constant/solid/polyMesh");
  moved.points.row(2).array() += 0.125;
  fs::create_directories(dir / "0.5/solid");
  CHECK(is_openfoam_target(dir / "0.5/solid"));
  write_mesh(dir / "0.5/solid", moved);
  CHECK(detail::read_foam_file(dir / "0.5/solid/polyMesh/points").find("\"0.5/solid/polyMesh\"") != std::string::npos);
  CHECK(read_openfoam(dir / "0.5/solid").points == moved.points);
  // Later times that hold no points read the last moved ones; earlier ones the constant ones.
  fs::create_directories(dir / "0.75/solid");
  fs::create_directories(dir / "0.25/solid");
  CHECK(read_polymesh(dir / "0.75/solid").points == moved.points);
  CHECK(read_polymesh(dir / "0.25/solid").points == solid.points);
  // The default region did not move.
  CHECK(read_polymesh(dir / "0.75").points == fluid.points);
  // A folder in a time folder that is no region of the case is no target.
  CHECK_FALSE(is_openfoam_target(dir / "0.5/polyMesh"));
  CHECK_FALSE(is_openfoam_target(dir / "0.5/liquid"));
}

TEST_CASE("OpenFOAM: a decomposed case's processor folders take the moved points through their addressing", "[io][openfoam]") {
  const fs::path dir = test::scratch_path("foam_decomposed");
  const PolyMesh c = hanging_node_case();
  write_case(dir, c);
  // Each processor's points and pointProcAddressing (what decomposePar writes; the rest of a
  // processor's mesh is not read here): points 0 to 9, and 6 to 15 (6 to 9 on both).
  const auto addressing_of = [](Index first, Index last) {
    std::vector<Index> a;
    for (Index i = first; i <= last; ++i) a.push_back(i);
    return a;
  };
  const std::vector<std::vector<Index>> addressing{addressing_of(0, 9), addressing_of(6, 15)};
  const auto processor_file = [&](int rank, const std::string& object, const std::string& cls, const std::string& body) {
    const fs::path poly = dir / ("processor" + std::to_string(rank)) / "constant/polyMesh";
    fs::create_directories(poly);
    std::ofstream(poly / object) << "FoamFile { version 2.0; format ascii; class " << cls << "; location \"constant/polyMesh\"; object "
                                 << object << "; }\n" << body;
  };
  for (int rank = 0; rank < 2; ++rank) {
    std::ostringstream points, labels;
    points << addressing[rank].size() << "\n(\n";
    labels << addressing[rank].size() << "\n(\n";
    for (const Index a : addressing[rank]) {
      points << "(" << c.points(0, a) << " " << c.points(1, a) << " " << c.points(2, a) << ")\n";
      labels << a << "\n";
    }
    processor_file(rank, "points", "vectorField", points.str() + ")\n");
    processor_file(rank, "pointProcAddressing", "labelList", labels.str() + ")\n");
  }
  Mesh<3> moved = read_openfoam(dir);
  moved.points.row(0).array() += 0.25;
  const auto processors_follow = [&](const std::string& folder) {
    for (int rank = 0; rank < 2; ++rank) {
      const fs::path file = dir / ("processor" + std::to_string(rank)) / folder / "points";
      const Points<3> local = detail::read_foam_points(file);
      REQUIRE(local.cols() == static_cast<Index>(addressing[rank].size()));
      for (std::size_t i = 0; i < addressing[rank].size(); ++i) CHECK(local.col(static_cast<Index>(i)) == moved.points.col(addressing[rank][i]));
      CHECK(detail::read_foam_file(file).find("\"" + folder + "\"") != std::string::npos);
    }
  };
  write_mesh(dir / "0.5", moved);
  processors_follow("0.5/polyMesh");
  write_mesh(dir, moved);
  processors_follow("constant/polyMesh");
  // An addressing that names a point the case lacks: refused, nothing written.
  processor_file(1, "pointProcAddressing", "labelList", "1\n(99)\n");
  CHECK_THAT(test::message_of<InputError>([&] { write_mesh(dir / "0.75", moved); }),
             Catch::Contains("pointProcAddressing: entry 0 is point 99 (the case has 16)"));
  CHECK_FALSE(fs::exists(dir / "0.75/polyMesh/points"));
  // One processor folder on its own is no place for moved points; a decomposed case without
  // its whole mesh is no input.
  const fs::path alone = test::scratch_path("foam_decomposed_alone") / "processor3";
  write_case(alone, c);
  CHECK_THAT(test::message_of<InputError>([&] { write_mesh(alone / "0.5", moved); }), Catch::Contains("one processor folder"));
  fs::remove_all(dir / "constant");
  CHECK_THAT(test::message_of<IoError>([&] { (void)read_polymesh(dir); }), Catch::Contains("a decomposed case without its whole mesh"));
}

TEST_CASE("OpenFOAM: a moved case goes into another case only where that case holds the same mesh", "[io][openfoam]") {
  const fs::path source = test::scratch_path("foam_source"), other = test::scratch_path("foam_other");
  const PolyMesh c = hanging_node_case();
  write_case(source, c);
  Mesh<3> moved = read_openfoam(source);
  moved.points.row(0).array() += 0.125;
  // As many points, another mesh: a face listed from another vertex, or a patch renamed.
  PolyMesh rotated = c;
  std::rotate(rotated.face_nodes.begin() + rotated.face_offsets[3], rotated.face_nodes.begin() + rotated.face_offsets[3] + 1,
              rotated.face_nodes.begin() + rotated.face_offsets[4]);
  PolyMesh renamed = c;
  renamed.patches[1].name = "exit";
  for (const auto& [mesh, says] : {std::pair{&rotated, "face 3 differs"}, std::pair{&renamed, "patch 1 is 'exit' there, 'outlet' here"}}) {
    write_case(other, *mesh);
    CHECK_THAT(test::message_of<InputError>([&] { write_moved_case(other, source, moved); }),
               Catch::Contains("holds another mesh") && Catch::Contains(says));
    CHECK_THAT(test::message_of<InputError>([&] { write_moved_case(other / "0.5", source, moved); }), Catch::Contains(says));
    CHECK(read_polymesh(other).points == c.points);
    CHECK_FALSE(fs::exists(other / "0.5/polyMesh/points"));
  }
  // The same mesh in another case, and the source's own time folder: written.
  write_case(other, c);
  write_moved_case(other / "0.5", source, moved);
  CHECK(read_polymesh(other / "0.5").points == moved.points.leftCols(16));
  write_moved_case(source / "0.5", source, moved);
  CHECK(read_polymesh(source / "0.5").points == moved.points.leftCols(16));
}

TEST_CASE("OpenFOAM: a new case is not written inside another case", "[io][openfoam]") {
  const fs::path dir = test::scratch_path("foam_nested");
  write_case(dir, hanging_node_case());
  const Mesh<3> mesh = read_openfoam(dir);
  for (const fs::path& inside : {dir / "0.3" / "polyMesh", dir / "latest", dir / "constant" / "polyMesh" / "copy"}) {
    INFO(inside);
    CHECK_THAT(test::message_of<InputError>([&] { check_mesh_output(inside); }), Catch::Contains("inside the OpenFOAM case"));
    CHECK_THAT(test::message_of<InputError>([&] { write_mesh(inside, mesh); }), Catch::Contains("inside the OpenFOAM case"));
    CHECK_FALSE(fs::exists(inside));
  }
  // Beside it, a new case is written.
  const fs::path beside = test::scratch_path("foam_nested_beside");
  fs::remove_all(beside);
  write_mesh(beside, mesh);
  CHECK(read_polymesh(beside).num_cells > 0);
}
