// Meshes past order 4 moved as a solver moves them: every registered method set up once on
// the reference (no displacement yet), then moved from it several times; the wall nodes, the
// high-order ones among them, land where they are sent and every cell stays valid by the
// certified scaled Jacobian. Torsion springs refuse any cell past P1, as at P2. Past P5 the
// methods part: the DGRBF's map is piecewise linear over its Delaunay graph, and a P6 cell
// that a graph edge crosses folds at the kink (14 cells at 8 degrees). The finite-element
// movers take cells of every order (their element matrices on the heap): they and the default
// move hexahedra at P4 and tetrahedra at P5 and P8 below.

#include "meshmotion/core/generators.hpp"
#include "meshmotion/curving/order_conversion.hpp"
#include "meshmotion/movers.hpp"
#include "meshmotion/quality/quality_report.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

using namespace meshmotion;

namespace {

// The largest distance of a boundary node of `moved` from where `boundary` sends it.
template <int Dim>
double largest_miss(const Mesh<Dim>& mesh, const Mesh<Dim>& moved, const ResolvedBoundary<Dim>& boundary) {
  double miss = 0.0;
  for (Index k = 0; k < boundary.size(); ++k) {
    const Index v = boundary.nodes[static_cast<std::size_t>(k)];
    miss = std::max(miss, (moved.points.col(v) - mesh.points.col(v) - boundary.displacements.col(k)).norm());
  }
  return miss;
}

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
          // A refusal is not new past order 4: a method for linear cells (torsion springs)
          // refuses P2 as well.
          INFO(e.what());
          bool refuses_p2 = false;
          try {
            make_mover(mover_config<2>(std::string(method.name))).setup(p2, turned_inner_wall(p2, 0.0));
          } catch (const InputError&) {
            refuses_p2 = true;
          }
          CHECK(refuses_p2);
          continue;
        }
        for (const double degrees : {4.0, 8.0, 12.0}) {
          INFO(degrees << " degrees");
          const ResolvedBoundary<2> turned = turned_inner_wall(mesh, degrees);
          REQUIRE(turned.nodes == reference.nodes);
          Mesh<2> moved = mesh;
          moved.points += mover.move(turned.displacements);
          CHECK(largest_miss(mesh, moved, turned) <= 1e-10);
          const QualityReport q = quality_report(moved, Metric::scaled_jacobian);
          CHECK(q.num_invalid == 0);
          CHECK(q.min > 0.1);
        }
      }
    }
  }
}

namespace {

// The bottom of the unit box raised by a sin(πx) sin(πy): a smooth wall motion, zero on the box's
// edges (not rigid: what a deforming wall sends).
struct Bump {
  double height = 0.0;
  [[nodiscard]] Vec<3> position(const Vec<3>& x, double t = 1.0) const {
    return x + Vec<3>(0.0, 0.0, t * height * std::sin(std::numbers::pi * x.x()) * std::sin(std::numbers::pi * x.y()));
  }
};

ResolvedBoundary<3> raised_bottom(const Mesh<3>& mesh, double height) {
  return BoundarySpec<3>{}.moving("bottom", Bump{height}).fixed("top").fixed("left").fixed("right").fixed("front").fixed("back").resolve(mesh);
}

}  // namespace

TEST_CASE("set up once, the finite-element movers and the default move P4 hexahedra, P5 prisms and pyramids, P5 and P8 tetrahedra, each move certified valid",
          "[movers][high_order]") {
  // The graph methods are left to the rings above: on these lattices of one or two cells across,
  // the Delaunay graph of the high-order nodes (many on one sphere) inverts simplices at once.
  // At P8 (a tet165's certificate is a tenth of a second per cell) one finite-element mover.
  struct Case {
    BoxCells cells;
    Index n;
    int order;
    std::vector<const char*> methods;
  };
  for (const Case& c : {Case{BoxCells::hex8, 2, 4, {"rbf", "le", "sle", "nle"}}, Case{BoxCells::tet4, 2, 5, {"rbf", "le", "sle", "nle"}},
                        Case{BoxCells::prism6, 2, 5, {"rbf", "le", "sle", "nle"}},
                        Case{BoxCells::pyramid5, 1, 5, {"rbf", "le", "sle", "nle"}}, Case{BoxCells::tet4, 1, 8, {"sle"}}}) {
    const Mesh<3> mesh = convert_to_order(box_mesh({c.n, c.n, c.n, 0.0, 1.0, 0.0, 1.0, 0.0, 1.0, c.cells}), c.order).mesh;
    REQUIRE(meshmotion::order(mesh.cells.front().type) == c.order);
    const ResolvedBoundary<3> reference = raised_bottom(mesh, 0.0);
    for (const char* method : c.methods) {
      INFO(name(mesh.cells.front().type) << " " << method);
      AnyMover<3> mover = make_mover(mover_config<3>(method));
      mover.setup(mesh, reference);
      for (const double height : {0.05, 0.15}) {
        INFO("bump " << height);
        const ResolvedBoundary<3> raised = raised_bottom(mesh, height);
        REQUIRE(raised.nodes == reference.nodes);
        Mesh<3> moved = mesh;
        moved.points += mover.move(raised.displacements);
        CHECK(largest_miss(mesh, moved, raised) <= 1e-10);
        const QualityReport q = quality_report(moved, Metric::scaled_jacobian);
        CHECK(q.num_invalid == 0);
        CHECK(q.min > 0.5);
      }
    }
  }
}
