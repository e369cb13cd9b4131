// The CAD component: models read through OpenCASCADE, closest points, group matching, the
// parametric placement of high-order nodes, and curve_mesh on CAD geometry at orders 2 to 4.
#include "meshmotion/cad/cad_model.hpp"
#include "meshmotion/core/generators.hpp"
#include "meshmotion/curving/curve_mesh.hpp"
#include "meshmotion/io/mesh_io.hpp"

#include "test_data.hpp"

#include <catch2/catch.hpp>

#include <BRepBuilderAPI_MakeEdge.hxx>
#include <BRepPrimAPI_MakeSphere.hxx>
#include <BRepTools.hxx>
#include <BRep_Builder.hxx>
#include <Message.hxx>
#include <Message_Messenger.hxx>
#include <STEPControl_Writer.hxx>
#include <TopoDS_Compound.hxx>
#include <gp_Circ.hxx>

#include <cmath>
#include <fstream>
#include <numbers>
#include <random>

using namespace meshmotion;

namespace {

// Two circles in z = 0 (the wall and farfield of o_mesh()), written as a BREP file.
std::filesystem::path circles_brep(double wall_radius, double farfield_radius) {
  const auto file = test::scratch_path("circles_" + std::to_string(wall_radius) + ".brep");
  BRep_Builder builder;
  TopoDS_Compound compound;
  builder.MakeCompound(compound);
  for (const double r : {wall_radius, farfield_radius})
    builder.Add(compound, BRepBuilderAPI_MakeEdge(gp_Circ(gp_Ax2(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), r)).Edge());
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
    for (int k = 0; k < 20; ++k) {
      const Vec<3> x(coordinate(rng), coordinate(rng), coordinate(rng));
      const CadPoint c = model.nearest(2, {}, x);
      CHECK(std::abs(c.point.norm() - 0.5) < 1e-9 * model.diagonal());
      CHECK(c.distance == Approx(std::abs(x.norm() - 0.5)).margin(1e-9));
      CHECK((model.point_at(2, 1, c.u, c.v) - c.point).norm() < 1e-9);
    }
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
  const CadModel model = CadModel::read(circles_brep(0.5, 4.0));
  for (const int p : {2, 3, 4}) {
    INFO("order " << p);
    CurveOptions<2> options;
    options.order = p;
    for (const auto& m : match_cad_groups(mesh, model)) options.geometry.insert_or_assign(m.group, cad_boundary<2>(model, m));
    const CurveResult<2> curved = curve_mesh(mesh, options);
    CHECK(curved.invalid() == 0);
    const Mesh<2>& c = curved.curved;
    for (const Index v : c.group_nodes("wall")) CHECK(std::abs(c.points.col(v).norm() - 0.5) < 1e-9 * model.diagonal());
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
          CHECK(std::abs(diff) < 1e-12);
          ++checked;
        }
      }
    CHECK(checked == 32 * (p - 1));
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
  for (const int p : {2, 3, 4}) {
    INFO("RAE2822, order " << p);
    CurveOptions<2> options;
    options.order = p;
    for (const auto& m : rae_matches) options.geometry.insert_or_assign(m.group, cad_boundary<2>(rae, m));
    const CurveResult<2> curved = curve_mesh(airfoil, options);
    CHECK(curved.invalid() == 0);
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
    for (const auto& m : sphere_matches)
      if (m.matched()) options.geometry.insert_or_assign(m.group, cad_boundary<3>(sphere, m));
    const CurveResult<3> curved = curve_mesh(volume, options);
    CHECK(curved.invalid() == 0);
    for (const auto& m : sphere_matches)
      if (m.matched())
        for (const Index v : curved.curved.group_nodes(m.group))
          CHECK(sphere.nearest(2, m.entities, Vec<3>(curved.curved.points.col(v))).distance < 1e-9 * sphere.diagonal());
  }
}
