#pragma once
/// \file
/// AnyMover<Dim>: any MeshMover behind one type, for movers chosen at run time (make_mover()
/// in movers/registry.hpp builds the registered ones by method name).

#include "meshmotion/core/error.hpp"
#include "meshmotion/core/mesh_like.hpp"
#include "meshmotion/movers/detail/mover_support.hpp"
#include "meshmotion/movers/mover.hpp"

#include <atomic>
#include <concepts>
#include <memory>
#include <string>

namespace meshmotion {

/// A type-erased MeshMover over Mesh<Dim>.
///
/// One mover serves one thread at a time: setup, move and the derivatives use the mover's own
/// scratch (factorizations, buffers), and copies of an AnyMover share one mover. A call made
/// while another thread is inside one of them throws SolverError instead of returning a wrong
/// mesh. Give each thread its own mover (make_mover() again, and setup) to move concurrently.
template <int Dim>
class AnyMover {
 public:
  static constexpr int dim = Dim;

  template <MeshMover M>
    requires(M::dim == Dim)
  explicit AnyMover(M mover) : self_(std::make_shared<Model<M>>(std::move(mover))) {}

  void setup(const Mesh<Dim>& mesh, const ResolvedBoundary<Dim>& boundary) {
    const Exclusive use(*self_, "setup");
    self_->setup(mesh, boundary);
  }
  /// A solver's own mesh type: copied into a Mesh<Dim> for the mover, which keeps what it
  /// needs of it anyway.
  template <MeshLike M>
    requires(mesh_dim<M> == Dim && !std::same_as<M, Mesh<Dim>>)
  void setup(const M& mesh, const ResolvedBoundary<Dim>& boundary) {
    setup(to_mesh(mesh), boundary);
  }
  [[nodiscard]] Points<Dim> move(PointsView<Dim> d) {
    Points<Dim> out;
    move_into(d, out);
    return out;
  }
  /// Throws SolverError when the mover returns a non-finite displacement (a defect of the
  /// mover, refused rather than written into a mesh).
  void move_into(PointsView<Dim> d, Points<Dim>& out) {
    const Exclusive use(*self_, "move");
    self_->move_into(d, out);
    check_finite(out);
  }
  /// Into the caller's own storage (an Eigen::Map over a solver's array of Dim × n_nodes
  /// doubles): the RBF mover writes there directly, the others through a buffer of their own
  /// (no allocation after the first move). Throws InputError when its shape is not Dim × n_nodes.
  void move_into(PointsView<Dim> d, Eigen::Ref<Points<Dim>> out) {
    const Exclusive use(*self_, "move");
    self_->move_into_storage(d, out);
    check_finite(out);
  }
  [[nodiscard]] MoverStats stats() const { return self_->stats(); }

  /// True when the mover offers derivative_forward and derivative_reverse (the movers linear
  /// in the boundary displacements that implement them).
  [[nodiscard]] bool has_derivatives() const { return self_->has_derivatives(); }
  /// J w for a boundary displacement change w (Dim × boundary size): the movers linear in the
  /// displacements (RBF, springs, torsion springs, linear and stiffened elasticity, DGM,
  /// improved DGM, DGRBF).
  /// Throws InputError when the mover has no derivatives.
  [[nodiscard]] Points<Dim> derivative_forward(PointsView<Dim> w) {
    const Exclusive use(*self_, "derivative_forward");
    return self_->derivative_forward(w);
  }
  /// The grid velocity an ALE solver needs: every node's velocity (Dim × n_nodes) for the
  /// boundary nodes' velocities `boundary_velocities` (Dim × boundary size), through the map of
  /// the current move: for positions x(t) = X + move(d(t)) of a mover linear in the
  /// displacements, dx/dt = J ḋ(t), exactly (no difference of positions; the RBF's map between
  /// two growths of its default radius, the last move's). Sliding nodes get their projected
  /// velocity. Throws InputError for a mover whose move is not linear in the displacements
  /// (nle, dgrbf2): their grid velocity is a difference of positions.
  [[nodiscard]] Points<Dim> velocity(PointsView<Dim> boundary_velocities) {
    const Exclusive use(*self_, "velocity");
    if (!self_->has_derivatives())
      throw InputError("AnyMover::velocity: this mover's move is not linear in the displacements (nle, dgrbf2): take the "
                       "grid velocity as a difference of positions in time, or use a mover with derivatives (rbf, spring, "
                       "torsion, le, sle, dgm, idgm, dgrbf)");
    return self_->derivative_forward(boundary_velocities);
  }
  /// Jᵀ v for v (Dim × n_nodes): the gradient of ⟨v, move(d)⟩ with respect to d.
  /// Throws InputError when the mover has no derivatives.
  [[nodiscard]] Points<Dim> derivative_reverse(PointsView<Dim> v) {
    const Exclusive use(*self_, "derivative_reverse");
    return self_->derivative_reverse(v);
  }

 private:
  template <class Out>
  static void check_finite(const Out& out) {
    if (out.allFinite()) return;
    Index node = 0;
    while (node < out.cols() && out.col(node).allFinite()) ++node;
    throw SolverError("AnyMover::move: the mover returned a non-finite displacement at node " + std::to_string(node) +
                      " (a defect of the mover for this mesh and boundary: please report it)");
  }

  struct Concept {
    virtual ~Concept() = default;
    virtual void setup(const Mesh<Dim>&, const ResolvedBoundary<Dim>&) = 0;
    virtual void move_into(PointsView<Dim>, Points<Dim>&) = 0;
    virtual void move_into_storage(PointsView<Dim>, Eigen::Ref<Points<Dim>>) = 0;
    [[nodiscard]] virtual MoverStats stats() const = 0;
    [[nodiscard]] virtual bool has_derivatives() const = 0;
    [[nodiscard]] virtual Points<Dim> derivative_forward(PointsView<Dim>) = 0;
    [[nodiscard]] virtual Points<Dim> derivative_reverse(PointsView<Dim>) = 0;
    std::atomic<bool> busy{false};
  };
  // Holds the mover for one call; throws SolverError when another thread holds it.
  class Exclusive {
   public:
    Exclusive(Concept& c, const char* call) : c_(c) {
      if (c_.busy.exchange(true, std::memory_order_acquire))
        throw SolverError(std::string("AnyMover::") + call + ": the mover is in use by another thread (one mover serves "
                          "one thread at a time: give each thread its own)");
    }
    Exclusive(const Exclusive&) = delete;
    Exclusive& operator=(const Exclusive&) = delete;
    ~Exclusive() { c_.busy.store(false, std::memory_order_release); }

   private:
    Concept& c_;
  };
  template <class M>
  struct Model final : Concept {
    static constexpr bool differentiable = requires(M& m, const Points<Dim>& v, PointsView<Dim> r) {
      { m.derivative_forward(v) } -> std::same_as<Points<Dim>>;
      { m.derivative_reverse(r) } -> std::same_as<Points<Dim>>;
    };
    explicit Model(M m) : mover(std::move(m)) {}
    void setup(const Mesh<Dim>& mesh, const ResolvedBoundary<Dim>& b) override { mover.setup(mesh, b); }
    void move_into(PointsView<Dim> d, Points<Dim>& out) override { mover.move_into(d, out); }
    void move_into_storage(PointsView<Dim> d, Eigen::Ref<Points<Dim>> out) override {
      if constexpr (requires { mover.move_into(d, out); }) {
        mover.move_into(d, out);
      } else {  // a user's mover with only the Points<Dim> form
        mover.move_into(d, scratch);
        detail::copy_to_caller<Dim>("AnyMover::move_into", scratch, out);
      }
    }
    [[nodiscard]] MoverStats stats() const override { return mover.stats(); }
    [[nodiscard]] bool has_derivatives() const override { return differentiable; }
    [[nodiscard]] Points<Dim> derivative_forward(PointsView<Dim> w) override {
      if constexpr (differentiable) return mover.derivative_forward(w);
      else no_derivatives();
    }
    [[nodiscard]] Points<Dim> derivative_reverse(PointsView<Dim> v) override {
      if constexpr (differentiable) return mover.derivative_reverse(v);
      else no_derivatives();
    }
    [[noreturn]] static void no_derivatives() {
      throw InputError("AnyMover: this mover has no derivatives (the movers linear in the displacements have them: rbf, "
                       "spring, torsion, le, sle, dgm, idgm, dgrbf; see has_derivatives())");
    }
    M mover;
    Points<Dim> scratch;
  };
  std::shared_ptr<Concept> self_;
};

}  // namespace meshmotion
