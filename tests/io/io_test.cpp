// Tests of the io layer: real meshes read with the counts of SOURCES.md, round trips between
// every format variant, P2 elements of every type, VTK node orders, orientation, bad input.

#include "meshmotion/core/generators.hpp"
#include "meshmotion/core/orientation.hpp"
#include "meshmotion/core/shape_functions.hpp"
#include "meshmotion/curving/p2_conversion.hpp"
#include "meshmotion/io.hpp"

#include "io_support.hpp"
#include "test_data.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <sstream>
#include <string>
#include <string_view>
#include <tuple>
#include <vector>

using namespace meshmotion;
using test::all_types_mesh;
using test::group_size;
using test::require_same_mesh;
namespace fs = std::filesystem;

namespace {

std::map<std::string, Index> type_counts(const std::vector<ElementBlock>& blocks) {
  std::map<std::string, Index> counts;
  for (const auto& b : blocks) counts[std::string(name(b.type))] += b.size();
  return counts;
}

template <int Dim>
Index tag_size(const Mesh<Dim>& mesh, int tag) {
  Index n = 0;
  for (const auto& b : mesh.facets) n += std::count(b.tags.begin(), b.tags.end(), tag);
  return n;
}

void write_text(const fs::path& file, const std::string& text) {
  std::ofstream(file, std::ios::binary) << text;
}

// Expects a ParseError whose message names the file and contains `what`, and returns its position.
template <class F>
std::uint64_t parse_error_position(F&& f, const std::string& what) {
  try {
    f();
  } catch (const ParseError& e) {
    INFO(e.what());
    CHECK(std::string(e.what()).find(what) != std::string::npos);
    return e.position();
  }
  FAIL("no ParseError thrown (expected one mentioning '" << what << "')");
  return 0;
}

std::vector<fs::path> files_in(const fs::path& dir) {
  std::vector<fs::path> out;
  for (const auto& entry : fs::directory_iterator(dir)) out.push_back(entry.path());
  return out;
}

const std::vector<WriteOptions> msh_variants{
    {MshVersion::v2_2, false, false}, {MshVersion::v2_2, true, false}, {MshVersion::v4_1, false, false}, {MshVersion::v4_1, true, false}};

}  // namespace

TEST_CASE("real SU2 meshes read with the counts of SOURCES.md", "[io]") {
  struct Expected {
    const char* file;
    Index nodes;
    std::map<std::string, Index> cells;
    std::map<std::string, Index> markers;
    Index negative;
  };
  const std::vector<Expected> cases{
      {"su2_naca0012_inviscid_tri.su2", 5233, {{"tri3", 10216}}, {{"airfoil", 200}, {"farfield", 50}}, 0},
      {"su2_rae2822_rans_hybrid.su2", 13937, {{"tri3", 18042}, {"quad4", 4800}}, {{"AIRFOIL", 192}, {"FARFIELD", 40}}, 0},
      {"su2_30p30n_rans_L1_coarse.su2", 64540, {{"quad4", 63957}}, {{"wall", 610}, {"farfield", 560}}, 0},
      {"su2_naca64a010_aeroelastic_hybrid.su2", 6532, {{"quad4", 3584}, {"tri3", 5729}}, {{"airfoil", 128}, {"farfield", 39}}, 9313},
      {"su2_bump_channel_deforming_tri.su2", 4550, {{"tri3", 8778}},
       {{"inlet", 20}, {"outlet", 20}, {"top", 140}, {"slip_bottom", 20}, {"bottom_front", 36}, {"interface", 40}, {"bottom_rear", 44}}, 0},
  };
  for (const auto& c : cases) {
    SECTION(c.file) {
      MESHMOTION_REQUIRE_DATA(file, c.file);
      const auto mesh = read_mesh_as<2>(file);
      CHECK(mesh.num_nodes() == c.nodes);
      CHECK(type_counts(mesh.cells) == c.cells);
      CHECK(mesh.groups.size() == c.markers.size());
      for (const auto& [marker, n] : c.markers) CHECK(group_size(mesh, marker) == n);
      const auto report = orientation_report(mesh);
      CHECK(report.num_negative == c.negative);
      CHECK(report.num_cells == mesh.num_cells());
    }
  }
}

TEST_CASE("30P30N wall marker holds three closed loops with the documented node counts", "[io]") {
  MESHMOTION_REQUIRE_DATA(file, "su2_30p30n_rans_L1_coarse.su2");
  const auto mesh = read_mesh_as<2>(file);
  const auto nodes = mesh.group_nodes("wall");
  Index slat = 0, main = 0, flap = 0;
  for (const Index i : nodes) {
    const double x = mesh.points(0, i);
    if (x < 0.0095) ++slat;
    else if (x < 0.3975) ++main;
    else ++flap;
  }
  CHECK(nodes.size() == 610);  // closed loops: as many nodes as lines
  CHECK(slat + main + flap == 610);
  CHECK(flap >= 90);
}

TEST_CASE("real Gmsh 2.2 meshes with $ParametricNodes read with their counts and CAD parameters", "[io]") {
  SECTION("RAE2822 2D") {
    MESHMOTION_REQUIRE_DATA(file, "meshopt_rae2822_linear_tri.msh");
    const auto mesh = read_mesh_as<2>(file);
    CHECK(mesh.num_nodes() == 3052);
    CHECK(type_counts(mesh.cells) == std::map<std::string, Index>{{"tri3", 6009}});
    CHECK(type_counts(mesh.facets) == std::map<std::string, Index>{{"line2", 95}});
    CHECK(tag_size(mesh, 6) == 53);
    CHECK(tag_size(mesh, 7) == 42);
    CHECK(orientation_report(mesh).num_negative == 0);
    REQUIRE(mesh.node_params.size() == 3052);
    // "7 -25 18.74999999999997 0 1 1 -243.75": node 7 on curve 1 at u = -243.75
    CHECK(mesh.node_params[6].entity_dim == 1);
    CHECK(mesh.node_params[6].entity_tag == 1);
    CHECK(mesh.node_params[6].u == -243.75);
    CHECK(mesh.points(1, 6) == 18.74999999999997);
  }
  SECTION("sphere 3D") {
    MESHMOTION_REQUIRE_DATA(file, "meshopt_sphere_symmetry_linear_tet.msh");
    const auto mesh = read_mesh_as<3>(file);
    CHECK(mesh.num_nodes() == 1189);
    CHECK(type_counts(mesh.cells) == std::map<std::string, Index>{{"tet4", 5615}});
    CHECK(type_counts(mesh.facets) == std::map<std::string, Index>{{"tri3", 868}});
    CHECK(type_counts(mesh.lower) == std::map<std::string, Index>{{"line2", 76}});
    CHECK(tag_size(mesh, 7) == 106);
    CHECK(tag_size(mesh, 6) == 128);
    CHECK(tag_size(mesh, 20) == 634);
    CHECK(orientation_report(mesh).num_negative == 0);
    for (const Index i : mesh.group_nodes(7)) CHECK(mesh.points.col(i).norm() == Approx(0.5).epsilon(1e-6));
  }
}

TEST_CASE("every real mesh round-trips through all msh variants and SU2", "[io]") {
  const auto data_dir = test::shared_data("SOURCES.md");
  if (!data_dir) {
    WARN("skipped: ../shared/data is absent");
    return;
  }
  for (const auto& file : files_in(data_dir->parent_path())) {
    const auto ext = file.extension();
    if (ext != ".su2" && ext != ".msh") continue;
    if (file.filename() == "su2_30p30n_rans_L1_coarse.su2") continue;  // large: covered by the read test
    INFO(file);
    const AnyMesh any = read_mesh(file);
    std::visit(
        [&](const auto& mesh) {
          for (const auto& options : msh_variants) {
            const auto out = test::scratch_path("roundtrip.msh");
            write_mesh(out, mesh, options);
            auto back = std::get<std::decay_t<decltype(mesh)>>(read_mesh(out));
            INFO("msh " << (options.msh_version == MshVersion::v2_2 ? "2.2" : "4.1") << (options.binary ? " binary" : " ascii"));
            require_same_mesh(mesh, back);
            // CAD parameters: 2.2 ASCII $ParametricNodes and 4.1 parametric node blocks
            // (2.2's binary node section has no place for them)
            const bool keeps_params = options.msh_version == MshVersion::v4_1 || !options.binary;
            REQUIRE(back.node_params.size() == (keeps_params ? mesh.node_params.size() : 0));
            for (std::size_t i = 0; i < back.node_params.size(); ++i) {
              const auto &p = mesh.node_params[i], &q = back.node_params[i];
              REQUIRE(std::tuple{p.entity_dim, p.entity_tag, p.u, p.v} == std::tuple{q.entity_dim, q.entity_tag, q.u, q.v});
            }
          }
          // msh -> su2 -> msh keeps nodes, cells, facet groups (SU2 stores no lower elements, no ids)
          auto linear = mesh;
          linear.lower.clear();
          const auto su2 = test::scratch_path("roundtrip.su2");
          write_mesh(su2, linear);
          const auto from_su2 = std::get<std::decay_t<decltype(mesh)>>(read_mesh(su2));
          CHECK(from_su2.points == mesh.points);
          REQUIRE(from_su2.cells.size() == mesh.cells.size());
          for (std::size_t k = 0; k < mesh.cells.size(); ++k) CHECK(from_su2.cells[k].connectivity == mesh.cells[k].connectivity);
          CHECK(from_su2.num_facets() == mesh.num_facets());
          for (const auto& g : from_su2.groups) {
            const auto* original = mesh.find_group(g.name);
            const int original_tag = original ? original->tag : std::stoi(g.name.substr(4));
            CHECK(from_su2.group_nodes(g.tag) == mesh.group_nodes(original_tag));
          }
          const auto again = test::scratch_path("roundtrip2.msh");
          write_mesh(again, from_su2, {MshVersion::v4_1, true, false});
          require_same_mesh(from_su2, std::get<std::decay_t<decltype(mesh)>>(read_mesh(again)), false);
        },
        any);
  }
}

TEST_CASE("msh text formatted by several threads is the text of one thread", "[io]") {
  // Over 3 × 2048 nodes and cells: records go to the threads in blocks, the last one partial;
  // one parametric node splits the node runs (4.1) or makes the nodes $ParametricNodes (2.2).
  Mesh<2> mesh = rectangle_mesh({.nx = 97, .ny = 83, .cells = RectangleCells::tri_quad});
  mesh.node_params.assign(static_cast<std::size_t>(mesh.num_nodes()), NodeParametrization{2, 1, 0.0, 0.0});
  mesh.node_params[5000] = NodeParametrization{1, 3, 0.25, 0.0};
  for (const auto& options : msh_variants) {
    const GmshWriteOptions gmsh{options.msh_version, options.binary};
    set_num_threads(1);
    const std::string one = format_gmsh(mesh, gmsh);
    set_num_threads(3);
    CHECK(format_gmsh(mesh, gmsh) == one);
    const auto out = test::scratch_path("threads.msh");
    write_mesh(out, mesh, options);
    require_same_mesh(mesh, read_mesh_as<2>(out));
  }
  set_num_threads(0);
}

TEST_CASE("elements of every type and order round-trip with non-contiguous ids", "[io]") {
  for (const int element_order : {1, 2, 3, 4, 5, 6, 7, 8}) {
    for (const auto& options : msh_variants) {
      INFO("order " << element_order << " msh " << (options.msh_version == MshVersion::v2_2 ? "2.2" : "4.1") << (options.binary ? " binary" : " ascii"));
      const auto mesh3 = all_types_mesh<3>(element_order);
      const auto out3 = test::scratch_path("all_types3.msh");
      write_mesh(out3, mesh3, options);
      const auto back3 = read_mesh_as<3>(out3);
      require_same_mesh(mesh3, back3);
      // P2: complete and serendipity types; P3 to P8: a tetrahedron, a hexahedron, a prism and a
      // pyramid.
      CHECK(back3.cells.size() == std::vector<std::size_t>{4, 7, 4, 4, 4, 4, 4, 4}[static_cast<std::size_t>(element_order - 1)]);
      CHECK(back3.lower.size() == 2);  // lines and the point (Gmsh type 15)

      const auto mesh2 = all_types_mesh<2>(element_order);
      const auto out2 = test::scratch_path("all_types2.msh");
      write_mesh(out2, mesh2, options);
      require_same_mesh(mesh2, read_mesh_as<2>(out2));
    }
    // SU2: VTK's order for linear elements, the DG-FEM lattice past order 1; serendipity
    // types have no SU2 form.
    INFO("order " << element_order << " su2");
    auto su2_mesh = all_types_mesh<3>(element_order);
    su2_mesh.lower.clear();
    std::erase_if(su2_mesh.cells, [](const ElementBlock& b) { return !element_info(b.type).complete; });
    std::erase_if(su2_mesh.facets, [](const ElementBlock& b) { return !element_info(b.type).complete; });
    const auto out = test::scratch_path("all_types3.su2");
    write_mesh(out, su2_mesh);
    const auto back = read_mesh_as<3>(out);
    CHECK(back.points == su2_mesh.points);
    using Lists = std::pair<const std::vector<ElementBlock>*, const std::vector<ElementBlock>*>;
    for (const Lists& lists : {Lists{&su2_mesh.cells, &back.cells}, Lists{&su2_mesh.facets, &back.facets}})
      for (const auto& b : *lists.first) {
        INFO(name(b.type));
        const auto it = std::find_if(lists.second->begin(), lists.second->end(), [&](const ElementBlock& r) { return r.type == b.type; });
        REQUIRE(it != lists.second->end());
        CHECK(it->connectivity == b.connectivity);
      }
  }
  CHECK_THROWS_WITH(write_mesh(test::scratch_path("p2.su2"), all_types_mesh<2>(2)), Catch::Contains("serendipity"));
}

TEST_CASE("SU2's DG-FEM lattice: element numbers and node rows as SU2 lists them", "[io]") {
  CHECK(su2_id(ElementType::tri10) == 205);
  CHECK(su2_id(ElementType::hex27) == 112);
  CHECK(su2_id(ElementType::tet35) == 310);
  CHECK(su2_id(ElementType::quad8) == -1);
  CHECK(element_type_from_su2(205) == ElementType::tri10);
  CHECK(element_type_from_su2(30212) == ElementType::hex64);  // solution degree 2 ahead of the type
  CHECK(element_type_from_su2(712) == ElementType::hex729);
  CHECK(element_type_from_su2(313) == ElementType::prism75);
  CHECK(element_type_from_su2(714) == ElementType::pyramid285);
  CHECK_THROWS_WITH(element_type_from_su2(813), Catch::Contains("no prism of order 9"));
  CHECK_THROWS_WITH(element_type_from_su2(7), Catch::Contains("unknown SU2 element type 7"));
  // SU2's own tables (its CGNS converter lists, per SU2 node, the CGNS node; CGNS and Gmsh
  // agree on these: vertices, then edges, then faces): a quad16's rows are 0 4 5 1 / 11 12 13 6
  // / 10 15 14 7 / 3 9 8 2, a tet10's 0 4 1 6 5 2 / 7 8 9 / 3.
  const auto quad16 = su2_node_order(ElementType::quad16);
  CHECK(std::vector<int>(quad16.begin(), quad16.end()) == std::vector<int>{0, 4, 5, 1, 11, 12, 13, 6, 10, 15, 14, 7, 3, 9, 8, 2});
  const auto tet10 = su2_node_order(ElementType::tet10);
  CHECK(std::vector<int>(tet10.begin(), tet10.end()) == std::vector<int>{0, 4, 1, 6, 5, 2, 7, 9, 8, 3});
  for (int t = 0; t < num_element_types; ++t) {
    const auto type = static_cast<ElementType>(t);
    if (order(type) < 2 || su2_id(type) < 0) continue;
    INFO(name(type));
    const auto perm = su2_node_order(type);
    std::vector<int> sorted(perm.begin(), perm.end());
    std::sort(sorted.begin(), sorted.end());
    for (int k = 0; k < num_nodes(type); ++k) CHECK(sorted[static_cast<std::size_t>(k)] == k);
  }
}

TEST_CASE("orientation: reference elements are positive and fix_orientation mirrors the nodes of every order consistently", "[io]") {
  for (const int element_order : {1, 2, 3, 4, 5, 6, 8}) {
    INFO("order " << element_order);
    auto mesh = all_types_mesh<3>(element_order);
    auto mesh2 = all_types_mesh<2>(element_order);
    CHECK(orientation_report(mesh).num_negative == 0);
    CHECK(orientation_report(mesh2).num_negative == 0);
    // Reflect x: every cell becomes negative while each node keeps its role.
    mesh.points.row(0) *= -1.0;
    mesh2.points.row(0) *= -1.0;
    const auto before = mesh;
    CHECK(orientation_report(mesh).num_negative == mesh.num_cells());
    CHECK(fix_orientation(mesh) == mesh.num_cells());
    CHECK(fix_orientation(mesh2) == mesh2.num_cells());
    CHECK(orientation_report(mesh).num_negative == 0);
    CHECK(orientation_report(mesh2).num_negative == 0);
    // After the fix each element is a valid Gmsh element: the nodes sit where the reference
    // element maps them (edge nodes at edge midpoints, face nodes at face centres).
    for (const auto* m : {&mesh}) {
      for (const auto& b : m->cells) {
        const auto nodes = b.element(0);
        const auto nv = static_cast<std::size_t>(num_vertices(b.type));
        Eigen::MatrixXd vertices(3, static_cast<Index>(nv));
        for (std::size_t k = 0; k < nv; ++k) vertices.col(static_cast<Index>(k)) = m->points.col(nodes[k]);
        for (std::size_t k = 0; k < nodes.size(); ++k) {
          // map the reference node through the linear element
          const auto ref = reference_nodes(b.type)[k];
          const auto p = map_to_physical(linear_type(b.type), vertices, ref);
          INFO(name(b.type) << " node " << k);
          CHECK((p - m->points.col(nodes[k])).norm() < 1e-12);
        }
      }
    }
    (void)before;
  }
  SECTION("the clockwise NACA64A010 file is fixed on request only") {
    MESHMOTION_REQUIRE_DATA(file, "su2_naca64a010_aeroelastic_hybrid.su2");
    auto mesh = read_mesh_as<2>(file);
    CHECK(orientation_report(mesh).num_negative == 9313);
    CHECK(fix_orientation(mesh) == 9313);
    CHECK(orientation_report(mesh).num_negative == 0);
  }
}

TEST_CASE("VTK Lagrange node orders put each VTK node where VTK expects it", "[io]") {
  // VTK's order-2 Lagrange cells (vtkHigherOrder{Curve,Triangle,Quadrilateral,Tetra,Hexahedron,
  // Wedge}::PointIndexFromIJK): each node is the centroid of these VTK vertices.
  const std::map<ElementType, std::vector<std::vector<int>>> vtk_nodes{
      {ElementType::line3, {{0}, {1}, {0, 1}}},
      {ElementType::tri6, {{0}, {1}, {2}, {0, 1}, {1, 2}, {2, 0}}},
      {ElementType::quad9, {{0}, {1}, {2}, {3}, {0, 1}, {1, 2}, {3, 2}, {0, 3}, {0, 1, 2, 3}}},
      {ElementType::tet10, {{0}, {1}, {2}, {3}, {0, 1}, {1, 2}, {2, 0}, {0, 3}, {1, 3}, {2, 3}}},
      {ElementType::hex27, {{0}, {1}, {2}, {3}, {4}, {5}, {6}, {7},
                            {0, 1}, {1, 2}, {3, 2}, {0, 3}, {4, 5}, {5, 6}, {7, 6}, {4, 7}, {0, 4}, {1, 5}, {3, 7}, {2, 6},
                            {0, 3, 7, 4}, {1, 2, 6, 5}, {0, 1, 5, 4}, {3, 2, 6, 7}, {0, 1, 2, 3}, {4, 5, 6, 7},
                            {0, 1, 2, 3, 4, 5, 6, 7}}},
      {ElementType::prism18, {{0}, {1}, {2}, {3}, {4}, {5}, {0, 1}, {1, 2}, {2, 0}, {3, 4}, {4, 5}, {5, 3}, {0, 3}, {1, 4}, {2, 5},
                              {0, 1, 4, 3}, {1, 2, 5, 4}, {2, 0, 3, 5}}},
  };
  for (const auto& [type, expected] : vtk_nodes) {
    INFO(name(type));
    const auto order = vtk_order(type, true);
    const auto ref = reference_nodes(type);
    REQUIRE(static_cast<std::size_t>(num_nodes(type)) == expected.size());
    for (std::size_t k = 0; k < expected.size(); ++k) {
      std::array<double, 3> centroid{};
      for (const int vtk_vertex : expected[k]) {
        // VTK's vertex v is our node order[v]: the vertices come first in both orders.
        const int v = order.empty() ? vtk_vertex : order[static_cast<std::size_t>(vtk_vertex)];
        for (int d = 0; d < 3; ++d) centroid[static_cast<std::size_t>(d)] += ref[static_cast<std::size_t>(v)][static_cast<std::size_t>(d)] / static_cast<double>(expected[k].size());
      }
      const auto ours = ref[static_cast<std::size_t>(order.empty() ? static_cast<int>(k) : order[k])];
      INFO("VTK node " << k);
      for (int d = 0; d < 3; ++d) CHECK(ours[static_cast<std::size_t>(d)] == Approx(centroid[static_cast<std::size_t>(d)]).margin(1e-14));
    }
  }
}

TEST_CASE("VTU output: Lagrange cell types, point and cell data, facets on request", "[io]") {
  const auto mesh = all_types_mesh<3>(2);
  VtuFields fields;
  fields.point_data.emplace_back("displacement", Eigen::MatrixXd::Ones(3, mesh.num_nodes()));
  fields.cell_data.emplace_back("quality", Eigen::MatrixXd::Constant(1, mesh.num_cells(), 0.5));
  const auto text = format_vtu(mesh, fields, VtuOptions{false, VtuEncoding::ascii});
  CHECK(text.find("NumberOfCells=\"7\"") != std::string::npos);
  const auto types_at = text.find("Name=\"types\"");
  const auto types = text.substr(types_at, text.find("</DataArray>", types_at) - types_at);
  // Lagrange tet10 hex27 prism18; classic hex20 prism15 and pyramid13 (also for pyramid14)
  for (const char* t : {"\n71\n", "\n72\n", "\n73\n", "\n25\n", "\n26\n", "\n27\n"}) CHECK(types.find(t) != std::string::npos);
  CHECK(text.find("Name=\"displacement\" NumberOfComponents=\"3\"") != std::string::npos);
  CHECK(text.find("Name=\"quality\"") != std::string::npos);
  const auto with_facets = format_vtu(mesh, fields, VtuOptions{true});
  CHECK(with_facets.find("NumberOfCells=\"" + std::to_string(mesh.num_cells() + mesh.num_facets()) + "\"") != std::string::npos);
  CHECK(with_facets.find("Name=\"facet_tag\"") != std::string::npos);
  fields.cell_data.emplace_back("wrong", Eigen::MatrixXd::Zero(1, 2));
  CHECK_THROWS_AS(format_vtu(mesh, fields), InputError);
  const auto out = test::scratch_path("mesh.vtu");
  write_mesh(out, mesh);
  CHECK(fs::file_size(out) > 0);
}

namespace {

std::vector<unsigned char> decode_base64(std::string_view text) {
  const std::string_view alphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  REQUIRE(text.size() % 4 == 0);
  std::vector<unsigned char> bytes;
  for (std::size_t i = 0; i < text.size(); i += 4) {
    unsigned bits = 0;
    int num_bytes = 3;
    for (std::size_t k = 0; k < 4; ++k) {
      const char c = text[i + k];
      if (c == '=') --num_bytes;
      bits = (bits << 6) | (c == '=' ? 0u : static_cast<unsigned>(alphabet.find(c)));
    }
    for (int k = 0; k < num_bytes; ++k) bytes.push_back(static_cast<unsigned char>((bits >> (16 - 8 * k)) & 0xffu));
  }
  return bytes;
}

/// The decoded payload of DataArray `name` (header and data were encoded separately).
template <class T>
std::vector<T> binary_array(const std::string& text, const std::string& name) {
  const auto at = text.find(name);
  REQUIRE(at != std::string::npos);
  const auto begin = text.find('>', at) + 1;
  const auto end = text.find("</DataArray>", begin);
  std::string body = text.substr(begin, end - begin);
  body.erase(std::remove_if(body.begin(), body.end(), [](char c) { return std::isspace(static_cast<unsigned char>(c)) != 0; }),
             body.end());
  // The UInt64 byte count is 8 bytes: 12 characters including its '=' padding.
  const auto header = decode_base64(body.substr(0, 12));
  std::uint64_t num_bytes = 0;
  std::memcpy(&num_bytes, header.data(), sizeof(num_bytes));
  const auto payload = decode_base64(body.substr(12));
  REQUIRE(payload.size() >= num_bytes);
  std::vector<T> values(num_bytes / sizeof(T));
  std::memcpy(values.data(), payload.data(), values.size() * sizeof(T));
  return values;
}

}  // namespace

TEST_CASE("VTU binary output decodes to the exact coordinates, connectivity and fields", "[io]") {
  auto mesh = all_types_mesh<3>(2);
  mesh.points.array() += 0.1;  // values with no short decimal form
  VtuFields fields;
  Eigen::MatrixXd displacement = mesh.points * 0.5;
  fields.point_data.emplace_back("displacement", displacement);
  const auto text = format_vtu(mesh, fields);
  CHECK(text.find("format=\"ascii\"") == std::string::npos);
  const auto points = binary_array<double>(text, "NumberOfComponents=\"3\" format");
  REQUIRE(points.size() == static_cast<std::size_t>(3 * mesh.num_nodes()));
  for (Index i = 0; i < mesh.num_nodes(); ++i)
    for (int d = 0; d < 3; ++d) CHECK(points[static_cast<std::size_t>(3 * i + d)] == mesh.points(d, i));
  const auto shown = binary_array<double>(text, "Name=\"displacement\"");
  REQUIRE(shown.size() == static_cast<std::size_t>(displacement.size()));
  CHECK(Eigen::Map<const Eigen::MatrixXd>(shown.data(), 3, mesh.num_nodes()) == displacement);
  const auto types = binary_array<std::uint8_t>(text, "Name=\"types\"");
  const auto offsets = binary_array<std::int64_t>(text, "Name=\"offsets\"");
  REQUIRE(types.size() == static_cast<std::size_t>(mesh.num_cells()));
  REQUIRE(offsets.size() == types.size());
  // The ASCII writer is the reference for the same arrays.
  const auto ascii = format_vtu(mesh, fields, VtuOptions{false, VtuEncoding::ascii});
  const auto ascii_types_at = ascii.find("Name=\"types\"");
  std::istringstream ascii_types(ascii.substr(ascii.find('>', ascii_types_at) + 1));
  for (const auto t : types) {
    int expected = -1;
    ascii_types >> expected;
    CHECK(int{t} == expected);
  }
  CHECK(offsets.back() == static_cast<std::int64_t>(binary_array<std::int64_t>(text, "Name=\"connectivity\"").size()));
}

TEST_CASE("VTU input: every type and order round-trips through .vtu, binary and ASCII, facets with their tags", "[io]") {
  // VTK 9.1 has no Lagrange pyramid, and writes a pyramid14 as its 13-node pyramid.
  const auto vtk_has = [](const ElementBlock& b) {
    return shape(b.type) != Shape::pyramid || order(b.type) == 1 || b.type == ElementType::pyramid13;
  };
  const auto check = [&]<int Dim>(Mesh<Dim> mesh, VtuEncoding encoding) {
    mesh.lower.clear();
    std::erase_if(mesh.cells, [&](const ElementBlock& b) { return !vtk_has(b); });
    std::erase_if(mesh.facets, [&](const ElementBlock& b) { return !vtk_has(b); });
    const auto file = test::scratch_path("all_types.vtu");
    write_vtu(file, mesh, {}, {true, encoding});
    const Mesh<Dim> back = read_mesh_as<Dim>(file);
    CHECK(back.points == mesh.points);
    using Lists = std::pair<const std::vector<ElementBlock>*, const std::vector<ElementBlock>*>;
    for (const Lists& lists : {Lists{&mesh.cells, &back.cells}, Lists{&mesh.facets, &back.facets}}) {
      REQUIRE(lists.first->size() == lists.second->size());
      for (std::size_t k = 0; k < lists.first->size(); ++k) {
        INFO(name((*lists.first)[k].type));
        CHECK((*lists.second)[k].type == (*lists.first)[k].type);
        CHECK((*lists.second)[k].connectivity == (*lists.first)[k].connectivity);
        CHECK((*lists.second)[k].tags == (*lists.first)[k].tags);
      }
    }
  };
  for (const int element_order : {1, 2, 3, 4, 5, 6, 7, 8})
    for (const auto encoding : {VtuEncoding::binary, VtuEncoding::ascii}) {
      INFO("order " << element_order << (encoding == VtuEncoding::binary ? " binary" : " ascii"));
      check(all_types_mesh<3>(element_order), encoding);
      check(all_types_mesh<2>(element_order), encoding);
    }
  // Without facet_tag (written without the facets) the file's cells are all there is.
  const Mesh<2> square = rectangle_mesh({.nx = 2, .ny = 2, .cells = RectangleCells::tri3});
  const auto file = test::scratch_path("square.vtu");
  write_mesh(file, square);
  const Mesh<2> back = read_mesh_as<2>(file);
  CHECK(back.points == square.points);
  CHECK(back.num_facets() == 0);
}

TEST_CASE("VTU input: bad files are refused with the file, the line and the reason", "[io]") {
  const Mesh<2> square = rectangle_mesh({.nx = 2, .ny = 2, .cells = RectangleCells::tri3});
  const std::string ascii = format_vtu(square, {}, {false, VtuEncoding::ascii});
  const auto refused = [](const std::string& text, const std::string& reason) {
    const auto file = test::scratch_path("bad.vtu");
    std::ofstream(file, std::ios::binary) << text;
    INFO(reason);
    CHECK_THROWS_AS(read_mesh(file), ParseError);
    CHECK_THROWS_WITH(read_mesh(file), Catch::Contains("bad.vtu:") && Catch::Contains(reason));
  };
  const auto replace = [&](std::string text, const std::string& from, const std::string& to) {
    const auto at = text.find(from);
    REQUIRE(at != std::string::npos);
    return text.replace(at, from.size(), to);
  };
  refused("not xml", "no <VTKFile>");
  refused(replace(ascii, "byte_order", "compressor=\"vtkZLibDataCompressor\" byte_order"), "compressed data");
  refused(replace(ascii, "<Cells>", "<Cellz>"), "no <Cells> section");
  refused(replace(ascii, "format=\"ascii\"", "format=\"appended\""), "appended data is not read");
  refused(replace(ascii, "Name=\"offsets\" format=\"ascii\">\n", "Name=\"offsets\" format=\"ascii\">\n0\n"),
          "'offsets' has 9 values (expected 8)");
  refused(replace(ascii, "Name=\"types\" format=\"ascii\">\n5", "Name=\"types\" format=\"ascii\">\n42"),
          "VTK type 42 with 3 nodes");
  refused(replace(ascii, "Name=\"connectivity\" format=\"ascii\">\n0", "Name=\"connectivity\" format=\"ascii\">\n99"),
          "names node 99");
  refused(replace(ascii, "Name=\"connectivity\" format=\"ascii\">\n0", "Name=\"connectivity\" format=\"ascii\">\nx"),
          "'x");
  refused(replace(ascii, "NumberOfComponents=\"3\" format=\"ascii\">\n0 0 0", "NumberOfComponents=\"3\" format=\"ascii\">\n0 0 1"),
          "point 0 has z = 1");
  const std::string binary = format_vtu(square, {});
  refused(replace(binary, "Name=\"types\" format=\"binary\">\n          ", "Name=\"types\" format=\"binary\">\n          !"),
          "'!' is not a base64 character");
  // Counts too large for the file are refused before they size anything.
  const auto points_count = "NumberOfPoints=\"" + std::to_string(square.num_nodes()) + "\"";
  refused(replace(ascii, points_count, "NumberOfPoints=\"99999999999999999999999\""), "NumberOfPoints '99999999999999999999999'");
  refused(replace(ascii, points_count, "NumberOfPoints=\"4000000000\""), "NumberOfPoints '4000000000' (expected a count");
  // Numbers in another notation than their type's are not read as something else.
  const std::string first_node = "Name=\"connectivity\" format=\"ascii\">\n0";
  for (const char* value : {"1.5", "0x10", "1e1"})
    refused(replace(ascii, first_node, std::string("Name=\"connectivity\" format=\"ascii\">\n") + value),
            std::string("'") + value + "' is not an integer");
  refused(replace(ascii, "NumberOfComponents=\"3\" format=\"ascii\">\n0 0 0", "NumberOfComponents=\"3\" format=\"ascii\">\n0x10 0 0"),
          "'0x10' is not a decimal number");
}

TEST_CASE("files written in chunks equal the formatted text, byte for byte", "[io]") {
  // Several megabytes per file, so the writers spill their buffer (1 MiB) many times, in the
  // middle of records as well as of base64 arrays.
  const auto mesh = convert_to_quadratic(box_mesh({.nx = 24, .ny = 18, .nz = 12, .cells = BoxCells::tet_pyramid_prism})).mesh;
  const auto linear = box_mesh({.nx = 30, .ny = 30, .nz = 30, .cells = BoxCells::hex_prism});
  const auto read_back = [](const fs::path& file) {
    std::ifstream in(file, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
  };
  for (const auto& options : msh_variants) {
    const auto file = test::scratch_path("chunked.msh");
    write_gmsh(file, mesh, {options.msh_version, options.binary});
    const std::string text = format_gmsh(mesh, {options.msh_version, options.binary});
    INFO("msh " << (options.msh_version == MshVersion::v2_2 ? "2.2" : "4.1") << (options.binary ? " binary" : " ascii"));
    REQUIRE(text.size() > 2 * detail::TextOutput::chunk);
    CHECK(read_back(file) == text);
  }
  VtuFields fields;
  fields.point_data.emplace_back("x", mesh.points);
  fields.cell_data.emplace_back("one", Eigen::MatrixXd::Ones(1, mesh.num_cells()));
  for (const auto encoding : {VtuEncoding::binary, VtuEncoding::ascii})
    for (const bool facets : {false, true}) {
      const auto file = test::scratch_path("chunked.vtu");
      write_vtu(file, mesh, fields, {facets, encoding});
      const std::string text = format_vtu(mesh, fields, {facets, encoding});
      REQUIRE(text.size() > 2 * detail::TextOutput::chunk);
      CHECK(read_back(file) == text);
    }
  const auto file = test::scratch_path("chunked.su2");
  write_su2(file, linear);
  const std::string text = format_su2(linear);
  REQUIRE(text.size() > 2 * detail::TextOutput::chunk);
  CHECK(read_back(file) == text);
  const auto back = read_mesh_as<3>(file);
  CHECK(back.points == linear.points);
  CHECK(back.num_cells() == linear.num_cells());
  CHECK(back.num_facets() == linear.num_facets());
}

TEST_CASE("mesh summary counts groups, edges and orientation", "[io]") {
  Mesh<2> mesh;
  mesh.points.resize(2, 4);
  mesh.points << 0, 2, 2, 0, 0, 0, 1, 1;
  mesh.block(ElementType::tri3).add({0, 1, 2});
  mesh.block(ElementType::tri3).add({0, 3, 2});  // clockwise
  mesh.block(ElementType::line2).add({0, 1}, 5);
  mesh.groups.push_back({1, 5, "bottom"});
  const auto s = summarize(mesh);
  CHECK(s.num_nodes == 4);
  CHECK(s.orientation.num_negative == 1);
  CHECK(s.min_edge == 1.0);
  CHECK(s.max_edge == Approx(std::sqrt(5.0)));
  REQUIRE(s.groups.size() == 1);
  CHECK(s.groups[0].num_elements == 1);
  CHECK(s.groups[0].num_nodes == 2);
  const std::string json = to_json(s);
  CHECK(json.find("\"negative_cells\":1") != std::string::npos);
  CHECK(to_text(s).find("bottom") != std::string::npos);
  // JSON and text come from the summary's description: every key, counts keyed by type, the
  // box in the mesh's dimension, groups as objects.
  const std::string text = to_text(s);
  for (const std::string& key : field_keys(s)) {
    INFO(key);
    CHECK(json.find("\"" + key + "\":") != std::string::npos);
    CHECK(text.find(key + ":") != std::string::npos);
  }
  CHECK(text.find("cells: tri3 2\n") != std::string::npos);
  CHECK(text.find("groups:\n  - name=bottom dim=1 tag=5 elements=1 nodes=2\n") != std::string::npos);
  CHECK(json.find("\"cells\":{\"tri3\":2}") != std::string::npos);
  CHECK(json.find("\"lower\":{}") != std::string::npos);
  CHECK(json.find("\"bbox_max\":[2,1]") != std::string::npos);
  CHECK(json.find("\"groups\":[{\"name\":\"bottom\",\"dim\":1,\"tag\":5,\"elements\":1,\"nodes\":2}]") != std::string::npos);
  CHECK(json.find("\"orientation\":\"mixed\"") != std::string::npos);
}

TEST_CASE("malformed files give ParseError with file, line and what was expected", "[io]") {
  const auto bad = test::scratch_path("bad.msh");
  const std::string header = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n";
  const std::string nodes = "$Nodes\n3\n1 0 0 0\n2 1 0 0\n3 0 1 0\n$EndNodes\n";
  const auto read = [&] { (void)read_mesh(bad); };

  write_text(bad, header + nodes + "$Elements\n1\n1 2 2 0 1 1 2 3\n");  // truncated
  CHECK(parse_error_position(read, "unexpected end of file") == 13);
  write_text(bad, header + "$Nodes\n3\n1 0 0 0\n2 1.5e 0 0\n3 0 1 0\n$EndNodes\n");
  CHECK(parse_error_position(read, "expected node coordinate as a number (got '1.5e')") == 7);
  write_text(bad, header + "$Nodes\n3\n1 0 0 0\n2 nan 0 0\n3 0 1 0\n$EndNodes\n");
  CHECK(parse_error_position(read, "not finite") == 7);
  write_text(bad, header + "$Nodes\n3\n1 0 0 0\n2 inf 0 0\n3 0 1 0\n$EndNodes\n");
  CHECK(parse_error_position(read, "not finite") == 7);
  write_text(bad, header + nodes + "$Elements\n1\n1 45 2 0 1 1 2 3\n$EndElements\n");
  CHECK(parse_error_position(read, "unsupported Gmsh element type 45") == 12);
  write_text(bad, header + nodes + "$Elements\n2\n1 2 2 0 1 1 2 3\n$EndElements\n");
  CHECK(parse_error_position(read, "expected element id") == 13);
  write_text(bad, header + nodes + "$Elements\n1\n1 2 2 0 1 1 2 3\n2 2 2 0 1 1 2 3\n$EndElements\n");
  CHECK(parse_error_position(read, "more or fewer entries than its count") == 13);
  write_text(bad, header + nodes + "$Elements\n1\n1 2 2 0 1 1 2 7\n$EndElements\n");
  CHECK(parse_error_position(read, "refers to node 7") == 12);
  write_text(bad, header + nodes + "$Elements\n1\n1 2 2 0 1 1 2 -3\n$EndElements\n");
  CHECK(parse_error_position(read, "refers to node -3") == 12);
  write_text(bad, "$MeshFormat\n3.0 0 8\n$EndMeshFormat\n");
  CHECK(parse_error_position(read, "unsupported msh version 3.0") == 2);
  write_text(bad, "");
  CHECK(parse_error_position(read, "empty file") == 1);

  SECTION("binary: truncated data reports the byte offset") {
    auto mesh = all_types_mesh<3>(1);
    const auto good = test::scratch_path("good_binary.msh");
    write_mesh(good, mesh, {MshVersion::v4_1, true, false});
    std::string data;
    {
      std::ifstream in(good, std::ios::binary);
      data.assign(std::istreambuf_iterator<char>(in), {});
    }
    const auto cut = data.find("$Elements") + 40;
    write_text(bad, data.substr(0, cut));
    try {
      (void)read_mesh(bad);
      FAIL("no error");
    } catch (const ParseError& e) {
      CHECK(e.position_kind() == ParseError::Position::byte_offset);
      CHECK(e.position() <= cut);
      CHECK(std::string(e.what()).find("truncated binary data") != std::string::npos);
    }
    // the endianness check word must read 1 one way or the other
    auto wrong = data;
    wrong[wrong.find("1 8\n") + 4] = 7;
    write_text(bad, wrong);
    CHECK(parse_error_position(read, "endianness check word") > 0);
    // a byte-swapped file reads the same (swap every value by hand for 2.2)
  }

  SECTION("SU2") {
    const auto su2 = test::scratch_path("bad.su2");
    const auto read_su2_file = [&] { (void)read_mesh(su2); };
    const std::string points = "NPOIN= 3\n0 0 0\n1 0 1\n0 1 2\n";
    write_text(su2, "NDIME= 2\nNELEM= 1\n5 0 1 3 0\n" + points + "NMARK= 0\n");
    CHECK(parse_error_position(read_su2_file, "node index 3 out of range (expected 0 to 2)") == 3);
    write_text(su2, "NDIME= 2\nNELEM= 1\n5 0 -1 2 0\n" + points);
    CHECK(parse_error_position(read_su2_file, "node index out of range (got -1") == 3);
    write_text(su2, "NDIME= 2\nNELEM= 1\n7 0 1 2 0\n" + points);
    CHECK(parse_error_position(read_su2_file, "unknown SU2 element type 7") == 3);
    write_text(su2, "NDIME= 2\nNELEM= 1\n9 0 1 2\n" + points);
    CHECK(parse_error_position(read_su2_file, "quad4 element with 3 nodes (expected 4)") == 3);
    write_text(su2, "NDIME= 2\nNELEM= 2\n5 0 1 2\n" + points);
    CHECK(parse_error_position(read_su2_file, "expected element type as an integer (got 'NPOIN=')") == 4);
    write_text(su2, "NDIME= 2\nNELEM= 1\n5 0 1 2\nNPOIN= 3\n0 0\n1 x\n0 1\n");
    CHECK(parse_error_position(read_su2_file, "expected point coordinate as a number (got 'x')") == 6);
    write_text(su2, "NDIME= 2\nNELEM= 1\n5 0 1 2\n" + points + "NMARK= 1\nMARKER_TAG= wall\nMARKER_ELEMS= 1\n5 0 1 2\n");
    CHECK(parse_error_position(read_su2_file, "tri3 element of dimension 2 (expected dimension 1 here)") == 11);
    write_text(su2, "NELEM= 1\n");
    CHECK(parse_error_position(read_su2_file, "NDIME must come first") == 1);
  }
}

TEST_CASE("bad paths, dimensions and meshes give clear errors", "[io]") {
  CHECK_THROWS_AS((void)read_mesh(test::scratch_path("missing.msh")), IoError);
  CHECK_THROWS_WITH((void)read_mesh(test::scratch_path("mesh.obj")), Catch::Contains("unknown mesh format '.obj'"));
  CHECK_THROWS_AS(write_mesh(test::scratch_path("mesh.obj"), all_types_mesh<2>(1)), InputError);

  const auto flat = test::scratch_path("nonzero_z.msh");
  write_text(flat, "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n3\n1 0 0 0\n2 1 0 0.5\n3 0 1 0\n$EndNodes\n"
                   "$Elements\n1\n1 2 2 0 1 1 2 3\n$EndElements\n");
  CHECK_THROWS_WITH((void)read_mesh(flat), Catch::Contains("node 2 has z = 0.5"));

  const auto tri = test::scratch_path("tri.msh");
  write_mesh(tri, all_types_mesh<2>(1));
  CHECK_THROWS_WITH((void)read_mesh_as<3>(tri), Catch::Contains("holds a 2D mesh (expected 3D)"));
  CHECK_NOTHROW((void)read_mesh_as<2>(tri));
}

TEST_CASE("every row of the format table is written and read back by its extension, in any case", "[io]") {
  const auto mesh = all_types_mesh<3>(1);
  for (const auto& format : mesh_file_formats) {
    if (!format.available) {
      WARN("skipped " << format.extension << ": this build lacks " << format.library);
      continue;
    }
    std::string upper(format.extension);
    for (char& c : upper) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    INFO(upper);
    const auto file = test::scratch_path("format_table" + upper);
    REQUIRE(mesh_format_of(file) == &format);
    CHECK_NOTHROW(check_mesh_output(file, 2));
    write_mesh(file, mesh);
    const auto back = read_mesh_as<3>(file);
    CHECK(back.num_nodes() == mesh.num_nodes());
    CHECK(back.num_cells() == mesh.num_cells());
    CHECK(back.points.isApprox(mesh.points));
  }
  CHECK(mesh_format_of(test::scratch_path("mesh.obj")) == nullptr);
  CHECK_THROWS_WITH(check_mesh_output(test::scratch_path("mesh.obj")), Catch::Contains("one of .msh, .su2, .cgns, .vtu"));
  CHECK_THROWS_WITH(check_mesh_output(test::scratch_path("p5.cgns"), 5), Catch::Contains("up to order 4 (expected one of .msh, .su2, .vtu for order 5)") ||
                                                                         Catch::Contains("needs the CGNS library"));
}

TEST_CASE("a failing write leaves no output and no temporary file, and never touches the input", "[io]") {
  const auto dir = test::scratch_path("atomic");
  fs::remove_all(dir);
  fs::create_directories(dir);
  auto mesh = all_types_mesh<3>(1);
  mesh.cells.front().connectivity[0] = 999;  // out of range: invalid mesh
  for (const char* name : {"out.msh", "out.su2", "out.vtu"}) CHECK_THROWS_AS(write_mesh(dir / name, mesh), InputError);
  CHECK(files_in(dir).empty());

  // an existing file is replaced only by a complete new one
  const auto valid = all_types_mesh<3>(1);
  write_mesh(dir / "keep.msh", valid);
  const auto size_before = fs::file_size(dir / "keep.msh");
  CHECK_THROWS_AS(write_mesh(dir / "keep.msh", mesh), InputError);
  CHECK(fs::file_size(dir / "keep.msh") == size_before);
  CHECK(files_in(dir).size() == 1);

  CHECK_THROWS_AS(write_mesh(dir / "no_such_folder" / "out.msh", valid), IoError);
  CHECK(files_in(dir).size() == 1);

  // reading then writing elsewhere leaves the input byte for byte
  const auto input = dir / "keep.msh";
  const auto time_before = fs::last_write_time(input);
  write_mesh(dir / "copy.msh", read_mesh_as<3>(input));
  CHECK(fs::last_write_time(input) == time_before);
  CHECK(fs::file_size(input) == size_before);
}

TEST_CASE("writing over an existing output replaces it whole, as a rename would", "[io]") {
  const auto dir = test::scratch_path("replace");
  fs::remove_all(dir);
  fs::create_directories(dir);
  const auto read_text = [](const fs::path& file) {
    std::ifstream in(file, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
  };
  const auto small = all_types_mesh<2>(1);
  const auto large = all_types_mesh<2>(3);
  write_mesh(dir / "out.msh", large);
  fs::create_hard_link(dir / "out.msh", dir / "earlier.msh");  // another name of the old file
  const std::string old_text = read_text(dir / "out.msh");
  write_mesh(dir / "out.msh", small);
  CHECK(read_mesh_as<2>(dir / "out.msh").num_nodes() == small.num_nodes());
  CHECK(small.num_nodes() != large.num_nodes());
  CHECK(read_text(dir / "earlier.msh") == old_text);  // the old file is unlinked, not rewritten
  CHECK(fs::hard_link_count(dir / "out.msh") == 1);
  CHECK(files_in(dir).size() == 2);  // no temporary left

  // a symbolic link is replaced by the file, its target kept (rename's behaviour)
  fs::create_symlink(dir / "earlier.msh", dir / "link.msh");
  write_mesh(dir / "link.msh", small);
  CHECK(!fs::is_symlink(dir / "link.msh"));
  CHECK(read_text(dir / "earlier.msh") == old_text);

  // a folder is not replaced
  fs::create_directories(dir / "folder.msh");
  CHECK_THROWS_AS(write_mesh(dir / "folder.msh", small), IoError);
  CHECK(fs::is_directory(dir / "folder.msh"));
  CHECK(files_in(dir).size() == 4);
}

TEST_CASE("a killed run's temporaries are removed once an hour old, anyone else's never", "[io]") {
  const auto dir = test::scratch_path("stale");
  fs::remove_all(dir);
  fs::create_directories(dir);
  const auto touch = [&](const std::string& name, std::chrono::hours age) {
    std::ofstream(dir / name) << "partial";
    fs::last_write_time(dir / name, fs::file_time_type::clock::now() - age);
  };
  touch("out.msh.tmp123456_7", std::chrono::hours(2));  // a killed run's
  touch("out.msh.tmp999_0", std::chrono::hours(0));     // a run writing now
  touch("out.msh.tmp_notes", std::chrono::hours(5));    // not of our naming
  touch("other.msh.tmp1_1", std::chrono::hours(5));     // another output's
  write_mesh(dir / "out.msh", all_types_mesh<2>(1));
  std::vector<std::string> names;
  for (const auto& file : files_in(dir)) names.push_back(file.filename().string());
  std::sort(names.begin(), names.end());
  CHECK(names == std::vector<std::string>{"other.msh.tmp1_1", "out.msh", "out.msh.tmp999_0", "out.msh.tmp_notes"});
}

TEST_CASE("in-memory parsing entry points name the source in errors", "[io]") {
  CHECK_THROWS_WITH((void)parse_gmsh("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n", "memory.msh"), Catch::Contains("memory.msh:") && Catch::Contains("no $Nodes"));
  const auto mesh = parse_su2("NDIME= 2\nNPOIN= 3\n0 0\n1 0\n0 1\nNELEM= 1\n5 0 1 2\nNMARK= 1\nMARKER_TAG= wall\nMARKER_ELEMS= 1\n3 0 1\n", "memory.su2");
  const auto& m = std::get<Mesh<2>>(mesh);
  CHECK(m.num_cells() == 1);
  CHECK(m.group("wall").tag == 1);
  CHECK(m.group_nodes("wall") == std::vector<Index>{0, 1});
  // SU2's repository has meshes spelling the keywords MARKERTAG= and MARKERELEMS=, which SU2
  // reads; another keyword there is still refused.
  const auto spelled = parse_su2("NDIME= 2\nNPOIN= 3\n0 0\n1 0\n0 1\nNELEM= 1\n5 0 1 2\nNMARK= 2\nMARKERTAG= wall\n"
                                 "MARKERELEMS= 1\n3 0 1\nMARKER_TAG= far\nMARKER_ELEMS= 1\n3 1 2\n", "memory.su2");
  CHECK(std::get<Mesh<2>>(spelled).group_nodes("wall") == std::vector<Index>{0, 1});
  CHECK(std::get<Mesh<2>>(spelled).group_nodes("far") == std::vector<Index>{1, 2});
  CHECK_THROWS_WITH((void)parse_su2("NDIME= 2\nNPOIN= 3\n0 0\n1 0\n0 1\nNELEM= 1\n5 0 1 2\nNMARK= 1\nMARKER_NAME= wall\n"
                                    "MARKER_ELEMS= 1\n3 0 1\n", "memory.su2"),
                    Catch::Contains("memory.su2:9") && Catch::Contains("expected MARKER_TAG= for marker 1"));
}
