#pragma once
/// \file
/// AnyMover<Dim> and make_mover(): movers chosen by name at run time (the `--method` of the
/// example programs). A new mover joins by adding one entry to mover_registry() below.

#include "meshmotion/core/error.hpp"
#include "meshmotion/movers/dgm.hpp"
#include "meshmotion/movers/dgrbf.hpp"
#include "meshmotion/movers/dgrbf2.hpp"
#include "meshmotion/movers/elasticity.hpp"
#include "meshmotion/movers/improved_dgm.hpp"
#include "meshmotion/movers/mover.hpp"
#include "meshmotion/movers/nonlinear_elasticity.hpp"
#include "meshmotion/movers/rbf.hpp"
#include "meshmotion/movers/rbf_kernels.hpp"
#include "meshmotion/movers/spring.hpp"
#include "meshmotion/movers/torsion_spring.hpp"

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

namespace detail {

/// "x,y[,z]" as a vector; throws InputError naming the parameter otherwise.
template <int Dim>
[[nodiscard]] Vec<Dim> parse_vector(const std::string& text, const char* key) {
  Vec<Dim> v;
  std::size_t at = 0;
  for (int d = 0; d < Dim; ++d) {
    const std::size_t end = d + 1 < Dim ? text.find(',', at) : text.size();
    try {
      std::size_t used = 0;
      if (end == std::string::npos) throw std::invalid_argument(text);
      v[d] = std::stod(text.substr(at, end - at), &used);
      if (used != end - at) throw std::invalid_argument(text);
    } catch (const std::exception&) {
      throw InputError(std::string("mover parameter '") + key + "': expected " + std::to_string(Dim) +
                       " comma-separated numbers (got '" + text + "')");
    }
    at = end + 1;
  }
  return v;
}

/// Per-simplex RBF options of the Delaunay-graph movers from "kernel" and "simplex_support".
[[nodiscard]] inline SimplexRbfOptions simplex_rbf_parameters(const MoverParameters& p) {
  SimplexRbfOptions o;
  o.kernel = rbf_kernel_from_name(p.get("kernel", std::string(name(o.kernel))));
  o.relative_support = p.get("simplex_support", o.relative_support);
  return o;
}

/// Solver of the mechanics movers from "solver" (a SolverKind name) and "tolerance".
[[nodiscard]] inline SolverOptions mechanics_solver(const MoverParameters& p) {
  SolverOptions o;
  const std::string kind = p.get("solver", std::string(name(o.kind)));
  bool known = false;
  for (const auto k : {SolverKind::simplicial_ldlt, SolverKind::simplicial_llt, SolverKind::sparse_lu, SolverKind::cg_jacobi,
                       SolverKind::cg_incomplete_cholesky, SolverKind::bicgstab})
    if (name(k) == kind) {
      o.kind = k;
      known = true;
    }
  if (!known) throw InputError("mover parameter 'solver': unknown solver '" + kind + "'");
  o.tolerance = p.get("tolerance", o.tolerance);
  return o;
}

/// RBF options from "kernel", "support_radius", "polynomial" (nonzero: on), "solver", "tolerance".
[[nodiscard]] inline RbfOptions rbf_parameters(const MoverParameters& p) {
  RbfOptions o;
  o.kernel = rbf_kernel_from_name(p.get("kernel", std::string(name(o.kernel))));
  o.support_radius = p.get("support_radius", o.support_radius);
  o.polynomial = p.get("polynomial", 0.0) != 0.0;
  o.solver = mechanics_solver(p);
  return o;
}

/// Elasticity options from "youngs_modulus", "poisson_ratio", "stiffening_exponent",
/// "reference_jacobian", "distance_exponent", "active_radius" (or "active_radius_factor" ×
/// "support_radius"), "solver", "tolerance".
[[nodiscard]] inline ElasticityOptions elasticity_parameters(const MoverParameters& p, double default_exponent) {
  ElasticityOptions o;
  o.youngs_modulus = p.get("youngs_modulus", o.youngs_modulus);
  o.poisson_ratio = p.get("poisson_ratio", o.poisson_ratio);
  o.stiffening_exponent = p.get("stiffening_exponent", default_exponent);
  o.reference_jacobian = p.get("reference_jacobian", o.reference_jacobian);
  o.distance_exponent = p.get("distance_exponent", o.distance_exponent);
  o.active_radius = p.get("active_radius", o.active_radius);
  // A radius relative to the "support_radius" every caller of the registry may pass (the
  // curving pipeline: its wall-layer estimate).
  if (!p.values.contains("active_radius") && p.values.contains("active_radius_factor"))
    o.active_radius = p.get("active_radius_factor", 0.0) * p.get("support_radius", 0.0);
  o.solver = mechanics_solver(p);
  return o;
}

}  // namespace detail

/// Factories by method name. Add new movers here.
template <int Dim>
[[nodiscard]] const std::map<std::string, std::function<AnyMover<Dim>(const MoverParameters&)>, std::less<>>&
mover_registry() {
  static const std::map<std::string, std::function<AnyMover<Dim>(const MoverParameters&)>, std::less<>> registry{
      {"rbf", [](const MoverParameters& p) { return AnyMover<Dim>(RbfMover<Dim>(detail::rbf_parameters(p))); }},
      // Delaunay-graph movers: "simplex_support" (relative per-simplex RBF support), "kernel",
      // and for dgrbf2 "center" ("x,y[,z]") and "axis" ("ax,ay,az") of the rigid rotation.
      {"dgm", [](const MoverParameters&) { return AnyMover<Dim>(DgmMover<Dim>()); }},
      {"idgm", [](const MoverParameters& p) {
         ImprovedDgmOptions o;
         o.layer_offset = p.get("layer_offset", o.layer_offset);
         return AnyMover<Dim>(ImprovedDgmMover<Dim>(o));
       }},
      {"dgrbf", [](const MoverParameters& p) {
         DgrbfOptions o;
         o.rbf = detail::simplex_rbf_parameters(p);
         return AnyMover<Dim>(DgrbfMover<Dim>(o));
       }},
      {"dgrbf2", [](const MoverParameters& p) {
         Dgrbf2Options<Dim> o;
         o.rbf = detail::simplex_rbf_parameters(p);
         if (p.values.contains("center")) o.center = detail::parse_vector<Dim>(p.get("center", std::string()), "center");
         if constexpr (Dim == 3)
           if (p.values.contains("axis")) o.axis = detail::parse_vector<3>(p.get("axis", std::string()), "axis");
         return AnyMover<Dim>(Dgrbf2Mover<Dim>(o));
       }},
      // Mechanics movers: "solver" (SolverKind name) and "tolerance"; le/sle/nle take
      // "youngs_modulus", "poisson_ratio"; le/sle "stiffening_exponent" (sle default 2.75, the
      // thesis's table 4.2), "reference_jacobian", "distance_exponent", "active_radius" (or "active_radius_factor" ×
      // "support_radius"); nle "load_steps",
      // "newton_iterations", "newton_tolerance".
      {"spring", [](const MoverParameters& p) {
         SpringOptions o;
         o.solver = detail::mechanics_solver(p);
         return AnyMover<Dim>(SpringMover<Dim>(o));
       }},
      {"torsion", [](const MoverParameters& p) {
         TorsionSpringOptions o;
         o.torsion_weight = p.get("torsion_weight", o.torsion_weight);
         o.solver = detail::mechanics_solver(p);
         return AnyMover<Dim>(TorsionSpringMover<Dim>(o));
       }},
      {"le", [](const MoverParameters& p) { return AnyMover<Dim>(ElasticityMover<Dim>(detail::elasticity_parameters(p, 0.0))); }},
      {"sle", [](const MoverParameters& p) { return AnyMover<Dim>(ElasticityMover<Dim>(detail::elasticity_parameters(p, 2.75))); }},
      {"nle", [](const MoverParameters& p) {
         NonlinearElasticityOptions o;
         o.youngs_modulus = p.get("youngs_modulus", o.youngs_modulus);
         o.poisson_ratio = p.get("poisson_ratio", o.poisson_ratio);
         o.load_steps = static_cast<int>(p.get("load_steps", double(o.load_steps)));
         o.max_newton_iterations = static_cast<int>(p.get("newton_iterations", double(o.max_newton_iterations)));
         o.tolerance = p.get("newton_tolerance", o.tolerance);
         o.solver = detail::mechanics_solver(p);
         return AnyMover<Dim>(NonlinearElasticityMover<Dim>(o));
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
