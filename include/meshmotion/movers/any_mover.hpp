#pragma once
/// \file
/// AnyMover<Dim> and make_mover(): movers chosen by name at run time (the `--method` of the
/// example programs). A new mover joins by adding one entry to mover_registry() below.

#include "meshmotion/core/error.hpp"
#include "meshmotion/movers/mover.hpp"
#include "meshmotion/movers/rbf.hpp"
#include "meshmotion/movers/rbf_kernels.hpp"

#include <functional>
#include <map>
#include <memory>
#include <string>

namespace meshmotion {

/// Textual options of a mover chosen at run time ("kernel" → "wendland2",
/// "support_radius" → "0.5", ...); each mover reads the keys it knows.
struct MoverParameters {
  std::map<std::string, std::string, std::less<>> values;

  [[nodiscard]] std::string get(const std::string& key, const std::string& fallback) const {
    const auto it = values.find(key);
    return it == values.end() ? fallback : it->second;
  }
  [[nodiscard]] double get(const std::string& key, double fallback) const {
    const auto it = values.find(key);
    if (it == values.end()) return fallback;
    try {
      return std::stod(it->second);
    } catch (const std::exception&) {
      throw InputError("mover parameter '" + key + "': not a number (got '" + it->second + "')");
    }
  }
};

/// A type-erased MeshMover over Mesh<Dim>.
template <int Dim>
class AnyMover {
 public:
  static constexpr int dim = Dim;

  template <MeshMover M>
    requires(M::dim == Dim)
  explicit AnyMover(M mover) : self_(std::make_shared<Model<M>>(std::move(mover))) {}

  void setup(const Mesh<Dim>& mesh, const ResolvedBoundary<Dim>& boundary) { self_->setup(mesh, boundary); }
  [[nodiscard]] Points<Dim> move(const Points<Dim>& d) {
    Points<Dim> out;
    self_->move_into(d, out);
    return out;
  }
  void move_into(const Points<Dim>& d, Points<Dim>& out) { self_->move_into(d, out); }
  [[nodiscard]] MoverStats stats() const { return self_->stats(); }

 private:
  struct Concept {
    virtual ~Concept() = default;
    virtual void setup(const Mesh<Dim>&, const ResolvedBoundary<Dim>&) = 0;
    virtual void move_into(const Points<Dim>&, Points<Dim>&) = 0;
    [[nodiscard]] virtual MoverStats stats() const = 0;
  };
  template <class M>
  struct Model final : Concept {
    explicit Model(M m) : mover(std::move(m)) {}
    void setup(const Mesh<Dim>& mesh, const ResolvedBoundary<Dim>& b) override { mover.setup(mesh, b); }
    void move_into(const Points<Dim>& d, Points<Dim>& out) override { mover.move_into(d, out); }
    [[nodiscard]] MoverStats stats() const override { return mover.stats(); }
    M mover;
  };
  std::shared_ptr<Concept> self_;
};

/// Factories by method name. Add new movers here.
template <int Dim>
[[nodiscard]] const std::map<std::string, std::function<AnyMover<Dim>(const MoverParameters&)>, std::less<>>&
mover_registry() {
  static const std::map<std::string, std::function<AnyMover<Dim>(const MoverParameters&)>, std::less<>> registry{
      {"rbf",
       [](const MoverParameters& p) {
         RbfOptions o;
         o.kernel = rbf_kernel_from_name(p.get("kernel", std::string(name(o.kernel))));
         o.support_radius = p.get("support_radius", o.support_radius);
         o.polynomial = p.get("polynomial", 0.0) != 0.0;
         return AnyMover<Dim>(RbfMover<Dim>(o));
       }},
  };
  return registry;
}

/// The mover registered as `method`; throws InputError listing the known methods otherwise.
template <int Dim>
[[nodiscard]] AnyMover<Dim> make_mover(const std::string& method, const MoverParameters& parameters = {}) {
  const auto& registry = mover_registry<Dim>();
  const auto it = registry.find(method);
  if (it != registry.end()) return it->second(parameters);
  std::string known;
  for (const auto& [key, factory] : registry) known += (known.empty() ? "" : ", ") + key;
  throw InputError("make_mover: unknown method '" + method + "' (expected one of " + known + ")");
}

}  // namespace meshmotion
