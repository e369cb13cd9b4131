// The meshmotion half of the OpenFOAM plugin (C++20): the mover by name, set up once.

#include "bridge.hpp"

#include "meshmotion/movers/mover_options.hpp"

#include <memory>
#include <stdexcept>

namespace meshmotion::foam {

struct Bridge::Impl {
  AnyMover<3> mover;
  Index points = 0, boundary = 0;
};

Bridge::Bridge(const BridgeInput& input) : impl_(nullptr) {
  try {
    // The cells (OpenFOAM's polyhedra) are not passed yet: only movers that need none.
    if (input.method != "rbf")
      throw InputError("method '" + input.method + "' needs the mesh's cells, which this plugin does not pass to it yet; use method rbf");
    const auto n = static_cast<Index>(input.points.size() / 3), nb = static_cast<Index>(input.boundary.size());
    Mesh<3> mesh;
    mesh.points = Eigen::Map<const Points<3>>(input.points.data(), 3, n);
    ResolvedBoundary<3> b;
    b.nodes.assign(input.boundary.begin(), input.boundary.end());
    b.displacements = Points<3>::Zero(3, nb);
    b.normals = Points<3>::Zero(3, nb);
    b.directions = Points<3>::Zero(3, nb);
    const Eigen::Map<const Points<3>> along(input.directions.data(), 3, nb);
    for (Index k = 0; k < nb; ++k) {
      const auto role = static_cast<PointRole>(input.roles[static_cast<std::size_t>(k)]);
      b.kinds.push_back(role == PointRole::prescribed ? BoundaryKind::prescribed : BoundaryKind::sliding);
      if (role == PointRole::sliding_plane) b.normals.col(k) = along.col(k);
      if (role == PointRole::sliding_line) b.directions.col(k) = along.col(k);
    }
    auto impl = std::make_unique<Impl>(Impl{make_mover(mover_config<3>(input.method, parse_key_values(input.options))), n, nb});
    impl->mover.setup(mesh, b);
    impl_ = impl.release();
  } catch (const std::exception& e) {
    throw std::runtime_error(e.what());
  }
}

Bridge::~Bridge() { delete impl_; }

void Bridge::move(const std::vector<double>& boundary_displacements, std::vector<double>& out) {
  try {
    const Eigen::Map<const Points<3>> d(boundary_displacements.data(), 3, impl_->boundary);
    out.resize(static_cast<std::size_t>(3 * impl_->points));
    Eigen::Map<Points<3>> moved(out.data(), 3, impl_->points);
    impl_->mover.move_into(d, moved);
  } catch (const std::exception& e) {
    throw std::runtime_error(e.what());
  }
}

}  // namespace meshmotion::foam
