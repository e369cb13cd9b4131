// Tests of CGNS reading and writing (io/cgns.hpp): round trips of every element type and of
// the real meshes, cgnscheck on what we write, files as other writers make them (MIXED
// sections, vertex BCs, element-range BCs in families, several zones) built with the CGNS
// library itself, and the error for each kind of bad file.

#include "meshmotion/core/generators.hpp"
#include "meshmotion/core/orientation.hpp"
#include "meshmotion/curving/p2_conversion.hpp"
#include "meshmotion/io.hpp"
#include "meshmotion/quality/quality_report.hpp"

#include "io_support.hpp"
#include "messages.hpp"
#include "test_data.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

using namespace meshmotion;
namespace fs = std::filesystem;

#ifdef MESHMOTION_HAVE_CGNS

#include <cgns_io.h>

namespace {

// cgnscheck (Debian cgns-convert) on a file: its output, or empty when the tool is absent.
std::string cgnscheck(const fs::path& file) {
  if (std::system("command -v cgnscheck > /dev/null 2>&1") != 0) return {};
  const fs::path log = fs::path(file).replace_extension(".cgnscheck.txt");
  const std::string command = "cgnscheck " + file.string() + " > " + log.string() + " 2>&1";
  const int status = std::system(command.c_str());
  std::ifstream in(log);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (status != 0) text += "\n(cgnscheck exit status " + std::to_string(status) + ")";
  return text;
}

// No error and no warning; `detached_facets` lets cgnscheck say that facets are not on the
// cells' boundary: true of the synthetic one-element-per-type mesh, and what cgnscheck 3.4.0
// also says of facets in MIXED sections (even of a file the CGNS library wrote itself).
void require_cgnscheck_clean(const fs::path& file, bool detached_facets = false) {
  std::string report = cgnscheck(file);
  if (report.empty()) {
    WARN("cgnscheck not installed (cgns-convert): the file's validity was not checked");
    return;
  }
  INFO(report);
  CHECK(report.find("ERROR") == std::string::npos);
  CHECK(report.find("checking complete") != std::string::npos);
  if (detached_facets)
    for (std::size_t at = report.find("WARNING:"); at != std::string::npos; at = report.find("WARNING:", at + 1)) {
      const std::size_t end = report.find('\n', at);
      const std::string line = report.substr(at, end - at);
      if (line.find("are not boundary elements") != std::string::npos || line.find("are not faces of the volume elements") != std::string::npos)
        report.erase(at, end - at);
    }
  CHECK(report.find("WARNING:") == std::string::npos);
}

// Same nodes and cells and, group by group (by name), the same nodes.
template <int Dim>
void require_same_geometry(const Mesh<Dim>& a, const Mesh<Dim>& b) {
  REQUIRE(a.points == b.points);
  for (const auto& lists : {std::pair{&a.cells, &b.cells}, std::pair{&a.facets, &b.facets}, std::pair{&a.lower, &b.lower}}) {
    REQUIRE(lists.first->size() == lists.second->size());
    for (std::size_t k = 0; k < lists.first->size(); ++k) {
      CHECK((*lists.first)[k].type == (*lists.second)[k].type);
      CHECK((*lists.first)[k].connectivity == (*lists.second)[k].connectivity);
    }
  }
  for (const auto& g : a.groups) {
    INFO("group " << g.name);
    const PhysicalGroup* other = b.find_group(g.name);
    REQUIRE(other != nullptr);
    CHECK(a.group_nodes(g.tag, g.dim) == b.group_nodes(other->tag, other->dim));
  }
}

// A CGNS file written with the library's own calls, as another program would.
class CgnsBuilder {
 public:
  explicit CgnsBuilder(const fs::path& file, int cell_dim = 2, int phys_dim = 2) {
    REQUIRE(cg_open(file.c_str(), CG_MODE_WRITE, &fn_) == CG_OK);
    REQUIRE(cg_base_write(fn_, "Base", cell_dim, phys_dim, &base_) == CG_OK);
    phys_dim_ = phys_dim;
  }
  ~CgnsBuilder() { cg_close(fn_); }
  CgnsBuilder(const CgnsBuilder&) = delete;
  CgnsBuilder& operator=(const CgnsBuilder&) = delete;

  int zone(const char* name, const std::vector<std::array<double, 3>>& xyz, cgsize_t num_cells) {
    cgsize_t size[3] = {static_cast<cgsize_t>(xyz.size()), num_cells, 0};
    int z = 0;
    REQUIRE(cg_zone_write(fn_, base_, name, size, CGNS_ENUMV(Unstructured), &z) == CG_OK);
    static constexpr const char* names[3] = {"CoordinateX", "CoordinateY", "CoordinateZ"};
    for (int d = 0; d < phys_dim_; ++d) {
      std::vector<double> c;
      for (const auto& p : xyz) c.push_back(p[static_cast<std::size_t>(d)]);
      int C = 0;
      REQUIRE(cg_coord_write(fn_, base_, z, CGNS_ENUMV(RealDouble), names[d], c.data(), &C) == CG_OK);
    }
    return z;
  }
  /// A structured block of ni × nj [× nk] vertices (nk 0 in 2D) on a unit grid from x = x0,
  /// i fastest.
  int structured_zone(const char* name, int ni, int nj, int nk, double x0) {
    return structured_zone(name, ni, nj, nk, [x0](int i, int j, int k) {
      return std::array<double, 3>{x0 + i, static_cast<double>(j), static_cast<double>(k)};
    });
  }
  /// A structured block whose vertex (i, j, k) (0-based) is at place(i, j, k).
  template <class Place>
  int structured_zone(const char* name, int ni, int nj, int nk, Place&& place) {
    const bool three = nk > 0;
    cgsize_t size[9] = {};
    const std::array<int, 3> n{ni, nj, three ? nk : 1};
    const int index_dim = three ? 3 : 2;
    for (int d = 0; d < index_dim; ++d) {
      size[d] = n[static_cast<std::size_t>(d)];
      size[index_dim + d] = n[static_cast<std::size_t>(d)] - 1;
    }
    int z = 0;
    REQUIRE(cg_zone_write(fn_, base_, name, size, CGNS_ENUMV(Structured), &z) == CG_OK);
    static constexpr const char* names[3] = {"CoordinateX", "CoordinateY", "CoordinateZ"};
    for (int d = 0; d < phys_dim_; ++d) {
      std::vector<double> c;
      for (int k = 0; k < n[2]; ++k)
        for (int j = 0; j < nj; ++j)
          for (int i = 0; i < ni; ++i) c.push_back(place(i, j, k)[static_cast<std::size_t>(d)]);
      int C = 0;
      REQUIRE(cg_coord_write(fn_, base_, z, CGNS_ENUMV(RealDouble), names[d], c.data(), &C) == CG_OK);
    }
    return z;
  }
  void section(int z, const char* name, CGNS_ENUMT(ElementType_t) type, cgsize_t start, cgsize_t end,
               const std::vector<cgsize_t>& nodes) {
    int S = 0;
    REQUIRE(cg_section_write(fn_, base_, z, name, type, start, end, 0, nodes.data(), &S) == CG_OK);
  }
  void mixed(int z, const char* name, cgsize_t start, cgsize_t end, const std::vector<cgsize_t>& data,
             const std::vector<cgsize_t>& offsets) {
    int S = 0;
    REQUIRE(cg_poly_section_write(fn_, base_, z, name, CGNS_ENUMV(MIXED), start, end, 0, data.data(), offsets.data(), &S) == CG_OK);
  }
  /// `index_dim`: numbers per point (i, j, k of a structured zone's vertex; 1 otherwise).
  int boco(int z, const char* name, CGNS_ENUMT(PointSetType_t) set, const std::vector<cgsize_t>& points,
           CGNS_ENUMT(GridLocation_t) location = CGNS_ENUMV(Vertex), int index_dim = 1) {
    int bc = 0;
    REQUIRE(cg_boco_write(fn_, base_, z, name, CGNS_ENUMV(BCWall), set, static_cast<cgsize_t>(points.size()) / index_dim,
                          points.data(), &bc) == CG_OK);
    if (location != CGNS_ENUMV(Vertex)) REQUIRE(cg_boco_gridlocation_write(fn_, base_, z, bc, location) == CG_OK);
    return bc;
  }
  /// A 1-to-1 connection of zone z with zone `donor` (index ranges as CGNS stores them).
  void one_to_one(int z, const char* name, const char* donor, const std::vector<cgsize_t>& range,
                  const std::vector<cgsize_t>& donor_range, const std::vector<int>& transform) {
    int I = 0;
    REQUIRE(cg_1to1_write(fn_, base_, z, name, donor, range.data(), donor_range.data(), transform.data(), &I) == CG_OK);
  }
  /// Overwrites the data of the node at `path` (from the file's root) as a file written by
  /// another tool could hold it, past the checks of the library's own writers.
  template <class T>
  void overwrite(const std::string& path, const std::vector<T>& data) {
    int cgio = 0;
    double root = 0.0, node = 0.0;
    REQUIRE(cg_get_cgio(fn_, &cgio) == CG_OK);
    REQUIRE(cg_root_id(fn_, &root) == CG_OK);
    REQUIRE(cgio_get_node_id(cgio, root, path.c_str(), &node) == CG_OK);
    REQUIRE(cgio_write_all_data(cgio, node, data.data()) == CG_OK);
  }
  void family(int z, int bc, const char* name) {
    int F = 0;
    REQUIRE(cg_family_write(fn_, base_, name, &F) == CG_OK);
    REQUIRE(cg_goto(fn_, base_, "Zone_t", z, "ZoneBC_t", 1, "BC_t", bc, "end") == CG_OK);
    REQUIRE(cg_famname_write(name) == CG_OK);
  }
  [[nodiscard]] int id() const { return fn_; }
  [[nodiscard]] int base() const { return base_; }

 private:
  int fn_ = -1, base_ = 0, phys_dim_ = 2;
};

// An nx × ny grid of nodes on [x0, x0 + nx - 1] × [0, ny - 1] and its quads (1-based).
std::vector<std::array<double, 3>> grid_nodes(int nx, int ny, double x0 = 0.0) {
  std::vector<std::array<double, 3>> xyz;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) xyz.push_back({x0 + i, static_cast<double>(j), 0.0});
  return xyz;
}
std::vector<cgsize_t> grid_quads(int nx, int ny) {
  std::vector<cgsize_t> q;
  for (int j = 0; j + 1 < ny; ++j)
    for (int i = 0; i + 1 < nx; ++i) {
      const cgsize_t a = j * nx + i + 1;
      q.insert(q.end(), {a, a + 1, a + 1 + nx, a + nx});
    }
  return q;
}

template <class F>
void require_input_error(F&& f, const std::vector<std::string>& parts) {
  const std::string message = test::message_of<InputError>(f);
  INFO(message);
  for (const auto& p : parts) CHECK(message.find(p) != std::string::npos);
}

}  // namespace

TEST_CASE("CGNS: every element type to order 4 round-trips and passes cgnscheck", "[io][cgns]") {
  // CGNS names no element past order 4: refused by name before the file exists.
  CHECK_THROWS_WITH(write_mesh(test::scratch_path("all_types3_p5_refused.cgns"), test::all_types_mesh<3>(5)),
                    Catch::Contains("elements: CGNS names elements to order 4"));
  CHECK_FALSE(fs::exists(test::scratch_path("all_types3_p5_refused.cgns")));
  for (const int element_order : {1, 2, 3, 4}) {
    INFO("order " << element_order);
    const auto check = [&](const auto& mesh, const std::string& stem) {
      using M = std::decay_t<decltype(mesh)>;
      const fs::path file = test::scratch_path(stem + ".cgns");
      write_mesh(file, mesh);
      require_cgnscheck_clean(file, true);
      const M a = std::get<M>(read_mesh(file));
      require_same_geometry(mesh, a);
      CHECK(a.node_ids.empty());  // CGNS numbers nodes 1..n
      // Element numbers follow the input's ids, renumbered 1..n in that order.
      std::vector<std::pair<std::int64_t, std::int64_t>> numbers;  // (input id, CGNS number)
      for (const auto& lists : {std::pair{&mesh.cells, &a.cells}, std::pair{&mesh.facets, &a.facets}, std::pair{&mesh.lower, &a.lower}})
        for (std::size_t k = 0; k < lists.first->size(); ++k) {
          REQUIRE((*lists.second)[k].ids.size() == static_cast<std::size_t>((*lists.second)[k].size()));
          for (Index e = 0; e < (*lists.first)[k].size(); ++e)
            numbers.emplace_back((*lists.first)[k].ids[static_cast<std::size_t>(e)], (*lists.second)[k].ids[static_cast<std::size_t>(e)]);
        }
      std::sort(numbers.begin(), numbers.end());
      for (std::size_t k = 0; k < numbers.size(); ++k) CHECK(numbers[k].second == static_cast<std::int64_t>(k) + 1);
      // What was read writes back to the same file content and reads back identical.
      const fs::path again = test::scratch_path(stem + "_again.cgns");
      write_mesh(again, a);
      test::require_same_mesh(a, std::get<M>(read_mesh(again)));
    };
    check(test::all_types_mesh<3>(element_order), "all_types3_p" + std::to_string(element_order));
    check(test::all_types_mesh<2>(element_order), "all_types2_p" + std::to_string(element_order));
  }
}

TEST_CASE("CGNS node orders: a permutation for every type CGNS holds, a refusal by name for the others", "[io][cgns]") {
  for (int t = 0; t < num_element_types; ++t) {
    const auto type = static_cast<ElementType>(t);
    INFO(name(type));
    if (!detail::cgns_writes(type)) {
      if (order(type) > 1) CHECK_THROWS_WITH(detail::cgns_order(type), Catch::Contains(std::string(name(type))));
      continue;
    }
    std::vector<int> order_of = detail::cgns_order(type);
    std::sort(order_of.begin(), order_of.end());
    for (std::size_t i = 0; i < order_of.size(); ++i) CHECK(order_of[i] == static_cast<int>(i));
  }
  // Where CGNS's conventions show (SIDS and its cubic and quartic extensions; every order here
  // agrees node by node with SU2's CGNS reader): CGNS node -> the reference point it sits at.
  struct Placed {
    ElementType type;
    int node;
    RefPoint at;
  };
  const double t = 1.0 / 3.0;
  const Placed placed[] = {
      // The side face on the hexahedron's bottom edge (3, 0) starts at vertex 3 (VTK agrees).
      {ElementType::hex64, 48, {-1, t, -t}},
      // A cubic prism: the bottom face, each side face's ring from its first vertex toward its
      // second ((0, 1, 4, 3), (2, 0, 3, 5)), the top face, then the inside from the bottom up.
      {ElementType::prism40, 24, {t, t, -1}}, {ElementType::prism40, 25, {t, 0, -t}}, {ElementType::prism40, 26, {2 * t, 0, -t}},
      {ElementType::prism40, 28, {t, 0, t}}, {ElementType::prism40, 33, {0, 2 * t, -t}}, {ElementType::prism40, 37, {t, t, 1}},
      {ElementType::prism40, 38, {t, t, -t}}, {ElementType::prism40, 39, {t, t, t}},
      // A cubic pyramid: the base's ring from vertex 0 toward 1, the side faces (0, 1, 4) ..., the inside.
      {ElementType::pyramid30, 21, {-t, -t, 0}}, {ElementType::pyramid30, 22, {t, -t, 0}},
      {ElementType::pyramid30, 25, {0, -2 * t, t}}, {ElementType::pyramid30, 29, {0, 0, t}},
      // Quartic: a quadrilateral's inside goes round its ring, then the centre (Gmsh's nests a P2 quad).
      {ElementType::quad25, 16, {-0.5, -0.5, 0}}, {ElementType::quad25, 17, {0, -0.5, 0}}, {ElementType::quad25, 19, {0.5, 0, 0}},
      {ElementType::quad25, 23, {-0.5, 0, 0}}, {ElementType::quad25, 24, {0, 0, 0}},
      {ElementType::hex125, 44, {-0.5, -0.5, -1}}, {ElementType::hex125, 52, {0, 0, -1}},
      {ElementType::hex125, 98, {-0.5, -0.5, -0.5}}, {ElementType::hex125, 106, {0, 0, -0.5}}, {ElementType::hex125, 107, {-0.5, -0.5, 0}},
      {ElementType::tri15, 12, {0.25, 0.25, 0}}, {ElementType::tri15, 13, {0.5, 0.25, 0}}, {ElementType::tri15, 14, {0.25, 0.5, 0}},
      {ElementType::tet35, 25, {0.25, 0, 0.25}}, {ElementType::tet35, 26, {0.5, 0, 0.25}}, {ElementType::tet35, 27, {0.25, 0, 0.5}},
      {ElementType::tet35, 34, {0.25, 0.25, 0.25}},
      {ElementType::prism75, 66, {0.25, 0.25, -0.5}}, {ElementType::prism75, 67, {0.5, 0.25, -0.5}}, {ElementType::prism75, 69, {0.25, 0.25, 0}},
      {ElementType::pyramid55, 50, {-0.25, -0.25, 0.25}}, {ElementType::pyramid55, 54, {0, 0, 0.5}}};
  for (const Placed& p : placed) {
    INFO(name(p.type) << " CGNS node " << p.node);
    const RefPoint x = reference_nodes(p.type)[static_cast<std::size_t>(detail::cgns_order_of(p.type)[static_cast<std::size_t>(p.node)])];
    for (std::size_t d = 0; d < 3; ++d) CHECK(x[d] == Approx(p.at[d]).margin(1e-12));
  }
}

TEST_CASE("CGNS: mixed P1 and P2 boxes keep orientation, numbering and groups", "[io][cgns]") {
  for (const auto cells : {BoxCells::tet_pyramid_prism, BoxCells::hex_prism, BoxCells::pyramid5}) {
    const Mesh<3> linear = box_mesh({.nx = 4, .ny = 3, .nz = 2, .cells = cells});
    for (const Mesh<3>& mesh : {linear, to_quadratic(linear)}) {
      REQUIRE(orientation_report(mesh).num_negative == 0);
      const fs::path file = test::scratch_path("box.cgns");
      write_mesh(file, mesh);
      const Mesh<3> back = read_mesh_as<3>(file, ReadOptions{ReadOrientation::require_positive});
      require_same_geometry(mesh, back);
      for (const auto& g : mesh.groups)
        if (g.dim == 2) CHECK(test::group_size(back, g.name) == test::group_size(mesh, g.name));
    }
  }
  // Facets of one group that alternate in type (tri/quad faces of a mixed box listed by id)
  // make one MIXED section, read back element by element.
  Mesh<3> box = box_mesh({.nx = 4, .ny = 2, .nz = 2, .cells = BoxCells::hex_prism});
  std::int64_t id = 1;
  for (auto& b : box.cells) {
    b.ids.resize(static_cast<std::size_t>(b.size()));
    for (auto& i : b.ids) i = id++;
  }
  for (auto& b : box.facets) {
    b.ids.resize(static_cast<std::size_t>(b.size()));
    for (std::size_t k = 0; k < b.ids.size(); ++k) b.ids[k] = id + 2 * static_cast<std::int64_t>(k) + (b.type == ElementType::quad4 ? 1 : 0);
  }
  const fs::path file = test::scratch_path("alternating.cgns");
  write_mesh(file, box);
  require_cgnscheck_clean(file, true);
  const Mesh<3> back = read_mesh_as<3>(file);
  CHECK(back.num_facets() == box.num_facets());
  for (const auto& g : box.groups)
    if (g.dim == 2) CHECK(back.group_nodes(back.group(g.name).tag) == box.group_nodes(g.tag));
}

TEST_CASE("CGNS: facet groups interleaved face by face are written as one section per group", "[io][cgns]") {
  // A generated box lists its facets face by face, so that in id order the groups alternate
  // hundreds of times; a section per run made thousands of sections.
  const Mesh<3> box = box_mesh({.nx = 12, .ny = 12, .nz = 12, .cells = BoxCells::tet4});
  std::size_t runs = 0;
  for (const auto& b : box.facets)
    for (std::size_t k = 0; k < b.tags.size(); ++k) runs += k == 0 || b.tags[k] != b.tags[k - 1] ? 1 : 0;
  REQUIRE(runs > 200);
  const fs::path file = test::scratch_path("interleaved.cgns");
  write_mesh(file, box);
  require_cgnscheck_clean(file);
  int fn = -1, nsections = 0;
  REQUIRE(cg_open(file.c_str(), CG_MODE_READ, &fn) == CG_OK);
  CHECK(cg_nsections(fn, 1, 1, &nsections) == CG_OK);
  cg_close(fn);
  CHECK(nsections == 1 + 6);  // the tetrahedra, then one section per side
  const Mesh<3> back = read_mesh_as<3>(file, ReadOptions{ReadOrientation::require_positive});
  CHECK(back.points == box.points);
  REQUIRE(back.cells.size() == 1);
  CHECK(back.cells[0].connectivity == box.cells[0].connectivity);
  CHECK(back.num_facets() == box.num_facets());
  for (const auto& g : box.groups)
    if (g.dim == 2) CHECK(back.group_nodes(back.group(g.name).tag) == box.group_nodes(g.tag));
}

TEST_CASE("CGNS: every real mesh round-trips with its groups", "[io][cgns]") {
  const auto data_dir = test::shared_data("SOURCES.md");
  if (!data_dir) {
    WARN("skipped: ../shared/data is absent");
    return;
  }
  for (const auto& entry : fs::directory_iterator(data_dir->parent_path())) {
    const fs::path& file = entry.path();
    if (file.extension() != ".su2" && file.extension() != ".msh") continue;
    INFO(file);
    std::visit(
        [&](const auto& mesh) {
          using M = std::decay_t<decltype(mesh)>;
          const fs::path out = test::scratch_path("real.cgns");
          write_mesh(out, mesh);
          require_cgnscheck_clean(out);
          const M back = std::get<M>(read_mesh(out));
          CHECK(back.points == mesh.points);
          REQUIRE(back.cells.size() == mesh.cells.size());
          for (std::size_t k = 0; k < mesh.cells.size(); ++k) CHECK(back.cells[k].connectivity == mesh.cells[k].connectivity);
          CHECK(back.num_facets() == mesh.num_facets());
          for (const auto& g : mesh.groups)
            if (g.dim == M::dim - 1) CHECK(back.group_nodes(back.group(g.name).tag) == mesh.group_nodes(g.tag));
          const fs::path again = test::scratch_path("real_again.cgns");
          write_mesh(again, back);
          test::require_same_mesh(back, std::get<M>(read_mesh(again)));
        },
        read_mesh(file));
  }
}

TEST_CASE("CGNS written by other programs: MIXED sections, vertex BCs, families, element ranges", "[io][cgns]") {
  SECTION("2D: one MIXED section of cells, BCs as vertex lists, no facet section") {
    // 3 × 2 nodes: a quad on the left, two triangles on the right.
    const fs::path file = test::scratch_path("vertex_bcs.cgns");
    {
      CgnsBuilder f(file);
      const int z = f.zone("dom", grid_nodes(3, 2), 3);
      f.mixed(z, "Fluid", 1, 3,
              {CGNS_ENUMV(QUAD_4), 1, 2, 5, 4, CGNS_ENUMV(TRI_3), 2, 3, 6, CGNS_ENUMV(TRI_3), 2, 6, 5}, {0, 5, 9, 13});
      f.boco(z, "bottom", CGNS_ENUMV(PointList), {1, 2, 3});
      f.boco(z, "right", CGNS_ENUMV(PointRange), {3, 3});  // one node: no edge lies in it
      f.boco(z, "top", CGNS_ENUMV(PointRange), {4, 6});
    }
    const Mesh<2> mesh = read_mesh_as<2>(file);
    CHECK(mesh.num_nodes() == 6);
    CHECK(mesh.num_cells() == 3);
    CHECK(test::group_size(mesh, "Fluid") == 3);
    CHECK(test::group_size(mesh, "bottom") == 2);
    CHECK(test::group_size(mesh, "top") == 2);
    CHECK(mesh.group_nodes("bottom") == std::vector<Index>{0, 1, 2});
    CHECK(mesh.group_nodes("top") == std::vector<Index>{3, 4, 5});
    CHECK(mesh.find_group("right") != nullptr);
    CHECK(orientation_report(mesh).num_negative == 0);
  }
  SECTION("3D: cells and faces in one MIXED section, BCs as element ranges and lists, in families") {
    // Two hexahedra along x; the x = 0 face and the x = 2 face as quads.
    std::vector<std::array<double, 3>> xyz;
    for (int k = 0; k < 2; ++k)
      for (int j = 0; j < 2; ++j)
        for (int i = 0; i < 3; ++i) xyz.push_back({double(i), double(j), double(k)});
    const auto n = [](int i, int j, int k) { return static_cast<cgsize_t>(k * 6 + j * 3 + i + 1); };
    const fs::path file = test::scratch_path("element_bcs.cgns");
    {
      CgnsBuilder f(file, 3, 3);
      const int z = f.zone("block", xyz, 2);
      std::vector<cgsize_t> data, offsets{0};
      for (int i = 0; i < 2; ++i) {
        data.insert(data.end(), {CGNS_ENUMV(HEXA_8), n(i, 0, 0), n(i + 1, 0, 0), n(i + 1, 1, 0), n(i, 1, 0), n(i, 0, 1),
                                 n(i + 1, 0, 1), n(i + 1, 1, 1), n(i, 1, 1)});
        offsets.push_back(static_cast<cgsize_t>(data.size()));
      }
      data.insert(data.end(), {CGNS_ENUMV(QUAD_4), n(0, 0, 0), n(0, 0, 1), n(0, 1, 1), n(0, 1, 0)});
      offsets.push_back(static_cast<cgsize_t>(data.size()));
      data.insert(data.end(), {CGNS_ENUMV(QUAD_4), n(2, 0, 0), n(2, 1, 0), n(2, 1, 1), n(2, 0, 1)});
      offsets.push_back(static_cast<cgsize_t>(data.size()));
      f.mixed(z, "All", 1, 4, data, offsets);
      const int inlet = f.boco(z, "inlet_bc", CGNS_ENUMV(ElementRange), {3, 3});
      f.family(z, inlet, "INLET");
      f.boco(z, "outlet", CGNS_ENUMV(PointList), {4}, CGNS_ENUMV(FaceCenter));
    }
    const Mesh<3> mesh = read_mesh_as<3>(file);
    CHECK(mesh.num_cells() == 2);
    CHECK(test::group_size(mesh, "INLET") == 1);  // the family names the group
    CHECK(mesh.find_group("inlet_bc") == nullptr);
    CHECK(test::group_size(mesh, "outlet") == 1);
    CHECK(mesh.group_nodes("outlet") == std::vector<Index>{2, 5, 8, 11});
    CHECK(orientation_report(mesh).num_negative == 0);
    // Element numbers are the file's.
    CHECK(mesh.find_block(ElementType::quad4)->ids == std::vector<std::int64_t>{3, 4});
  }
  SECTION("several zones: one mesh, interface nodes shared, the zones as cell groups") {
    const fs::path file = test::scratch_path("two_zones.cgns");
    {
      CgnsBuilder f(file);
      for (const int k : {0, 1}) {
        const int z = f.zone(k == 0 ? "left" : "right", grid_nodes(3, 3, 2.0 * k), 4);
        f.section(z, "cells", CGNS_ENUMV(QUAD_4), 1, 4, grid_quads(3, 3));
        f.section(z, "bottom_edges", CGNS_ENUMV(BAR_2), 5, 6, {1, 2, 2, 3});
        f.boco(z, "bottom", CGNS_ENUMV(PointRange), {5, 6}, CGNS_ENUMV(EdgeCenter));
      }
    }
    const Mesh<2> mesh = read_mesh_as<2>(file);
    CHECK(mesh.num_nodes() == 15);  // 5 × 3: the x = 2 column is shared
    CHECK(mesh.num_cells() == 8);
    CHECK(test::group_size(mesh, "left") == 4);
    CHECK(test::group_size(mesh, "right") == 4);
    CHECK(test::group_size(mesh, "bottom") == 4);
    CHECK(mesh.group_nodes("bottom").size() == 5);
    CHECK(orientation_report(mesh).num_negative == 0);
    std::vector<std::int64_t> ids = mesh.cells.front().ids;
    CHECK(ids == std::vector<std::int64_t>{1, 2, 3, 4, 7, 8, 9, 10});  // the right zone's continue after the left's
  }
}

TEST_CASE("CGNS structured zones read as hexahedra and quadrilaterals, blocks joined, BCs on their faces", "[io][cgns]") {
  SECTION("3D: two blocks meeting at x = 2, BCs as vertex ranges and a list, one in a family") {
    const fs::path file = test::scratch_path("structured_blocks.cgns");
    {
      CgnsBuilder f(file, 3, 3);
      for (const int b : {0, 1}) {
        const int z = f.structured_zone(b == 0 ? "upstream" : "downstream", 3, 3, 3, 2.0 * b);
        f.boco(z, "wall", CGNS_ENUMV(PointRange), {1, 1, 1, 3, 3, 1}, CGNS_ENUMV(Vertex), 3);  // k = 1
        if (b == 0) {
          std::vector<cgsize_t> inlet;  // i = 1, every vertex listed
          for (cgsize_t k = 1; k <= 3; ++k)
            for (cgsize_t j = 1; j <= 3; ++j) inlet.insert(inlet.end(), {1, j, k});
          f.boco(z, "inlet", CGNS_ENUMV(PointList), inlet, CGNS_ENUMV(Vertex), 3);
        } else {
          const int sym = f.boco(z, "side", CGNS_ENUMV(PointRange), {3, 1, 3, 1, 1, 1}, CGNS_ENUMV(Vertex), 3);  // j = 1, corners swapped
          f.family(z, sym, "SYMMETRY");
        }
      }
    }
    const Mesh<3> mesh = read_mesh_as<3>(file);
    CHECK(mesh.num_nodes() == 5 * 3 * 3);  // the x = 2 face is shared
    CHECK(mesh.num_cells() == 16);
    CHECK(mesh.cells.front().type == ElementType::hex8);
    CHECK(test::group_size(mesh, "upstream") == 8);
    CHECK(test::group_size(mesh, "downstream") == 8);
    CHECK(test::group_size(mesh, "wall") == 8);
    CHECK(test::group_size(mesh, "inlet") == 4);
    CHECK(test::group_size(mesh, "SYMMETRY") == 4);
    for (const Index v : mesh.group_nodes("wall")) CHECK(mesh.points(2, v) == 0.0);
    for (const Index v : mesh.group_nodes("inlet")) CHECK(mesh.points(0, v) == 0.0);
    for (const Index v : mesh.group_nodes("SYMMETRY")) CHECK((mesh.points(1, v) == 0.0 && mesh.points(0, v) >= 2.0));
    CHECK(orientation_report(mesh).num_negative == 0);
    CHECK(quality_report(mesh, Metric::scaled_jacobian).min > 0.99);  // unit cubes

    // Written back with new coordinates: the same structured blocks and BCs.
    Mesh<3> moved = mesh;
    for (Index v = 0; v < moved.num_nodes(); ++v) moved.points(2, v) += 0.1 * moved.points(0, v) * moved.points(1, v);
    const fs::path out = test::scratch_path("structured_blocks_moved.cgns");
    write_cgns_coordinates(file, out, moved);
    int fn = 0, nzones = 0;
    REQUIRE(cg_open(out.c_str(), CG_MODE_READ, &fn) == CG_OK);
    REQUIRE(cg_nzones(fn, 1, &nzones) == CG_OK);
    CHECK(nzones == 2);
    for (int z = 1; z <= nzones; ++z) {
      CGNS_ENUMT(ZoneType_t) type{};
      REQUIRE(cg_zone_type(fn, 1, z, &type) == CG_OK);
      CHECK(type == CGNS_ENUMV(Structured));
    }
    cg_close(fn);
    const Mesh<3> back = read_mesh_as<3>(out);
    CHECK(back.points == moved.points);
    CHECK(back.group_nodes("wall") == mesh.group_nodes("wall"));
    CHECK(back.group_nodes("SYMMETRY") == mesh.group_nodes("SYMMETRY"));
    Mesh<3> fewer = mesh;
    fewer.points.conservativeResize(3, mesh.num_nodes() - 1);
    require_input_error([&] { write_cgns_coordinates(file, out, fewer); }, {"45 nodes", "3D with 44"});
  }
  SECTION("2D: one block of quadrilaterals, a BC along j = 1") {
    const fs::path file = test::scratch_path("structured_2d.cgns");
    {
      CgnsBuilder f(file);
      const int z = f.structured_zone("plate", 4, 3, 0, 0.0);
      f.boco(z, "bottom", CGNS_ENUMV(PointRange), {1, 1, 4, 1}, CGNS_ENUMV(Vertex), 2);
    }
    const Mesh<2> mesh = read_mesh_as<2>(file);
    CHECK(mesh.num_nodes() == 12);
    CHECK(mesh.num_cells() == 6);
    CHECK(test::group_size(mesh, "bottom") == 3);
    CHECK(mesh.group_nodes("bottom") == std::vector<Index>{0, 1, 2, 3});
    CHECK(orientation_report(mesh).num_negative == 0);
  }
  SECTION("refused: a BC on faces, an index outside the block") {
    const auto refused = [&](const std::string& stem, auto&& build, const std::vector<std::string>& parts) {
      const fs::path file = test::scratch_path(stem + ".cgns");
      {
        CgnsBuilder f(file, 3, 3);
        build(f);
      }
      require_input_error([&] { (void)read_mesh(file); }, parts);
    };
    refused("structured_cell_bc", [](CgnsBuilder& f) {
      const int z = f.structured_zone("blk", 3, 3, 3, 0.0);
      f.boco(z, "wall", CGNS_ENUMV(PointRange), {1, 1, 1, 2, 2, 1}, CGNS_ENUMV(CellCenter), 3);
    }, {"/Base/blk/ZoneBC/wall", "located at cells or edges"});
    refused("structured_range", [](CgnsBuilder& f) {
      const int z = f.structured_zone("blk", 3, 3, 3, 0.0);
      f.boco(z, "wall", CGNS_ENUMV(PointRange), {1, 1, 1, 4, 3, 1}, CGNS_ENUMV(Vertex), 3);
    }, {"/Base/blk/ZoneBC/wall", "index 1 is 4", "3 vertices along it"});
  }
}

TEST_CASE("CGNS structured: a C-grid's wake cut joined by its 1-to-1 record, BCs located at faces", "[io][cgns]") {
  // z = ζ² maps the strip ζ = s + i t, s in [-4, 4], t in [0, 3] onto a C-grid around a slit
  // of the x axis: vertices (s, 0) and (-s, 0) coincide. |s| ≥ 2 is the wake cut, declared
  // 1-to-1 (i 1..3 with i 9..7, the trailing edge at x = 4 included); |s| < 2 is a plate of zero
  // thickness whose two sides coincide too but are no connection: they stay apart.
  const int ni = 9, nj = 4;
  const auto cgrid = [](int i, int j, int) {
    const double s = i - 4.0, t = j;
    return std::array<double, 3>{s * s - t * t, 2.0 * s * t, 0.0};
  };
  const auto build = [&](const fs::path& file, auto&& extra) {
    CgnsBuilder f(file);
    const int z = f.structured_zone("cgrid", ni, nj, 0, cgrid);
    extra(f, z);
  };
  const auto count_at = [](const Mesh<2>& mesh, double x, double y) {
    Index n = 0;
    for (Index v = 0; v < mesh.num_nodes(); ++v) n += mesh.points(0, v) == x && mesh.points(1, v) == y ? 1 : 0;
    return n;
  };
  SECTION("the cut is one node per pair, its facets interior; face BCs by range; written back as the block") {
    const fs::path file = test::scratch_path("cgrid.cgns");
    build(file, [](CgnsBuilder& f, int z) {
      f.one_to_one(z, "wake", "cgrid", {1, 1, 3, 1}, {9, 1, 7, 1}, {-1, -2});
      // A 2D block's face BCs are at EdgeCenter (the library refuses FaceCenter there).
      f.boco(z, "plate", CGNS_ENUMV(PointRange), {3, 1, 6, 1}, CGNS_ENUMV(EdgeCenter), 2);    // cells i 3..6 at j = 1
      f.boco(z, "outflow", CGNS_ENUMV(PointRange), {1, 1, 1, 3}, CGNS_ENUMV(EdgeCenter), 2);  // i = 1, cells j 1..3
      f.boco(z, "far", CGNS_ENUMV(PointRange), {1, 4, 9, 4}, CGNS_ENUMV(Vertex), 2);
    });
    const Mesh<2> mesh = read_mesh_as<2>(file);
    CHECK(mesh.num_nodes() == ni * nj - 3);
    CHECK(mesh.num_cells() == 24);
    // Free edges: the plate's 4, the far field's 8 and the two outflows' 3 each; the wake's
    // 2 + 2 edges are interior (a cut read apart would leave 22).
    Index free = 0;
    for (const auto& b : boundary_facets(mesh)) free += b.size();
    CHECK(free == 18);
    CHECK(count_at(mesh, 9.0, 0.0) == 1);   // wake (s = ±3)
    CHECK(count_at(mesh, 4.0, 0.0) == 1);   // trailing edge (s = ±2)
    CHECK(count_at(mesh, 1.0, 0.0) == 2);   // the plate's two sides (s = ±1)
    CHECK(test::group_size(mesh, "plate") == 4);
    CHECK(mesh.group_nodes("plate").size() == 4);
    CHECK(test::group_size(mesh, "outflow") == 3);
    for (const Index v : mesh.group_nodes("outflow")) CHECK(mesh.points(1, v) <= 0.0);  // s = -4: y = -8 t
    CHECK(test::group_size(mesh, "far") == 8);

    Mesh<2> moved = mesh;
    for (Index v = 0; v < moved.num_nodes(); ++v) moved.points(1, v) += 0.01 * moved.points(0, v);
    const fs::path out = test::scratch_path("cgrid_moved.cgns");
    write_cgns_coordinates(file, out, moved);
    const Mesh<2> back = read_mesh_as<2>(out);
    CHECK(back.num_nodes() == mesh.num_nodes());  // both copies of each cut vertex written alike
    CHECK(back.points == moved.points);
  }
  SECTION("a connection whose vertices are apart (periodic) joins nothing") {
    const fs::path file = test::scratch_path("cgrid_periodic.cgns");
    build(file, [](CgnsBuilder& f, int z) { f.one_to_one(z, "periodic", "cgrid", {1, 2, 1, 4}, {9, 2, 9, 4}, {1, 2}); });
    CHECK(read_mesh_as<2>(file).num_nodes() == ni * nj);
  }
  SECTION("3D: face BCs by range (FaceCenter, on the block face it lies on) and by list (KFaceCenter)") {
    const fs::path file = test::scratch_path("structured_face_bcs.cgns");
    {
      CgnsBuilder f(file, 3, 3);
      const int z = f.structured_zone("blk", 3, 3, 3, 0.0);
      f.boco(z, "top", CGNS_ENUMV(PointRange), {1, 1, 3, 2, 2, 3}, CGNS_ENUMV(FaceCenter), 3);      // k = 3, every cell
      f.boco(z, "bottom", CGNS_ENUMV(PointList), {1, 1, 1, 2, 2, 1}, CGNS_ENUMV(KFaceCenter), 3);   // two of the four at k = 1
      f.boco(z, "inlet", CGNS_ENUMV(PointRange), {1, 2, 1, 1, 2, 2}, CGNS_ENUMV(IFaceCenter), 3);   // i = 1, j cell 2, k cells 1..2
    }
    const Mesh<3> mesh = read_mesh_as<3>(file);
    CHECK(test::group_size(mesh, "top") == 4);
    for (const Index v : mesh.group_nodes("top")) CHECK(mesh.points(2, v) == 2.0);
    CHECK(test::group_size(mesh, "bottom") == 2);
    for (const Index v : mesh.group_nodes("bottom")) CHECK((mesh.points(2, v) == 0.0 && std::abs(mesh.points(0, v) - mesh.points(1, v)) <= 1.0));
    CHECK(mesh.group_nodes("bottom").size() == 7);  // faces (1,1) and (2,2) share their corner (1,1)
    CHECK(test::group_size(mesh, "inlet") == 2);
    for (const Index v : mesh.group_nodes("inlet")) CHECK((mesh.points(0, v) == 0.0 && mesh.points(1, v) >= 1.0));
  }
  SECTION("refused, naming the record") {
    const auto refused = [&](const std::string& stem, auto&& extra, const std::vector<std::string>& parts) {
      const fs::path file = test::scratch_path(stem + ".cgns");
      build(file, extra);
      require_input_error([&] { (void)read_mesh(file); }, parts);
    };
    // The library's writer refuses these three; another tool's file may hold them.
    const auto wake = [](std::vector<cgsize_t> range, std::vector<cgsize_t> donor, std::vector<int> transform) {
      return [=](CgnsBuilder& f, int z) {
        f.one_to_one(z, "wake", "cgrid", {1, 1, 3, 1}, {9, 1, 7, 1}, {-1, -2});
        const std::string at = "/Base/cgrid/ZoneGridConnectivity/wake";
        f.overwrite(at + "/PointRange", range);
        f.overwrite(at + "/PointRangeDonor", donor);
        f.overwrite(at + "/Transform", transform);
      };
    };
    refused("cgrid_transform", wake({1, 1, 3, 1}, {9, 1, 7, 1}, {-1, -1}),
            {"/Base/cgrid/ZoneGridConnectivity/wake", "transform (-1, -1)", "signed permutation"});
    refused("cgrid_range", wake({1, 1, 10, 1}, {9, 1, 7, 1}, {-1, -2}),
            {"/Base/cgrid/ZoneGridConnectivity/wake", "range index 1 is 10", "9 vertices"});
    refused("cgrid_donor", wake({1, 1, 3, 1}, {9, 1, 8, 1}, {-1, -2}),
            {"/Base/cgrid/ZoneGridConnectivity/wake", "vertex (3, 1)", "outside the donor range"});
    refused("cgrid_face_list", [](CgnsBuilder& f, int z) { f.boco(z, "plate", CGNS_ENUMV(PointList), {3, 1}, CGNS_ENUMV(EdgeCenter), 2); },
            {"/Base/cgrid/ZoneBC/plate", "EdgeCenter PointList", "IFaceCenter"});
    refused("cgrid_face_inside", [](CgnsBuilder& f, int z) { f.boco(z, "cut", CGNS_ENUMV(PointRange), {3, 2, 6, 2}, CGNS_ENUMV(EdgeCenter), 2); },
            {"/Base/cgrid/ZoneBC/cut", "lies on no block face"});
    refused("cgrid_face_index", [](CgnsBuilder& f, int z) { f.boco(z, "outflow", CGNS_ENUMV(PointRange), {1, 1, 1, 4}, CGNS_ENUMV(EdgeCenter), 2); },
            {"/Base/cgrid/ZoneBC/outflow", "face index 2 is 4", "expected 1 to 3 for cells"});
    const auto refused_3d = [&](const std::string& stem, auto&& extra, const std::vector<std::string>& parts) {
      const fs::path file = test::scratch_path(stem + ".cgns");
      {
        CgnsBuilder f(file, 3, 3);
        extra(f, f.structured_zone("blk", 3, 3, 3, 0.0));
      }
      require_input_error([&] { (void)read_mesh(file); }, parts);
    };
    refused_3d("structured_face_interior", [](CgnsBuilder& f, int z) { f.boco(z, "cut", CGNS_ENUMV(PointRange), {2, 1, 1, 2, 2, 2}, CGNS_ENUMV(IFaceCenter), 3); },
               {"/Base/blk/ZoneBC/cut", "not on the block's boundary"});
    refused_3d("structured_edge_bc", [](CgnsBuilder& f, int z) { f.boco(z, "edge", CGNS_ENUMV(PointRange), {1, 1, 1, 2, 1, 1}, CGNS_ENUMV(EdgeCenter), 3); },
               {"/Base/blk/ZoneBC/edge", "located at cells or edges"});
  }
}

TEST_CASE("CGNS: each kind of bad file gets a clear error naming the node path", "[io][cgns]") {
  const fs::path dir = test::scratch_path("cgns_bad");
  fs::remove_all(dir);
  fs::create_directories(dir);
  CHECK_THROWS_AS(read_mesh(dir / "absent.cgns"), IoError);
  {
    std::ofstream(dir / "text.cgns") << "not a CGNS file\n";
    CHECK(test::message_of<IoError>([&] { (void)read_mesh(dir / "text.cgns"); }).find("text.cgns: cannot open as a CGNS file") !=
          std::string::npos);
  }
  {
    const fs::path file = dir / "structured.cgns";
    {
      CgnsBuilder f(file);
      cgsize_t size[6] = {3, 3, 2, 2, 0, 0};
      int z = 0;
      REQUIRE(cg_zone_write(f.id(), f.base(), "blk", size, CGNS_ENUMV(Structured), &z) == CG_OK);
    }
    require_input_error([&] { (void)read_mesh(file); }, {"structured.cgns", "/Base/blk/GridCoordinates", "no CoordinateX"});
  }
  const auto one_quad = [&](const std::string& stem, auto&& add) {
    const fs::path file = dir / (stem + ".cgns");
    {
      CgnsBuilder f(file);
      const int z = f.zone("dom", grid_nodes(2, 2), 1);
      add(f, z);
    }
    return file;
  };
  require_input_error([&] { (void)read_mesh(one_quad("node_range", [](CgnsBuilder& f, int z) {
                          f.section(z, "q", CGNS_ENUMV(QUAD_4), 1, 1, {1, 2, 99, 3});
                        })); },
                      {"/Base/dom/q", "element 1 has node 99", "4 nodes"});
  require_input_error([&] { (void)read_mesh(one_quad("repeated_node", [](CgnsBuilder& f, int z) {
                          f.section(z, "q", CGNS_ENUMV(QUAD_4), 1, 1, {1, 2, 2, 3});
                        })); },
                      {"/Base/dom/q", "element 1 lists node 2 twice"});
  require_input_error([&] { (void)read_mesh(one_quad("tri12", [](CgnsBuilder& f, int z) {
                          f.section(z, "p4", CGNS_ENUMV(TRI_12), 1, 1, {1, 2, 3, 1, 2, 3, 1, 2, 3, 4, 1, 2});
                        })); },
                      {"/Base/dom/p4", "TRI_12", "no serendipity ones past order 2"});
  require_input_error([&] { (void)read_mesh(one_quad("two_bcs", [](CgnsBuilder& f, int z) {
                          f.section(z, "q", CGNS_ENUMV(QUAD_4), 1, 1, {1, 2, 4, 3});
                          f.section(z, "e", CGNS_ENUMV(BAR_2), 2, 2, {1, 2});
                          f.boco(z, "a", CGNS_ENUMV(PointList), {2}, CGNS_ENUMV(EdgeCenter));
                          f.boco(z, "b", CGNS_ENUMV(PointList), {2}, CGNS_ENUMV(EdgeCenter));
                        })); },
                      {"/Base/dom/ZoneBC/b", "element 2 is also in BC 'a'"});
  require_input_error([&] { (void)read_mesh(one_quad("bc_element", [](CgnsBuilder& f, int z) {
                          f.section(z, "q", CGNS_ENUMV(QUAD_4), 1, 1, {1, 2, 4, 3});
                          f.boco(z, "a", CGNS_ENUMV(PointList), {7}, CGNS_ENUMV(EdgeCenter));
                        })); },
                      {"/Base/dom/ZoneBC/a", "element 7 is in no section"});
  require_input_error([&] { (void)read_mesh(one_quad("ngon", [](CgnsBuilder& f, int z) {
                          int S = 0;
                          const std::vector<cgsize_t> data{1, 2, 4, 3}, offsets{0, 4};
                          REQUIRE(cg_poly_section_write(f.id(), f.base(), z, "faces", CGNS_ENUMV(NGON_n), 1, 1, 0, data.data(),
                                                        offsets.data(), &S) == CG_OK);
                        })); },
                      {"/Base/dom/faces", "NGON_n", "polyhedral"});
  {
    const fs::path file = dir / "two_bases.cgns";
    {
      CgnsBuilder f(file);
      int b = 0;
      REQUIRE(cg_base_write(f.id(), "Other", 2, 2, &b) == CG_OK);
    }
    require_input_error([&] { (void)read_mesh(file); }, {"2 bases", "Base, Other"});
  }
  {
    const fs::path file = dir / "no_y.cgns";
    {
      CgnsBuilder f(file, 2, 2);
      cgsize_t size[3] = {3, 1, 0};
      int z = 0, C = 0;
      REQUIRE(cg_zone_write(f.id(), f.base(), "dom", size, CGNS_ENUMV(Unstructured), &z) == CG_OK);
      const double x[3] = {0, 1, 0};
      REQUIRE(cg_coord_write(f.id(), f.base(), z, CGNS_ENUMV(RealDouble), "CoordinateR", x, &C) == CG_OK);
    }
    require_input_error([&] { (void)read_mesh(file); }, {"/Base/dom/GridCoordinates", "no CoordinateX", "CoordinateR"});
  }

  // A file that cannot be created: the user's path and the reason in the user's terms, not the
  // temporary file's name or HDF5's words.
  {
    const Mesh<2> square = rectangle_mesh({.nx = 2, .ny = 2});
    for (const auto& [target, reason] : {std::pair{dir / "missing" / "out.cgns", std::string("does not exist")},
                                         std::pair{dir / "no_y.cgns" / "out.cgns", std::string("is not a folder")}}) {
      const std::string message = test::message_of<IoError>([&] { write_cgns(target, square); });
      INFO(message);
      CHECK(message.find(target.string() + ": cannot write: ") != std::string::npos);
      CHECK(message.find(reason) != std::string::npos);
      CHECK(message.find(".tmp") == std::string::npos);
      CHECK(message.find("HDF5") == std::string::npos);
    }
  }

  // A group name CGNS cannot hold: nothing written, an existing file untouched.
  Mesh<2> mesh = rectangle_mesh({.nx = 2, .ny = 2});
  const fs::path out = dir / "named.cgns";
  write_mesh(out, mesh);
  const auto size_before = fs::file_size(out);
  mesh.groups.front().name = std::string(40, 'w');
  require_input_error([&] { write_mesh(out, mesh); }, {std::string(40, 'w'), "32 characters"});
  CHECK(fs::file_size(out) == size_before);
  std::size_t files = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++files;
  mesh.groups.front().name = "a/b";
  CHECK_THROWS_AS(write_mesh(dir / "slash.cgns", mesh), InputError);
  std::size_t files_after = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++files_after;
  CHECK(files_after == files);  // no temporary left behind
}

#else

TEST_CASE("CGNS: without the CGNS library, .cgns files are refused with the reason", "[io][cgns]") {
  const fs::path file = test::scratch_path("absent_library.cgns");
  const Mesh<2> mesh = rectangle_mesh({.nx = 2, .ny = 2});
  CHECK(test::message_of<InputError>([&] { write_mesh(file, mesh); }).find("libcgns-dev") != std::string::npos);
  CHECK(!fs::exists(file));
  CHECK_THROWS_AS(check_mesh_output(file), InputError);
}

#endif
