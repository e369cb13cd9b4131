#pragma once
// rbf_bench's 3D box case, shared by the benchmarks that measure it: an n³ hex box whose bottom
// face moves as a bump, d_z = 0.05 sin(πx) sin(πy) (support radius 6 / n in every benchmark).

#include "meshmotion/core/generators.hpp"
#include "meshmotion/movers/boundary.hpp"

#include <cmath>
#include <vector>

namespace bench {

inline meshmotion::Mesh<3> box(int n) {
  meshmotion::BoxOptions b;
  b.nx = b.ny = b.nz = n;
  return meshmotion::box_mesh(b);
}

/// The bump's displacement of each node of the group "bottom", in group_nodes("bottom") order.
inline meshmotion::Points<3> bump_displacements(const meshmotion::Mesh<3>& mesh) {
  const std::vector<meshmotion::Index> bottom = mesh.group_nodes("bottom");
  meshmotion::Points<3> d = meshmotion::Points<3>::Zero(3, static_cast<meshmotion::Index>(bottom.size()));
  for (std::size_t k = 0; k < bottom.size(); ++k) {
    const double x = mesh.points(0, bottom[k]), y = mesh.points(1, bottom[k]);
    d(2, static_cast<meshmotion::Index>(k)) = 0.05 * std::sin(M_PI * x) * std::sin(M_PI * y);
  }
  return d;
}

inline meshmotion::ResolvedBoundary<3> bottom_bump(const meshmotion::Mesh<3>& mesh) {
  meshmotion::BoundarySpec<3> spec;
  spec.moving("bottom", bump_displacements(mesh));
  return spec.resolve(mesh);
}

}  // namespace bench
