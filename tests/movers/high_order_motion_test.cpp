// Meshes past order 4 moved as a solver moves them: every registered method set up once on
// the reference (no displacement yet), then moved from it several times; the wall nodes, the
// high-order ones among them, land where they are sent and every cell stays valid by the
// certified scaled Jacobian. Torsion springs refuse any cell past P1, as at P2. Past P5 the
// methods part: the DGRBF's map is piecewise linear over its Delaunay graph, and a P6 cell
// that a graph edge crosses folds at the kink (14 cells at 8 degrees); the finite-element
// movers take cells of up to 40 nodes (quad49 and up are refused by name).

#include "meshmotion/core/generators.hpp"
#include "meshmotion/curving/order_conversion.hpp"
#include "meshmotion/movers.hpp"
#include "meshmotion/movers/detail/fem_assembly.hpp"
#include "meshmotion/quality/quality_report.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <string>

using namespace meshmotion;

namespace {

ResolvedBoundary<2> turned_inner_wall(const Mesh<2>& mesh, double degrees) {
  return BoundarySpec<2>{}.moving("inner", Rotation2D{{0.0, 0.0}, radians(degrees)}).fixed("outer").resolve(mesh);
}

}  // namespace

TEST_CASE("set up once, every method moves P5 rings of triangles and quadrilaterals, each move certified valid",
          "[movers][high_order]") {
  for (const bool triangles : {false, true}) {
    const Mesh<2> ring = annulus_mesh(
        {.n_around = 24, .inner_first_height = 0.02, .outer_first_height = 0.05, .core_spacing = 0.12, .triangles = triangles});
    const Mesh<2> p2 = convert_to_order(ring, 2).mesh;
    {
      constexpr int order = 5;
      const Mesh<2> mesh = convert_to_order(ring, order).mesh;
      REQUIRE(meshmotion::order(mesh.cells.front().type) == order);
      const ResolvedBoundary<2> reference = turned_inner_wall(mesh, 0.0);
      for (const auto& method : mover_methods<2>()) {
        if (!method.moves_interior) continue;  // the boundary alone moves: it folds the first layer by design
        INFO((triangles ? "triangles" : "quadrilaterals") << " P" << order << " " << method.name);
        AnyMover<2> mover = make_mover(mover_config<2>(std::string(method.name)));
        try {
          mover.setup(mesh, reference);
        } catch (const InputError& e) {
          // A refusal names its reason and is not new past order 4: the finite-element movers
          // keep an element matrix on the stack and take cells of up to 40 nodes; a method
          // for linear cells (torsion springs) refuses P2 as well.
          INFO(e.what());
          bool refuses_p2 = false;
          try {
            make_mover(mover_config<2>(std::string(method.name))).setup(p2, turned_inner_wall(p2, 0.0));
          } catch (const InputError&) {
            refuses_p2 = true;
          }
          const bool too_large = num_nodes(mesh.cells.front().type) > detail::max_cell_nodes &&
                                 std::string(e.what()).find("take cells of up to 40 nodes") != std::string::npos;
          CHECK((too_large || refuses_p2));
          continue;
        }
        for (const double degrees : {4.0, 8.0, 12.0}) {
          INFO(degrees << " degrees");
          const ResolvedBoundary<2> turned = turned_inner_wall(mesh, degrees);
          REQUIRE(turned.nodes == reference.nodes);
          Mesh<2> moved = mesh;
          moved.points += mover.move(turned.displacements);
          double off_target = 0.0;
          for (Index k = 0; k < turned.size(); ++k) {
            const Index v = turned.nodes[static_cast<std::size_t>(k)];
            off_target = std::max(off_target, (moved.points.col(v) - mesh.points.col(v) - turned.displacements.col(k)).norm());
          }
          CHECK(off_target <= 1e-10);
          const QualityReport q = quality_report(moved, Metric::scaled_jacobian);
          CHECK(q.num_invalid == 0);
          CHECK(q.min > 0.1);
        }
      }
    }
  }
}
