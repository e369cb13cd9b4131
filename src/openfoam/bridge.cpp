// The meshmotion half of the OpenFOAM plugin (C++20): the mover by name, set up once.

#include "bridge.hpp"

#include "meshmotion/movers/mover_options.hpp"
#ifdef MESHMOTION_FOAM_PARALLEL
#include "meshmotion/parallel/distributed_rbf.hpp"
#endif

#include <cstdint>
#include <memory>
#include <optional>
#include <stdexcept>

namespace meshmotion::foam {

#ifdef MESHMOTION_FOAM_PARALLEL
namespace {

// The options of the boundary system's place on a decomposed case (BoundarySolveOptions) are
// taken out of the method's: a case's dictionary runs alike serially, where they do nothing.
KeyValues take_options(KeyValues& given, parallel::BoundarySolveOptions& solve) {
  KeyValues rest;
  for (auto& [key, text] : given)
    if (!set_option(solve, key, text)) rest.emplace_back(std::move(key), std::move(text));
  return rest;
}

}  // namespace
#endif

struct Bridge::Impl {
  std::optional<AnyMover<3>> mover;
#ifdef MESHMOTION_FOAM_PARALLEL
  std::optional<parallel::DistributedRbfMover<3>> distributed;
  Points<3> points;  // the distributed mover's view of them must outlive its setup
  std::vector<std::int64_t> global_ids;
  std::vector<int> owners;
#endif
  Index points_count = 0, boundary = 0;
};

Bridge::Bridge(const BridgeInput& input) : impl_(nullptr) {
  try {
    // The cells (OpenFOAM's polyhedra) are not passed yet: only movers that need none.
    if (input.method != "rbf")
      throw InputError("method '" + input.method + "' needs the mesh's cells, which this plugin does not pass to it yet; use method rbf");
    const auto n = static_cast<Index>(input.points.size() / 3), nb = static_cast<Index>(input.boundary.size());
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
    KeyValues given = parse_key_values(input.options);
    auto impl = std::make_unique<Impl>();
    impl->points_count = n;
    impl->boundary = nb;
    const Eigen::Map<const Points<3>> points(input.points.data(), 3, n);
#ifdef MESHMOTION_FOAM_PARALLEL
    parallel::BoundarySolveOptions solve;
    const KeyValues rest = take_options(given, solve);
    if (!input.global_ids.empty()) {
      // OpenFOAM has MPI running; PETSc, which the boundary system may take, is started once.
      PetscBool started = PETSC_FALSE;
      PetscInitialized(&started);
      if (!started && PetscInitializeNoArguments() != 0) throw InputError("PETSc failed to start");
      impl->points = points;
      impl->global_ids.assign(input.global_ids.begin(), input.global_ids.end());
      impl->owners = input.owners;
      const parallel::PartitionView<3> part{MPI_COMM_WORLD, impl->points, impl->global_ids, impl->owners};
      auto config = mover_config<3>(input.method, rest);
      impl->distributed.emplace(std::get<RbfOptions>(config.options), solve);
      impl->distributed->setup(part, b);
      impl_ = impl.release();
      return;
    }
#else
    if (!input.global_ids.empty())
      throw InputError("this plugin was built without meshmotion's parallel layer (MPI, PETSc, METIS): run the motion serially");
    const KeyValues& rest = given;
#endif
    Mesh<3> mesh;
    mesh.points = points;
    impl->mover.emplace(make_mover(mover_config<3>(input.method, rest)));
    impl->mover->setup(mesh, b);
    impl_ = impl.release();
  } catch (const std::exception& e) {
    throw std::runtime_error(e.what());
  }
}

Bridge::~Bridge() { delete impl_; }

void Bridge::move(const std::vector<double>& boundary_displacements, std::vector<double>& out) {
  try {
    const Eigen::Map<const Points<3>> d(boundary_displacements.data(), 3, impl_->boundary);
#ifdef MESHMOTION_FOAM_PARALLEL
    if (impl_->distributed) {
      Points<3> moved;
      impl_->distributed->move_into(d, moved);
      out.assign(moved.data(), moved.data() + moved.size());
      return;
    }
#endif
    out.resize(static_cast<std::size_t>(3 * impl_->points_count));
    Eigen::Map<Points<3>> moved(out.data(), 3, impl_->points_count);
    impl_->mover->move_into(d, moved);
  } catch (const std::exception& e) {
    throw std::runtime_error(e.what());
  }
}

}  // namespace meshmotion::foam
