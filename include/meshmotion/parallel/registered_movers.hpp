#pragma once
/// \file
/// The table behind the distributed registry (parallel/registry.hpp): the distributed RBF
/// for rbf, distributed (stiffened) linear elasticity for le and sle. Compiled once per
/// dimension into meshmotion::parallel (src/parallel.cpp); a header-only program includes it
/// once (meshmotion/parallel.hpp does).

#include "meshmotion/parallel/distributed_elasticity.hpp"
#include "meshmotion/parallel/distributed_rbf.hpp"
#include "meshmotion/parallel/registry.hpp"

#include <array>
#include <memory>
#include <span>
#include <string_view>
#include <variant>

namespace meshmotion::parallel {

namespace detail {

template <int Dim>
class DistributedRbf final : public DistributedMover<Dim> {
 public:
  DistributedRbf(const RbfOptions& options, const BoundarySolveOptions& solve) : mover_(options, solve) {}
  using DistributedMover<Dim>::setup;
  void setup(const PartitionView<Dim>& part, const Mesh<Dim>& local, const ResolvedBoundary<Dim>& boundary) override {
    mover_.setup(part, local, boundary);
  }
  void setup(const PartitionView<Dim>& part, const ResolvedBoundary<Dim>& boundary) override { mover_.setup(part, boundary); }
  void move_into(PointsView<Dim> d, Points<Dim>& out) override { mover_.move_into(d, out); }
  void move_into(PointsView<Dim> d, Eigen::Ref<Points<Dim>> out) override { mover_.move_into(d, out); }
  [[nodiscard]] Points<Dim> derivative_reverse(PointsView<Dim> v) override { return mover_.derivative_reverse(v); }
  [[nodiscard]] Points<Dim> velocity(PointsView<Dim> v) override { return mover_.velocity(v); }
  [[nodiscard]] MoverStats stats() const override { return mover_.stats(); }
  [[nodiscard]] DistributedChoices choices() const override {
    return {mover_.support_radius(), std::string(name(mover_.solved_by())), "none"};
  }

 private:
  DistributedRbfMover<Dim> mover_;
};

template <int Dim>
class DistributedElasticity final : public DistributedMover<Dim> {
 public:
  DistributedElasticity(const ElasticityOptions& material, DistributedElasticityOptions solve)
      : mover_(with_material(std::move(solve), material)) {}
  using DistributedMover<Dim>::setup;
  void setup(const PartitionView<Dim>& part, const Mesh<Dim>& local, const ResolvedBoundary<Dim>& boundary) override {
    mover_.setup(part, local, boundary);
  }
  void setup(const PartitionView<Dim>&, const ResolvedBoundary<Dim>&) override {
    throw InputError("a solver's own partition (local nodes without cells) is moved by rbf only: elasticity needs the "
                     "cells (partition a mesh read on rank 0 instead)");
  }
  using DistributedMover<Dim>::move_into;
  void move_into(PointsView<Dim> d, Points<Dim>& out) override { mover_.move_into(d, out); }
  [[nodiscard]] Points<Dim> derivative_reverse(PointsView<Dim> v) override { return mover_.derivative_reverse(v); }
  [[nodiscard]] Points<Dim> velocity(PointsView<Dim> v) override { return mover_.derivative_forward(v); }
  [[nodiscard]] MoverStats stats() const override { return mover_.stats(); }
  [[nodiscard]] DistributedChoices choices() const override { return {0.0, "none", name(mover_.solver_kind())}; }

 private:
  static DistributedElasticityOptions with_material(DistributedElasticityOptions o, const ElasticityOptions& material) {
    o.elasticity = material;
    return o;
  }
  DistributedElasticityMover<Dim> mover_;
};

template <int Dim>
std::unique_ptr<DistributedMover<Dim>> make_distributed_rbf(const MoverOptions<Dim>& options, const ParallelOptions& parallel) {
  return std::make_unique<DistributedRbf<Dim>>(std::get<RbfOptions>(options), parallel.boundary);
}

template <int Dim>
std::unique_ptr<DistributedMover<Dim>> make_distributed_elasticity(const MoverOptions<Dim>& options, const ParallelOptions& parallel) {
  return std::make_unique<DistributedElasticity<Dim>>(std::get<ElasticityOptions>(options), parallel.elasticity);
}

}  // namespace detail

template <int Dim>
std::span<const DistributedMethod<Dim>> distributed_methods() {
  static const std::array<DistributedMethod<Dim>, 3> methods{{
      {"rbf", false, &detail::make_distributed_rbf<Dim>},
      {"le", true, &detail::make_distributed_elasticity<Dim>},
      {"sle", true, &detail::make_distributed_elasticity<Dim>},
  }};
  return methods;
}

}  // namespace meshmotion::parallel
