// The curving pipeline: boundary-layer estimate, blending regularizer, snapping, and the
// whole linear -> certified P2 pipeline on circles, boundary layers, every element type
// and a 3D sphere.

#include <catch2/catch.hpp>

#include "meshmotion/core/generators.hpp"
#include "meshmotion/curving/boundary_layer.hpp"

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

using namespace meshmotion;

namespace {

// The O-mesh layer by construction: ring j at wall distance s_j = h1 (g^j - 1)/(g - 1); the
// cell of layer j is w_j (inner chord) by h1 g^j with outer chord w_{j+1}. Returns the
// distance where the first cell with aspect ratio below `threshold` starts.
double o_mesh_layer_thickness(const OMeshOptions& o, double threshold) {
  const double h1 = o.first_height, g = o.growth;
  const auto s = [&](Index j) { return h1 * (std::pow(g, static_cast<double>(j)) - 1.0) / (g - 1.0); };
  const auto chord = [&](Index j) {
    return 2.0 * (o.semi_axis_x + s(j)) * std::sin(std::numbers::pi / static_cast<double>(o.n_around));
  };
  for (Index j = 0; j < o.n_radial; ++j) {
    const double h = h1 * std::pow(g, static_cast<double>(j));
    const double ratio = std::max(chord(j + 1), h) / std::min(chord(j), h);
    if (ratio < threshold) return s(j);
  }
  return s(o.n_radial);
}

const std::vector<std::string> wall_group{"wall"};

}  // namespace

TEST_CASE("boundary layer: thickness of a generated O-mesh layer is the one built", "[curving]") {
  OMeshOptions o;
  o.n_around = 64;
  o.n_radial = 40;
  o.first_height = 1e-4;
  o.growth = 1.2;
  for (const double threshold : {2.0, 3.0, 4.0}) {
    const Mesh<2> mesh = o_mesh(o);
    const auto estimate = estimate_boundary_layer(mesh, wall_group, {threshold});
    const double expected = o_mesh_layer_thickness(o, threshold);
    INFO("threshold " << threshold << ", expected " << expected);
    REQUIRE(expected > 10 * o.first_height);
    CHECK(estimate.wall("wall").thickness == Approx(expected).epsilon(1e-9));
    CHECK(estimate.wall("wall").max_thickness == Approx(expected).epsilon(1e-9));
    CHECK(estimate.wall_nodes.size() == 64);
  }
  SECTION("triangles: the same layer to within one cell") {
    o.triangles = true;
    const Mesh<2> mesh = o_mesh(o);
    const double expected = o_mesh_layer_thickness(o, 3.0);
    const double estimate = estimate_boundary_layer(mesh, wall_group).wall("wall").thickness;
    CHECK(estimate >= expected / o.growth);
    CHECK(estimate <= expected * o.growth * o.growth);
  }
  SECTION("an isotropic mesh has no layer") {
    const Mesh<2> grid = rectangle_mesh({});
    const std::vector<std::string> bottom{"bottom"};
    CHECK(estimate_boundary_layer(grid, bottom).wall("bottom").thickness == 0.0);
  }
  SECTION("bad input") {
    const Mesh<2> mesh = o_mesh(o);
    CHECK_THROWS_AS(estimate_boundary_layer(mesh, std::vector<std::string>{}), InputError);
    CHECK_THROWS_AS(estimate_boundary_layer(mesh, std::vector<std::string>{"nope"}), InputError);
    CHECK_THROWS_AS(estimate_boundary_layer(mesh, wall_group, {0.5}), InputError);
  }
}
