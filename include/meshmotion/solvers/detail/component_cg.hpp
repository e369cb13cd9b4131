#pragma once
/// \file
/// ComponentCg: conjugate gradients for a coupled mechanics system (several unknowns per node,
/// elasticity) preconditioned by one Cholesky factorization of the nodes' scalar matrix, the
/// mean of the components' diagonal blocks, applied to every component at once (the separate
/// displacement component preconditioner: for an isotropic body held on part of its boundary
/// the preconditioned condition number is bounded by Korn's constant, about 2 + λ/μ = 3.5 at
/// ν = 0.3, whatever the mesh size and the stiffening, which scales both matrices alike). Each
/// solve starts from the projection of its right-hand side on the earlier solutions (Fischer,
/// "Projection techniques for iterative solution of Ax = b with successive right-hand sides",
/// 1998): the moves of a time loop or an optimizer are few families (a body turning about an
/// axis is two), so after the first moves a solve takes a few iterations.
///
/// With CHOLMOD the factor is then rounded to single precision in place and solved through
/// the BLAS (SingleSupernodalFactor): an iteration reads half the bytes, and the preconditioner
/// it changes is still SPD, so CG stops at the same test.
///
/// Why: a 3D coupled system's direct factor holds Dim² times the scalar one's entries and
/// costs about Dim³ times its work (256k unknowns: 25–33 s and 4.5 GB against 2 s and 0.3 GB
/// here). A solve that does not converge in max_iterations factorizes the coupled system
/// directly once (SolverReport::fell_back) and answers every later solve from it. So does a
/// run whose iterations add up to what that factorization costs (direct_after): a long run of
/// motions that keep changing shape then pays at most about twice the cheaper of the two.

#include "meshmotion/core/error.hpp"
#include "meshmotion/core/types.hpp"
#include "meshmotion/solvers/detail/cholmod_library.hpp"
#include "meshmotion/solvers/detail/stopwatch.hpp"
#include "meshmotion/solvers/linear_solver.hpp"
#include "meshmotion/solvers/solver_options.hpp"

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

namespace meshmotion::detail {

/// Earlier solutions of one matrix A, A-orthonormal (xᵢᵀ A xⱼ = δᵢⱼ), with their images A xᵢ:
/// Σ xᵢ (xᵢᵀ b) is the combination of them nearest to A⁻¹ b in the energy norm. One per stream
/// of right-hand sides (a mover's moves and its reverse derivatives are different families).
struct SolutionHistory {
  std::vector<Eigen::VectorXd> solutions, images;
  void clear() {
    solutions.clear();
    images.clear();
  }
};

class ComponentCg {
 public:
  /// A solve stops when the preconditioned residual M⁻¹ r, the preconditioner's estimate of
  /// the error A⁻¹ r, is at most this fraction of the solution, node by node (max norms). In
  /// displacement units, as the stiffening asks: an energy-norm test is dominated by the
  /// stiffest cells and leaves the soft ones' error orders of magnitude larger (a box graded
  /// 1:5000 towards its wall: 1e-5 of the displacement behind an energy test at 1e-10).
  static constexpr double tolerance = 1e-9;
  /// Solutions kept per history; past it the oldest goes (the rest stay orthonormal).
  static constexpr std::size_t history_size = 10;
  static constexpr Index max_iterations = 200;

  /// Iterations whose time, added up, matches the coupled system's direct factorization on
  /// `rows` unknowns: measured 270 at 222k unknowns (35 s against 0.13 s an iteration, one
  /// thread), 160 at 59k; the factorization's work grows as rows², an iteration's as
  /// rows^(4/3).
  [[nodiscard]] static Index direct_after(Index rows) {
    return static_cast<Index>(270.0 * std::pow(static_cast<double>(rows) / 222264.0, 2.0 / 3.0));
  }

  /// `a`: the SPD matrix of the unknowns; `lift`: unknowns → the Cartesian dofs (`components`
  /// per node, node-major) of the nodes that hold unknowns (a sliding node's tangent unknowns
  /// through its basis); `nodes`: those nodes' scalar matrix; `direct_after`: the iterations
  /// after which the coupled system is factorized (SolverOptions::coupled_direct_after_iterations).
  /// A scalar matrix that is not positive definite factorizes the coupled system instead
  /// (SolverError when that fails too).
  void compute(SparseMatrix a, SparseMatrix lift, const SparseMatrix& nodes, int components, Index direct_after) {
    const Stopwatch watch;
    a_ = std::move(a);
    lift_ = std::move(lift);
    lift_transpose_ = lift_.transpose();
    components_ = components;
    direct_.reset();
    iterations_ = 0;
    direct_after_ = direct_after < 0 ? ComponentCg::direct_after(a_.rows()) : direct_after;
    factor_ = std::make_unique<NodeFactor>();
    factor_->analyzePattern(nodes);
    factor_->factorize(nodes);
    report_ = SolverReport{};
    report_.analyses = report_.factorizations = 1;
    report_.supernodal = have_cholmod();
    report_.component_cg = true;
    // A nodal matrix that is not positive definite (a tangent stiffness past a fold, which the
    // direct LDLᵀ still takes): the coupled system is factorized as before.
    if (factor_->info() != Eigen::Success) {
      fall_back();
      report_.fell_back = true;
    }
#ifdef MESHMOTION_HAVE_CHOLMOD
    // The preconditioner's solves in single precision: half the factor's bytes to read at each
    // iteration, and the double factor freed.
    single_.reset();
    if (factor_) {
      auto single = std::make_unique<SingleSupernodalFactor>();
      if (single->take(factor_)) single_ = std::move(single);
    }
#endif
    report_.seconds = watch.seconds();
  }

  /// x = A⁻¹ b for each column of b, each started from its projection on `history`, to which
  /// the new solutions are added.
  void solve(const Eigen::MatrixXd& b, Eigen::MatrixXd& x, SolutionHistory& history) {
    const Stopwatch watch;
    x.resize(b.rows(), b.cols());
    report_.iterations = 0;
    report_.residual = 0.0;
    for (Index c = 0; c < b.cols(); ++c) {
      rhs_ = b.col(c);
      if (!direct_ && !iterate(history)) {
        fall_back();
        report_.fell_back = true;
      }
      if (direct_) {
        column_ = direct_->solve(rhs_);
        residual_ = rhs_ - a_ * column_;
      }
      const double norm_b = rhs_.norm();
      report_.residual = std::max(report_.residual, norm_b > 0.0 ? residual_.norm() / norm_b : residual_.norm());
      x.col(c) = column_;
    }
    if (!direct_ && direct_after_ > 0 && iterations_ >= direct_after_) fall_back();
    report_.seconds += watch.seconds();
  }

  [[nodiscard]] const SolverReport& report() const noexcept { return report_; }

 private:
#ifdef MESHMOTION_HAVE_CHOLMOD
  using NodeFactor = CholmodSupernodalLLT;
#else
  using NodeFactor = Eigen::SimplicialLLT<SparseMatrix, Eigen::Lower>;
#endif

  /// CG on rhs_ into column_ (residual_ its residual); false when it did not converge.
  bool iterate(SolutionHistory& history) {
    column_.setZero(rhs_.size());
    for (std::size_t k = 0; k < history.solutions.size(); ++k) column_ += history.solutions[k] * history.solutions[k].dot(rhs_);
    residual_ = rhs_ - a_ * column_;
    precondition(residual_, preconditioned_);
    direction_ = preconditioned_;
    double rz = residual_.dot(preconditioned_);
    Index iterations = 0;
    while (!(preconditioned_.cwiseAbs().maxCoeff() <= tolerance * column_.cwiseAbs().maxCoeff())) {
      if (iterations == max_iterations || !std::isfinite(rz)) return false;
      image_.noalias() = a_ * direction_;
      const double step = rz / direction_.dot(image_);
      column_ += step * direction_;
      residual_ -= step * image_;
      precondition(residual_, preconditioned_);
      const double next = residual_.dot(preconditioned_);
      direction_ = preconditioned_ + (next / rz) * direction_;
      rz = next;
      ++iterations;
    }
    report_.iterations = std::max(report_.iterations, iterations);
    iterations_ += iterations;
    if (iterations > 0) remember(history);
    return true;
  }

  /// Adds column_ to `history`, A-orthogonalized (twice, as Gram–Schmidt needs in floating
  /// point), when it brings more than round-off beyond the solutions already there. What is
  /// left is the correction the iterations made to the projection: kept even when small, as
  /// the earlier solutions' error grows with the coefficients a later move gives them (a turn
  /// of 30° in 20 steps weighs the first step's 1 − cos θ term by 400).
  void remember(SolutionHistory& history) {
    image_ = rhs_ - residual_;  // A x to the solve's accuracy, without another product
    direction_ = column_;
    const double energy = std::sqrt(std::max(direction_.dot(image_), 0.0));
    for (int pass = 0; pass < 2; ++pass)
      for (std::size_t k = 0; k < history.solutions.size(); ++k) {
        const double along = history.images[k].dot(direction_);
        direction_ -= along * history.solutions[k];
        image_ -= along * history.images[k];
      }
    const double left = std::sqrt(std::max(direction_.dot(image_), 0.0));
    if (!(left > 1e-12 * energy)) return;
    if (history.solutions.size() == history_size) {
      history.solutions.erase(history.solutions.begin());
      history.images.erase(history.images.begin());
    }
    history.solutions.push_back(direction_ / left);
    history.images.push_back(image_ / left);
  }

  /// z = Liftᵀ diag(S⁻¹, …, S⁻¹) Lift r: one solve of the nodal factor for all components.
  void precondition(const Eigen::VectorXd& r, Eigen::VectorXd& z) {
    cartesian_.noalias() = lift_ * r;
    const Index nodes = cartesian_.size() / components_;
    by_component_ = Eigen::Map<const Eigen::MatrixXd>(cartesian_.data(), components_, nodes).transpose();
#ifdef MESHMOTION_HAVE_CHOLMOD
    if (single_) {
      single_->solve_in_place(by_component_);
      solved_.swap(by_component_);
    } else
#endif
      solved_ = factor_->solve(by_component_);
    if (solved_.rows() != nodes) throw SolverError("component CG: the nodal factor's solve failed");
    Eigen::Map<Eigen::MatrixXd>(cartesian_.data(), components_, nodes) = solved_.transpose();
    z.noalias() = lift_transpose_ * cartesian_;
  }

  /// Factorizes the coupled system; every later solve is direct.
  void fall_back() {
    SolverOptions direct;
    direct.coupled_cg_min_rows = 0;
    direct_ = std::make_unique<LinearSolver>(direct);
    direct_->compute(a_);
    report_.factorizations += direct_->report().factorizations;
    report_.component_cg = false;
    factor_.reset();
#ifdef MESHMOTION_HAVE_CHOLMOD
    single_.reset();
#endif
  }

  SparseMatrix a_, lift_, lift_transpose_;
  int components_ = 1;
  Index iterations_ = 0;  ///< since compute()
  Index direct_after_ = 0;
  std::unique_ptr<NodeFactor> factor_;
#ifdef MESHMOTION_HAVE_CHOLMOD
  std::unique_ptr<SingleSupernodalFactor> single_;  ///< factor_ in single precision, when it could be made
#endif
  std::unique_ptr<LinearSolver> direct_;
  SolverReport report_;
  Eigen::VectorXd rhs_, column_, residual_, preconditioned_, direction_, image_, cartesian_;
  Eigen::MatrixXd by_component_, solved_;
};

}  // namespace meshmotion::detail
