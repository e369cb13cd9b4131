#pragma once
/// \file
/// Every mover by method name: the one table of registered methods, their typed options and
/// the one text form of those options.
///
/// A mover chosen at run time is a MoverConfig: its method name and its typed options struct
/// (RbfOptions, ElasticityOptions, ...). Text (command line, config file, Python keywords)
/// reaches those structs through MoverConfig::set, which knows every key of the method and
/// refuses any other (naming the known ones), refuses malformed values, and reads numbers
/// exactly (core/option_text.hpp). MoverConfig::values() writes them back the same way.
///
/// Registering a mover is one entry in registered_movers() (its options struct must have a
/// visit_options description here): its name, options type, summary and defaults then reach
/// MoverOptions, mover_methods(), make_mover(), the programs' flags and Python.
///
/// \code
/// MoverConfig<2> c = mover_config<2>("rbf", parse_key_values("support_radius=4.9e-6 kernel=wendland4"));
/// std::get<RbfOptions>(c.options).polynomial = true;   // or typed, directly
/// AnyMover<2> mover = make_mover(c);
/// \endcode

#include "meshmotion/core/error.hpp"
#include "meshmotion/core/option_text.hpp"
#include "meshmotion/movers/any_mover.hpp"
#include "meshmotion/movers/blend.hpp"
#include "meshmotion/movers/boundary_layer.hpp"
#include "meshmotion/movers/boundary_only.hpp"
#include "meshmotion/movers/delaunay_graph_options.hpp"
#include "meshmotion/movers/dgm.hpp"
#include "meshmotion/movers/dgrbf.hpp"
#include "meshmotion/movers/dgrbf2.hpp"
#include "meshmotion/movers/elasticity.hpp"
#include "meshmotion/movers/improved_dgm.hpp"
#include "meshmotion/movers/nonlinear_elasticity.hpp"
#include "meshmotion/movers/rbf.hpp"
#include "meshmotion/movers/spring.hpp"
#include "meshmotion/movers/torsion_spring.hpp"
#include "meshmotion/solvers/dense_solver.hpp"
#include "meshmotion/solvers/solver_options.hpp"

#include <array>
#include <cstddef>
#include <string>
#include <string_view>
#include <tuple>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

namespace meshmotion {

// visit_options(o, f) calls f(key, field, help) for every field of `o` that text may set.
// Nested structs of a mover's options add their keys with a prefix ("rbf." in idgm).

template <class F>
void visit_options(SolverOptions& o, F&& f, const std::string& prefix = {}) {
  f(prefix + "solver", o.kind, "sparse solver of the system");
  f(prefix + "tolerance", o.tolerance, "relative residual an iterative solver must reach");
  f(prefix + "max_iterations", o.max_iterations, "iteration cap of an iterative solver (0: twice the size)");
  f(prefix + "fallback_to_direct", o.fallback_to_direct, "solve with sparse LU when an iterative solver fails");
  f(prefix + "diagonal_scaling", o.diagonal_scaling, "solve the diagonally scaled system");
}

template <class F>
void visit_options(RbfOptions& o, F&& f, const std::string& prefix = {}) {
  f(prefix + "kernel", o.kernel, "radial function");
  f(prefix + "support_radius", o.support_radius, "support radius (scale of global kernels), mesh units; 0: from the boundary");
  f(prefix + "support_radii", o.support_radii, "a radius per boundary entry (comma-separated), replacing support_radius");
  f(prefix + "polynomial", o.polynomial, "add a linear polynomial (affine motions exact)");
  visit_options(o.solver, f, prefix);
  f(prefix + "dense_solver", o.dense_solver, "factorization of the dense system of global kernels");
  f(prefix + "max_dense_centres", o.max_dense_centres, "largest centre count of a global kernel");
  f(prefix + "coincidence_tolerance", o.coincidence_tolerance, "boundary nodes closer than this × the diagonal are one");
  f(prefix + "max_evaluation_cache_bytes", o.max_evaluation_cache_bytes, "largest dense evaluation matrix kept");
  f(prefix + "partition_of_unity", o.partition_of_unity, "local systems on overlapping patches (boundaries of ~100k+ nodes)");
  f(prefix + "patch_centres", o.patch_centres, "partition of unity: most centres per patch before the overlap");
  f(prefix + "patch_overlap", o.patch_overlap, "partition of unity: overlap, x each patch's radius (at least the support radius)");
  f(prefix + "max_memory_bytes", o.max_memory_bytes,
    "compact kernels: estimated memory allowed, bytes (0: half the machine's); a default radius is reduced to fit");
  f(prefix + "rigid_part", o.rigid_part, "blend a large rigid motion into the volume before interpolating the rest");
  f(prefix + "condition_limit", o.condition_limit,
    "compact kernels: thin centres closer than the radius resolves when the condition exceeds this (0: never)");
}

template <class F>
void visit_options(DgmOptions& o, F&& f, const std::string& prefix = {}) {
  f(prefix + "outside", o.outside, "nodes outside the graph's hull");
  f(prefix + "check_inversion", o.check_inversion, "refuse when the moved graph inverts");
}

template <class F>
void visit_options(SimplexRbfOptions& o, F&& f, const std::string& prefix = {}) {
  f(prefix + "kernel", o.kernel, "radial function of the per-simplex interpolation");
  f(prefix + "simplex_support_radius", o.support_radius, "absolute per-simplex support radius (0: relative)");
  f(prefix + "simplex_support", o.relative_support, "per-simplex support, × the simplex's longest edge");
  f(prefix + "normalize", o.normalize, "divide the cardinal weights by their sum");
}

template <class F>
void visit_options(DgrbfOptions& o, F&& f, const std::string& prefix = {}) {
  visit_options(o.rbf, f, prefix);
  f(prefix + "outside", o.outside, "nodes outside the graph's hull");
}

template <int Dim, class F>
void visit_options(Dgrbf2Options<Dim>& o, F&& f, const std::string& prefix = {}) {
  visit_options(o.rbf, f, prefix);
  f(prefix + "outside", o.outside, "nodes outside the graph's hull");
  f(prefix + "center", o.center, "centre of the rigid rotation (none: centroid of the moving nodes)");
  if constexpr (Dim == 3) f(prefix + "axis", o.axis, "rotation axis");
}

template <class F>
void visit_options(ImprovedDgmOptions& o, F&& f, const std::string& prefix = {}) {
  visit_options(o.dgm, f, prefix);
  f(prefix + "layer_offset", o.layer_offset, "layer distance from the wall, in wall spacings");
  f(prefix + "layer_spacing", o.layer_spacing, "thinning of the layer, in wall spacings");
  f(prefix + "auto_support_radius", o.auto_support_radius, "the layer RBF's radius from the layer's reach");
  f(prefix + "relative_support_radius", o.relative_support_radius, "factor of the automatic radius");
  visit_options(o.rbf, f, prefix + "rbf.");
}

template <class F>
void visit_options(SpringOptions& o, F&& f, const std::string& prefix = {}) {
  f(prefix + "length_exponent", o.length_exponent, "p in k = length^-p");
  visit_options(o.solver, f, prefix);
}

template <class F>
void visit_options(TorsionSpringOptions& o, F&& f, const std::string& prefix = {}) {
  f(prefix + "torsion_weight", o.torsion_weight, "factor of every torsional stiffness");
  f(prefix + "coupled_lineal", o.coupled_lineal, "lineal springs in the coupled truss form");
  f(prefix + "vertex_facet_springs", o.vertex_facet_springs, "3D: vertex-facet springs too");
  visit_options(o.solver, f, prefix);
}

template <class F>
void visit_options(ElasticityOptions& o, F&& f, const std::string& prefix = {}) {
  f(prefix + "youngs_modulus", o.youngs_modulus, "Young's modulus E > 0 (scales K only)");
  f(prefix + "poisson_ratio", o.poisson_ratio, "Poisson ratio in (-1, 0.5)");
  f(prefix + "stiffening_exponent", o.stiffening_exponent, "chi of the Jacobian stiffening (J0/J)^chi");
  f(prefix + "reference_jacobian", o.reference_jacobian, "J0 (<= 0: the mean cell measure)");
  f(prefix + "distance_exponent", o.distance_exponent, "psi of the wall-distance stiffening");
  visit_options(o.solver, f, prefix);
  f(prefix + "active_radius", o.active_radius, "solve only within this distance of the moving walls (0: whole mesh)");
}

template <class F>
void visit_options(NonlinearElasticityOptions& o, F&& f, const std::string& prefix = {}) {
  f(prefix + "youngs_modulus", o.youngs_modulus, "Young's modulus E > 0 (scales the energy only)");
  f(prefix + "poisson_ratio", o.poisson_ratio, "Poisson ratio in (-1, 0.5)");
  f(prefix + "load_steps", o.load_steps, "equal boundary increments");
  f(prefix + "newton_iterations", o.max_newton_iterations, "Newton iterations per load step");
  f(prefix + "newton_tolerance", o.tolerance, "largest update / bounding-box diagonal that stops Newton");
  f(prefix + "min_step", o.min_step, "smallest line-search step");
  visit_options(o.solver, f, prefix);
}

template <class F>
void visit_options(BoundaryLayerOptions& o, F&& f, const std::string& prefix = {}) {
  f(prefix + "aspect_ratio_threshold", o.aspect_ratio_threshold,
    "cells at least this anisotropic (longest/shortest edge) form a wall's boundary layer");
}

template <class F>
void visit_options(BlendOptions& o, F&& f, const std::string& prefix = {}) {
  f(prefix + "blending_length", o.blending_length, "blending length of every wall (0: blending_factor x each wall's layer)");
  f(prefix + "blending_factor", o.blending_factor, "default blending length, in layer thicknesses of each wall");
  f(prefix + "fallback_spacings", o.fallback_spacings, "walls without a layer: blending length in facet sizes at each node");
  visit_options(o.layer, f, prefix);
}

template <class F>
void visit_options(BoundaryOnlyOptions&, F&&, const std::string& = {}) {}

/// One registered method: the mover it builds, its options type, its name, a line saying
/// what it is, and what its defaults change in the options struct's own (nullptr: nothing).
template <class Mover, class Options>
struct RegisteredMover {
  using mover_type = Mover;
  using options_type = Options;
  std::string_view name;
  std::string_view summary;
  void (*tune)(Options&) = nullptr;
};

/// Every method make_mover() builds, in the order programs list them: the one table.
template <int Dim>
[[nodiscard]] constexpr auto registered_movers() {
  return std::tuple{
      RegisteredMover<RbfMover<Dim>, RbfOptions>{"rbf", "radial basis function interpolation (thesis 2.2.2)"},
      RegisteredMover<DgmMover<Dim>, DgmOptions>{"dgm", "Delaunay graph mapping (thesis 2.2.1)"},
      RegisteredMover<ImprovedDgmMover<Dim>, ImprovedDgmOptions>{"idgm", "Delaunay graph mapping with an RBF-moved layer"},
      RegisteredMover<DgrbfMover<Dim>, DgrbfOptions>{"dgrbf", "Delaunay graph with per-simplex RBF (thesis 2.2.3)"},
      RegisteredMover<Dgrbf2Mover<Dim>, Dgrbf2Options<Dim>>{"dgrbf2", "DGRBF with rigid rotations exact (thesis 2.2.4)"},
      RegisteredMover<SpringMover<Dim>, SpringOptions>{"spring", "lineal springs (thesis 2.1.1)"},
      RegisteredMover<TorsionSpringMover<Dim>, TorsionSpringOptions>{"torsion", "torsion springs (thesis 2.1.2)"},
      RegisteredMover<ElasticityMover<Dim>, ElasticityOptions>{"le", "linear elasticity (thesis 2.1.3)"},
      RegisteredMover<ElasticityMover<Dim>, ElasticityOptions>{"sle", "stiffened linear elasticity, chi 2.75 (thesis table 4.2)",
                                                               [](ElasticityOptions& o) { o.stiffening_exponent = 2.75; }},
      RegisteredMover<NonlinearElasticityMover<Dim>, NonlinearElasticityOptions>{"nle",
                                                                                 "neo-Hookean nonlinear elasticity (thesis 2.1.4)"},
      RegisteredMover<BlendMover<Dim>, BlendOptions>{"blend", "wall-distance blending of the moving walls (no solve)",
                                                     [](BlendOptions& o) { o.blending_factor = 6.0; }},
      RegisteredMover<BoundaryOnlyMover<Dim>, BoundaryOnlyOptions>{"none", "the prescribed boundary nodes alone"},
  };
}

namespace detail {

template <class Variant, class T>
struct with_alternative;
template <class... Ts, class T>
struct with_alternative<std::variant<Ts...>, T> {
  using type = std::conditional_t<(std::is_same_v<T, Ts> || ...), std::variant<Ts...>, std::variant<Ts..., T>>;
};

template <class Variant, class... Entries>
struct options_variant {
  using type = Variant;
};
template <class Variant, class First, class... Rest>
struct options_variant<Variant, First, Rest...> {
  using type = typename options_variant<typename with_alternative<Variant, typename First::options_type>::type, Rest...>::type;
};

template <class Table>
struct options_of_table;
template <class First, class... Rest>
struct options_of_table<std::tuple<First, Rest...>> {
  using type = typename options_variant<std::variant<typename First::options_type>, Rest...>::type;
};

template <int Dim, std::size_t I>
using registered_entry = std::tuple_element_t<I, decltype(registered_movers<Dim>())>;

}  // namespace detail

/// The typed options of every registered mover (each options type once).
template <int Dim>
using MoverOptions = typename detail::options_of_table<decltype(registered_movers<Dim>())>::type;

/// Options a caller such as the curving pipeline sets from what it measured, when the
/// mover's options have them (the pipeline asks through these instead of naming methods).
template <class O>
concept TakesSupportRadius = requires(O o) {
  { o.support_radius } -> std::same_as<double&>;
  { o.support_radii } -> std::same_as<std::vector<double>&>;
};
template <class O>
concept TakesActiveRadius = requires(O o) {
  { o.active_radius } -> std::same_as<double&>;
};
/// A blending length, derived from the walls' layers when 0.
template <class O>
concept TakesBlendingLength = requires(O o) {
  { o.blending_length } -> std::same_as<double&>;
};
/// How the walls' boundary layers are recognized.
template <class O>
concept TakesLayerOptions = requires(O o) {
  { o.layer } -> std::same_as<BoundaryLayerOptions&>;
};

/// A registered method at run time (mover_methods()).
template <int Dim>
struct MoverMethod {
  std::string_view name;
  std::string_view summary;
  MoverOptions<Dim> (*defaults)();
  AnyMover<Dim> (*make)(const MoverOptions<Dim>&);
  /// false: the mover leaves the interior as it is (its options say so: moves_interior).
  bool moves_interior = true;
};

namespace detail {

template <int Dim, std::size_t I>
[[nodiscard]] MoverOptions<Dim> registered_defaults() {
  using Options = typename registered_entry<Dim, I>::options_type;
  Options o{};
  if (const auto tune = std::get<I>(registered_movers<Dim>()).tune) tune(o);
  return o;
}

template <int Dim, std::size_t I>
[[nodiscard]] AnyMover<Dim> registered_make(const MoverOptions<Dim>& options) {
  using Entry = registered_entry<Dim, I>;
  return AnyMover<Dim>(typename Entry::mover_type(std::get<typename Entry::options_type>(options)));
}

template <int Dim, std::size_t... I>
[[nodiscard]] auto method_array(std::index_sequence<I...>) {
  constexpr auto table = registered_movers<Dim>();
  return std::array<MoverMethod<Dim>, sizeof...(I)>{MoverMethod<Dim>{
      std::get<I>(table).name, std::get<I>(table).summary, &registered_defaults<Dim, I>, &registered_make<Dim, I>,
      [] {
        using Options = typename registered_entry<Dim, I>::options_type;
        if constexpr (requires { Options::moves_interior; }) return Options::moves_interior;
        else return true;
      }()}...};
}

}  // namespace detail

/// Every method make_mover() builds, in the order of registered_movers().
template <int Dim>
[[nodiscard]] const auto& mover_methods() {
  static const auto methods =
      detail::method_array<Dim>(std::make_index_sequence<std::tuple_size_v<decltype(registered_movers<Dim>())>>{});
  return methods;
}

/// "rbf, dgm, ..." for messages.
template <int Dim>
[[nodiscard]] std::string known_methods() {
  std::string known;
  for (const auto& m : mover_methods<Dim>()) {
    if (!known.empty()) known += ", ";
    known += m.name;
  }
  return known;
}

/// The registered method of that name; throws InputError listing the known ones otherwise.
template <int Dim>
[[nodiscard]] const MoverMethod<Dim>& mover_method(std::string_view method) {
  for (const auto& m : mover_methods<Dim>())
    if (m.name == method) return m;
  throw InputError("unknown mover method '" + std::string(method) + "' (expected one of " + known_methods<Dim>() + ")");
}

/// A method and its typed options: what make_mover() builds.
template <int Dim>
struct MoverConfig {
  std::string method = "rbf";
  MoverOptions<Dim> options = RbfOptions{};

  /// Every key this method takes, in a fixed order.
  [[nodiscard]] std::vector<std::string> keys() const {
    std::vector<std::string> out;
    for_each_field([&](const std::string& key, auto&, std::string_view) { out.push_back(key); });
    return out;
  }
  /// Every key with its value as text (numbers in their shortest exact form).
  [[nodiscard]] KeyValues values() const {
    KeyValues out;
    for_each_field([&](const std::string& key, auto& value, std::string_view) {
      out.emplace_back(key, format_option_value(value));
    });
    return out;
  }
  /// Every key with its type, current value and line of help.
  [[nodiscard]] std::vector<OptionDoc> docs() const {
    check();
    return std::visit([](const auto& o) { return option_docs(o); }, options);
  }
  /// Sets one option from text. Throws InputError for a key this method does not take
  /// (listing the ones it does) or a value its field cannot hold.
  void set(std::string_view key, std::string_view text) {
    check();
    if (!std::visit([&](auto& o) { return set_option(o, key, text); }, options))
      throw InputError(unknown_key_message("method '" + method + "'", key, keys()));
  }
  /// Sets every pair in order (see set()).
  void set(const KeyValues& values) {
    for (const auto& [k, v] : values) set(k, v);
  }
  /// Throws InputError when `options` is not the options type of `method`.
  void check() const {
    const MoverMethod<Dim>& m = mover_method<Dim>(method);
    if (m.defaults().index() != options.index())
      throw InputError("MoverConfig: the options given are not those of method '" + method + "'");
  }

 private:
  template <class F>
  void for_each_field(F&& f) const {
    check();
    MoverOptions<Dim> copy = options;
    std::visit([&](auto& o) { visit_options(o, f); }, copy);
  }
};

/// The defaults of `method` with `values` set over them (see MoverConfig::set).
template <int Dim>
[[nodiscard]] MoverConfig<Dim> mover_config(std::string_view method, const KeyValues& values = {}) {
  MoverConfig<Dim> c{std::string(method), mover_method<Dim>(method).defaults()};
  c.set(values);
  return c;
}

/// The mover `config` describes, with its typed options. Throws InputError when the options
/// are not those of the method (MoverConfig::check) or the method is unknown.
template <int Dim>
[[nodiscard]] AnyMover<Dim> make_mover(const MoverConfig<Dim>& config) {
  config.check();
  return mover_method<Dim>(config.method).make(config.options);
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
