#pragma once
/// \file
/// DistributedElasticityMover: linear and Jacobian-stiffened elasticity on a partitioned mesh,
/// assembled into a PETSc MPIAIJ matrix and solved by PETSc (CG with GAMG or hypre's
/// BoomerAMG, or MUMPS's Cholesky).
///
/// - Numbering: each rank's owned nodes take a contiguous range of PETSc rows (Dim dofs per
///   node, node-major, block size Dim); a ghost's row is asked of its owner once in setup,
///   together with its boundary condition (the owner's entry decides).
/// - Assembly: each rank integrates its own cells with the serial element code
///   (ElasticityMover::assemble_stiffness) and adds them by COO with global indices; PETSc
///   sends the rows of ghost nodes to their owners. J0, the mean cell measure, is reduced over
///   all ranks, so stiffening matches the serial mover.
/// - Sliding nodes: their dofs are rotated into (tangents, normal) frames (Tᵀ K T); the normal
///   component is then a zero Dirichlet dof, as the line's normals are for a node on two planes.
/// - Dirichlet dofs: zeroed rows and columns with a unit diagonal (MatZeroRowsColumns); the
///   unmodified matrix is kept to move their values to the right-hand side at each move.
/// - Scaling: the system is solved symmetrically scaled by its diagonal, as the serial mover
///   does, so the tolerance is a relative residual in displacement units.
/// - Setup builds the preconditioner (or factorization) once; a move is one solve. A Krylov
///   solve that does not converge falls back to MUMPS when fallback_to_direct is set, and
///   raises SolverError on every rank otherwise.
/// - A time loop's moves are close to each other: a Krylov solve of a move starts from the
///   last move's solution or its extrapolation through the one before (exact for a motion
///   growing by equal steps), whichever leaves the smaller residual, or from zero when neither
///   does better (two matrix products to choose). The derivatives start from zero and leave
///   the moves' history alone. The stopping test is the same relative residual, so the result
///   is the cold start's to the tolerance, in fewer iterations.
///
/// Not supported here (InputError): distance stiffening (distance_exponent) and active_radius;
/// the serial ElasticityMover has them.
///
/// PETSc must be initialized (PetscInitialize) before setup and finalized after the mover is
/// destroyed.

#include "meshmotion/core/error.hpp"
#include "meshmotion/core/option_text.hpp"
#include "meshmotion/core/mesh_like.hpp"
#include "meshmotion/core/types.hpp"
#include "meshmotion/movers/boundary.hpp"
#include "meshmotion/movers/detail/mover_support.hpp"
#include "meshmotion/movers/elasticity.hpp"
#include "meshmotion/parallel/communicator.hpp"
#include "meshmotion/parallel/distributed_mesh.hpp"
#include "meshmotion/parallel/parallel_options.hpp"
#include "meshmotion/parallel/petsc.hpp"
#include "meshmotion/solvers/detail/stopwatch.hpp"

#include <petscksp.h>

#include <array>

#include <cmath>
#include <cstdint>
#include <string>
#include <utility>
#include <unordered_map>
#include <vector>

namespace meshmotion::parallel {

template <int Dim>
class DistributedElasticityMover {
 public:
  static constexpr int dim = Dim;

  explicit DistributedElasticityMover(DistributedElasticityOptions options = {}) : options_(std::move(options)) {}
  DistributedElasticityMover(const DistributedElasticityMover&) = delete;
  DistributedElasticityMover& operator=(const DistributedElasticityMover&) = delete;

  [[nodiscard]] const DistributedElasticityOptions& options() const noexcept { return options_; }
  [[nodiscard]] const MoverStats& stats() const noexcept { return stats_; }
  /// The solver the last setup built (PetscSolverKind::automatic resolved).
  [[nodiscard]] PetscSolverKind solver_kind() const noexcept { return solver_kind_; }

  /// Collective. `part`: this rank's nodes; `local_mesh`: its cells over the local node
  /// indices (any MeshLike, whose nodes are part's); `boundary`: entries of local nodes (owned
  /// entries decide). Throws on every rank what any rank finds wrong.
  template <MeshLike M>
    requires(mesh_dim<M> == Dim)
  void setup(const PartitionView<Dim>& part, const M& local_mesh, const ResolvedBoundary<Dim>& boundary) {
    if constexpr (std::same_as<M, Mesh<Dim>>)
      setup_mesh(part, local_mesh, boundary);
    else
      setup_mesh(part, to_mesh(local_mesh), boundary);
  }
  void setup(const DistributedMesh<Dim>& mesh, const ResolvedBoundary<Dim>& boundary) {
    setup_mesh(mesh.view(), mesh.local, boundary);
  }

  /// Collective. Displacement (Dim × part.size(), ghosts included) for the displacements `d`
  /// (Dim × boundary.size()) of this rank's boundary entries; owned entries are read.
  void move_into(PointsView<Dim> d, Points<Dim>& out);
  [[nodiscard]] Points<Dim> move(PointsView<Dim> d) {
    Points<Dim> out;
    move_into(d, out);
    return out;
  }

  /// Collective. Forward derivative: the displacement change (Dim × part.size()) for a change
  /// `w` of the boundary entries' displacements. The mover is linear, so this is move(w),
  /// started from zero rather than from the last move.
  [[nodiscard]] Points<Dim> derivative_forward(PointsView<Dim> w) {
    Points<Dim> out;
    solve_for(w, out, false);
    return out;
  }

  /// Collective. For v (Dim × part.size()), the gradient of Σ over ranks of ⟨v, move(d)⟩ on
  /// owned nodes with respect to this rank's boundary entries (Dim × boundary.size()): owned
  /// prescribed entries carry it, ghost, fixed and sliding entries are zero, so the ranks'
  /// gradients add up to the serial one. One solve of the symmetric system (x̄ = seed in the
  /// nodes' frames, y = K_FF⁻¹ x̄_F, gradient = x̄_D − (K y)_D), to the solver's tolerance.
  [[nodiscard]] Points<Dim> derivative_reverse(PointsView<Dim> v);

 private:
  using Frame = Eigen::Matrix<double, Dim, Dim>;
  enum Condition : int { free_node = -1, prescribed = 0, fixed = 1, sliding = 2 };
  struct NodeCondition {
    int kind = free_node;
    Frame frame = Frame::Identity();  ///< columns: free directions first, then constrained ones
    int constrained = 0;              ///< trailing columns of `frame` held at zero (sliding)
  };

  void setup_mesh(const PartitionView<Dim>& part, const Mesh<Dim>& mesh, const ResolvedBoundary<Dim>& boundary);
  using OwnedKsp = detail::OwnedKsp;
  using OwnedMat = detail::OwnedMat;
  using OwnedVec = detail::OwnedVec;

  void build_solver(OwnedKsp& ksp, PetscSolverKind kind, const char* where);
  /// move_into(); a move of the time loop (`step`) starts where choose_start() says and joins
  /// the history it chooses from.
  void solve_for(PointsView<Dim> d, Points<Dim>& out, bool step);
  /// x_ ← the start of a move's Krylov solve for b_ (see the file comment); false: from zero.
  [[nodiscard]] bool choose_start(const char* where);
  /// Solves the scaled system for b_ into x_ (MUMPS again when CG fails and fallback_to_direct
  /// is set), a Krylov solve from x_ as it is when `warm`, else from zero; the iterations and
  /// the relative residual into stats_.
  void solve_scaled(const char* where, bool warm = false);
  void release() {
    ksp_.reset();
    direct_.reset();
    scatter_.reset();
    for (OwnedVec* v : {&scale_, &b_, &x_, &values_, &ghosts_, &last_, &before_, &trial_, &residual_}) v->reset();
    a_.reset();
    k_.reset();
  }

  static NodeCondition condition_of(const ResolvedBoundary<Dim>& b, Index k) {
    NodeCondition c;
    c.kind = static_cast<int>(b.kinds[static_cast<std::size_t>(k)]);
    if (c.kind != sliding) return c;
    const auto basis = b.sliding_basis(k);  // the free directions
    const auto free_count = static_cast<int>(basis.cols());
    c.constrained = Dim - free_count;
    // Complete the free directions into an orthonormal frame: the constrained ones follow.
    const Eigen::HouseholderQR<Eigen::Matrix<double, Dim, Eigen::Dynamic>> qr{Eigen::Matrix<double, Dim, Eigen::Dynamic>(basis)};
    Frame q = qr.householderQ();
    q.leftCols(free_count) = basis;
    c.frame = q;
    return c;
  }

  DistributedElasticityOptions options_;
  MoverStats stats_;
  MPI_Comm comm_ = MPI_COMM_NULL;
  bool ready_ = false;
  Index n_local_ = 0;
  std::vector<Index> owned_nodes_;        ///< local indices of owned nodes, in PETSc row order
  std::vector<Index> ghost_nodes_;        ///< local indices of ghosts, in scatter order
  std::vector<NodeCondition> conditions_; ///< per local node
  std::vector<Index> owned_entries_;      ///< boundary entries of owned nodes
  std::vector<Index> entry_nodes_;        ///< their local nodes
  std::vector<PetscInt> entry_rows_;      ///< their positions among the owned nodes
  std::vector<PetscInt> dirichlet_;       ///< owned Dirichlet rows (global)
  Index boundary_size_ = 0;
  PetscInt first_row_ = 0;
  OwnedMat k_, a_;  ///< K in the rotated frames; the same with Dirichlet rows, scaled
  OwnedVec scale_, b_, x_, values_, ghosts_;
  OwnedVec last_, before_;  ///< the last two moves' solutions of the scaled system (empty until there are)
  OwnedVec trial_, residual_;  ///< a start being tried, a residual: work vectors of every solve
  detail::OwnedScatter scatter_;
  OwnedKsp ksp_, direct_;
  PetscSolverKind solver_kind_ = PetscSolverKind::automatic;
};

template <int Dim>
void DistributedElasticityMover<Dim>::build_solver(OwnedKsp& ksp, PetscSolverKind kind, const char* where) {
  using detail::petsc_check;
  petsc_check(KSPCreate(comm_, ksp.out()), where, "KSPCreate");
  petsc_check(KSPSetOperators(ksp.get(), a_.get(), a_.get()), where, "KSPSetOperators");
  PC pc = nullptr;
  petsc_check(KSPGetPC(ksp.get(), &pc), where, "KSPGetPC");
  if (kind == PetscSolverKind::direct_mumps) {
    detail::use_mumps_cholesky(ksp.get(), where);
  } else {
    petsc_check(KSPSetType(ksp.get(), KSPCG), where, "KSPSetType");
    if (kind == PetscSolverKind::cg_hypre) {
      petsc_check(PCSetType(pc, PCHYPRE), where, "PCSetType");
      petsc_check(PCHYPRESetType(pc, "boomeramg"), where, "PCHYPRESetType");
    } else {
      petsc_check(PCSetType(pc, PCGAMG), where, "PCSetType");
    }
    petsc_check(KSPSetTolerances(ksp.get(), options_.petsc_tolerance, 0.0, PETSC_DEFAULT, static_cast<PetscInt>(options_.petsc_max_iterations)), where, "KSPSetTolerances");
    petsc_check(KSPSetNormType(ksp.get(), KSP_NORM_UNPRECONDITIONED), where, "KSPSetNormType");
  }
  petsc_check(KSPSetOptionsPrefix(ksp.get(), options_.petsc_prefix.c_str()), where, "KSPSetOptionsPrefix");
  petsc_check(KSPSetFromOptions(ksp.get()), where, "KSPSetFromOptions");
  petsc_check(KSPSetUp(ksp.get()), where, "KSPSetUp");
}

template <int Dim>
void DistributedElasticityMover<Dim>::setup_mesh(const PartitionView<Dim>& part, const Mesh<Dim>& mesh,
                                                 const ResolvedBoundary<Dim>& boundary) {
  using detail::petsc_check;
  constexpr const char* where = "DistributedElasticityMover::setup";
  const meshmotion::detail::Stopwatch watch;
  ready_ = false;
  release();
  comm_ = part.comm;
  const int me = rank_of(comm_), p = size_of(comm_);
  const Index n = part.size();
  const ElasticityOptions& eo = options_.elasticity;
  collective(comm_, [&] {
    PetscBool initialized = PETSC_FALSE;
    PetscInitialized(&initialized);
    if (!initialized) throw InputError("DistributedElasticityMover::setup: PETSc is not initialized (call PetscInitialize first)");
    part.check("DistributedElasticityMover::setup");
    if (mesh.num_nodes() != n)
      throw InputError("DistributedElasticityMover::setup: the local mesh has " + std::to_string(mesh.num_nodes()) +
                       " nodes but the part " + std::to_string(n) + " (expected the same local nodes)");
    if (eo.distance_exponent != 0.0 || eo.active_radius != 0.0)
      throw InputError("DistributedElasticityMover::setup: distance_exponent and active_radius are not supported in "
                       "parallel (expected 0; the serial ElasticityMover has them)");
    if (!(eo.stiffening_exponent >= 0.0) || !std::isfinite(eo.stiffening_exponent))
      throw InputError("DistributedElasticityMover::setup: stiffening_exponent must be finite and >= 0 (got " +
                       std::to_string(eo.stiffening_exponent) + ")");
    if (!(options_.petsc_tolerance > 0.0)) throw InputError("DistributedElasticityMover::setup: petsc_tolerance must be positive");
    static_cast<void>(meshmotion::detail::lame_parameters(eo.youngs_modulus, eo.poisson_ratio, "DistributedElasticityMover::setup"));
    for (const auto& block : mesh.cells)
      for (const Index v : block.connectivity)
        if (v < 0 || v >= n)
          throw InputError("DistributedElasticityMover::setup: a " + std::string(name(block.type)) + " cell refers to local node " +
                           std::to_string(v) + " (expected 0 to " + std::to_string(n - 1) + ")");
    if (boundary.size() > 0) meshmotion::detail::check_boundary<Dim>("DistributedElasticityMover::setup", boundary, n, false);
  });
  n_local_ = n;
  boundary_size_ = boundary.size();

  // Rows: owned nodes in local order, contiguous per rank.
  owned_nodes_.clear();
  ghost_nodes_.clear();
  for (Index i = 0; i < n; ++i) (part.owns(i) ? owned_nodes_ : ghost_nodes_).push_back(i);
  const auto n_owned = static_cast<PetscInt>(owned_nodes_.size());
  PetscInt first_node = 0;
  MPI_Exscan(&n_owned, &first_node, 1, MPIU_INT, MPI_SUM, comm_);
  if (me == 0) first_node = 0;
  first_row_ = first_node * Dim;
  std::vector<PetscInt> row_of(static_cast<std::size_t>(n), -1);  // first dof of each local node
  std::vector<PetscInt> position(static_cast<std::size_t>(n), -1);
  for (PetscInt j = 0; j < n_owned; ++j) {
    row_of[static_cast<std::size_t>(owned_nodes_[static_cast<std::size_t>(j)])] = (first_node + j) * Dim;
    position[static_cast<std::size_t>(owned_nodes_[static_cast<std::size_t>(j)])] = j;
  }

  // Conditions of owned nodes from the owned entries; ghosts ask their owners for both.
  conditions_.assign(static_cast<std::size_t>(n), NodeCondition{});
  owned_entries_.clear();
  entry_nodes_.clear();
  entry_rows_.clear();
  for (Index k = 0; k < boundary.size(); ++k) {
    const Index v = boundary.nodes[static_cast<std::size_t>(k)];
    if (!part.owns(v)) continue;
    conditions_[static_cast<std::size_t>(v)] = condition_of(boundary, k);
    owned_entries_.push_back(k);
    entry_nodes_.push_back(v);
    entry_rows_.push_back(position[static_cast<std::size_t>(v)]);
  }
  std::unordered_map<std::int64_t, Index> owned_by_id;
  owned_by_id.reserve(owned_nodes_.size());
  for (const Index i : owned_nodes_) owned_by_id.emplace(part.global_ids[static_cast<std::size_t>(i)], i);
  std::vector<std::vector<std::int64_t>> asks(static_cast<std::size_t>(p));
  for (const Index i : ghost_nodes_) asks[static_cast<std::size_t>(part.owner[static_cast<std::size_t>(i)])].push_back(part.global_ids[static_cast<std::size_t>(i)]);
  const auto asked = parallel::exchange(comm_, asks);
  // Reply per asked node: its first row, kind, constrained count, frame.
  constexpr int reply_size = 3 + Dim * Dim;
  std::vector<std::vector<double>> replies(static_cast<std::size_t>(p));
  std::int64_t unknown_id = -1;
  for (int r = 0; r < p; ++r)
    for (const std::int64_t id : asked[static_cast<std::size_t>(r)]) {
      auto& out = replies[static_cast<std::size_t>(r)];
      const auto it = owned_by_id.find(id);
      if (it == owned_by_id.end()) {
        unknown_id = id;
        out.insert(out.end(), reply_size, 0.0);
        continue;
      }
      const NodeCondition& c = conditions_[static_cast<std::size_t>(it->second)];
      out.push_back(static_cast<double>(row_of[static_cast<std::size_t>(it->second)]));
      out.push_back(c.kind);
      out.push_back(c.constrained);
      out.insert(out.end(), c.frame.data(), c.frame.data() + Dim * Dim);
    }
  collective(comm_, [&] {
    if (unknown_id >= 0)
      throw InputError("DistributedElasticityMover::setup: another rank holds global node " + std::to_string(unknown_id) +
                       " as a ghost owned here, but this rank does not hold it");
  });
  const auto answers = parallel::exchange(comm_, replies);
  std::vector<std::size_t> at(static_cast<std::size_t>(p), 0);
  for (const Index i : ghost_nodes_) {
    const auto r = static_cast<std::size_t>(part.owner[static_cast<std::size_t>(i)]);
    const double* a = answers[r].data() + at[r];
    at[r] += reply_size;
    row_of[static_cast<std::size_t>(i)] = static_cast<PetscInt>(a[0]);
    NodeCondition& c = conditions_[static_cast<std::size_t>(i)];
    c.kind = static_cast<int>(a[1]);
    c.constrained = static_cast<int>(a[2]);
    c.frame = Eigen::Map<const Frame>(a + 3);
  }

  // J0 over the whole mesh, then this rank's cells.
  double j0 = eo.reference_jacobian;
  if (eo.stiffening_exponent != 0.0 && !(j0 > 0.0)) {
    double sums[2] = {0.0, static_cast<double>(mesh.num_cells())};
    collective(comm_, [&] { sums[0] = ElasticityMover<Dim>::total_cell_measure(mesh); });
    MPI_Allreduce(MPI_IN_PLACE, sums, 2, MPI_DOUBLE, MPI_SUM, comm_);
    j0 = sums[1] > 0.0 ? sums[0] / sums[1] : 0.0;
    collective(comm_, [&] {
      if (!(j0 > 0.0)) throw InputError("DistributedElasticityMover::setup: every cell has zero measure (expected a positive mean)");
    });
  }
  SparseMatrix k;
  collective(comm_, [&] { k = ElasticityMover<Dim>::assemble_stiffness(mesh, eo, j0); });
  // Rotate the dofs of sliding nodes into their frames: K ← Tᵀ K T.
  bool rotated = false;
  for (const auto& c : conditions_) rotated = rotated || c.kind == sliding;
  if (rotated) {
    std::vector<Eigen::Triplet<double>> t;
    t.reserve(static_cast<std::size_t>(n) * Dim * Dim);
    for (Index i = 0; i < n; ++i)
      for (int a = 0; a < Dim; ++a)
        for (int b = 0; b < Dim; ++b)
          if (const double f = conditions_[static_cast<std::size_t>(i)].frame(a, b); f != 0.0) t.emplace_back(i * Dim + a, i * Dim + b, f);
    SparseMatrix rotation(n * Dim, n * Dim);
    rotation.setFromTriplets(t.begin(), t.end());
    k = SparseMatrix(rotation.transpose() * k * rotation);
  }

  // COO assembly with global indices.
  std::vector<PetscInt> ci, cj;
  std::vector<PetscScalar> cv;
  ci.reserve(static_cast<std::size_t>(k.nonZeros()));
  cj.reserve(static_cast<std::size_t>(k.nonZeros()));
  cv.reserve(static_cast<std::size_t>(k.nonZeros()));
  for (Index c = 0; c < k.outerSize(); ++c)
    for (SparseMatrix::InnerIterator it(k, c); it; ++it) {
      ci.push_back(row_of[static_cast<std::size_t>(it.row() / Dim)] + static_cast<PetscInt>(it.row() % Dim));
      cj.push_back(row_of[static_cast<std::size_t>(it.col() / Dim)] + static_cast<PetscInt>(it.col() % Dim));
      cv.push_back(it.value());
    }
  const PetscInt local_rows = n_owned * Dim;
  petsc_check(MatCreate(comm_, k_.out()), where, "MatCreate");
  petsc_check(MatSetSizes(k_.get(), local_rows, local_rows, PETSC_DETERMINE, PETSC_DETERMINE), where, "MatSetSizes");
  petsc_check(MatSetType(k_.get(), MATAIJ), where, "MatSetType");
  petsc_check(MatSetBlockSize(k_.get(), Dim), where, "MatSetBlockSize");
  petsc_check(MatSetPreallocationCOO(k_.get(), static_cast<PetscCount>(ci.size()), ci.data(), cj.data()), where, "MatSetPreallocationCOO");
  petsc_check(MatSetValuesCOO(k_.get(), cv.data(), ADD_VALUES), where, "MatSetValuesCOO");
  ci = {}, cj = {}, cv = {};

  // Dirichlet dofs: prescribed and fixed nodes, the constrained directions of sliding ones,
  // and dofs without stiffness (a node in no cell).
  petsc_check(MatCreateVecs(k_.get(), x_.out(), b_.out()), where, "MatCreateVecs");
  petsc_check(VecDuplicate(x_.get(), values_.out()), where, "VecDuplicate");
  petsc_check(VecDuplicate(x_.get(), scale_.out()), where, "VecDuplicate");
  petsc_check(VecDuplicate(x_.get(), trial_.out()), where, "VecDuplicate");
  petsc_check(VecDuplicate(x_.get(), residual_.out()), where, "VecDuplicate");
  petsc_check(MatGetDiagonal(k_.get(), scale_.get()), where, "MatGetDiagonal");
  dirichlet_.clear();
  {
    const PetscScalar* diag = nullptr;
    petsc_check(VecGetArrayRead(scale_.get(), &diag), where, "VecGetArrayRead");
    for (PetscInt j = 0; j < n_owned; ++j) {
      const NodeCondition& c = conditions_[static_cast<std::size_t>(owned_nodes_[static_cast<std::size_t>(j)])];
      for (int a = 0; a < Dim; ++a) {
        const bool held = c.kind == prescribed || c.kind == fixed || (c.kind == sliding && a >= Dim - c.constrained) ||
                          !(diag[j * Dim + a] != 0.0);
        if (held) dirichlet_.push_back(first_row_ + j * Dim + a);
      }
    }
    petsc_check(VecRestoreArrayRead(scale_.get(), &diag), where, "VecRestoreArrayRead");
  }
  petsc_check(MatDuplicate(k_.get(), MAT_COPY_VALUES, a_.out()), where, "MatDuplicate");
  petsc_check(MatZeroRowsColumns(a_.get(), static_cast<PetscInt>(dirichlet_.size()), dirichlet_.data(), 1.0, nullptr, nullptr),
              where, "MatZeroRowsColumns");
  // Symmetric diagonal scaling: s = diag^-1/2.
  petsc_check(MatGetDiagonal(a_.get(), scale_.get()), where, "MatGetDiagonal");
  double smallest = 0.0;
  petsc_check(VecMin(scale_.get(), nullptr, &smallest), where, "VecMin");
  collective(comm_, [&] {
    if (!(smallest > 0.0))
      throw SolverError("DistributedElasticityMover::setup: the stiffness matrix has a non-positive diagonal entry "
                        "(an inverted cell, or a material that is not positive definite)");
  });
  petsc_check(VecSqrtAbs(scale_.get()), where, "VecSqrtAbs");
  petsc_check(VecReciprocal(scale_.get()), where, "VecReciprocal");
  petsc_check(MatDiagonalScale(a_.get(), scale_.get(), scale_.get()), where, "MatDiagonalScale");
  petsc_check(MatSetOption(a_.get(), MAT_SYMMETRIC, PETSC_TRUE), where, "MatSetOption");
  petsc_check(MatSetOption(a_.get(), MAT_SPD, PETSC_TRUE), where, "MatSetOption");
  if (options_.petsc_solver == PetscSolverKind::cg_gamg || (options_.petsc_solver == PetscSolverKind::automatic && Dim == 3)) {
    // Rigid-body modes of the owned nodes (in the unrotated frame: near enough for the AMG).
    OwnedVec coordinates;
    petsc_check(VecCreateMPI(comm_, local_rows, PETSC_DETERMINE, coordinates.out()), where, "VecCreateMPI");
    petsc_check(VecSetBlockSize(coordinates.get(), Dim), where, "VecSetBlockSize");
    PetscScalar* xyz = nullptr;
    petsc_check(VecGetArray(coordinates.get(), &xyz), where, "VecGetArray");
    for (PetscInt j = 0; j < n_owned; ++j)
      for (int a = 0; a < Dim; ++a) xyz[j * Dim + a] = part.points(a, owned_nodes_[static_cast<std::size_t>(j)]);
    petsc_check(VecRestoreArray(coordinates.get(), &xyz), where, "VecRestoreArray");
    detail::OwnedNullSpace modes;
    petsc_check(MatNullSpaceCreateRigidBody(coordinates.get(), modes.out()), where, "MatNullSpaceCreateRigidBody");
    petsc_check(MatSetNearNullSpace(a_.get(), modes.get()), where, "MatSetNearNullSpace");
  }
  solver_kind_ = options_.petsc_solver != PetscSolverKind::automatic ? options_.petsc_solver
                 : Dim == 2                                   ? PetscSolverKind::direct_mumps
                                                              : PetscSolverKind::cg_gamg;
  build_solver(ksp_, solver_kind_, where);

  // Ghost values come from their owners' rows.
  std::vector<PetscInt> from;
  from.reserve(ghost_nodes_.size() * Dim);
  for (const Index i : ghost_nodes_)
    for (int a = 0; a < Dim; ++a) from.push_back(row_of[static_cast<std::size_t>(i)] + a);
  detail::OwnedIs is_from, is_to;
  petsc_check(ISCreateGeneral(PETSC_COMM_SELF, static_cast<PetscInt>(from.size()), from.data(), PETSC_COPY_VALUES, is_from.out()), where, "ISCreateGeneral");
  petsc_check(ISCreateStride(PETSC_COMM_SELF, static_cast<PetscInt>(from.size()), 0, 1, is_to.out()), where, "ISCreateStride");
  petsc_check(VecCreateSeq(PETSC_COMM_SELF, static_cast<PetscInt>(from.size()), ghosts_.out()), where, "VecCreateSeq");
  petsc_check(VecScatterCreate(x_.get(), is_from.get(), ghosts_.get(), is_to.get(), scatter_.out()), where, "VecScatterCreate");

  MatInfo info;
  MatGetInfo(a_.get(), MAT_LOCAL, &info);
  stats_ = MoverStats{};
  stats_.boundary_nodes = static_cast<Index>(owned_entries_.size());
  MPI_Allreduce(MPI_IN_PLACE, &stats_.boundary_nodes, 1, MPI_INT64_T, MPI_SUM, comm_);
  stats_.evaluated_nodes = n_owned;
  stats_.nonzeros = static_cast<Index>(info.nz_used);
  stats_.factorizations = 1;
  ready_ = true;
  stats_.setup_seconds = watch.seconds();
}

template <int Dim>
void DistributedElasticityMover<Dim>::move_into(PointsView<Dim> d, Points<Dim>& out) {
  solve_for(d, out, true);
}

template <int Dim>
void DistributedElasticityMover<Dim>::solve_for(PointsView<Dim> d, Points<Dim>& out, bool step) {
  using detail::petsc_check;
  constexpr const char* where = "DistributedElasticityMover::move";
  const meshmotion::detail::Stopwatch watch;
  collective(comm_, [&] {
    if (!ready_) throw InputError("DistributedElasticityMover::move: setup() was not called");
    if (d.cols() != boundary_size_)
      throw InputError("DistributedElasticityMover::move: got " + std::to_string(d.cols()) + " displacements (expected " +
                       std::to_string(boundary_size_) + ", one per local boundary entry)");
    for (const Index k : owned_entries_)
      if (!d.col(k).allFinite())
        throw InputError("DistributedElasticityMover::move: boundary entry " + std::to_string(k) + " has a non-finite displacement");
  });
  // values_: the prescribed displacements on their owned rows, zero elsewhere.
  petsc_check(VecSet(values_.get(), 0.0), where, "VecSet");
  PetscScalar* v = nullptr;
  petsc_check(VecGetArray(values_.get(), &v), where, "VecGetArray");
  for (std::size_t e = 0; e < owned_entries_.size(); ++e) {
    const Index k = owned_entries_[e];
    if (conditions_[static_cast<std::size_t>(entry_nodes_[e])].kind != prescribed) continue;
    for (int a = 0; a < Dim; ++a) v[entry_rows_[e] * Dim + a] = d(a, k);
  }
  std::vector<double> held(dirichlet_.size());
  for (std::size_t r = 0; r < held.size(); ++r) held[r] = v[dirichlet_[r] - first_row_];
  petsc_check(VecRestoreArray(values_.get(), &v), where, "VecRestoreArray");
  // b = −K u_D on free rows, u_D on Dirichlet rows; then scaled like the matrix.
  petsc_check(MatMult(k_.get(), values_.get(), b_.get()), where, "MatMult");
  petsc_check(VecScale(b_.get(), -1.0), where, "VecScale");
  PetscScalar* b = nullptr;
  petsc_check(VecGetArray(b_.get(), &b), where, "VecGetArray");
  for (std::size_t r = 0; r < held.size(); ++r) b[dirichlet_[r] - first_row_] = held[r];
  petsc_check(VecRestoreArray(b_.get(), &b), where, "VecRestoreArray");
  petsc_check(VecPointwiseMult(b_.get(), b_.get(), scale_.get()), where, "VecPointwiseMult");
  const meshmotion::detail::Stopwatch solving;
  solve_scaled(where, step && choose_start(where));
  const double solve_seconds = solving.seconds();
  if (step) {
    std::swap(before_, last_);
    if (!last_) petsc_check(VecDuplicate(x_.get(), last_.out()), where, "VecDuplicate");
    petsc_check(VecCopy(x_.get(), last_.get()), where, "VecCopy");
  }
  petsc_check(VecPointwiseMult(x_.get(), x_.get(), scale_.get()), where, "VecPointwiseMult");
  // Dirichlet values exactly, whatever the Krylov iterate left there.
  PetscScalar* x = nullptr;
  petsc_check(VecGetArray(x_.get(), &x), where, "VecGetArray");
  for (std::size_t r = 0; r < held.size(); ++r) x[dirichlet_[r] - first_row_] = held[r];
  out.resize(Dim, n_local_);
  for (std::size_t j = 0; j < owned_nodes_.size(); ++j) {
    const Index i = owned_nodes_[j];
    out.col(i) = conditions_[static_cast<std::size_t>(i)].frame * Eigen::Map<const Vec<Dim>>(x + j * Dim);
  }
  petsc_check(VecRestoreArray(x_.get(), &x), where, "VecRestoreArray");
  petsc_check(VecScatterBegin(scatter_.get(), x_.get(), ghosts_.get(), INSERT_VALUES, SCATTER_FORWARD), where, "VecScatterBegin");
  petsc_check(VecScatterEnd(scatter_.get(), x_.get(), ghosts_.get(), INSERT_VALUES, SCATTER_FORWARD), where, "VecScatterEnd");
  const PetscScalar* g = nullptr;
  petsc_check(VecGetArrayRead(ghosts_.get(), &g), where, "VecGetArrayRead");
  for (std::size_t j = 0; j < ghost_nodes_.size(); ++j) {
    const Index i = ghost_nodes_[j];
    out.col(i) = conditions_[static_cast<std::size_t>(i)].frame * Eigen::Map<const Vec<Dim>>(g + j * Dim);
  }
  petsc_check(VecRestoreArrayRead(ghosts_.get(), &g), where, "VecRestoreArrayRead");
  ++stats_.moves;
  stats_.move_seconds = watch.seconds();
  stats_.solve_seconds = solve_seconds;
  stats_.rebuild_seconds = 0.0;
}

template <int Dim>
Points<Dim> DistributedElasticityMover<Dim>::derivative_reverse(PointsView<Dim> v) {
  using detail::petsc_check;
  constexpr const char* where = "DistributedElasticityMover::derivative_reverse";
  collective(comm_, [&] {
    if (!ready_) throw InputError("DistributedElasticityMover::derivative_reverse: setup() was not called");
    meshmotion::detail::check_node_field<Dim>(where, v, n_local_);
  });
  // x̄: the owned nodes' seeds in their frames (a ghost's term is its owner's).
  PetscScalar* seed = nullptr;
  petsc_check(VecGetArray(values_.get(), &seed), where, "VecGetArray");
  for (std::size_t j = 0; j < owned_nodes_.size(); ++j) {
    const Index i = owned_nodes_[j];
    Eigen::Map<Vec<Dim>>(seed + j * Dim) = conditions_[static_cast<std::size_t>(i)].frame.transpose() * v.col(i);
  }
  petsc_check(VecRestoreArray(values_.get(), &seed), where, "VecRestoreArray");
  // y = K_FF⁻¹ x̄_F through the scaled system: b = S x̄ with zero Dirichlet rows, y = S x.
  petsc_check(VecPointwiseMult(b_.get(), values_.get(), scale_.get()), where, "VecPointwiseMult");
  PetscScalar* b = nullptr;
  petsc_check(VecGetArray(b_.get(), &b), where, "VecGetArray");
  for (const PetscInt row : dirichlet_) b[row - first_row_] = 0.0;
  petsc_check(VecRestoreArray(b_.get(), &b), where, "VecRestoreArray");
  solve_scaled(where);
  petsc_check(VecPointwiseMult(x_.get(), x_.get(), scale_.get()), where, "VecPointwiseMult");
  PetscScalar* x = nullptr;
  petsc_check(VecGetArray(x_.get(), &x), where, "VecGetArray");
  for (const PetscInt row : dirichlet_) x[row - first_row_] = 0.0;
  petsc_check(VecRestoreArray(x_.get(), &x), where, "VecRestoreArray");
  petsc_check(MatMult(k_.get(), x_.get(), b_.get()), where, "MatMult");
  // A prescribed node's rows are its own (no frame): its gradient is x̄ − K y there.
  Points<Dim> gradient = Points<Dim>::Zero(Dim, boundary_size_);
  const PetscScalar* x_bar = nullptr;
  petsc_check(VecGetArrayRead(values_.get(), &x_bar), where, "VecGetArrayRead");
  const PetscScalar* ky = nullptr;
  petsc_check(VecGetArrayRead(b_.get(), &ky), where, "VecGetArrayRead");
  for (std::size_t e = 0; e < owned_entries_.size(); ++e) {
    if (conditions_[static_cast<std::size_t>(entry_nodes_[e])].kind != prescribed) continue;
    const std::size_t at = static_cast<std::size_t>(entry_rows_[e]) * Dim;
    for (int a = 0; a < Dim; ++a) gradient(a, owned_entries_[e]) = x_bar[at + static_cast<std::size_t>(a)] - ky[at + static_cast<std::size_t>(a)];
  }
  petsc_check(VecRestoreArrayRead(b_.get(), &ky), where, "VecRestoreArrayRead");
  petsc_check(VecRestoreArrayRead(values_.get(), &x_bar), where, "VecRestoreArrayRead");
  return gradient;
}

template <int Dim>
bool DistributedElasticityMover<Dim>::choose_start(const char* where) {
  using detail::petsc_check;
  if (!last_ || solver_kind_ == PetscSolverKind::direct_mumps) return false;
  const auto misfit = [&](::Vec start) {
    petsc_check(MatMult(a_.get(), start, residual_.get()), where, "MatMult");
    petsc_check(VecAYPX(residual_.get(), -1.0, b_.get()), where, "VecAYPX");
    PetscReal norm = 0.0;
    petsc_check(VecNorm(residual_.get(), NORM_2, &norm), where, "VecNorm");
    return norm;
  };
  PetscReal best = 0.0;
  petsc_check(VecNorm(b_.get(), NORM_2, &best), where, "VecNorm");
  bool warm = false;
  const auto consider = [&](::Vec start) {
    const PetscReal norm = misfit(start);
    if (!(norm < best)) return;
    best = norm;
    warm = true;
    petsc_check(VecCopy(start, x_.get()), where, "VecCopy");
  };
  consider(last_.get());
  if (before_) {
    petsc_check(VecWAXPY(trial_.get(), -1.0, before_.get(), last_.get()), where, "VecWAXPY");
    petsc_check(VecAYPX(trial_.get(), 1.0, last_.get()), where, "VecAYPX");  // 2 last − before
    consider(trial_.get());
  }
  return warm;
}

template <int Dim>
void DistributedElasticityMover<Dim>::solve_scaled(const char* where, bool warm) {
  using detail::petsc_check;
  PetscReal rhs_norm = 0.0;
  petsc_check(VecNorm(b_.get(), NORM_2, &rhs_norm), where, "VecNorm");
  // MUMPS's preonly solve takes no start; a Krylov solve's relative test is against ‖b‖ either way.
  if (solver_kind_ != PetscSolverKind::direct_mumps)
    petsc_check(KSPSetInitialGuessNonzero(ksp_.get(), warm ? PETSC_TRUE : PETSC_FALSE), where, "KSPSetInitialGuessNonzero");
  petsc_check(KSPSolve(ksp_.get(), b_.get(), x_.get()), where, "KSPSolve");
  KSPConvergedReason reason = KSP_CONVERGED_ITERATING;
  petsc_check(KSPGetConvergedReason(ksp_.get(), &reason), where, "KSPGetConvergedReason");
  PetscInt iterations = 0;
  petsc_check(KSPGetIterationNumber(ksp_.get(), &iterations), where, "KSPGetIterationNumber");
  stats_.fell_back = false;
  // The reason is the same on every rank, so every rank raises or falls back alike.
  if (reason < 0) {
    if (!options_.petsc_fallback_to_direct) {
      throw SolverError(std::string(where) + ": CG did not converge (PETSc reason " + std::to_string(static_cast<int>(reason)) +
                        " after " + std::to_string(iterations) + " iterations; tolerance " + std::to_string(options_.petsc_tolerance) +
                        "); set fallback_to_direct or another solver");
    }
    if (!direct_) build_solver(direct_, PetscSolverKind::direct_mumps, where);
    petsc_check(KSPSolve(direct_.get(), b_.get(), x_.get()), where, "KSPSolve");
    stats_.fell_back = true;
  }
  petsc_check(MatMult(a_.get(), x_.get(), residual_.get()), where, "MatMult");
  petsc_check(VecAYPX(residual_.get(), -1.0, b_.get()), where, "VecAYPX");
  PetscReal residual_norm = 0.0;
  petsc_check(VecNorm(residual_.get(), NORM_2, &residual_norm), where, "VecNorm");
  stats_.iterations = iterations;
  stats_.residual = rhs_norm > 0.0 ? residual_norm / rhs_norm : 0.0;
}

}  // namespace meshmotion::parallel

// The compiled parallel library (target meshmotion::parallel, src/parallel.cpp) holds these.
#ifdef MESHMOTION_PARALLEL_COMPILED
namespace meshmotion::parallel {
extern template class DistributedElasticityMover<2>;
extern template class DistributedElasticityMover<3>;
}  // namespace meshmotion::parallel
#endif
