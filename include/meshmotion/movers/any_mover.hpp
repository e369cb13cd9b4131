#pragma once
/// \file
/// AnyMover<Dim> and make_mover(): movers chosen by name at run time (the `--method` of the
/// example programs) from their typed options (movers/mover_options.hpp). A new mover joins
/// with an entry in mover_methods(), its options in MoverOptions and a line in make_mover().

#include "meshmotion/core/error.hpp"
#include "meshmotion/core/mesh_like.hpp"
#include "meshmotion/movers/detail/mover_support.hpp"
#include "meshmotion/movers/dgm.hpp"
#include "meshmotion/movers/dgrbf.hpp"
#include "meshmotion/movers/dgrbf2.hpp"
#include "meshmotion/movers/elasticity.hpp"
#include "meshmotion/movers/improved_dgm.hpp"
#include "meshmotion/movers/mover.hpp"
#include "meshmotion/movers/mover_options.hpp"
#include "meshmotion/movers/nonlinear_elasticity.hpp"
#include "meshmotion/movers/rbf.hpp"
#include "meshmotion/movers/rbf_kernels.hpp"
#include "meshmotion/movers/spring.hpp"
#include "meshmotion/movers/torsion_spring.hpp"

#include <concepts>
#include <memory>
#include <string>
#include <string_view>
#include <variant>

namespace meshmotion {

/// A type-erased MeshMover over Mesh<Dim>.
template <int Dim>
class AnyMover {
 public:
  static constexpr int dim = Dim;

  template <MeshMover M>
    requires(M::dim == Dim)
  explicit AnyMover(M mover) : self_(std::make_shared<Model<M>>(std::move(mover))) {}

  void setup(const Mesh<Dim>& mesh, const ResolvedBoundary<Dim>& boundary) { self_->setup(mesh, boundary); }
  /// A solver's own mesh type: copied into a Mesh<Dim> for the mover, which keeps what it
  /// needs of it anyway.
  template <MeshLike M>
    requires(mesh_dim<M> == Dim && !std::same_as<M, Mesh<Dim>>)
  void setup(const M& mesh, const ResolvedBoundary<Dim>& boundary) {
    self_->setup(to_mesh(mesh), boundary);
  }
  [[nodiscard]] Points<Dim> move(const Points<Dim>& d) {
    Points<Dim> out;
    self_->move_into(d, out);
    return out;
  }
  void move_into(const Points<Dim>& d, Points<Dim>& out) { self_->move_into(d, out); }
  /// Into the caller's own storage (an Eigen::Map over a solver's array of Dim × n_nodes
  /// doubles): the RBF mover writes there directly, the others through a buffer of their own
  /// (no allocation after the first move). Throws InputError when its shape is not Dim × n_nodes.
  void move_into(const Points<Dim>& d, Eigen::Ref<Points<Dim>> out) { self_->move_into_storage(d, out); }
  [[nodiscard]] MoverStats stats() const { return self_->stats(); }

  /// True when the mover offers derivative_forward and derivative_reverse (the movers linear
  /// in the boundary displacements that implement them).
  [[nodiscard]] bool has_derivatives() const { return self_->has_derivatives(); }
  /// J w for a boundary displacement change w (Dim × boundary size): the movers linear in the
  /// displacements (RBF, springs, torsion springs, linear and stiffened elasticity, DGM,
  /// improved DGM, DGRBF).
  /// Throws InputError when the mover has no derivatives.
  [[nodiscard]] Points<Dim> derivative_forward(const Points<Dim>& w) { return self_->derivative_forward(w); }
  /// Jᵀ v for v (Dim × n_nodes): the gradient of ⟨v, move(d)⟩ with respect to d.
  /// Throws InputError when the mover has no derivatives.
  [[nodiscard]] Points<Dim> derivative_reverse(Eigen::Ref<const Points<Dim>> v) { return self_->derivative_reverse(v); }

 private:
  struct Concept {
    virtual ~Concept() = default;
    virtual void setup(const Mesh<Dim>&, const ResolvedBoundary<Dim>&) = 0;
    virtual void move_into(const Points<Dim>&, Points<Dim>&) = 0;
    virtual void move_into_storage(const Points<Dim>&, Eigen::Ref<Points<Dim>>) = 0;
    [[nodiscard]] virtual MoverStats stats() const = 0;
    [[nodiscard]] virtual bool has_derivatives() const = 0;
    [[nodiscard]] virtual Points<Dim> derivative_forward(const Points<Dim>&) = 0;
    [[nodiscard]] virtual Points<Dim> derivative_reverse(Eigen::Ref<const Points<Dim>>) = 0;
  };
  template <class M>
  struct Model final : Concept {
    static constexpr bool differentiable = requires(M& m, const Points<Dim>& v, Eigen::Ref<const Points<Dim>> r) {
      { m.derivative_forward(v) } -> std::same_as<Points<Dim>>;
      { m.derivative_reverse(r) } -> std::same_as<Points<Dim>>;
    };
    explicit Model(M m) : mover(std::move(m)) {}
    void setup(const Mesh<Dim>& mesh, const ResolvedBoundary<Dim>& b) override { mover.setup(mesh, b); }
    void move_into(const Points<Dim>& d, Points<Dim>& out) override { mover.move_into(d, out); }
    void move_into_storage(const Points<Dim>& d, Eigen::Ref<Points<Dim>> out) override {
      if constexpr (requires { mover.move_into(d, out); }) {
        mover.move_into(d, out);
      } else {  // a user's mover with only the Points<Dim> form
        mover.move_into(d, scratch);
        detail::copy_to_caller<Dim>("AnyMover::move_into", scratch, out);
      }
    }
    [[nodiscard]] MoverStats stats() const override { return mover.stats(); }
    [[nodiscard]] bool has_derivatives() const override { return differentiable; }
    [[nodiscard]] Points<Dim> derivative_forward(const Points<Dim>& w) override {
      if constexpr (differentiable) return mover.derivative_forward(w);
      else no_derivatives();
    }
    [[nodiscard]] Points<Dim> derivative_reverse(Eigen::Ref<const Points<Dim>> v) override {
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

/// The mover `config` describes, with its typed options. Throws InputError when the options
/// are not those of the method (MoverConfig::check) or the method is unknown.
template <int Dim>
[[nodiscard]] AnyMover<Dim> make_mover(const MoverConfig<Dim>& config) {
  config.check();
  return std::visit(
      [&]<class O>(const O& o) -> AnyMover<Dim> {
        if constexpr (std::same_as<O, RbfOptions>) return AnyMover<Dim>(RbfMover<Dim>(o));
        else if constexpr (std::same_as<O, DgmOptions>) return AnyMover<Dim>(DgmMover<Dim>(o));
        else if constexpr (std::same_as<O, ImprovedDgmOptions>) return AnyMover<Dim>(ImprovedDgmMover<Dim>(o));
        else if constexpr (std::same_as<O, DgrbfOptions>) return AnyMover<Dim>(DgrbfMover<Dim>(o));
        else if constexpr (std::same_as<O, Dgrbf2Options<Dim>>) return AnyMover<Dim>(Dgrbf2Mover<Dim>(o));
        else if constexpr (std::same_as<O, SpringOptions>) return AnyMover<Dim>(SpringMover<Dim>(o));
        else if constexpr (std::same_as<O, TorsionSpringOptions>) return AnyMover<Dim>(TorsionSpringMover<Dim>(o));
        else if constexpr (std::same_as<O, ElasticityOptions>) return AnyMover<Dim>(ElasticityMover<Dim>(o));
        else return AnyMover<Dim>(NonlinearElasticityMover<Dim>(o));
      },
      config.options);
}

/// The mover `method` with its defaults and `values` set over them (mover_config()).
template <int Dim>
[[nodiscard]] AnyMover<Dim> make_mover(std::string_view method, const KeyValues& values = {}) {
  return make_mover(mover_config<Dim>(method, values));
}

}  // namespace meshmotion

// The compiled library (target meshmotion::compiled, src/) holds these for Dim 2 and 3.
#ifdef MESHMOTION_COMPILED
namespace meshmotion {
extern template AnyMover<2> make_mover<2>(const MoverConfig<2>&);
extern template AnyMover<3> make_mover<3>(const MoverConfig<3>&);
}  // namespace meshmotion
#endif
