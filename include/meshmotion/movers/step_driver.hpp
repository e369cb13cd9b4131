#pragma once
/// \file
/// run_steps: drives any MeshMover in n steps. Rigid motions are split by fraction of the
/// motion (fraction of the angle), displacement arrays linearly; the quality of the mesh is
/// reported after every step. The mover is set up once on the reference with nothing moved
/// yet, as a solver's time loop sets it up: one that then takes each move's rigid part itself
/// (MoverStats::rigid_part, the RBF's default) is moved to every step's whole target from that
/// setup, so the programs give the displacements a time loop, Python's Warp and the OpenFOAM
/// plugin give. Every other mover is set up again on the moved mesh each step, as the thesis
/// does for large rotations (section 4, 2–3 steps): its operator is the reference's, linear
/// in the displacement, and cannot follow a large rotation from one setup.

#include "meshmotion/core/error.hpp"
#include "meshmotion/core/mesh.hpp"
#include "meshmotion/core/mesh_like.hpp"
#include "meshmotion/movers/boundary.hpp"
#include "meshmotion/movers/mover.hpp"
#include "meshmotion/quality/quality_report.hpp"

#include <concepts>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace meshmotion {

/// Options of run_steps().
struct StepOptions {
  int steps = 1;                    ///< number of increments, ≥ 1
  Metric metric = Metric::skew;     ///< quality reported after each step
  bool report_quality = true;       ///< false skips the per-step quality evaluation
};

/// What one step did.
struct StepInfo {
  MoverStats stats;
  std::optional<QualityReport> quality;  ///< after the step (when StepOptions::report_quality)
};

/// Result of run_steps(): the moved mesh, total displacement of every node (Dim × n_nodes)
/// and one StepInfo per step.
template <int Dim>
struct StepResult {
  Mesh<Dim> mesh;
  Points<Dim> displacements;
  std::vector<StepInfo> steps;
};

/// Moves `mesh` by `spec` in options.steps increments with `mover` (set up at rest, then as
/// the file's comment says). `group_nodes` gives node lists for meshes without named groups
/// (empty: use the mesh's groups). Throws what the spec's resolve and the mover throw, and
/// InputError for steps < 1.
template <MeshMover Mover>
[[nodiscard]] StepResult<Mover::dim> run_steps(Mover& mover, const Mesh<Mover::dim>& mesh,
                                               const BoundarySpec<Mover::dim>& spec, const StepOptions& options = {},
                                               const GroupNodes& group_nodes = {}) {
  constexpr int Dim = Mover::dim;
  if (options.steps < 1) throw InputError("run_steps: steps must be at least 1 (got " + std::to_string(options.steps) + ")");
  StepResult<Dim> result{mesh, Points<Dim>::Zero(Dim, mesh.num_nodes()), {}};
  const auto resolve = [&](double to, double from) {
    // Targets always come from the reference positions, so rigid motions stay rigid.
    return group_nodes.empty() ? spec.resolve(mesh, to, from) : spec.resolve(mesh.points, group_nodes, to, from);
  };
  ResolvedBoundary<Dim> rest = resolve(1.0 / options.steps, 0.0);
  rest.displacements.setZero();
  mover.setup(mesh, rest);
  const bool from_rest = mover.stats().rigid_part;
  Points<Dim> step_displacement;
  for (int s = 1; s <= options.steps; ++s) {
    const double to = double(s) / options.steps;
    if (from_rest) {
      mover.move_into(resolve(to, 0.0).displacements, result.displacements);
      result.mesh.points = mesh.points + result.displacements;
    } else {
      const ResolvedBoundary<Dim> boundary = resolve(to, double(s - 1) / options.steps);
      if (s > 1) mover.setup(result.mesh, boundary);
      mover.move_into(boundary.displacements, step_displacement);
      result.mesh.points += step_displacement;
      result.displacements += step_displacement;
    }
    StepInfo info{mover.stats(), std::nullopt};
    if (options.report_quality) info.quality = quality_report(result.mesh, options.metric);
    result.steps.push_back(std::move(info));
  }
  return result;
}

/// What a move did, as the programs report it (move_mesh --json, its text).
struct MoveReport {
  std::string method;
  int steps = 1;
  Index nodes = 0;
  double setup_seconds = 0.0;  ///< summed over the setups
  double move_seconds = 0.0;   ///< summed over the steps
  QualityReport before;        ///< of the mesh given
  QualityReport after;         ///< of the moved mesh
  std::vector<MoverStats> mover_steps;
};

template <class F>
void visit_fields(const MoveReport& r, F&& f) {
  f("method", r.method, "the mover");
  f("steps", r.steps, "increments (run_steps: one setup at rest, again each step unless the mover takes each move's rigid part)");
  f("nodes", r.nodes, "nodes of the mesh");
  f("setup_seconds", r.setup_seconds, "the mover's setups, summed");
  f("move_seconds", r.move_seconds, "the mover's moves, summed over the steps");
  f("before", r.before, "quality of the mesh given");
  f("after", r.after, "quality of the moved mesh");
  f("mover_steps", r.mover_steps, "the mover's stats per step");
}

/// The report of `result` (run with StepOptions::report_quality) for `method` from `before`,
/// the quality of the mesh given in the same metric.
template <int Dim>
[[nodiscard]] MoveReport move_report(std::string method, QualityReport before, const StepResult<Dim>& result) {
  MoveReport r{std::move(method), static_cast<int>(result.steps.size()), result.mesh.num_nodes(), 0.0, 0.0,
               std::move(before), {}, {}};
  for (const StepInfo& s : result.steps) {
    if (s.stats.moves <= 1) r.setup_seconds += s.stats.setup_seconds;  // later moves share a setup
    r.move_seconds += s.stats.move_seconds;
    r.mover_steps.push_back(s.stats);
  }
  if (!result.steps.empty() && result.steps.back().quality) r.after = *result.steps.back().quality;
  return r;
}

/// run_steps() on a solver's own mesh type (any MeshLike), copied into a Mesh<Dim>; the
/// groups come from `group_nodes` (a MeshLike carries none).
template <MeshMover Mover, MeshLike M>
  requires(!std::same_as<M, Mesh<Mover::dim>> && mesh_dim<M> == Mover::dim)
[[nodiscard]] StepResult<Mover::dim> run_steps(Mover& mover, const M& mesh, const BoundarySpec<Mover::dim>& spec,
                                               const StepOptions& options, const GroupNodes& group_nodes) {
  return run_steps(mover, to_mesh(mesh), spec, options, group_nodes);
}

}  // namespace meshmotion
