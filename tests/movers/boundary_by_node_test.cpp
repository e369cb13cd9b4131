// Displacements given with their nodes (issue 17): a solver's own marker order must give the
// same wall as the sorted order, and every kind of bad node list is refused, naming the node.

#include "meshmotion/core/generators.hpp"
#include "meshmotion/core/mesh_like.hpp"
#include "meshmotion/io/openfoam_polymesh.hpp"
#include "meshmotion/movers.hpp"
#include "meshmotion/movers/boundary.hpp"
#include "meshmotion/movers/rbf.hpp"
#include "meshmotion/movers/step_driver.hpp"

#include "messages.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <random>
#include <utility>

using namespace meshmotion;

namespace {

template <class F>
std::string input_error_of(F&& f) {
  return test::message_of<InputError>(std::forward<F>(f));
}

// A 0-to-0.05 ramp in y along the bottom wall, node by node, in a shuffled (solver's) order.
struct Ramp {
  std::vector<Index> nodes;
  Points<2> displacements;
};
Ramp shuffled_ramp(const Mesh<2>& mesh) {
  Ramp r{mesh.group_nodes("bottom"), {}};
  std::shuffle(r.nodes.begin(), r.nodes.end(), std::mt19937(5));
  r.displacements.setZero(2, static_cast<Index>(r.nodes.size()));
  for (std::size_t k = 0; k < r.nodes.size(); ++k) r.displacements(1, static_cast<Index>(k)) = 0.05 * mesh.points(0, r.nodes[k]);
  return r;
}

}  // namespace

TEST_CASE("displacements by node: any order gives the intended wall", "[movers][boundary]") {
  const Mesh<2> mesh = rectangle_mesh({});
  const Ramp ramp = shuffled_ramp(mesh);
  BoundarySpec<2> spec;
  spec.moving("bottom", ramp.nodes, ramp.displacements).fixed("top");
  const ResolvedBoundary<2> b = spec.resolve(mesh);
  for (std::size_t k = 0; k < ramp.nodes.size(); ++k)
    CHECK(b.displacements.col(b.column(ramp.nodes[k])) == ramp.displacements.col(static_cast<Index>(k)));

  // The same array through the sorted-order overload is the silent wrong wall this API avoids.
  BoundarySpec<2> sorted;
  sorted.moving("bottom", ramp.displacements).fixed("top");
  const ResolvedBoundary<2> wrong = sorted.resolve(mesh);
  double largest = 0.0;
  for (std::size_t k = 0; k < ramp.nodes.size(); ++k)
    largest = std::max(largest, (wrong.displacements.col(wrong.column(ramp.nodes[k])) - ramp.displacements.col(static_cast<Index>(k))).norm());
  CHECK(largest > 0.01);

  // The moved wall is the ramp exactly; steps split it linearly.
  RbfOptions o;
  o.support_radius = 0.5;
  RbfMover<2> rbf(o);
  const StepResult<2> r = run_steps(rbf, mesh, spec, StepOptions{2, Metric::skew});
  for (std::size_t k = 0; k < ramp.nodes.size(); ++k)
    CHECK((r.displacements.col(ramp.nodes[k]) - ramp.displacements.col(static_cast<Index>(k))).norm() < 1e-14);
}

TEST_CASE("displacements by node: bad node lists are refused, naming the node", "[movers][boundary]") {
  const Mesh<2> mesh = rectangle_mesh({});
  Ramp ramp = shuffled_ramp(mesh);
  const auto resolve = [&](std::vector<Index> nodes, Points<2> d) {
    BoundarySpec<2> spec;
    spec.moving("bottom", std::move(nodes), std::move(d));
    (void)spec.resolve(mesh);
  };
  CHECK_NOTHROW(resolve(ramp.nodes, ramp.displacements));
  auto nodes = ramp.nodes;
  nodes[3] = mesh.num_nodes() + 7;
  CHECK_THAT(input_error_of([&] { resolve(nodes, ramp.displacements); }),
             Catch::Contains("node " + std::to_string(mesh.num_nodes() + 7)) && Catch::Contains("not a node of the mesh"));
  const Index top_node = mesh.group_nodes("top").front();
  nodes = ramp.nodes;
  nodes[3] = top_node;
  CHECK_THAT(input_error_of([&] { resolve(nodes, ramp.displacements); }),
             Catch::Contains("node " + std::to_string(top_node)) && Catch::Contains("not in the group"));
  nodes = ramp.nodes;
  nodes[3] = nodes[4];
  CHECK_THAT(input_error_of([&] { resolve(nodes, ramp.displacements); }),
             Catch::Contains("node " + std::to_string(nodes[4])) && Catch::Contains("twice"));
  nodes = ramp.nodes;
  nodes.pop_back();
  CHECK_THAT(input_error_of([&] { resolve(nodes, ramp.displacements.leftCols(ramp.displacements.cols() - 1)); }),
             Catch::Contains("node " + std::to_string(ramp.nodes.back())) && Catch::Contains("no displacement"));
  CHECK_THROWS_AS(resolve(ramp.nodes, ramp.displacements.leftCols(2)), InputError);  // sizes differ
  Points<2> nan = ramp.displacements;
  nan(0, 2) = std::nan("");
  CHECK_THAT(input_error_of([&] { resolve(ramp.nodes, nan); }), Catch::Contains("non-finite"));
}

TEST_CASE("a group given two conditions is refused, groups sharing nodes say which condition wins", "[movers][boundary]") {
  const Mesh<2> mesh = rectangle_mesh({});
  BoundarySpec<2> twice;
  twice.moving("bottom", Translation<2>{Vec<2>(0.0, 0.1)}).fixed("top").fixed("bottom");
  CHECK_THAT(input_error_of([&] { (void)twice.resolve(mesh); }),
             Catch::Contains("group 'bottom' is given twice (prescribed and fixed)"));

  // The bottom moves, the left and top sides are fixed, the right side slides: each corner
  // is in two groups, and the strongest condition wins (prescribed, fixed, sliding).
  BoundarySpec<2> spec;
  spec.moving("bottom", Translation<2>{Vec<2>(0.0, 0.1)}).fixed("left").sliding("right").fixed("top");
  const auto overlaps = spec.overlaps(mesh);
  const auto find = [&](const std::string& winner, const std::string& other) {
    for (const auto& o : overlaps)
      if (o.winner == winner && o.other == other) return o.nodes;
    return Index{-1};
  };
  CHECK(overlaps.size() == 3);  // left and top are both fixed: no conflict to report
  CHECK(find("bottom", "left") == 1);
  CHECK(find("bottom", "right") == 1);
  CHECK(find("top", "right") == 1);
  const ResolvedBoundary<2> b = spec.resolve(mesh);
  const std::vector<Index> left = mesh.group_nodes("left");
  const Index corner = mesh.group_nodes("bottom").front();
  REQUIRE(std::binary_search(left.begin(), left.end(), corner));
  CHECK(b.kinds[static_cast<std::size_t>(b.column(corner))] == BoundaryKind::prescribed);
  CHECK(b.displacements.col(b.column(corner)).isApprox(Vec<2>(0.0, 0.1)));
}

TEST_CASE("prescribed group: displacements given to move() by node", "[movers][boundary]") {
  const Mesh<2> mesh = rectangle_mesh({});
  const Ramp ramp = shuffled_ramp(mesh);
  BoundarySpec<2> spec;
  spec.prescribed("bottom").fixed("top").sliding("left").sliding("right");
  const ResolvedBoundary<2> b = spec.resolve(mesh);
  CHECK(b.displacements.isZero());
  Points<2> d;
  b.scatter(ramp.nodes, ramp.displacements, d);
  REQUIRE(d.cols() == b.size());
  for (std::size_t k = 0; k < ramp.nodes.size(); ++k)
    CHECK(d.col(b.column(ramp.nodes[k])) == ramp.displacements.col(static_cast<Index>(k)));
  RbfOptions o;
  o.support_radius = 0.5;
  AnyMover<2> mover = make_mover(MoverConfig<2>{"rbf", o});
  mover.setup(mesh, b);
  // Into the caller's own storage: an Eigen::Map over a solver's array.
  std::vector<double> solver_array(static_cast<std::size_t>(2 * mesh.num_nodes()), -1.0);
  Eigen::Map<Points<2>> out(solver_array.data(), 2, mesh.num_nodes());
  mover.move_into(d, out);
  for (std::size_t k = 0; k < ramp.nodes.size(); ++k)
    CHECK((out.col(ramp.nodes[k]) - ramp.displacements.col(static_cast<Index>(k))).norm() < 1e-14);
  std::vector<double> short_array(4);
  Eigen::Map<Points<2>> too_small(short_array.data(), 2, 2);
  CHECK_THROWS_AS(mover.move_into(d, too_small), InputError);

  const Index fixed = mesh.group_nodes("top")[2];
  CHECK_THAT(input_error_of([&] { b.scatter({fixed}, Points<2>::Zero(2, 1), d); }), Catch::Contains("fixed"));
  CHECK_THAT(input_error_of([&] { b.scatter({ramp.nodes[0], ramp.nodes[0]}, Points<2>::Zero(2, 2), d); }),
             Catch::Contains("twice"));
  Index interior = 0;
  while (std::binary_search(b.nodes.begin(), b.nodes.end(), interior)) ++interior;
  CHECK_THAT(input_error_of([&] { (void)b.column(interior); }), Catch::Contains("not a boundary node"));
}

TEST_CASE("boundary messages name a node by the file's id too, where the file numbers it otherwise", "[movers][boundary]") {
  Mesh<2> mesh = rectangle_mesh({});
  const Ramp ramp = shuffled_ramp(mesh);
  const Index top_node = mesh.group_nodes("top").front();
  std::vector<Index> nodes = ramp.nodes;
  nodes[3] = top_node;
  const auto message = [&] {
    return input_error_of([&] {
      BoundarySpec<2> spec;
      spec.moving("bottom", nodes, ramp.displacements);
      (void)spec.resolve(mesh);
    });
  };
  // A .msh numbers from 1: the user's id is the index + 1.
  CHECK_THAT(message(), Catch::Contains("node " + std::to_string(top_node) + " (id " + std::to_string(top_node + 1) +
                                        " in the file) is not in the group"));
  // SU2 and OpenFOAM number from 0: index and id agree, and only one is given.
  mesh.first_node_id = 0;
  CHECK_THAT(message(), Catch::Contains("node " + std::to_string(top_node) + " is not in the group"));
  mesh.node_ids.resize(static_cast<std::size_t>(mesh.num_nodes()));
  for (Index i = 0; i < mesh.num_nodes(); ++i) mesh.node_ids[static_cast<std::size_t>(i)] = 1000 + 3 * i;
  CHECK_THAT(message(), Catch::Contains("(id " + std::to_string(1000 + 3 * top_node) + " in the file)"));

  // Two prescribed groups giving a shared node different displacements.
  mesh.node_ids.clear();
  mesh.first_node_id = 1;
  const Index corner = mesh.group_nodes("left").front();
  BoundarySpec<2> clash;
  clash.moving("left", Translation<2>{Vec<2>(0.1, 0.0)}).moving("bottom", Translation<2>{Vec<2>(0.0, 0.1)});
  CHECK_THAT(input_error_of([&] { (void)clash.resolve(mesh); }),
             Catch::Contains("node " + std::to_string(corner) + " (id " + std::to_string(corner + 1) + " in the file) gets two"));
}

TEST_CASE("file node ids map to node indices", "[movers][boundary]") {
  Mesh<2> mesh = rectangle_mesh({});
  const std::vector<std::int64_t> ids{1, 5, 3};
  CHECK(mesh.node_indices(ids) == std::vector<Index>{0, 4, 2});
  CHECK_THROWS_AS(mesh.node_indices(std::vector<std::int64_t>{0}), InputError);
  mesh.node_ids.resize(static_cast<std::size_t>(mesh.num_nodes()));
  for (Index i = 0; i < mesh.num_nodes(); ++i) mesh.node_ids[static_cast<std::size_t>(i)] = 1000 - 3 * i;
  CHECK(mesh.node_indices(std::vector<std::int64_t>{1000, 997, 1000 - 3 * (mesh.num_nodes() - 1)}) ==
        std::vector<Index>{0, 1, mesh.num_nodes() - 1});
  CHECK_THAT(input_error_of([&] { (void)mesh.node_indices(std::vector<std::int64_t>{999}); }), Catch::Contains("999"));
}

TEST_CASE("a name of several groups, an OpenFOAM patch group or a pattern, gives each group its condition", "[movers][boundary]") {
  Mesh<2> mesh = rectangle_mesh({});
  for (auto& g : mesh.groups)
    if (g.name == "left" || g.name == "right") g.in_groups = {"sides"};
  // Each side slides on its own line: taken as one group, the two sides are not one line.
  const ResolvedBoundary<2> expected =
      BoundarySpec<2>{}.moving("top", Translation<2>{{0.1, 0.0}}).fixed("bottom").sliding("left").sliding("right").resolve(mesh);
  for (const std::string sides : {"sides", "(left|right)", "[lr].*t"}) {
    INFO(sides);
    const BoundarySpec<2> spec = BoundarySpec<2>{}.moving("top", Translation<2>{{0.1, 0.0}}).fixed("bottom").sliding(sides);
    const ResolvedBoundary<2> b = spec.resolve(mesh);
    CHECK(b.nodes == expected.nodes);
    CHECK(b.kinds == expected.kinds);
    CHECK(b.normals == expected.normals);
    CHECK(b.displacements == expected.displacements);
    CHECK(spec.overlaps(mesh).size() == 4);  // each corner: top or bottom over a side
  }
  CHECK_THAT(input_error_of([&] { (void)BoundarySpec<2>{}.moving("(top|bottom)", Points<2>::Zero(2, 11)).resolve(mesh); }),
             Catch::Contains("'(top|bottom)' names 2 groups but is given one displacement array"));
  CHECK_THAT(input_error_of([&] { (void)BoundarySpec<2>{}.fixed("(top|bottom").resolve(mesh); }),
             Catch::Contains("'(' is not closed"));
  CHECK_THAT(input_error_of([&] { (void)BoundarySpec<2>{}.fixed("inlet.*").resolve(mesh); }),
             Catch::Contains("no group named 'inlet.*'"));
  // A pattern naming a group twice over is the same group given twice.
  CHECK_THAT(input_error_of([&] { (void)BoundarySpec<2>{}.fixed("(top|bottom)").sliding("top").resolve(mesh); }),
             Catch::Contains("group 'top' is given twice"));
}


TEST_CASE("displacements by node: a polyhedral mesh's auxiliary centres take their face's or cell's mean", "[movers][boundary]") {
  // A box's cells cut into tetrahedra around the centres of their faces and cells, as a
  // polyhedral OpenFOAM case is: the user gives the displacements of the box's own points.
  const Mesh<3> mesh = to_mesh(to_polymesh(box_mesh({.nx = 3, .ny = 2, .nz = 2})), true);
  REQUIRE(mesh.num_auxiliary_nodes > 0);
  const Index first_auxiliary = mesh.num_nodes() - mesh.num_auxiliary_nodes;
  const Rotation3D turn{Vec<3>(0.5, 0.5, 0.5), Vec<3>(0.3, -0.2, 1.0), 0.2};
  const auto motion_at = [&](const Vec<3>& x) -> Vec<3> { return turn.position(x) - x; };
  const auto given_for = [&](const std::vector<Index>& group) {
    std::pair<std::vector<Index>, Points<3>> out;
    for (const Index v : group)
      if (v < first_auxiliary) out.first.push_back(v);
    out.second.resize(3, static_cast<Index>(out.first.size()));
    for (std::size_t k = 0; k < out.first.size(); ++k)
      out.second.col(static_cast<Index>(k)) = motion_at(mesh.points.col(out.first[k]));
    return out;
  };
  const std::vector<Index> bottom = mesh.group_nodes("bottom");
  auto [nodes, d] = given_for(bottom);
  REQUIRE(nodes.size() < bottom.size());  // the bottom's face centres are left out
  BoundarySpec<3> spec;
  spec.moving("bottom", nodes, d);
  const ResolvedBoundary<3> r = spec.resolve(mesh);
  // Affine: the centres' mean is the motion at the centre.
  for (const Index v : bottom)
    CHECK((r.displacements.col(r.column(v)) - motion_at(mesh.points.col(v))).norm() < 1e-14);
  // A centre whose face has a point without a displacement stays missing.
  nodes.erase(nodes.begin());
  d = Points<3>(d.rightCols(d.cols() - 1));
  BoundarySpec<3> short_one;
  short_one.moving("bottom", nodes, d);
  CHECK_THAT(input_error_of([&] { (void)short_one.resolve(mesh); }), Catch::Contains("has no displacement"));
}
