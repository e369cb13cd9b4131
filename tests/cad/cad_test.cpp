// The CAD component: models read through OpenCASCADE, closest points, group matching, the
// parametric placement of high-order nodes, and curve_mesh on CAD geometry at orders 2 to 4.
#include "meshmotion/cad/cad_model.hpp"
#include "meshmotion/core/generators.hpp"
#include "meshmotion/curving/curve_mesh.hpp"
#include "meshmotion/curving/order_conversion.hpp"
#include "meshmotion/io/mesh_io.hpp"

#include "test_data.hpp"

#include <catch2/catch.hpp>

#include <BRepBuilderAPI_MakeEdge.hxx>
#include <BRepBuilderAPI_NurbsConvert.hxx>
#include <BRepPrimAPI_MakeTorus.hxx>
#include <IGESControl_Controller.hxx>
#include <IGESControl_Writer.hxx>
#include <GeomConvert.hxx>
#include <Geom_BSplineCurve.hxx>
#include <Geom_Circle.hxx>
#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepPrimAPI_MakeCylinder.hxx>
#include <BRepPrimAPI_MakeSphere.hxx>
#include <BRepTools.hxx>
#include <BRep_Builder.hxx>
#include <Message.hxx>
#include <Message_Messenger.hxx>
#include <STEPControl_Writer.hxx>
#include <TopoDS_Compound.hxx>
#include <gp_Circ.hxx>
#include <gp_Elips.hxx>

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <numbers>
#include <random>
#include <set>
#include <span>
#include <string>
#include <tuple>
#include <type_traits>
#include <vector>

using namespace meshmotion;

namespace {

// Two circles in z = 0 (the wall and farfield of o_mesh()); with `minor_radius` the wall is
// an ellipse of semi-axes wall_radius (x) and minor_radius (y).
TopoDS_Shape circles(double wall_radius, double farfield_radius, double minor_radius = 0.0) {
  BRep_Builder builder;
  TopoDS_Compound compound;
  builder.MakeCompound(compound);
  const gp_Ax2 axes(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1));
  builder.Add(compound, minor_radius > 0.0 ? BRepBuilderAPI_MakeEdge(gp_Elips(axes, wall_radius, minor_radius)).Edge()
                                           : BRepBuilderAPI_MakeEdge(gp_Circ(axes, wall_radius)).Edge());
  builder.Add(compound, BRepBuilderAPI_MakeEdge(gp_Circ(axes, farfield_radius)).Edge());
  return compound;
}

// The ways one shape reaches a user: OpenCASCADE's own BREP, STEP, IGES in both of its writer's
// modes (faces as trimmed surfaces, or a B-rep solid), and BREP converted to NURBS first (every
// curve and surface a B-spline, as other CAD systems export them).
enum class CadFormat { brep, step, iges_faces, iges_brep, nurbs };

std::filesystem::path write_model(const TopoDS_Shape& shape, const std::string& name, CadFormat format) {
  Message::DefaultMessenger()->ChangePrinters().Clear();  // the writers' progress reports
  switch (format) {
    case CadFormat::brep:
    case CadFormat::nurbs: {
      const auto file = test::scratch_path(name + (format == CadFormat::nurbs ? "_nurbs.brep" : ".brep"));
      const TopoDS_Shape written = format == CadFormat::nurbs ? BRepBuilderAPI_NurbsConvert(shape).Shape() : shape;
      REQUIRE(BRepTools::Write(written, file.c_str()));
      return file;
    }
    case CadFormat::step: {
      const auto file = test::scratch_path(name + ".step");
      STEPControl_Writer writer;
      REQUIRE(writer.Transfer(shape, STEPControl_AsIs) == IFSelect_RetDone);
      REQUIRE(writer.Write(file.c_str()) == IFSelect_RetDone);
      return file;
    }
    case CadFormat::iges_faces:
    case CadFormat::iges_brep: {
      const auto file = test::scratch_path(name + (format == CadFormat::iges_brep ? "_brep.igs" : "_faces.igs"));
      IGESControl_Controller::Init();
      IGESControl_Writer writer("MM", format == CadFormat::iges_brep ? 1 : 0);
      REQUIRE(writer.AddShape(shape));
      writer.ComputeModel();
      REQUIRE(writer.Write(file.c_str()));
      return file;
    }
  }
  return {};
}

std::filesystem::path circles_brep(double wall_radius, double farfield_radius, double minor_radius = 0.0) {
  return write_model(circles(wall_radius, farfield_radius, minor_radius),
                     "circles_" + std::to_string(wall_radius) + "_" + std::to_string(minor_radius), CadFormat::brep);
}

// The shell between two tori of major radius 1 about the z axis, tube radii 0.3 (group "wall")
// and 0.6 ("outer"): n_major × n_minor × layers hexahedra in the tori's angles and the tube's
// radius, each cut into six tetrahedra along its diagonal (Kuhn's cut, conforming across faces).
Mesh<3> torus_shell(int n_major, int n_minor, int layers) {
  Mesh<3> mesh;
  const auto node = [&](int i, int j, int k) {
    return static_cast<Index>(((i % n_major) * n_minor + j % n_minor) * (layers + 1) + k);
  };
  mesh.points.resize(3, static_cast<Index>(n_major) * n_minor * (layers + 1));
  for (int i = 0; i < n_major; ++i)
    for (int j = 0; j < n_minor; ++j)
      for (int k = 0; k <= layers; ++k) {
        const double theta = 2 * std::numbers::pi * i / n_major, phi = 2 * std::numbers::pi * j / n_minor;
        const double r = 0.3 + 0.3 * k / layers;
        mesh.points.col(node(i, j, k)) = Vec<3>((1 + r * std::cos(phi)) * std::cos(theta), (1 + r * std::cos(phi)) * std::sin(theta), r * std::sin(phi));
      }
  auto& tets = mesh.block(ElementType::tet4);
  std::array<int, 3> axes{0, 1, 2};
  for (int i = 0; i < n_major; ++i)
    for (int j = 0; j < n_minor; ++j)
      for (int k = 0; k < layers; ++k) {
        std::sort(axes.begin(), axes.end());
        do {
          std::array<int, 3> at{i, j, k};
          std::array<Index, 4> tet{node(i, j, k)};
          for (std::size_t step = 0; step < 3; ++step) {
            ++at[static_cast<std::size_t>(axes[step])];
            tet[step + 1] = node(at[0], at[1], at[2]);
          }
          meshmotion::detail::add_positive_tet(tets, mesh.points, tet);
        } while (std::next_permutation(axes.begin(), axes.end()));
      }
  meshmotion::detail::add_boundary_groups(mesh, {"wall", "outer"}, [&](std::span<const Index> nodes) {
    return nodes[0] % (layers + 1) == 0 ? 1 : 2;
  });
  return mesh;
}

TopoDS_Shape tori() {
  BRep_Builder builder;
  TopoDS_Compound compound;
  builder.MakeCompound(compound);
  builder.Add(compound, BRepPrimAPI_MakeTorus(1.0, 0.3).Shape());
  builder.Add(compound, BRepPrimAPI_MakeTorus(1.0, 0.6).Shape());
  return compound;
}

// The same circles, the wall as IGES stores a circle: a rational B-spline, closed but not
// periodic, whose seam is at angle 0.
std::filesystem::path closed_bspline_brep(double wall_radius, double farfield_radius) {
  const auto file = test::scratch_path("closed_bspline_" + std::to_string(wall_radius) + ".brep");
  const gp_Ax2 axes(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1));
  Handle(Geom_BSplineCurve) wall = GeomConvert::CurveToBSplineCurve(new Geom_Circle(axes, wall_radius));
  wall->SetNotPeriodic();
  REQUIRE(!wall->IsPeriodic());
  REQUIRE(wall->IsClosed());
  BRep_Builder builder;
  TopoDS_Compound compound;
  builder.MakeCompound(compound);
  builder.Add(compound, BRepBuilderAPI_MakeEdge(wall).Edge());
  builder.Add(compound, BRepBuilderAPI_MakeEdge(gp_Circ(axes, farfield_radius)).Edge());
  REQUIRE(BRepTools::Write(compound, file.c_str()));
  return file;
}

OMeshOptions small_o_mesh() {
  OMeshOptions o;
  o.n_around = 32;
  o.n_radial = 12;
  o.first_height = 1e-3;
  o.farfield_radius = 4.0;
  return o;
}

double angle(const Vec<2>& x) { return std::atan2(x[1], x[0]); }

// The mesh curved at order p with every group the model fits on the model, the defaults otherwise.
CurveResult<2> curve_on_model(const Mesh<2>& mesh, const CadModel& model, int p) {
  CurveOptions<2> options;
  options.order = p;
  for (const auto& m : match_cad_groups(mesh, model)) options.geometry.insert_or_assign(m.group, cad_boundary<2>(model, m));
  return curve_mesh(mesh, options);
}

}  // namespace

TEST_CASE("CAD: a sphere from OpenCASCADE reads back as STEP and BREP, its closest points on it", "[cad]") {
  Message::DefaultMessenger()->ChangePrinters().Clear();  // the STEP writer's progress report
  const TopoDS_Shape sphere = BRepPrimAPI_MakeSphere(0.5).Shape();
  const auto brep = test::scratch_path("sphere.brep");
  const auto step = test::scratch_path("sphere.step");
  REQUIRE(BRepTools::Write(sphere, brep.c_str()));
  STEPControl_Writer writer;
  REQUIRE(writer.Transfer(sphere, STEPControl_AsIs) == IFSelect_RetDone);
  REQUIRE(writer.Write(step.c_str()) == IFSelect_RetDone);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> coordinate(-1.0, 1.0);
  for (const auto& file : {brep, step}) {
    INFO(file);
    const CadModel model = CadModel::read(file);
    CHECK(model.num_faces() == 1);
    CHECK(model.diagonal() == Approx(std::sqrt(3.0)).epsilon(0.05));
    CHECK(model.periods(2, 1)[0] == Approx(2 * std::numbers::pi));
    CHECK(!model.flat(2, 1));
    for (int k = 0; k < 20; ++k) {
      const Vec<3> x(coordinate(rng), coordinate(rng), coordinate(rng));
      const CadPoint c = model.nearest(2, {}, x);
      CHECK(std::abs(c.point.norm() - 0.5) < 1e-9 * model.diagonal());
      CHECK(c.distance == Approx(std::abs(x.norm() - 0.5)).margin(1e-9));
      CHECK((model.point_at(2, 1, c.u, c.v) - c.point).norm() < 1e-9);
    }
  }
}

TEST_CASE("CAD: a box's faces are planes and its edges lines, a cylinder's side and rims neither", "[cad]") {
  const auto box = test::scratch_path("box.brep");
  const auto cylinder = test::scratch_path("cylinder.brep");
  REQUIRE(BRepTools::Write(BRepPrimAPI_MakeBox(1.0, 2.0, 3.0).Shape(), box.c_str()));
  REQUIRE(BRepTools::Write(BRepPrimAPI_MakeCylinder(0.5, 1.0).Shape(), cylinder.c_str()));
  const CadModel b = CadModel::read(box);
  REQUIRE(b.num_faces() == 6);
  for (int f = 1; f <= 6; ++f) CHECK(b.flat(2, f));
  for (int e = 1; e <= b.num_edges(); ++e) CHECK(b.flat(1, e));
  CHECK_THROWS_WITH(b.flat(2, 7), Catch::Contains("no face 7"));
  // The side, a cylinder: curved; its two caps planes; its rims circles, its seam a line.
  const CadModel c = CadModel::read(cylinder);
  int flat_faces = 0, flat_edges = 0;
  for (int f = 1; f <= c.num_faces(); ++f) flat_faces += c.flat(2, f);
  for (int e = 1; e <= c.num_edges(); ++e) flat_edges += c.flat(1, e);
  CHECK(c.num_faces() == 3);
  CHECK(flat_faces == 2);
  CHECK(flat_edges == 1);
}

TEST_CASE("CAD: high-order nodes on the model's edges slide along them to untangle what a bunched edge folds", "[cad]") {
  // A P3 tetrahedral cube on a CAD box, every face a group: the nodes of one box edge are
  // bunched towards a vertex, so the edge's cubic doubles back and the cells along it fold.
  // Nodes on the border of two groups do not slide on either face; they slide along the
  // model's common edge of their facet's vertices (detail::edge_sliding_node), which untangles
  // the cells; held, they leave them folded.
  const auto path = test::scratch_path("unit_box.brep");
  REQUIRE(BRepTools::Write(BRepPrimAPI_MakeBox(1.0, 1.0, 1.0).Shape(), path.c_str()));
  const CadModel model = CadModel::read(path);
  Mesh<3> mesh = convert_to_order(box_mesh({.nx = 2, .ny = 2, .nz = 2, .x_min = 0, .x_max = 1, .y_min = 0, .y_max = 1, .z_min = 0,
                                            .z_max = 1, .cells = BoxCells::tet4}),
                                  3).mesh;
  std::map<int, BoundaryGeometry<3>> geometry;
  for (const CadGroupMatch& m : match_cad_groups(mesh, model)) {
    REQUIRE(m.matched());
    geometry.emplace(mesh.group(m.group).tag, cad_boundary<3>(model, m));
  }
  std::vector<Index> bunched;  // the edge nodes of x in (0, 0.5) on y = z = 0
  for (Index v = 0; v < mesh.num_nodes(); ++v) {
    const Vec<3> x = mesh.points.col(v);
    if (x.y() == 0.0 && x.z() == 0.0 && x.x() > 0.01 && x.x() < 0.49) bunched.push_back(v);
  }
  REQUIRE(bunched.size() == 2);
  std::sort(bunched.begin(), bunched.end(), [&](Index a, Index b) { return mesh.points(0, a) < mesh.points(0, b); });
  mesh.points(0, bunched[0]) = 0.40;
  mesh.points(0, bunched[1]) = 0.46;
  std::vector<char> fixed(static_cast<std::size_t>(mesh.num_nodes()), 0);
  for (const auto& block : mesh.facets)
    for (const Index v : block.connectivity) fixed[static_cast<std::size_t>(v)] = 1;
  const auto certified = [](const Mesh<3>& m) {
    std::vector<double> q;
    for (const ScaledJacobian& s : scaled_jacobians(m)) q.push_back(s.certified_min);
    return q;
  };
  const std::vector<double> before = certified(mesh);
  REQUIRE(std::count_if(before.begin(), before.end(), [](double q) { return q <= 0.0; }) > 0);

  const SlidingNodes<3> sliding = detail::wall_sliding_nodes(mesh, geometry, 30.0);
  for (const Index v : bunched) {
    REQUIRE(sliding.contains(v));
    const SlidingNode<3>& node = sliding.at(v);
    REQUIRE(node.directions.size() == 1);
    CHECK(std::abs(node.directions[0].x()) == Approx(1.0));
    const Vec<3> p = node.project(mesh.points.col(v) + Vec<3>(-0.2, 0.05, 0.03));  // back onto the edge
    CHECK(p.y() == Approx(0.0).margin(1e-12));
    CHECK(p.z() == Approx(0.0).margin(1e-12));
    CHECK(p.x() == Approx(mesh.points(0, v) - 0.2).margin(1e-9));
  }

  Mesh<3> held = mesh;
  SlidingNodes<3> without = sliding;
  for (const Index v : bunched) without.erase(v);
  std::vector<double> held_quality = before;
  const UntangleReport stuck = untangle(held, fixed, held_quality, {}, without);
  CHECK(stuck.invalid_after > 0);

  std::vector<double> quality = before;
  const UntangleReport report = untangle(mesh, fixed, quality, {}, sliding);
  CHECK(report.invalid_before > 0);
  CHECK(report.invalid_after == 0);
  for (const double q : certified(mesh)) CHECK(q > 0.0);
  CHECK(mesh.points(0, bunched[0]) < mesh.points(0, bunched[1]));
  for (const Index v : bunched) {
    CHECK(mesh.points(1, v) == Approx(0.0).margin(1e-12));
    CHECK(mesh.points(2, v) == Approx(0.0).margin(1e-12));
    CHECK(mesh.points(0, v) > 0.0);
    CHECK(mesh.points(0, v) < 0.5);
  }
}

TEST_CASE("CAD: groups match the model's edges, and a model that does not fit is named", "[cad]") {
  const Mesh<2> mesh = o_mesh(small_o_mesh());
  const CadModel model = CadModel::read(circles_brep(0.5, 4.0));
  const auto matches = match_cad_groups(mesh, model);
  REQUIRE(matches.size() == 2);
  for (const auto& m : matches) {
    INFO(m.group);
    CHECK(m.matched());
    CHECK(m.entities.size() == 1);
    CHECK(m.max_distance < 1e-12);
  }
  CHECK(matches[0].entities != matches[1].entities);
  CHECK_THAT(describe_cad_matches(matches), Catch::Contains("group 'wall': edge"));
  // A wall circle of the wrong radius: the group does not fit, and naming it is an error.
  const CadModel wrong = CadModel::read(circles_brep(0.6, 4.0));
  const auto loose = match_cad_groups(mesh, wrong);
  CHECK(!loose[0].matched());
  CHECK(loose[0].max_distance == Approx(0.1));
  CHECK_THROWS_WITH(match_cad_groups(mesh, wrong, 0.0, {"wall"}),
                    Catch::Contains("does not fit group 'wall'") && Catch::Contains("node ") && Catch::Contains("from the model"));
}

TEST_CASE("CAD: a model that fits no group is refused, with the size ratio of another unit", "[cad]") {
  const CadModel model = CadModel::read(circles_brep(0.5, 4.0));
  Mesh<2> mesh = o_mesh(small_o_mesh());
  require_cad_fit(mesh, model, match_cad_groups(mesh, model));  // fits: nothing thrown
  mesh.points *= 1000.0;  // the same mesh in millimetres
  const auto matches = match_cad_groups(mesh, model);
  CHECK(std::none_of(matches.begin(), matches.end(), [](const CadGroupMatch& m) { return m.matched(); }));
  CHECK_THROWS_WITH(require_cad_fit(mesh, model, matches),
                    Catch::Contains("fits no group") && Catch::Contains("1000 times the model's size") &&
                        Catch::Contains("another unit of length"));
}

TEST_CASE("CAD: bad files are refused with the reason", "[cad]") {
  CHECK_THROWS_AS(CadModel::read(test::scratch_path("missing.step")), IoError);
  const auto junk = test::scratch_path("junk.step");
  std::ofstream(junk) << "not a STEP file\n";
  CHECK_THROWS_AS(CadModel::read(junk), Error);
  const auto other = test::scratch_path("model.obj");
  std::ofstream(other) << "v 0 0 0\n";
  CHECK_THROWS_WITH(CadModel::read(other), Catch::Contains("unknown CAD format"));
}

TEST_CASE("CAD: high-order wall nodes at even parameter steps of the model's curve, on it to round-off", "[cad]") {
  const Mesh<2> mesh = o_mesh(small_o_mesh());
  // A periodic circle, and a closed B-spline: the facets next to its seam took the long way
  // round (a node on the far side of the body, and still a valid certificate).
  for (const auto& file : {circles_brep(0.5, 4.0), closed_bspline_brep(0.5, 4.0)})
  for (const int p : {2, 3, 4}) {
    const CadModel model = CadModel::read(file);
    INFO(file.filename().string() << ", order " << p);
    // Equal arc lengths are equal angles, on the B-spline too, whose parameter is not the angle.
    const double tolerance = 1e-12;
    const CurveResult<2> curved = curve_on_model(mesh, model, p);
    CHECK(curved.invalid() == 0);
    const Mesh<2>& c = curved.curved;
    for (const Index v : c.group_nodes("wall")) CHECK(std::abs(c.points.col(v).norm() - 0.5) < 1e-9 * model.diagonal());
    // The geometric certificate measures the wall on the model: the long way round put a facet
    // 0.44 from the circle, several times its size; here every facet is within 1e-3 of its size.
    const auto on_wall = std::find_if(curved.geometry_distance.begin(), curved.geometry_distance.end(),
                                      [](const GeometryDistance& d) { return d.group == "wall"; });
    REQUIRE(on_wall != curved.geometry_distance.end());
    CHECK(on_wall->geometry == "projection");
    CHECK(on_wall->max_node_distance < 1e-9 * model.diagonal());
    CHECK(on_wall->max_relative_distance < 1e-3);
    CHECK(curved.off_geometry() == 0);
    // The circle's parameter is the angle: edge node j of a facet sits at angle a0 + j/p (a1 - a0).
    const int wall = c.group("wall").tag;
    Index checked = 0;
    for (const auto& b : c.facets)
      for (Index e = 0; e < b.size(); ++e) {
        if (b.tags[static_cast<std::size_t>(e)] != wall) continue;
        const auto el = b.element(e);
        const double a0 = angle(c.points.col(el[0])), a1 = angle(c.points.col(el[1]));
        double step = a1 - a0;
        step -= 2 * std::numbers::pi * std::round(step / (2 * std::numbers::pi));
        for (int j = 1; j < p; ++j) {
          double expected = a0 + step * j / p, got = angle(c.points.col(el[static_cast<std::size_t>(1 + j)]));
          double diff = got - expected;
          diff -= 2 * std::numbers::pi * std::round(diff / (2 * std::numbers::pi));
          CHECK(std::abs(diff) < tolerance);
          ++checked;
        }
      }
    CHECK(checked == 32 * (p - 1));
  }
}

TEST_CASE("CAD: high-order wall nodes split each edge of an ellipse into equal arc lengths", "[cad]") {
  // The ellipse's parameter is the eccentric angle, whose speed varies 2:1 along it: equal
  // parameter steps would give arcs differing by up to a tenth on these facets.
  OMeshOptions o = small_o_mesh();
  o.semi_axis_y = 0.25;
  const Mesh<2> mesh = o_mesh(o);
  const CadModel model = CadModel::read(circles_brep(0.5, 4.0, 0.25));
  const auto arc = [](double t0, double t1) {  // arc length of the ellipse between eccentric angles
    double length = 0.0;
    constexpr int n = 2000;
    for (int k = 0; k < n; ++k) {
      const double t = t0 + (t1 - t0) * (k + 0.5) / n;
      length += std::hypot(0.5 * std::sin(t), 0.25 * std::cos(t)) * std::abs(t1 - t0) / n;
    }
    return length;
  };
  for (const int p : {2, 3, 4}) {
    INFO("order " << p);
    const CurveResult<2> curved = curve_on_model(mesh, model, p);
    CHECK(curved.invalid() == 0);
    const Mesh<2>& c = curved.curved;
    const auto eccentric = [&](Index v) { return std::atan2(c.points(1, v) / 0.25, c.points(0, v) / 0.5); };
    double uneven = 0.0, parameter_uneven = 0.0;
    const int wall = c.group("wall").tag;
    for (const auto& b : c.facets)
      for (Index e = 0; e < b.size(); ++e) {
        if (b.tags[static_cast<std::size_t>(e)] != wall) continue;
        const auto el = b.element(e);
        std::vector<double> t{eccentric(el[0])};
        for (int j = 2; j < p + 1; ++j) t.push_back(eccentric(el[static_cast<std::size_t>(j)]));
        t.push_back(eccentric(el[1]));
        for (std::size_t k = 1; k < t.size(); ++k) t[k] = t[k - 1] + std::remainder(t[k] - t[k - 1], 2 * std::numbers::pi);
        const double whole = arc(t.front(), t.back());
        for (std::size_t k = 1; k < t.size(); ++k) {
          uneven = std::max(uneven, std::abs(arc(t[k - 1], t[k]) - whole / p) / whole);
          parameter_uneven = std::max(parameter_uneven, std::abs((t[k] - t[k - 1]) - (t.back() - t.front()) / p) / std::abs(t.back() - t.front()));
        }
      }
    INFO("arc lengths within " << uneven << ", parameter steps within " << parameter_uneven);
    CHECK(uneven < 1e-4);
    CHECK(parameter_uneven > 1e-2);
  }
}

TEST_CASE("CAD: the RAE2822 and sphere meshes curve onto their STEP files at orders 2 to 4", "[cad][slow]") {
  MESHMOTION_REQUIRE_DATA(rae_mesh, "meshopt_rae2822_linear_tri.msh");
  MESHMOTION_REQUIRE_DATA(rae_step, "meshopt_rae2822Square.stp");
  MESHMOTION_REQUIRE_DATA(sphere_mesh, "meshopt_sphere_symmetry_linear_tet.msh");
  MESHMOTION_REQUIRE_DATA(sphere_step, "meshopt_Sphere25CSymmetry.stp");
  const CadModel rae = CadModel::read(rae_step);
  const Mesh<2> airfoil = read_mesh_as<2>(rae_mesh);
  const auto rae_matches = match_cad_groups(airfoil, rae);
  INFO(describe_cad_matches(rae_matches));
  for (const auto& m : rae_matches) CHECK(m.matched());
  // Gmsh 4.8.4's best certified minimum on the same meshes and files, any of its variants
  // (curving_bench, docs/curving.md "Against Gmsh"): the default must reach it.
  const std::array<double, 5> gmsh_rae{0.0, 0.0, 0.7941, 0.7511, 0.7396};
  for (const int p : {2, 3, 4}) {
    INFO("RAE2822, order " << p);
    CurveOptions<2> options;
    options.order = p;
    for (const auto& m : rae_matches) options.geometry.insert_or_assign(m.group, cad_boundary<2>(rae, m));
    const CurveResult<2> curved = curve_mesh(airfoil, options);
    CHECK(curved.invalid() == 0);
    CHECK(curved.quality.min > gmsh_rae[static_cast<std::size_t>(p)]);
    for (const auto& m : rae_matches)
      for (const Index v : curved.curved.group_nodes(m.group)) {
        Vec<3> x = Vec<3>::Zero();
        x.head<2>() = curved.curved.points.col(v);
        CHECK(rae.nearest(1, m.entities, x).distance < 1e-9 * rae.diagonal());
      }
  }
  const CadModel sphere = CadModel::read(sphere_step);
  const Mesh<3> volume = read_mesh_as<3>(sphere_mesh);
  const auto sphere_matches = match_cad_groups(volume, sphere);
  INFO(describe_cad_matches(sphere_matches));
  for (const int p : {2, 3, 4}) {
    INFO("sphere, order " << p);
    CurveOptions<3> options;
    options.order = p;
    // The sphere curved, the symmetry plane sliding (as curving_bench has it).
    for (const auto& m : sphere_matches)
      if (m.group == "7") options.geometry.insert_or_assign(m.group, cad_boundary<3>(sphere, m));
    options.sliding = {"20"};
    const CurveResult<3> curved = curve_mesh(volume, options);
    CHECK(curved.invalid() == 0);
    // Gmsh's best here is its elastic analogy: 0.7526 at P2, 0.7684 at P3, 0.7751 at P4.
    CHECK(curved.quality.min > std::array<double, 5>{0.0, 0.0, 0.7526, 0.7684, 0.7751}[static_cast<std::size_t>(p)]);
    if (p == 2) {
      // An edge across the sphere's face follows a great circle (a parameter line would follow
      // the latitude), its node halfway along it.
      double off_plane = 0.0, uneven = 0.0;
      const int wall = curved.curved.group("7").tag;
      for (const auto& b : curved.curved.facets)
        for (Index e = 0; e < b.size(); ++e) {
          if (b.tags[static_cast<std::size_t>(e)] != wall) continue;
          const auto el = b.element(e);
          for (std::size_t k = 0; k < 3; ++k) {
            const Vec<3> a = curved.curved.points.col(el[k]), c = curved.curved.points.col(el[(k + 1) % 3]);
            const Vec<3> m = curved.curved.points.col(el[3 + k]);
            off_plane = std::max(off_plane, std::abs(m.dot(a.cross(c))) / (a.cross(c).norm() * m.norm()));
            uneven = std::max(uneven, std::abs((m - a).norm() - (m - c).norm()) / (a - c).norm());
          }
        }
      CHECK(off_plane < 1e-9);
      CHECK(uneven < 1e-3);
    }
    for (const auto& m : sphere_matches)
      if (m.group == "7")
        for (const Index v : curved.curved.group_nodes(m.group))
          CHECK(sphere.nearest(2, m.entities, Vec<3>(curved.curved.points.col(v))).distance < 1e-9 * sphere.diagonal());
  }
}

TEST_CASE("CAD: a Gmsh mesh's entity tags and parameters locate its vertices on the model", "[cad]") {
  MESHMOTION_REQUIRE_DATA(sphere_mesh, "meshopt_sphere_symmetry_linear_tet.msh");
  MESHMOTION_REQUIRE_DATA(sphere_step, "meshopt_Sphere25CSymmetry.stp");
  const CadModel sphere = CadModel::read(sphere_step);
  const Mesh<3> with_params = read_mesh_as<3>(sphere_mesh);
  REQUIRE(!with_params.node_params.empty());
  Mesh<3> without = with_params;
  without.node_params.clear();
  const auto by_file = match_cad_groups(with_params, sphere, 0.0, {"7"}).front();
  const auto by_distance = match_cad_groups(without, sphere, 0.0, {"7"}).front();
  INFO(describe_cad_matches({by_file}));
  // The file's surface nodes are on the faces its tags name, and the same faces come out as by
  // distance; the vertices on model edges and corners (tagged with those) are located by distance.
  CHECK(by_file.by_file > by_file.vertices / 2);
  CHECK(by_file.by_file < by_file.vertices);
  CHECK(by_file.file_mismatches == 0);
  CHECK(by_file.located.size() == static_cast<std::size_t>(by_file.by_file));
  CHECK(by_file.entities == by_distance.entities);
  CHECK(by_distance.by_file == 0);
  CHECK(describe_cad_matches({by_file}).find("located by the file's entity tags") != std::string::npos);
  for (const auto& [x, on] : by_file.located) {
    const CadPoint closest = sphere.closest_point(2, on.index, x);
    CHECK((on.point - closest.point).norm() < 1e-9 * sphere.diagonal());
  }
  // The curved mesh is the same either way.
  CurveOptions<3> options;
  options.sliding = {"20"};
  options.geometry.insert_or_assign("7", cad_boundary<3>(sphere, by_file));
  const CurveResult<3> a = curve_mesh(with_params, options);
  options.geometry.insert_or_assign("7", cad_boundary<3>(sphere, by_distance));
  const CurveResult<3> b = curve_mesh(without, options);
  CHECK((a.curved.points - b.curved.points).cwiseAbs().maxCoeff() < 1e-9);

  // Tags that name another face (a mesh made on another model, or numbered otherwise): those
  // vertices are located by distance, and said so.
  Mesh<3> renumbered = with_params;
  Index changed = 0;
  for (auto& p : renumbered.node_params)
    if (p.entity_dim == 2 && p.entity_tag == by_file.located.front().second.index) {
      p.entity_tag = p.entity_tag % sphere.num_faces() + 1;
      ++changed;
    }
  REQUIRE(changed > 0);
  const auto mismatched = match_cad_groups(renumbered, sphere, 0.0, {"7"}).front();
  INFO(describe_cad_matches({mismatched}));
  CHECK(mismatched.file_mismatches > 0);
  CHECK(mismatched.by_file + mismatched.file_mismatches == by_file.by_file);
  CHECK(mismatched.entities == by_distance.entities);
  CHECK(describe_cad_matches({mismatched}).find("do not fit the model") != std::string::npos);
}

TEST_CASE("CAD: the local search from nearby parameters finds the face's closest point", "[cad]") {
  MESHMOTION_REQUIRE_DATA(sphere_mesh, "meshopt_sphere_symmetry_linear_tet.msh");
  MESHMOTION_REQUIRE_DATA(sphere_step, "meshopt_Sphere25CSymmetry.stp");
  const CadModel sphere = CadModel::read(sphere_step);
  const auto match = match_cad_groups(read_mesh_as<3>(sphere_mesh), sphere, 0.0, {"7"}).front();
  REQUIRE(!match.located.empty());
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> offset(-0.03, 0.03);
  int local = 0;
  for (const auto& [x, on] : match.located) {
    const Vec<3> p = x + Vec<3>(offset(rng), offset(rng), offset(rng));
    const CadPoint global = sphere.closest_point(2, on.index, p);
    const CadPoint near = sphere.closest_point_near(2, on.index, p, on.u, on.v);
    CHECK(near.index == on.index);
    CHECK(near.distance == Approx(global.distance).margin(1e-12));
    CHECK((near.point - global.point).norm() < 1e-9);
    local += (near.point - sphere.point_at(2, on.index, near.u, near.v)).norm() < 1e-12 ? 1 : 0;
    // A start a few cells away: the same closest point (the search or its fallback).
    const CadPoint far = sphere.closest_point_near(2, on.index, p, on.u + 0.3, on.v - 0.2);
    CHECK((far.point - global.point).norm() < 1e-9);
  }
  CHECK(local == static_cast<int>(match.located.size()));
  CHECK_THROWS_WITH(sphere.closest_point_near(2, sphere.num_faces() + 1, Vec<3>::Zero(), 0.0, 0.0), Catch::Contains("no face"));
}

TEST_CASE("CAD: points on a B-spline face and just off it project along the normal", "[cad]") {
  // The sphere's faces are B-splines: a point on one, or pushed a little along the sphere's
  // normal, has that surface point as its closest (found from the face's sample grid, or
  // by the global search farther off, alike).
  MESHMOTION_REQUIRE_DATA(sphere_mesh, "meshopt_sphere_symmetry_linear_tet.msh");
  MESHMOTION_REQUIRE_DATA(sphere_step, "meshopt_Sphere25CSymmetry.stp");
  const CadModel sphere = CadModel::read(sphere_step);
  const auto match = match_cad_groups(read_mesh_as<3>(sphere_mesh), sphere, 0.0, {"7"}).front();
  REQUIRE(match.located.size() > 20);
  // The sphere's centre and radius, fitted: |x|² = 2 c·x + (R² − |c|²) is linear in c and R².
  Eigen::MatrixXd a(static_cast<Index>(match.located.size()), 4);
  Eigen::VectorXd b(a.rows());
  for (Index i = 0; i < a.rows(); ++i) {
    const Vec<3>& x = match.located[static_cast<std::size_t>(i)].second.point;
    a.row(i) << 2.0 * x.transpose(), 1.0;
    b(i) = x.squaredNorm();
  }
  const Eigen::Vector4d fit = a.colPivHouseholderQr().solve(b);
  const Vec<3> centre = fit.head<3>();
  const double radius = std::sqrt(fit(3) + centre.squaredNorm());
  const double scale = sphere.diagonal();
  for (const double push : {0.0, 1e-5, -1e-5, 0.02}) {
    CAPTURE(push);
    for (const auto& [x, on] : match.located) {
      const Vec<3> normal = (on.point - centre).normalized();
      const CadPoint c = sphere.closest_point(2, on.index, on.point + push * scale * normal);
      CHECK((c.point - on.point).norm() < 1e-6 * scale);
      CHECK(c.distance == Approx(std::abs(push) * scale).margin(1e-6 * scale));
      CHECK(std::abs((c.point - centre).norm() - radius) < 1e-5 * radius);
    }
  }
}

TEST_CASE("CAD: arc lengths along a face's isolines, across its seams, in every format", "[cad]") {
  // On the torus of radii 1 and 0.3, an isoline is a circle: the point at a fraction of the
  // arc length between two points is at that fraction of the angle between them, whatever
  // the file's parametrization (IGES's faces mode and NURBS store other ones).
  const auto at = [](double around_axis, double around_tube) {
    return Vec<3>((1.0 + 0.3 * std::cos(around_tube)) * std::cos(around_axis), (1.0 + 0.3 * std::cos(around_tube)) * std::sin(around_axis),
                  0.3 * std::sin(around_tube));
  };
  const double deg = std::acos(-1.0) / 180.0;
  for (const CadFormat format : {CadFormat::brep, CadFormat::iges_faces, CadFormat::nurbs}) {
    const auto file = write_model(tori(), "tori", format);
    INFO(file.filename().string());
    const CadModel model = CadModel::read(file);
    // {fixed parameter's angle, from, to, fraction, expected}: along the tube at angle 0 around
    // the axis (the seam), and around the axis across the seam.
    struct Way {
      Vec<3> from, to, expected;
      double fraction;
    };
    const std::array ways{Way{at(0, 0), at(0, 120 * deg), at(0, 40 * deg), 1.0 / 3.0},
                          Way{at(0, -60 * deg), at(0, 60 * deg), at(0, -30 * deg), 0.25},
                          Way{at(-30 * deg, 50 * deg), at(30 * deg, 50 * deg), at(0, 50 * deg), 0.5}};
    for (const Way& way : ways) {
      const CadPoint a = model.nearest(2, {}, way.from);
      const CadPoint b = model.closest_point(2, a.index, way.to);
      REQUIRE(a.distance < 1e-9);
      REQUIRE(b.distance < 1e-9);
      const std::array<double, 2> period = model.periods(2, a.index);
      const auto unwrapped = [](double value, double reference, double p) { return p > 0.0 ? value + p * std::round((reference - value) / p) : value; };
      const double bu = unwrapped(b.u, a.u, period[0]), bv = unwrapped(b.v, a.v, period[1]);
      const int fixed = std::abs(bu - a.u) < 1e-9 ? 0 : 1;
      REQUIRE(std::abs((fixed == 0 ? bu - a.u : bv - a.v)) < 1e-9);
      const double s = fixed == 0 ? model.isoline_arc_length_parameter(a.index, 0, a.u, a.v, bv, way.fraction)
                                  : model.isoline_arc_length_parameter(a.index, 1, a.v, a.u, bu, way.fraction);
      const Vec<3> x = fixed == 0 ? model.point_at(2, a.index, a.u, s) : model.point_at(2, a.index, s, a.v);
      CHECK((x - way.expected).norm() < 1e-12);
    }
    CHECK_THROWS_WITH(model.isoline_arc_length_parameter(1, 2, 0.0, 0.0, 1.0, 0.5), Catch::Contains("0 (u) or 1 (v)"));
    CHECK_THROWS_WITH(model.isoline_arc_length_parameter(model.num_faces() + 1, 0, 0.0, 0.0, 1.0, 0.5), Catch::Contains("no face"));
  }
}

TEST_CASE("CAD: one model as BREP, STEP, IGES (both modes) and NURBS gives the same curved mesh", "[cad]") {
  // IGES stores a circle as a closed, non-periodic B-spline whose parameter is not the angle,
  // and NURBS conversion makes every curve and surface a B-spline: the placement works on the
  // geometry, not its parametrization, so every file gives the mesh of the BREP to 1e-9, the
  // untangling's rounds included (on these symmetric meshes they choose among cells that tie
  // to round-off, and its search took steps whose gain was at round-off: by round-off, the
  // meshes were 0.05 and 4e-3 apart).
  constexpr std::array formats{CadFormat::step, CadFormat::iges_faces, CadFormat::iges_brep, CadFormat::nurbs};
  const auto compare = [](const auto& curved, const auto& reference, const std::vector<std::string>& groups, double tolerance) {
    REQUIRE(curved.points.cols() == reference.points.cols());
    double boundary = 0.0;
    for (const auto& g : groups)
      for (const Index v : reference.group_nodes(g)) boundary = std::max(boundary, (curved.points.col(v) - reference.points.col(v)).norm());
    CHECK(boundary < tolerance);
    CHECK((curved.points - reference.points).cwiseAbs().maxCoeff() < tolerance);
  };
  OMeshOptions ellipse = small_o_mesh();
  ellipse.semi_axis_y = 0.25;
  for (const double minor : {0.0, 0.25}) {
    const Mesh<2> mesh = o_mesh(minor > 0.0 ? ellipse : small_o_mesh());
    const TopoDS_Shape shape = circles(0.5, 4.0, minor);
    const std::string name = minor > 0.0 ? "ellipse_model" : "circle_model";
    for (const int p : {2, 3}) {
      const auto curve = [&](const CadModel& model) {
        CurveOptions<2> options;
        options.order = p;
        for (const auto& m : match_cad_groups(mesh, model)) {
          CHECK(m.matched());
          options.geometry.insert_or_assign(m.group, cad_boundary<2>(model, m));
        }
        return curve_mesh(mesh, options);
      };
      const CurveResult<2> reference = curve(CadModel::read(write_model(shape, name, CadFormat::brep)));
      REQUIRE(reference.invalid() == 0);
      CHECK(reference.untangle.evaluations > 0);  // the rounds ran
      for (const CadFormat format : formats) {
        // OpenCASCADE's IGES writer stores an ellipse as a polynomial B-spline within 4e-7 of it.
        if (minor > 0.0 && (format == CadFormat::iges_faces || format == CadFormat::iges_brep)) continue;
        const auto file = write_model(shape, name, format);
        INFO(file.filename().string() << ", order " << p);
        const CurveResult<2> curved = curve(CadModel::read(file));
        CHECK(curved.off_geometry() == 0);
        compare(curved.curved, reference.curved, {"wall", "farfield"}, 1e-9);
      }
    }
  }
  const Mesh<3> shell = torus_shell(24, 12, 2);
  const auto curve = [&](const CadModel& model) {
    CurveOptions<3> options;
    options.order = 2;
    for (const auto& m : match_cad_groups(shell, model)) {
      CHECK(m.matched());
      options.geometry.insert_or_assign(m.group, cad_boundary<3>(model, m));
    }
    return curve_mesh(shell, options);
  };
  const CurveResult<3> reference = curve(CadModel::read(write_model(tori(), "tori", CadFormat::brep)));
  REQUIRE(reference.invalid() == 0);
  for (const auto& d : reference.geometry_distance) CHECK(d.max_relative_distance < 1e-2);
  for (const CadFormat format : formats) {
    const auto file = write_model(tori(), "tori", format);
    INFO(file.filename().string());
    const CurveResult<3> curved = curve(CadModel::read(file));
    CHECK(curved.off_geometry() == 0);
    // IGES's faces mode trims each face by curves in its parameters, and OpenCASCADE builds the
    // seams' 3D curves from them, 3e-6 off the torus: the seams' nodes are placed along the
    // torus's isolines, as the exact seam places them.
    compare(curved.curved, reference.curved, {"wall", "outer"}, 1e-9);
  }
}

TEST_CASE("CAD: the curved mesh's .msh places each node on the model as Gmsh numbers it and reads back located", "[cad]") {
  // Every node of a matched group gets the entity it lies on (a face, or an edge of it: seams,
  // ridges, borders) and its parameters there, and every facet its face; the others lie in the
  // domain. The point at those
  // parameters is the node, to round-off, for a periodic model and for IGES's closed B-splines.
  const auto check_on_model = [](const auto& mesh, const CadModel& model, double tolerance = 1e-12) {
    constexpr int dim = std::decay_t<decltype(mesh)>::dim;
    const std::vector<NodeParametrization>& params = mesh.node_params;
    REQUIRE(params.size() == static_cast<std::size_t>(mesh.num_nodes()));
    std::vector<char> on_wall(params.size(), 0);
    for (const auto& block : mesh.facets)
      for (const Index v : block.connectivity) on_wall[static_cast<std::size_t>(v)] = 1;
    double off = 0.0;
    for (std::size_t i = 0; i < params.size(); ++i) {
      const NodeParametrization& p = params[i];
      CHECK((p.entity_dim < dim) == (on_wall[i] != 0));
      if (p.entity_dim == dim) continue;
      Vec<3> x = Vec<3>::Zero();
      x.head<dim>() = mesh.points.col(static_cast<Index>(i));
      off = std::max(off, (model.point_at(p.entity_dim, p.entity_tag, p.u, p.v) - x).norm());
    }
    CHECK(off < tolerance * model.diagonal());
    // Each facet is in the model entity its nodes inside an entity lie in; the cells in one.
    for (const auto& block : mesh.facets) {
      REQUIRE(block.entities.size() == static_cast<std::size_t>(block.size()));
      for (Index e = 0; e < block.size(); ++e) {
        const int entity = block.entities[static_cast<std::size_t>(e)];
        CHECK(entity != 0);
        for (const Index v : block.element(e))
          if (params[static_cast<std::size_t>(v)].entity_dim == dim - 1) CHECK(params[static_cast<std::size_t>(v)].entity_tag == entity);
      }
    }
    for (const auto& block : mesh.cells) CHECK(block.entities == std::vector<int>(static_cast<std::size_t>(block.size()), 1));
  };
  // Written and read back (4.1 and 2.2), the parameters are the same numbers, and a mesh read
  // back is located on the model by them: its face nodes without a search.
  const auto round_trip = [](const auto& mesh, const CadModel& model) {
    using M = std::decay_t<decltype(mesh)>;
    for (const MshVersion version : {MshVersion::v4_1, MshVersion::v2_2}) {
      const auto file = test::scratch_path("on_model.msh");
      write_gmsh(file, mesh, {version, false});
      const M back = read_mesh_as<M::dim>(file);
      for (std::size_t b = 0; b < mesh.facets.size(); ++b) CHECK(back.facets[b].entities == mesh.facets[b].entities);
      for (std::size_t b = 0; b < mesh.cells.size(); ++b) CHECK(back.cells[b].entities == mesh.cells[b].entities);
      REQUIRE(back.node_params.size() == mesh.node_params.size());
      for (std::size_t i = 0; i < back.node_params.size(); ++i) {
        const auto &p = mesh.node_params[i], &q = back.node_params[i];
        REQUIRE(std::tuple{p.entity_dim, p.entity_tag, p.u, p.v} == std::tuple{q.entity_dim, q.entity_tag, q.u, q.v});
      }
      for (const CadGroupMatch& m : match_cad_groups(back, model)) {
        INFO(describe_cad_matches({m}));
        CHECK(m.matched());
        CHECK(m.file_mismatches == 0);
        // Every vertex the file puts inside one of the group's entities (not on an edge of them).
        std::set<Index> inside;
        for (const auto& block : back.facets)
          for (Index e = 0; e < block.size(); ++e)
            if (block.tags[static_cast<std::size_t>(e)] == back.group(m.group).tag)
              for (int k = 0; k < num_vertices(block.type); ++k)
                if (const Index v = block.element(e)[static_cast<std::size_t>(k)]; back.node_params[static_cast<std::size_t>(v)].entity_dim == m.dim)
                  inside.insert(v);
        CHECK(m.by_file > 0);
        CHECK(m.by_file == static_cast<Index>(inside.size()));
      }
    }
  };
  SECTION("2D circles, P3, as BREP and as IGES") {
    const Mesh<2> mesh = o_mesh(small_o_mesh());
    for (const CadFormat format : {CadFormat::brep, CadFormat::iges_brep}) {
      const CadModel model = CadModel::read(write_model(circles(0.5, 4.0), "circle_model", format));
      const auto matches = match_cad_groups(mesh, model);
      CurveResult<2> result = curve_on_model(mesh, model, 3);
      place_on_cad(result.curved, model, matches);
      check_on_model(result.curved, model);
      round_trip(result.curved, model);
    }
  }
  SECTION("3D torus shell, P2: the seams' nodes on the seam edges") {
    const Mesh<3> shell = torus_shell(24, 12, 2);
    for (const CadFormat format : {CadFormat::brep, CadFormat::iges_faces}) {
      const auto file = write_model(tori(), "tori", format);
      INFO(file.filename().string());
      const CadModel model = CadModel::read(file);
      const auto matches = match_cad_groups(shell, model);
      CurveOptions<3> options;
      options.order = 2;
      for (const auto& m : matches) options.geometry.insert_or_assign(m.group, cad_boundary<3>(model, m));
      CurveResult<3> result = curve_mesh(shell, options);
      auto& curved = result.curved;
      place_on_cad(curved, model, matches);
      // IGES's faces mode: OpenCASCADE builds the seams' 3D curves from the faces' parameter
      // curves, within the model's tolerance of the torus (the nodes are on the torus to
      // round-off, 3e-6 from the curve), and some seam nodes are farther than the matching's
      // tolerance from that curve: those stay on the face, which they are on.
      const bool iges_faces = format == CadFormat::iges_faces;
      check_on_model(curved, model, iges_faces ? 1e-6 : 1e-12);
      // The tori's seams are the circles at angle 0 around the axis and around the tube.
      Index on_seam = 0;
      for (Index v = 0; v < curved.num_nodes(); ++v) {
        const Vec<3> x = curved.points.col(v);
        const double theta = std::atan2(x[1], x[0]), phi = std::atan2(x[2], std::hypot(x[0], x[1]) - 1.0);
        const bool seam = std::abs(theta) < 1e-9 || std::abs(phi) < 1e-9;
        const int entity_dim = curved.node_params[static_cast<std::size_t>(v)].entity_dim;
        if (entity_dim == 3) continue;
        INFO("node " << v << " at theta " << theta << ", phi " << phi);
        if (entity_dim == 1) CHECK(seam);
        if (!iges_faces) CHECK((entity_dim == 1) == seam);
        on_seam += seam ? 1 : 0;
      }
      CHECK(on_seam == 2 * (2 * 24 + 2 * 12 - 1));  // two tori, each two seams at P2 less their common node
      round_trip(curved, model);
    }
  }
  SECTION("the sphere's Gmsh mesh: its vertices get the file's own entities and places") {
    MESHMOTION_REQUIRE_DATA(sphere_mesh, "meshopt_sphere_symmetry_linear_tet.msh");
    MESHMOTION_REQUIRE_DATA(sphere_step, "meshopt_Sphere25CSymmetry.stp");
    const CadModel sphere = CadModel::read(sphere_step);
    const Mesh<3> linear = read_mesh_as<3>(sphere_mesh);
    const auto matches = match_cad_groups(linear, sphere);
    CurveOptions<3> options;
    options.sliding = {"20"};
    for (const auto& m : matches)
      if (m.group == "7") options.geometry.insert_or_assign(m.group, cad_boundary<3>(sphere, m));
    CurveResult<3> result = curve_mesh(linear, options);
    place_on_cad(result.curved, sphere, matches);
    check_on_model(result.curved, sphere);
    const auto& params = result.curved.node_params;
    Index compared = 0;
    for (Index v = 0; v < linear.num_nodes(); ++v) {
      const NodeParametrization &file = linear.node_params[static_cast<std::size_t>(v)], &ours = params[static_cast<std::size_t>(v)];
      INFO("node " << v << " in the file on (" << file.entity_dim << ", " << file.entity_tag << "), ours (" << ours.entity_dim
                   << ", " << ours.entity_tag << ")");
      if (file.entity_dim == 0) {  // a model vertex: we give it an edge ending there
        CHECK(ours.entity_dim == 1);
        continue;
      }
      REQUIRE(ours.entity_dim == file.entity_dim);
      // (the symmetry plane's nodes slide in it)
      if (file.entity_dim == 3 || (result.curved.points.col(v) - linear.points.col(v)).norm() > 0.0) continue;
      CHECK(ours.entity_tag == file.entity_tag);
      CHECK((sphere.point_at(ours.entity_dim, ours.entity_tag, ours.u, ours.v) -
             sphere.point_at(file.entity_dim, file.entity_tag, file.u, file.v)).norm() < 1e-9 * sphere.diagonal());
      ++compared;
    }
    CHECK(compared > 300);  // the wall's and the box's (396)
  }
}
