// A solver's own mesh type (MeshLike) goes through the mover registry, the step driver, the
// quality report and the writer, with the results of the library's own Mesh<2> (issue 17).

#include "meshmotion/core/generators.hpp"
#include "meshmotion/core/mesh_like.hpp"
#include "meshmotion/io/mesh_io.hpp"
#include "meshmotion/movers.hpp"
#include "meshmotion/movers/step_driver.hpp"
#include "meshmotion/quality/quality_report.hpp"

#include "test_data.hpp"

#include <catch2/catch.hpp>

#include <vector>

namespace solver_side {
// Node coordinates interleaved, quadrilaterals as an int array.
struct Grid {
  std::vector<double> xy;
  std::vector<int> quads;
};
}  // namespace solver_side

template <>
struct meshmotion::MeshTraits<solver_side::Grid> {
  static constexpr int dim = 2;
  static Index num_nodes(const solver_side::Grid& g) { return static_cast<Index>(g.xy.size() / 2); }
  static double coordinate(const solver_side::Grid& g, Index node, int axis) { return g.xy[static_cast<std::size_t>(2 * node + axis)]; }
  static Index num_cell_blocks(const solver_side::Grid&) { return 1; }
  static ElementType cell_type(const solver_side::Grid&, Index) { return ElementType::quad4; }
  static Index num_cells(const solver_side::Grid& g, Index) { return static_cast<Index>(g.quads.size() / 4); }
  static Index cell_node(const solver_side::Grid& g, Index, Index cell, int local) {
    return g.quads[static_cast<std::size_t>(4 * cell + local)];
  }
};

using namespace meshmotion;

TEST_CASE("a solver's own mesh type through AnyMover, run_steps, quality_report, write_mesh", "[movers]") {
  const Mesh<2> mesh = rectangle_mesh({});
  solver_side::Grid grid;
  grid.xy.assign(mesh.points.data(), mesh.points.data() + mesh.points.size());
  for (const Index v : mesh.cells.front().connectivity) grid.quads.push_back(static_cast<int>(v));

  const QualityReport ours = quality_report(mesh, Metric::shape);
  const QualityReport theirs = quality_report(grid, Metric::shape);
  CHECK(theirs.min == ours.min);
  CHECK(theirs.num_elements == ours.num_elements);

  GroupNodes groups{{"bottom", mesh.group_nodes("bottom")}, {"top", mesh.group_nodes("top")}};
  BoundarySpec<2> spec;
  spec.moving("bottom", Translation<2>{Vec<2>(0.0, 0.05)}).fixed("top");
  AnyMover<2> a = make_mover<2>("rbf", {{"support_radius", "0.6"}});
  AnyMover<2> b = make_mover<2>("rbf", {{"support_radius", "0.6"}});
  const StepResult<2> with_mesh = run_steps(a, mesh, spec, StepOptions{2, Metric::skew}, groups);
  const StepResult<2> with_grid = run_steps(b, grid, spec, StepOptions{2, Metric::skew}, groups);
  CHECK((with_grid.displacements - with_mesh.displacements).cwiseAbs().maxCoeff() == 0.0);

  const ResolvedBoundary<2> resolved = spec.resolve(mesh.points, groups);
  a.setup(mesh, resolved);
  b.setup(grid, resolved);
  CHECK((b.move(resolved.displacements) - a.move(resolved.displacements)).norm() < 1e-15);

  const auto file = test::scratch_path("solver_grid.msh");
  write_mesh(file, grid);
  const Mesh<2> back = read_mesh_as<2>(file);
  CHECK(back.num_cells() == mesh.num_cells());
  CHECK(back.points == mesh.points);
}
