#pragma once
// The plugin's ways of serving moves, behind one interface (the Bridge holds one): the serial
// mover on the whole case (bridge.cpp), and on a decomposed case the distributed mover through
// the cells or through the points alone, or the case gathered on rank 0 for a method without a
// distributed mover (bridge_parallel.cpp; bridge_serial_only.cpp refuses decomposed cases where
// the parallel layer is not built). Internal to the plugin's C++20 side.

#include "bridge.hpp"

#include "meshmotion/io/openfoam_polymesh.hpp"
#include "meshmotion/movers/registry.hpp"
#include "meshmotion/parallel/parallel_options.hpp"

#include <memory>
#include <vector>

namespace meshmotion::foam {

/// One serving mode: set up on construction (on the reference, before anything moves), then
/// moved every time step.
class Serving {
 public:
  virtual ~Serving() = default;
  /// Bridge::move(): the boundary entries' displacements to every point's.
  virtual void move(const std::vector<double>& boundary_displacements, std::vector<double>& out) = 0;
  /// The mover's figures (empty on the ranks that hold no mover).
  [[nodiscard]] virtual MoverStats stats() const = 0;
};

/// Boundary points (ascending), their PointRole and direction (3 × points) as the mover's
/// boundary, with zero displacements.
[[nodiscard]] ResolvedBoundary<3> resolved_boundary(const std::vector<long>& points, const std::vector<int>& roles,
                                                    const std::vector<double>& directions);
/// The input's boundary points as the mover's boundary.
[[nodiscard]] inline ResolvedBoundary<3> input_boundary(const BridgeInput& input) {
  return resolved_boundary(input.boundary, input.roles, input.directions);
}
/// The input's cells as a polyMesh with one boundary patch.
[[nodiscard]] PolyMesh input_cells(const BridgeInput& input);
/// Per face, whether it is coupled (input.coupled_faces); empty when none is.
[[nodiscard]] std::vector<char> input_coupled(const BridgeInput& input);

/// The centres a polyhedral case's cells are cut around (to_mesh()), where they are on the
/// boundary: a boundary face's centre joins the mover's boundary, prescribed when all the
/// face's points are, by their mean displacement (exact for a rigid motion, the centre being
/// their mean), else sliding in the face's plane. A face between ranks (`coupled`) is interior.
class FaceCentres {
 public:
  FaceCentres() = default;
  /// Appends the centres' entries to `b` (after the points').
  FaceCentres(const PolyMesh& poly, const Mesh<3>& mesh, const std::vector<char>& coupled, ResolvedBoundary<3>& b);
  /// `given` (every entry): the points' entries `d`, then the centres' from them.
  void prescribe(const Eigen::Ref<const Points<3>>& d, Points<3>& given) const;
  [[nodiscard]] Index size() const noexcept { return static_cast<Index>(entries_.size()); }

 private:
  std::vector<std::vector<Index>> entries_;  // per centre, its face's points' entries (empty: sliding)
};

/// The serial mover on a whole case: the case itself, or on a decomposed case that has no
/// distributed mover, the case gathered on rank 0.
class SerialServing final : public Serving {
 public:
  SerialServing(const MoverConfig<3>& config, Mesh<3> mesh, ResolvedBoundary<3> boundary, const FaceCentres& centres,
                Index points);
  void move(const std::vector<double>& boundary_displacements, std::vector<double>& out) override;
  [[nodiscard]] MoverStats stats() const override { return mover_.stats(); }
  /// Every node moved for `d`, the displacements of the entries before the face centres'.
  const Points<3>& move_entries(const Eigen::Ref<const Points<3>>& d);

 private:
  Mesh<3> mesh_;  // what the mover was set up on
  FaceCentres centres_;
  Index points_, entries_;
  AnyMover<3> mover_;
  Points<3> given_, moved_;  // kept between moves
};

/// Whether a decomposed case hands `method` the cells although the method does not read them:
/// a method without a distributed mover is gathered on rank 0, cells and all.
[[nodiscard]] bool decomposed_needs_cells(const std::string& method);
/// The mode of a decomposed case (collective on MPI_COMM_WORLD).
[[nodiscard]] std::unique_ptr<Serving> serve_decomposed(const BridgeInput& input, const MoverConfig<3>& config,
                                                        const parallel::ParallelOptions& parallel);

}  // namespace meshmotion::foam
