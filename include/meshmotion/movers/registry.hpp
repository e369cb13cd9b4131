#pragma once
/// \file
/// The registry of serial movers: every method by name, with its typed options and the one
/// text form of those options. Light: it includes the options headers and AnyMover, never a
/// mover's implementation, so a front end (program, Python, plugin, curving) that includes it
/// compiles none of them.
///
/// A mover chosen at run time is a MoverConfig: its method name and its typed options struct
/// (RbfOptions, ElasticityOptions, ...). Text (command line, config file, Python keywords)
/// reaches those structs through MoverConfig::set, which knows every key of the method and
/// refuses any other (naming the known ones), refuses malformed values, and reads numbers
/// exactly (core/option_text.hpp). MoverConfig::values() writes them back the same way.
///
/// The table itself (method -> factory) is movers/registered_movers.hpp, compiled once per
/// dimension into meshmotion::compiled (src/registry.cpp). Registering a mover is one entry
/// there and, for a new options type, one alternative of MoverOptions here.
///
/// \code
/// MoverConfig<2> c = mover_config<2>("rbf", parse_key_values("support_radius=4.9e-6 kernel=wendland4"));
/// std::get<RbfOptions>(c.options).polynomial = true;   // or typed, directly
/// AnyMover<2> mover = make_mover(c);
/// \endcode

#include "meshmotion/core/error.hpp"
#include "meshmotion/core/option_text.hpp"
#include "meshmotion/movers/any_mover.hpp"
#include "meshmotion/movers/blend_options.hpp"
#include "meshmotion/movers/boundary_only_options.hpp"
#include "meshmotion/movers/dgm_options.hpp"
#include "meshmotion/movers/dgrbf2_options.hpp"
#include "meshmotion/movers/dgrbf_options.hpp"
#include "meshmotion/movers/elasticity_options.hpp"
#include "meshmotion/movers/improved_dgm_options.hpp"
#include "meshmotion/movers/nonlinear_elasticity_options.hpp"
#include "meshmotion/movers/rbf_options.hpp"
#include "meshmotion/movers/spring_options.hpp"
#include "meshmotion/movers/torsion_spring_options.hpp"
#include "meshmotion/solvers/solver_options.hpp"

#include <concepts>
#include <span>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

namespace meshmotion {

/// The typed options of every registered mover, each options type once.
template <int Dim>
using MoverOptions = std::variant<RbfOptions, DgmOptions, ImprovedDgmOptions, DgrbfOptions, Dgrbf2Options<Dim>,
                                  SpringOptions, TorsionSpringOptions, ElasticityOptions, NonlinearElasticityOptions,
                                  BlendOptions, BoundaryOnlyOptions>;

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

/// A registered method at run time: what a front end asks instead of comparing names.
template <int Dim>
struct MoverMethod {
  std::string_view name;
  std::string_view summary;
  MoverOptions<Dim> (*defaults)();
  AnyMover<Dim> (*make)(const MoverOptions<Dim>&);
  /// false: the mover leaves the interior as it is (its options say so: moves_interior).
  bool moves_interior = true;
  /// false: setup reads the boundary and the points, never the cells (a solver that holds
  /// no cell list, or a decomposed one, can use it as it is).
  bool needs_cells = true;
};

/// Every method make_mover() builds, in the order programs list them.
template <int Dim>
[[nodiscard]] std::span<const MoverMethod<Dim>> mover_methods();

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
  /// Throws InputError when `options` is not the options type of `method`, or a field is
  /// outside its range (check_option_ranges()).
  void check() const {
    const MoverMethod<Dim>& m = mover_method<Dim>(method);
    if (m.defaults().index() != options.index())
      throw InputError("MoverConfig: the options given are not those of method '" + method + "'");
    std::visit([](const auto& o) { check_option_ranges(o); }, options);
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

// The compiled library (target meshmotion::compiled, src/registry.cpp) holds the table for
// Dim 2 and 3; header-only, movers/registered_movers.hpp defines it (meshmotion/movers.hpp
// includes it).
#ifdef MESHMOTION_COMPILED
namespace meshmotion {
extern template std::span<const MoverMethod<2>> mover_methods<2>();
extern template std::span<const MoverMethod<3>> mover_methods<3>();
}  // namespace meshmotion
#endif
