// The untangling stage: tangled curved cells made valid by moving the nodes inside the
// domain around them, boundary nodes kept, the certified result never worse than the input.
#include "meshmotion/core/generators.hpp"
#include "meshmotion/core/topology.hpp"
#include "meshmotion/curving/curve_mesh.hpp"
#include "meshmotion/curving/order_conversion.hpp"
#include "meshmotion/curving/untangle.hpp"
#include "meshmotion/quality/cell_quality.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <random>
#include <vector>

using namespace meshmotion;

namespace {

// A square of 8 × 8 cells at order p whose high-order nodes inside the domain were shaken by
// up to 60% of the node spacing (a regularization gone wrong): tangled cells everywhere, the
// boundary intact.
Mesh<2> shaken_mesh(RectangleCells cells, int p, std::vector<char>& fixed, double share = 0.6) {
  const Mesh<2> linear = rectangle_mesh({.nx = 8, .ny = 8, .cells = cells});
  Mesh<2> m = to_order(linear, p);
  fixed.assign(static_cast<std::size_t>(m.num_nodes()), 0);
  for (const auto& b : boundary_facets(m))
    for (const Index v : b.connectivity) fixed[static_cast<std::size_t>(v)] = 1;
  std::mt19937 rng(1);
  const double amplitude = share * 0.125 / p;
  std::uniform_real_distribution<double> shake(-amplitude, amplitude);
  for (Index v = linear.num_nodes(); v < m.num_nodes(); ++v)
    if (!fixed[static_cast<std::size_t>(v)])
      for (int d = 0; d < 2; ++d) m.points(d, v) += shake(rng);
  return m;
}

// A boundary-layer O-mesh whose first layer is thinner than the sagitta of its wall's arcs.
Mesh<2> thin_layer_mesh() {
  OMeshOptions o;
  o.n_around = 24;
  o.n_radial = 12;
  o.first_height = 2e-3;
  o.farfield_radius = 4.0;
  return o_mesh(o);
}

}  // namespace

TEST_CASE("untangling turns a tangled curved mesh valid, keeping its boundary", "[curving]") {
  std::vector<char> fixed;
  Mesh<2> m = shaken_mesh(RectangleCells::tri3, 2, fixed);
  const Mesh<2> before = m;
  std::vector<double> quality = cell_quality(m, Metric::scaled_jacobian);
  UntangleOptions options;
  options.max_sweeps = 100;
  const UntangleReport report = untangle(m, fixed, quality, options);
  INFO("invalid " << report.invalid_before << " -> " << report.invalid_after << ", min " << report.min_before << " -> "
                  << report.min_after << ", " << report.free_nodes << " free nodes, " << report.sweeps << " sweeps");
  REQUIRE(report.invalid_before > 50);
  CHECK(report.invalid_after == 0);
  CHECK(report.min_after > 0.0);
  CHECK(!report.reverted);
  // The values it reports are the certified ones of the mesh it leaves.
  const auto certified = cell_quality(m, Metric::scaled_jacobian);
  for (std::size_t c = 0; c < quality.size(); ++c) CHECK(quality[c] == Approx(certified[c]).margin(1e-12));
  for (Index v = 0; v < m.num_nodes(); ++v)
    if (fixed[static_cast<std::size_t>(v)]) CHECK(m.points.col(v) == before.points.col(v));
}

TEST_CASE("untangling never leaves a mesh worse than it found it", "[curving]") {
  // Quadrilaterals and orders 3 and 4: the node-by-node search lifts some cells, not all; the
  // certified count and minimum never get worse (a worse result is undone).
  for (const RectangleCells cells : {RectangleCells::quad4, RectangleCells::tri3})
    for (const int p : {2, 3, 4}) {
      INFO("order " << p << (cells == RectangleCells::quad4 ? " quadrilaterals" : " triangles"));
      std::vector<char> fixed;
      Mesh<2> m = shaken_mesh(cells, p, fixed);
      std::vector<double> quality = cell_quality(m, Metric::scaled_jacobian);
      const UntangleReport report = untangle(m, fixed, quality, {});
      CHECK(report.invalid_after <= report.invalid_before);
      CHECK(report.min_after >= report.min_before);
      const auto certified = cell_quality(m, Metric::scaled_jacobian);
      CHECK(*std::min_element(certified.begin(), certified.end()) == Approx(report.min_after));
    }
}

TEST_CASE("untangling: nothing below the threshold, nothing moves, switched off, nothing moves", "[curving]") {
  std::vector<char> fixed;
  Mesh<2> m = shaken_mesh(RectangleCells::tri3, 2, fixed);
  const Mesh<2> before = m;
  std::vector<double> quality = cell_quality(m, Metric::scaled_jacobian);
  UntangleOptions off;
  off.enabled = false;
  CHECK(untangle(m, fixed, quality, off).sweeps == 0);
  CHECK(m.points == before.points);
  UntangleOptions low;
  low.threshold = -1e9;
  low.raise_rounds = 0;
  CHECK(untangle(m, fixed, quality, low).cells_below == 0);
  CHECK(m.points == before.points);
  UntangleOptions no_budget = low;
  no_budget.raise_rounds = 4;
  no_budget.raise_budget = 0.0;
  CHECK(untangle(m, fixed, quality, no_budget).evaluations == 0);
  CHECK(m.points == before.points);
  std::vector<double> short_quality(3, 1.0);
  CHECK_THROWS_WITH(untangle(m, fixed, short_quality, {}), Catch::Contains("3 cell values"));
}

TEST_CASE("the pipeline untangles after the regularization and reports it", "[curving]") {
  const Mesh<2> linear = thin_layer_mesh();
  CurveOptions<2> options;
  options.order = 3;
  options.geometry.emplace("wall", BoundaryGeometry<2>::project(SphereProjection<2>(Vec<2>::Zero(), 0.5)));
  options.method = "rbf";
  options.support_radius = 0.003;  // a support inside the first layers: the regularization alone leaves tangles
  options.untangle.enabled = false;
  const CurveResult<2> plain = curve_mesh(linear, options);
  REQUIRE(plain.invalid() > 0);
  CHECK(plain.untangle.sweeps == 0);
  options.untangle.enabled = true;
  const CurveResult<2> untangled = curve_mesh(linear, options);
  CHECK(untangled.untangle.cells_below > 0);
  CHECK(untangled.untangle.invalid_before == plain.invalid());
  CHECK(untangled.invalid() == untangled.untangle.invalid_after);
  CHECK(untangled.invalid() <= plain.invalid());
  CHECK(untangled.quality.min == untangled.untangle.min_after);
  CHECK(untangled.quality.min >= plain.quality.min);
}

TEST_CASE("raising the worst cells lifts the certified minimum of a valid mesh, boundary kept", "[curving]") {
  // Shaken by 15% of the spacing at P2, 5% at P3: valid everywhere, with a few poor cells.
  for (const int p : {2, 3}) {
    INFO("order " << p);
    std::vector<char> fixed;
    Mesh<2> m = shaken_mesh(RectangleCells::tri3, p, fixed, p == 2 ? 0.15 : 0.05);
    const Mesh<2> before = m;
    std::vector<double> quality = cell_quality(m, Metric::scaled_jacobian);
    REQUIRE(*std::min_element(quality.begin(), quality.end()) > 0.1);  // nothing to untangle
    const UntangleReport report = untangle(m, fixed, quality, {});
    INFO("min " << report.min_before << " -> " << report.min_after << " in " << report.raise_rounds << " rounds, "
                << report.evaluations << " evaluations");
    CHECK(report.cells_below == 0);
    CHECK(report.raise_rounds >= 1);
    CHECK(report.min_after > report.min_before + 0.02);
    // Within its budget: 4 evaluations per cell, and a node's last search may overrun it.
    CHECK(report.evaluations <= 4 * m.num_cells() + 200);
    const auto certified = cell_quality(m, Metric::scaled_jacobian);
    CHECK(*std::min_element(certified.begin(), certified.end()) == Approx(report.min_after).margin(1e-12));
    for (Index v = 0; v < m.num_nodes(); ++v)
      if (fixed[static_cast<std::size_t>(v)]) CHECK(m.points.col(v) == before.points.col(v));
  }
}
