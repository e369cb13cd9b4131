#pragma once
/// \file
/// The options of the distributed movers beyond their serial mover's: where the RBF boundary
/// system is solved (BoundarySolveOptions) and how PETSc solves distributed elasticity
/// (DistributedElasticityOptions), with their one description each, and ParallelOptions, the
/// two together as every front end takes them (move_mesh_mpi's flags, Python's Warp(comm=...)
/// keywords, the OpenFOAM plugin's meshmotionCoeffs). Light: no MPI or PETSc header, so the
/// programs built without the parallel layer document these options too.

#include "meshmotion/core/option_text.hpp"
#include "meshmotion/core/types.hpp"
#include "meshmotion/movers/elasticity_options.hpp"

#include <array>
#include <string>
#include <utility>

namespace meshmotion::parallel {

/// Where the distributed RBF mover solves its boundary system.
enum class BoundarySolve {
  automatic,   ///< patches for a partition of unity; PETSc when the options allow it and the system is big enough (BoundarySolveOptions); else replicated
  replicated,  ///< factorized on every rank (any option: sliding, radius per node, global kernels)
  petsc,       ///< factorized once across the ranks by MUMPS (compact kernel, one radius, no sliding, distinct centres)
  patches,     ///< RbfOptions::partition_of_unity with each patch on one rank (no sliding, distinct centres)
};

[[nodiscard]] constexpr const char* name(BoundarySolve k) {
  switch (k) {
    case BoundarySolve::automatic: return "automatic";
    case BoundarySolve::replicated: return "replicated";
    case BoundarySolve::petsc: return "petsc";
    case BoundarySolve::patches: return "patches";
  }
  return "?";
}
[[nodiscard]] constexpr std::array<BoundarySolve, 4> option_choices(BoundarySolve) {
  return {BoundarySolve::automatic, BoundarySolve::replicated, BoundarySolve::petsc, BoundarySolve::patches};
}

/// How automatic chooses, from the figures of docs/parallel.md: replicated, every rank on a node
/// factorizes the same system at once, which on a 16-core node made the 2.05M-node box's setup
/// 5× slower at 8 ranks and 25× at 16 than at one (16,129 centres), while MUMPS's setup fell
/// with the ranks and its moves were faster from 2 ranks on.
struct BoundarySolveOptions {
  BoundarySolve boundary_solve = BoundarySolve::automatic;
  Index petsc_min_centres = 50000;
  Index petsc_min_node_centres = 30000;
};

template <class F>
void visit_options(BoundarySolveOptions& o, F&& f, const std::string& prefix = {}) {
  f(prefix + "boundary_solve", o.boundary_solve, "where the RBF boundary system is solved");
  f(prefix + "petsc_min_centres", o.petsc_min_centres, OptionHelp{"automatic: fewest centres for PETSc at any rank count", range::non_negative});
  f(prefix + "petsc_min_node_centres", o.petsc_min_node_centres,
    OptionHelp{"automatic: fewest centres x ranks per node for PETSc on several ranks", range::non_negative,
      "Fewest centres × ranks sharing a node for which automatic takes PETSc on 2 ranks or more: the "
      "replicated factorizations a node runs at once, counted once more for each further round when the node "
      "has more ranks than cores (they then run one after another)."});
}

/// PETSc solver of the distributed elasticity system.
enum class PetscSolverKind {
  /// MUMPS in 2D, CG + GAMG in 3D: on boundary-layer meshes the stiffened 2D system defeats
  /// the multigrids (thousands of iterations on the 30P30N) while MUMPS factorizes it in
  /// seconds; 3D systems outgrow direct factorization first (docs/parallel.md).
  automatic,
  cg_gamg,       ///< CG preconditioned by PETSc's algebraic multigrid (rigid-body near null space)
  cg_hypre,      ///< CG preconditioned by hypre's BoomerAMG
  direct_mumps,  ///< Cholesky by MUMPS (distributed direct)
};

[[nodiscard]] constexpr const char* name(PetscSolverKind k) {
  switch (k) {
    case PetscSolverKind::automatic: return "automatic";
    case PetscSolverKind::cg_gamg: return "cg_gamg";
    case PetscSolverKind::cg_hypre: return "cg_hypre";
    case PetscSolverKind::direct_mumps: return "mumps";
  }
  return "?";
}
[[nodiscard]] constexpr std::array<PetscSolverKind, 4> option_choices(PetscSolverKind) {
  return {PetscSolverKind::automatic, PetscSolverKind::cg_gamg, PetscSolverKind::cg_hypre, PetscSolverKind::direct_mumps};
}

struct DistributedElasticityOptions {
  /// Material and Jacobian stiffening as in serial; `solver` there is not used (see below),
  /// distance_exponent and active_radius must be 0.
  ElasticityOptions elasticity = {};
  PetscSolverKind petsc_solver = PetscSolverKind::automatic;
  double petsc_tolerance = 1e-10;
  Index petsc_max_iterations = 10000;
  bool petsc_fallback_to_direct = false;
  std::string petsc_prefix = "meshmotion_";
};

/// The options of the distributed solve, as text may set them (the material is the serial
/// mover's, ElasticityOptions).
template <class F>
void visit_options(DistributedElasticityOptions& o, F&& f, const std::string& prefix = {}) {
  f(prefix + "petsc_solver", o.petsc_solver, "PETSc solver (automatic: mumps in 2D, cg_gamg in 3D)");
  f(prefix + "petsc_tolerance", o.petsc_tolerance, OptionHelp{"relative residual of CG on the scaled system (displacement units)", range::positive});
  f(prefix + "petsc_max_iterations", o.petsc_max_iterations, OptionHelp{"iteration cap of CG", range::at_least(1)});
  f(prefix + "petsc_fallback_to_direct", o.petsc_fallback_to_direct, "solve again with MUMPS when CG does not converge");
  f(prefix + "petsc_prefix", o.petsc_prefix, "prefix of the PETSc options that refine the solver");
}

/// Both distributed solves' options: what a front end splits off the keys it is given before
/// the serial mover takes the rest (take_parallel_options).
struct ParallelOptions {
  BoundarySolveOptions boundary;
  DistributedElasticityOptions elasticity;
};

template <class F>
void visit_options(ParallelOptions& o, F&& f, const std::string& prefix = {}) {
  visit_options(o.boundary, f, prefix);
  visit_options(o.elasticity, f, prefix);
}

/// What a distributed mover chose at its last setup (DistributedMover::choices()), reported by
/// move_mesh_mpi beside its move report and by Python's Warp(comm=...).
struct DistributedChoices {
  double support_radius = 0.0;
  std::string boundary_solve = "none";
  std::string petsc_solver = "none";
};

template <class F>
void visit_fields(const DistributedChoices& c, F&& f) {
  f("support_radius", c.support_radius, "the RBF's support radius (the default one when none was given); 0 for elasticity");
  f("boundary_solve", c.boundary_solve, "where the RBF's boundary system was solved: replicated, petsc or patches (none for elasticity)");
  f("petsc_solver", c.petsc_solver, "the elasticity's PETSc solver, automatic resolved: mumps, cg_gamg or cg_hypre (none for the RBF)");
}

/// Sets the keys of `given` that ParallelOptions takes on `o` and returns the others, in order,
/// for the serial mover's MoverConfig (which refuses what it does not know). Throws InputError
/// for a malformed value of a parallel key.
[[nodiscard]] inline KeyValues take_parallel_options(const KeyValues& given, ParallelOptions& o) {
  KeyValues rest;
  for (const auto& [key, text] : given)
    if (!set_option(o, key, text)) rest.emplace_back(key, text);
  return rest;
}

}  // namespace meshmotion::parallel
