#pragma once
/// \file
/// The registry of distributed movers: which methods move a partitioned mesh over MPI, what
/// each needs (the cells, or a rank's points alone), and one type over all of them that
/// every front end (move_mesh_mpi, Python's Warp(comm=...), the OpenFOAM plugin) sets up and
/// moves. A front end asks it instead of naming methods: the rigid part, the boundary solve
/// and the options each method takes are the registry's to decide.
///
/// The table itself is parallel/registered_movers.hpp, compiled into meshmotion::parallel
/// (src/parallel.cpp); it includes the distributed movers' implementations, which nothing
/// else compiles.

#include "meshmotion/core/error.hpp"
#include "meshmotion/core/types.hpp"
#include "meshmotion/movers/boundary.hpp"
#include "meshmotion/movers/mover.hpp"
#include "meshmotion/movers/registry.hpp"
#include "meshmotion/parallel/distributed_mesh.hpp"
#include "meshmotion/parallel/parallel_options.hpp"

#include <memory>
#include <span>
#include <string>
#include <string_view>

namespace meshmotion::parallel {

/// A distributed mover chosen at run time. Every call is collective over the communicator of
/// the part it was set up on.
template <int Dim>
class DistributedMover {
 public:
  static constexpr int dim = Dim;
  DistributedMover() = default;
  DistributedMover(const DistributedMover&) = delete;
  DistributedMover& operator=(const DistributedMover&) = delete;
  virtual ~DistributedMover() = default;

  /// A rank's part of a partitioned mesh (partition_mesh()): every method.
  void setup(const DistributedMesh<Dim>& mesh, const ResolvedBoundary<Dim>& boundary) { setup(mesh.view(), mesh.local, boundary); }
  /// A solver's own partition with its cells (`local`: the rank's nodes, those of `part`, and
  /// its cells): every method. `part`'s arrays must live as long as the mover.
  virtual void setup(const PartitionView<Dim>& part, const Mesh<Dim>& local, const ResolvedBoundary<Dim>& boundary) = 0;
  /// A solver's own partition, its points without cells: the methods that need no cells
  /// (DistributedMethod::needs_cells); InputError for the others. `part`'s arrays must live
  /// as long as the mover.
  virtual void setup(const PartitionView<Dim>& part, const ResolvedBoundary<Dim>& boundary) = 0;
  /// The displacement of every local node for the local boundary entries' displacements `d`.
  virtual void move_into(PointsView<Dim> d, Points<Dim>& out) = 0;
  /// move_into() straight into the caller's Dim × part.size() storage (numpy's array): the RBF
  /// writes there with no copy in between (and refuses another shape on every rank); the
  /// others move into a buffer and copy (their solve dwarfs the copy).
  virtual void move_into(PointsView<Dim> d, Eigen::Ref<Points<Dim>> out) {
    move_into(d, buffer_);
    if (buffer_.cols() != out.cols())
      throw InputError("move_into: the output has " + std::to_string(out.cols()) + " columns (expected " +
                       std::to_string(buffer_.cols()) + ", one per local node)");
    out = buffer_;
  }
  [[nodiscard]] Points<Dim> move(PointsView<Dim> d) {
    Points<Dim> out;
    move_into(d, out);
    return out;
  }
  /// Jᵀ v: the gradient of ⟨v, move(d)⟩ over the local boundary entries (every method is
  /// linear in the displacements).
  [[nodiscard]] virtual Points<Dim> derivative_reverse(PointsView<Dim> v) = 0;
  /// The grid velocity of every local node for the local boundary entries' velocities
  /// (AnyMover::velocity(): J v through the map of the current move).
  [[nodiscard]] virtual Points<Dim> velocity(PointsView<Dim> boundary_velocities) = 0;
  [[nodiscard]] virtual MoverStats stats() const = 0;
  /// What the last setup chose: the RBF's radius and where it solved its boundary system, the
  /// elasticity's PETSc solver.
  [[nodiscard]] virtual DistributedChoices choices() const = 0;

 private:
  Points<Dim> buffer_;  ///< move_into()'s result on its way to the caller's storage (not the RBF's)
};

/// A method with a distributed mover.
template <int Dim>
struct DistributedMethod {
  std::string_view name;
  /// false: setup(PartitionView) serves, a rank's points alone.
  bool needs_cells = true;
  /// The mover for the method's options (its MoverConfig's) and the parallel options.
  std::unique_ptr<DistributedMover<Dim>> (*make)(const MoverOptions<Dim>&, const ParallelOptions&);
};

/// Every method with a distributed mover.
template <int Dim>
[[nodiscard]] std::span<const DistributedMethod<Dim>> distributed_methods();

/// "rbf, le, sle" for messages.
template <int Dim>
[[nodiscard]] std::string known_distributed_methods() {
  std::string known;
  for (const auto& m : distributed_methods<Dim>()) {
    if (!known.empty()) known += ", ";
    known += m.name;
  }
  return known;
}

/// The distributed method of that name; nullptr when the method has no distributed mover.
template <int Dim>
[[nodiscard]] const DistributedMethod<Dim>* find_distributed_method(std::string_view method) {
  for (const auto& m : distributed_methods<Dim>())
    if (m.name == method) return &m;
  return nullptr;
}

/// The distributed mover of `config`. Throws InputError (naming the methods that have one)
/// when its method has none, or as MoverConfig::check.
template <int Dim>
[[nodiscard]] std::unique_ptr<DistributedMover<Dim>> make_distributed_mover(const MoverConfig<Dim>& config,
                                                                          const ParallelOptions& parallel = {}) {
  config.check();
  const DistributedMethod<Dim>* method = find_distributed_method<Dim>(config.method);
  if (method == nullptr)
    throw InputError("method '" + config.method + "' has no distributed mover (expected " + known_distributed_methods<Dim>() + ")");
  return method->make(config.options, parallel);
}

}  // namespace meshmotion::parallel

// The compiled parallel library (target meshmotion::parallel, src/parallel.cpp) holds the
// table for Dim 2 and 3; header-only, parallel/registered_movers.hpp defines it
// (meshmotion/parallel.hpp includes it).
#ifdef MESHMOTION_PARALLEL_COMPILED
namespace meshmotion::parallel {
extern template std::span<const DistributedMethod<2>> distributed_methods<2>();
extern template std::span<const DistributedMethod<3>> distributed_methods<3>();
}  // namespace meshmotion::parallel
#endif
