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
#include <array>
#include <map>
#include <random>
#include <set>
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
  options.untangle_sweeps = 100;
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

TEST_CASE("what the node-by-node search leaves folded, moving a patch's nodes together untangles", "[curving]") {
  // The shaken squares at orders 2 to 4: one node at a time, the search left quadrilaterals
  // (5 at P2, every cell at P3 and P4: undone) and triangles (20 at P3, 116 at P4) invalid.
  // The patches around those cells, their nodes moved together against a moving barrier
  // (UntangleReport::joint_passes), leave none; the boundary stays, and the values reported
  // are the certified ones of the mesh left.
  for (const RectangleCells cells : {RectangleCells::quad4, RectangleCells::tri3})
    for (const int p : {2, 3, 4}) {
      INFO("order " << p << (cells == RectangleCells::quad4 ? " quadrilaterals" : " triangles"));
      std::vector<char> fixed;
      Mesh<2> m = shaken_mesh(cells, p, fixed);
      const Mesh<2> before = m;
      // One node at a time: never worse than the input (a worse result is undone).
      Mesh<2> alone = m;
      std::vector<double> quality = cell_quality(m, Metric::scaled_jacobian);
      UntangleOptions search_only;
      search_only.untangle_joint = false;
      const UntangleReport searched = untangle(alone, fixed, quality, search_only);
      CHECK(searched.invalid_after <= searched.invalid_before);
      CHECK(searched.min_after >= searched.min_before);
      const auto searched_quality = cell_quality(alone, Metric::scaled_jacobian);
      CHECK(*std::min_element(searched_quality.begin(), searched_quality.end()) == Approx(searched.min_after));

      quality = cell_quality(m, Metric::scaled_jacobian);
      const UntangleReport report = untangle(m, fixed, quality, {});
      CHECK(report.invalid_before > 0);
      CHECK(report.invalid_after == 0);
      CHECK(report.min_after > 0.0);
      if (!(cells == RectangleCells::tri3 && p == 2)) CHECK(report.joint_passes > 0);  // the search alone untangles that one
      const auto certified = cell_quality(m, Metric::scaled_jacobian);
      for (std::size_t c = 0; c < quality.size(); ++c) CHECK(quality[c] == Approx(certified[c]).margin(1e-12));
      for (Index v = 0; v < m.num_nodes(); ++v)
        if (fixed[static_cast<std::size_t>(v)]) CHECK(m.points.col(v) == before.points.col(v));
    }
}

TEST_CASE("untangling: nothing below the threshold, nothing moves, switched off, nothing moves", "[curving]") {
  std::vector<char> fixed;
  Mesh<2> m = shaken_mesh(RectangleCells::tri3, 2, fixed);
  const Mesh<2> before = m;
  std::vector<double> quality = cell_quality(m, Metric::scaled_jacobian);
  UntangleOptions off;
  off.untangle = false;
  CHECK(untangle(m, fixed, quality, off).sweeps == 0);
  CHECK(m.points == before.points);
  UntangleOptions low;
  low.untangle_threshold = -1e9;
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
  options.untangle.untangle = false;
  const CurveResult<2> plain = curve_mesh(linear, options);
  REQUIRE(plain.invalid() > 0);
  CHECK(plain.untangle.sweeps == 0);
  options.untangle.untangle = true;
  const CurveResult<2> untangled = curve_mesh(linear, options);
  CHECK(untangled.untangle.cells_below > 0);
  CHECK(untangled.untangle.invalid_before == plain.invalid());
  CHECK(untangled.invalid() == untangled.untangle.invalid_after);
  CHECK(untangled.invalid() <= plain.invalid());
  CHECK(untangled.quality.min == untangled.untangle.min_after);
  CHECK(untangled.quality.min >= plain.quality.min);
  // The wall's nodes slid on their circle, none off it; switched off, they stay.
  CHECK(untangled.untangle.slid_nodes > 0);
  for (const Index v : untangled.curved.group_nodes("wall")) CHECK(untangled.curved.points.col(v).norm() == Approx(0.5).margin(1e-12));
  options.untangle.untangle_slide = false;
  const CurveResult<2> held = curve_mesh(linear, options);
  CHECK(held.untangle.slid_nodes == 0);
  for (const Index v : held.curved.group_nodes("wall")) CHECK(held.curved.points.col(v) == plain.curved.points.col(v));
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

TEST_CASE("a wall node slides along its geometry to untangle a cell the nodes inside cannot", "[curving]") {
  // The O-mesh's wall curved on its circle at P2, then one wall edge's node turned along the
  // circle to a tenth of the edge from one end: past the quarter, the edge folds at that end.
  CurveOptions<2> options;
  options.order = 2;
  const BoundaryGeometry<2> circle = BoundaryGeometry<2>::project(SphereProjection<2>(Vec<2>::Zero(), 0.5));
  options.geometry.emplace("wall", circle);
  options.untangle.untangle = false;
  const CurveResult<2> curved = curve_mesh(o_mesh({.n_around = 24, .n_radial = 6, .first_height = 0.05, .farfield_radius = 4.0}), options);
  REQUIRE(curved.invalid() == 0);
  Mesh<2> m = curved.curved;
  const int wall = m.find_group("wall")->tag;
  const auto& block = m.facets.front();
  Index facet = 0;
  while (block.tags[static_cast<std::size_t>(facet)] != wall) ++facet;
  const auto el = block.element(facet);
  const Vec<2> a = m.points.col(el[0]), b = m.points.col(el[1]);
  const Vec<2> middle = m.points.col(el[2]);
  const double towards_a = middle.x() * a.y() - middle.y() * a.x() > 0.0 ? 1.0 : -1.0;  // counter-clockwise when a is
  m.points.col(el[2]) = Eigen::Rotation2Dd(0.4 * towards_a * std::acos(a.dot(b) / a.squaredNorm())) * middle;
  REQUIRE((Vec<2>(m.points.col(el[2])) - a).norm() < 0.2 * (b - a).norm());

  std::vector<char> fixed(static_cast<std::size_t>(m.num_nodes()), 0);
  for (const auto& f : m.facets)
    for (const Index v : f.connectivity) fixed[static_cast<std::size_t>(v)] = 1;
  const std::vector<double> tangled = cell_quality(m, Metric::scaled_jacobian);
  REQUIRE(std::count_if(tangled.begin(), tangled.end(), [](double q) { return q <= 0.0; }) >= 1);

  // Every node off the walls free, one at a time: the fold stays. Moved together (the joint
  // pass), they find a place where det J is positive everywhere: the cell at the folded end
  // turns with its wall edge.
  Mesh<2> held = m;
  std::vector<double> quality = tangled;
  UntangleOptions one_at_a_time;
  one_at_a_time.untangle_joint = false;
  CHECK(untangle(held, fixed, quality, one_at_a_time).invalid_after >= 1);
  held = m;
  quality = tangled;
  const UntangleReport together = untangle(held, fixed, quality, {});
  CHECK(together.joint_passes >= 1);
  CHECK(together.invalid_after == 0);
  for (const double q : cell_quality(held, Metric::scaled_jacobian)) CHECK(q > 0.0);

  // The wall's nodes inside their facets slide on the circle: the fold opens, nothing leaves the circle.
  const std::map<int, BoundaryGeometry<2>> geometry{{wall, circle}};
  const SlidingNodes<2> sliding = detail::wall_sliding_nodes(m, geometry, 30.0);
  CHECK(sliding.count(el[2]) == 1);
  const Mesh<2> before = m;
  quality = tangled;
  const UntangleReport report = untangle(m, fixed, quality, {}, sliding);
  INFO("invalid " << report.invalid_before << " -> " << report.invalid_after << ", min " << report.min_after);
  CHECK(report.invalid_after == 0);
  CHECK(report.slid_nodes >= 1);
  const auto certified = cell_quality(m, Metric::scaled_jacobian);
  CHECK(*std::min_element(certified.begin(), certified.end()) == Approx(report.min_after).margin(1e-12));
  for (Index v = 0; v < m.num_nodes(); ++v) {
    if (!fixed[static_cast<std::size_t>(v)]) continue;
    if (sliding.count(v) == 0) CHECK(m.points.col(v) == before.points.col(v));
    else CHECK(m.points.col(v).norm() == Approx(0.5).margin(1e-12));
  }
}

TEST_CASE("wall nodes on a sharp edge of their group do not slide, whatever the facets' orientation", "[curving]") {
  // A box's six faces as one group: its edges and corners are sharp (90 degrees), the diagonals
  // of its faces flat. Half the facets turned over: the edge test does not depend on it.
  Mesh<3> m = to_order(box_mesh({.nx = 2, .ny = 2, .nz = 2, .cells = BoxCells::tet4}), 2);
  for (auto& block : m.facets) {
    REQUIRE(block.type == ElementType::tri6);
    for (Index e = 0; e < block.size(); ++e) {
      block.tags[static_cast<std::size_t>(e)] = 1;
      if (e % 2 == 0) {
        auto el = block.element(e);
        const std::array<Index, 6> turned{el[0], el[2], el[1], el[5], el[4], el[3]};
        std::copy(turned.begin(), turned.end(), el.begin());
      }
    }
  }
  const std::map<int, BoundaryGeometry<3>> geometry{{1, BoundaryGeometry<3>::project([](const Vec<3>& x) { return x; })}};
  const SlidingNodes<3> sliding = detail::wall_sliding_nodes(m, geometry, 30.0);
  const auto on_box_edge = [&](Index v) {
    int sides = 0;
    for (int d = 0; d < 3; ++d) sides += std::abs(m.points(d, v)) < 1e-12 || std::abs(m.points(d, v) - 1.0) < 1e-12;
    return sides >= 2;
  };
  std::set<Index> facet_nodes;
  for (const auto& block : m.facets)
    for (Index e = 0; e < block.size(); ++e)
      for (std::size_t k = 3; k < 6; ++k) facet_nodes.insert(block.element(e)[k]);
  Index flat = 0;
  for (const Index v : facet_nodes) {
    INFO("node " << v << " at " << m.points.col(v).transpose());
    CHECK(sliding.count(v) == (on_box_edge(v) ? 0u : 1u));
    flat += sliding.count(v) == 1;
  }
  CHECK(flat > 0);
  // A sliding node searches its face's plane and stays on its geometry.
  for (const auto& [v, node] : sliding) {
    REQUIRE(node.directions.size() == 4);
    Vec<3> normal = Vec<3>::Zero();
    for (int d = 0; d < 3; ++d)
      if (std::abs(m.points(d, v)) < 1e-12 || std::abs(m.points(d, v) - 1.0) < 1e-12) normal(d) = 1.0;
    for (const Vec<3>& t : node.directions) CHECK(std::abs(t.dot(normal)) < 1e-12);
    CHECK((node.project(m.points.col(v)) - m.points.col(v)).norm() < 1e-15);
  }
  // A group's border stays even where it is flat: the bottom's half x < 0.5 made another group.
  for (auto& block : m.facets)
    for (Index e = 0; e < block.size(); ++e) {
      const auto el = block.element(e);
      if (m.points(2, el[0]) + m.points(2, el[1]) + m.points(2, el[2]) < 1e-12 &&
          m.points(0, el[0]) + m.points(0, el[1]) + m.points(0, el[2]) < 1.5)
        block.tags[static_cast<std::size_t>(e)] = 2;
    }
  std::map<int, BoundaryGeometry<3>> two = geometry;
  two.emplace(2, geometry.at(1));
  const SlidingNodes<3> split = detail::wall_sliding_nodes(m, two, 30.0);
  Index border = 0;
  for (const Index v : facet_nodes) {
    const bool on_border = std::abs(m.points(2, v)) < 1e-12 && std::abs(m.points(0, v) - 0.5) < 1e-12;
    border += on_border;
    CHECK(split.count(v) == (on_box_edge(v) || on_border ? 0u : 1u));
  }
  CHECK(border > 0);
  // Without a projection for the group nothing slides.
  CHECK(detail::wall_sliding_nodes(m, std::map<int, BoundaryGeometry<3>>{}, 30.0).empty());
}
