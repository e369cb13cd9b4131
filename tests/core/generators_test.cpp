#include "meshmotion/core/extrusion.hpp"
#include "meshmotion/core/generators.hpp"

#include <Eigen/Geometry>
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>

using namespace meshmotion;

namespace {

// Signed area (2D, shoelace) or volume (3D, divergence theorem over the element's outward
// facets) of a linear element: negative when the element is inverted.
template <int Dim>
double signed_measure(const Mesh<Dim>& m, ElementType t, std::span<const Index> el) {
  const auto p = [&](int k) { return Vec<Dim>(m.points.col(el[static_cast<std::size_t>(k)])); };
  double s = 0.0;
  if constexpr (Dim == 2) {
    const int n = num_vertices(t);
    for (int k = 0; k < n; ++k) s += 0.5 * (p(k).x() * p((k + 1) % n).y() - p((k + 1) % n).x() * p(k).y());
  } else {
    for (const LocalFacet& f : facets(t)) {
      const auto v = [&](int k) { return p(f.vertices[static_cast<std::size_t>(k)]); };
      const Vec<3> area = f.num_vertices == 3 ? Vec<3>(0.5 * (v(1) - v(0)).cross(v(2) - v(0)))
                                              : Vec<3>(0.5 * (v(2) - v(0)).cross(v(3) - v(1)));
      Vec<3> centroid = Vec<3>::Zero();
      for (int k = 0; k < f.num_vertices; ++k) centroid += v(k) / f.num_vertices;
      s += area.dot(centroid) / 3.0;
    }
  }
  return s;
}

template <int Dim>
double min_measure(const Mesh<Dim>& m) {
  double lo = std::numeric_limits<double>::infinity();
  for (const auto& b : m.cells)
    for (Index e = 0; e < b.size(); ++e) lo = std::min(lo, signed_measure(m, b.type, b.element(e)));
  return lo;
}

}  // namespace

TEST_CASE("rectangle meshes: counts, groups, orientation", "[core]") {
  const Index nx = 5, ny = 3;
  for (RectangleCells cells : {RectangleCells::quad4, RectangleCells::tri3, RectangleCells::tri_quad}) {
    const Mesh<2> m = rectangle_mesh({.nx = nx, .ny = ny, .x_min = -1.0, .x_max = 2.0, .cells = cells});
    INFO("cells " << static_cast<int>(cells));
    CHECK(m.num_nodes() == (nx + 1) * (ny + 1));
    const Index tris = cells == RectangleCells::tri3 ? 2 * nx * ny : cells == RectangleCells::tri_quad ? 2 * ny * 3 : 0;
    const Index quads = cells == RectangleCells::quad4 ? nx * ny : cells == RectangleCells::tri_quad ? ny * 2 : 0;
    CHECK(m.num_cells() == tris + quads);
    CHECK(min_measure(m) > 0);
    CHECK(m.num_facets() == 2 * (nx + ny));
    CHECK(m.group_nodes("left").size() == static_cast<std::size_t>(ny + 1));
    CHECK(m.group_nodes("right").size() == static_cast<std::size_t>(ny + 1));
    CHECK(m.group_nodes("bottom").size() == static_cast<std::size_t>(nx + 1));
    CHECK(m.group_nodes("top").size() == static_cast<std::size_t>(nx + 1));
    for (Index v : m.group_nodes("left")) CHECK(m.points(0, v) == -1.0);
    for (Index v : m.group_nodes("top")) CHECK(m.points(1, v) == 1.0);
    CHECK_NOTHROW(validate(m));
  }
}

TEST_CASE("box meshes of every cell kind: counts, groups, orientation", "[core]") {
  const Index nx = 3, ny = 2, nz = 4;
  const Index grid_cells = nx * ny * nz;
  const std::vector<std::pair<BoxCells, Index>> kinds{{BoxCells::hex8, grid_cells},
                                                      {BoxCells::tet4, 6 * grid_cells},
                                                      {BoxCells::prism6, 2 * grid_cells},
                                                      {BoxCells::pyramid5, 6 * grid_cells},
                                                      {BoxCells::hex_prism, ny * nz * (2 * 2 + 1)},
                                                      {BoxCells::tet_pyramid_prism, ny * nz * (2 + 7 + 6)}};
  for (const auto& [cells, count] : kinds) {
    INFO("cells " << static_cast<int>(cells));
    const Mesh<3> m = box_mesh({.nx = nx, .ny = ny, .nz = nz, .z_max = 3.0, .cells = cells});
    CHECK(m.num_cells() == count);
    CHECK(min_measure(m) > 0);
    double volume = 0;
    for (const auto& b : m.cells)
      for (Index e = 0; e < b.size(); ++e) volume += signed_measure(m, b.type, b.element(e));
    CHECK(volume == Approx(3.0));
    const auto side = [&](const char* g) { return m.group_nodes(g).size(); };
    CHECK(side("left") == static_cast<std::size_t>((ny + 1) * (nz + 1)));
    CHECK(side("right") == static_cast<std::size_t>((ny + 1) * (nz + 1)));
    CHECK(side("front") == static_cast<std::size_t>((nx + 1) * (nz + 1)));
    CHECK(side("back") == static_cast<std::size_t>((nx + 1) * (nz + 1)));
    CHECK(side("bottom") == static_cast<std::size_t>((nx + 1) * (ny + 1)));
    CHECK(side("top") == static_cast<std::size_t>((nx + 1) * (ny + 1)));
    for (Index v : m.group_nodes("top")) CHECK(m.points(2, v) == 3.0);
    CHECK_NOTHROW(validate(m));
  }
  // The mixed kinds really are mixed.
  const Mesh<3> mixed = box_mesh({.nx = 3, .cells = BoxCells::tet_pyramid_prism});
  CHECK(mixed.find_block(ElementType::tet4));
  CHECK(mixed.find_block(ElementType::pyramid5));
  CHECK(mixed.find_block(ElementType::prism6));
}

TEST_CASE("default O-mesh is a valid boundary-layer mesh with aspect ratio above 1000", "[core]") {
  const OMeshOptions opt;
  const Mesh<2> m = o_mesh();
  const Index n = opt.n_around;
  CHECK(m.num_nodes() == n * (opt.n_radial + 1));
  CHECK(m.num_cells() == n * opt.n_radial);
  CHECK(min_measure(m) > 0);
  CHECK(m.group_nodes("wall").size() == static_cast<std::size_t>(n));
  CHECK(m.group_nodes("farfield").size() == static_cast<std::size_t>(n));
  const double wall_spacing = (m.points.col(1) - m.points.col(0)).norm();
  const double first_height = (m.points.col(n) - m.points.col(0)).norm();
  CHECK(first_height == Approx(opt.first_height).epsilon(1e-9));
  CHECK(wall_spacing / first_height >= 1000.0);
  for (Index v : m.group_nodes("wall")) CHECK(m.points.col(v).norm() == Approx(0.5).epsilon(1e-15));
  for (Index v : m.group_nodes("farfield")) CHECK(m.points.col(v).norm() == Approx(opt.farfield_radius).epsilon(1e-13));
}

TEST_CASE("O-mesh around an ellipse and a square, quads and triangles", "[core]") {
  const OMeshOptions ellipse{.semi_axis_x = 1.0, .semi_axis_y = 0.25, .n_around = 40, .n_radial = 12,
                             .first_height = 1e-4, .farfield_radius = 10.0, .triangles = true};
  const Mesh<2> m = o_mesh(ellipse);
  CHECK(m.num_cells() == 2 * 40 * 12);
  CHECK(min_measure(m) > 0);
  for (Index v : m.group_nodes("wall")) {
    const double x = m.points(0, v), y = m.points(1, v) / 0.25;
    CHECK(std::abs(x * x + y * y - 1.0) < 1e-14);
  }
  // Each ray starts with the requested first height.
  for (Index i = 0; i < 40; ++i) CHECK((m.points.col(40 + i) - m.points.col(i)).norm() == Approx(1e-4).epsilon(1e-9));

  const Mesh<2> sq = o_mesh({.body = OMeshBody::square, .semi_axis_x = 0.5, .n_around = 32, .n_radial = 10,
                             .first_height = 1e-3, .growth = 1.3});
  CHECK(min_measure(sq) > 0);
  for (Index v : sq.group_nodes("wall")) CHECK(sq.points.col(v).lpNorm<Eigen::Infinity>() == Approx(0.5).epsilon(1e-15));
  // With a given growth the second layer is growth × the first.
  const double h1 = (sq.points.col(32) - sq.points.col(0)).norm();
  const double h2 = (sq.points.col(64) - sq.points.col(32)).norm();
  CHECK(h1 == Approx(1e-3));
  CHECK(h2 / h1 == Approx(1.3));
}

TEST_CASE("annulus between two walls: each layer starts at its first height, rings on their circles", "[core]") {
  for (const bool triangles : {false, true}) {
    const AnnulusOptions o{.n_around = 64, .triangles = triangles};
    const Mesh<2> m = annulus_mesh(o);
    CHECK(min_measure(m) > 0);
    const Index n = o.n_around, rings = m.num_nodes() / n;
    CHECK(m.num_cells() == (triangles ? 2 : 1) * n * (rings - 1));
    CHECK(m.group_nodes("inner").size() == static_cast<std::size_t>(n));
    CHECK(m.group_nodes("outer").size() == static_cast<std::size_t>(n));
    for (Index v : m.group_nodes("inner")) CHECK(m.points.col(v).norm() == Approx(0.5).epsilon(1e-15));
    for (Index v : m.group_nodes("outer")) CHECK(m.points.col(v).norm() == Approx(1.5).epsilon(1e-15));
    CHECK(m.points.col(n).norm() - 0.5 == Approx(o.inner_first_height).epsilon(1e-9));
    CHECK(m.points.col(n).norm() - m.points.col(0).norm() == Approx(o.inner_first_height).epsilon(1e-9));
    CHECK(1.5 - m.points.col((rings - 2) * n).norm() == Approx(o.outer_first_height).epsilon(1e-9));
    // Heights grow by each wall's ratio, and no cell is taller than the core spacing.
    const auto height = [&](Index j) { return m.points.col((j + 1) * n).norm() - m.points.col(j * n).norm(); };
    CHECK(height(1) / height(0) == Approx(o.inner_growth));
    CHECK(height(rings - 3) / height(rings - 2) == Approx(o.outer_growth));
    for (Index j = 0; j + 1 < rings; ++j) CHECK(height(j) <= o.core_spacing * (1 + 1e-12));
  }
}

TEST_CASE("extruded 2D meshes: prisms and hexahedra, lateral groups keep their 2D tags, end caps", "[core]") {
  const Mesh<2> flat = rectangle_mesh({.nx = 4, .ny = 3, .x_max = 2.0, .cells = RectangleCells::tri_quad});
  const ExtrudeOptions o{.layers = 3, .height = 0.6};
  const Mesh<3> m = extrude_mesh(flat, o);
  CHECK_NOTHROW(validate(m));
  CHECK(m.num_nodes() == flat.num_nodes() * (o.layers + 1));
  REQUIRE(m.find_block(ElementType::prism6));
  REQUIRE(m.find_block(ElementType::hex8));
  CHECK(m.find_block(ElementType::prism6)->size() == flat.find_block(ElementType::tri3)->size() * o.layers);
  CHECK(m.find_block(ElementType::hex8)->size() == flat.find_block(ElementType::quad4)->size() * o.layers);
  CHECK(min_measure(m) > 0);
  double volume = 0;
  for (const auto& b : m.cells)
    for (Index e = 0; e < b.size(); ++e) volume += signed_measure(m, b.type, b.element(e));
  CHECK(volume == Approx(2.0 * 1.0 * 0.6));
  // Every boundary facet is tagged: the 2D sides keep name and tag, the caps come after them.
  for (const auto& b : m.facets)
    for (const int tag : b.tags) CHECK(tag > 0);
  for (const auto& g : flat.groups) {
    INFO(g.name);
    CHECK(m.group(g.name).tag == g.tag);
    CHECK(m.group_nodes(g.name).size() == flat.group_nodes(g.name).size() * static_cast<std::size_t>(o.layers + 1));
  }
  CHECK(m.group("z_min").tag == 5);
  CHECK(m.group("z_max").tag == 6);
  for (const Index v : m.group_nodes("left")) CHECK(m.points(0, v) == 0.0);
  for (const Index v : m.group_nodes("z_max")) CHECK(m.points(2, v) == Approx(0.6).epsilon(1e-15));
  CHECK(m.group_nodes("z_min").size() == static_cast<std::size_t>(flat.num_nodes()));

  // The walls of an extruded annulus are cylinders.
  const Mesh<3> tube = extrude_mesh(annulus_mesh({.n_around = 32}), {.layers = 2, .height = 0.1});
  CHECK(min_measure(tube) > 0);
  for (const Index v : tube.group_nodes("inner")) CHECK(tube.points.col(v).head<2>().norm() == Approx(0.5).epsilon(1e-15));

  CHECK_THROWS_WITH(extrude_mesh(flat, {.layers = 0}), Catch::Contains("layers >= 1"));
  CHECK_THROWS_WITH(extrude_mesh(flat, {.height = -1.0}), Catch::Contains("positive height"));
  Mesh<2> named = flat;
  named.groups.push_back({1, 9, "z_max"});
  CHECK_THROWS_WITH(extrude_mesh(named), Catch::Contains("'z_max'"));
  Mesh<2> curved = flat;
  curved.cells.clear();
  curved.block(ElementType::tri6).add({0, 1, 2, 3, 4, 5});
  CHECK_THROWS_WITH(extrude_mesh(curved), Catch::Contains("tri6"));
}

TEST_CASE("generators reject impossible sizes", "[core]") {
  CHECK_THROWS_AS(rectangle_mesh({.nx = 0}), InputError);
  CHECK_THROWS_AS(box_mesh({.nz = -1}), InputError);
  CHECK_THROWS_WITH(o_mesh({.body = OMeshBody::square, .n_around = 30}), Catch::Contains("multiple of 4"));
  CHECK_THROWS_WITH(o_mesh({.farfield_radius = 0.4}), Catch::Contains("does not enclose"));
  CHECK_THROWS_WITH(o_mesh({.n_radial = 10, .first_height = 5.0}), Catch::Contains("past the farfield"));
  CHECK_THROWS_WITH(annulus_mesh({.inner_radius = 2.0}), Catch::Contains("inner_radius < outer_radius"));
  CHECK_THROWS_WITH(annulus_mesh({.outer_growth = 1.0}), Catch::Contains("growths above 1"));
  CHECK_THROWS_WITH(annulus_mesh({.core_spacing = 0.6}), Catch::Contains("more than the gap"));
}

TEST_CASE("facet tags without a group get one named by their number", "[core]") {
  Mesh<2> m = rectangle_mesh({.nx = 4, .ny = 2});
  const PhysicalGroup left = m.group("left");
  // As read from a file without physical names: the tags stay, the names go, except "top".
  std::erase_if(m.groups, [](const PhysicalGroup& g) { return g.name != "top"; });
  const Index groups_with_a_name = static_cast<Index>(m.groups.size());
  CHECK_THROWS_AS(m.group_nodes(std::to_string(left.tag)), InputError);
  CHECK(name_unnamed_facet_groups(m) == 3);
  CHECK(static_cast<Index>(m.groups.size()) == groups_with_a_name + 3);
  CHECK(m.group_nodes(std::to_string(left.tag)).size() == 3);
  for (const Index v : m.group_nodes(std::to_string(left.tag))) CHECK(m.points(0, v) == 0.0);
  CHECK(m.group("top").name == "top");
  CHECK(name_unnamed_facet_groups(m) == 0);  // idempotent
}

TEST_CASE("a mesh one cell thick between two planes gives back its 2D section, other meshes none", "[core]") {
  const Mesh<2> flat = rectangle_mesh({.nx = 4, .ny = 3, .x_max = 2.0, .cells = RectangleCells::tri_quad});
  const Index n = flat.num_nodes();
  const Mesh<3> slab = extrude_mesh(flat, {.layers = 1, .height = 0.1});
  const auto same_section = [&](const Extrusion& ext) {
    CHECK(ext.section.points == flat.points);
    for (const auto t : {ElementType::tri3, ElementType::quad4}) {
      REQUIRE(ext.section.find_block(t));
      CHECK(ext.section.find_block(t)->connectivity == flat.find_block(t)->connectivity);
    }
    for (const auto& g : flat.groups) {
      INFO(g.name);
      CHECK(ext.section.group(g.name).tag == g.tag);
      CHECK(ext.section.group(g.name).dim == 1);
      CHECK(ext.section.group_nodes(g.name) == flat.group_nodes(g.name));
    }
    CHECK(ext.plane_groups == std::vector<std::string>{"z_min", "z_max"});
  };
  {
    const auto ext = find_extrusion(slab);
    REQUIRE(ext);
    CHECK(ext->axis == 2);
    CHECK(ext->front == 0.0);
    CHECK(ext->back == 0.1);
    same_section(*ext);
    for (Index s = 0; s < n; ++s) {
      CHECK(ext->front_nodes[static_cast<std::size_t>(s)] == s);
      CHECK(ext->back_nodes[static_cast<std::size_t>(s)] == s + n);
    }
    CHECK(ext->section.node_ids[3] == slab.node_id(3));
  }
  {
    // Thick along x: the section's coordinates are (y, z), in cyclic order.
    Mesh<3> along_x = slab;
    along_x.points.row(0) = slab.points.row(2);
    along_x.points.row(1) = slab.points.row(0);
    along_x.points.row(2) = slab.points.row(1);
    const auto ext = find_extrusion(along_x);
    REQUIRE(ext);
    CHECK(ext->axis == 0);
    same_section(*ext);
  }
  {
    // Mirrored: the front face of every cell turns clockwise and is reversed.
    Mesh<3> mirrored = slab;
    mirrored.points.row(1) *= -1.0;
    const auto ext = find_extrusion(mirrored);
    REQUIRE(ext);
    CHECK(min_measure(ext->section) > 0.0);
  }
  CHECK_FALSE(find_extrusion(extrude_mesh(flat, {.layers = 2, .height = 0.1})));
  Mesh<3> off_plane = slab;
  off_plane.points(2, 5) += 1e-6;
  CHECK_FALSE(find_extrusion(off_plane));
  Mesh<3> sheared = slab;
  sheared.points(0, n + 5) += 1e-6;  // a back node no longer behind its front node
  CHECK_FALSE(find_extrusion(sheared));
  CHECK_FALSE(find_extrusion(box_mesh({.nx = 3, .ny = 3, .nz = 1, .cells = BoxCells::tet4})));
  // One hexahedron thick along both y and z: no one plane.
  CHECK_FALSE(find_extrusion(box_mesh({.nx = 3, .ny = 1, .nz = 1})));
  CHECK(find_extrusion(box_mesh({.nx = 3, .ny = 4, .nz = 1, .cells = BoxCells::hex_prism})));
}
