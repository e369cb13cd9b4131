#pragma once
/// \file
/// The table behind the registry (movers/registry.hpp): every method make_mover() builds, its
/// mover and options types, and what a front end may ask of it. It includes every mover's
/// implementation, so the compiled library instantiates it once per dimension
/// (src/registry.cpp); a header-only program includes it once (meshmotion/movers.hpp does).
/// Registering a mover is one entry below.

#include "meshmotion/movers/blend.hpp"
#include "meshmotion/movers/boundary_only.hpp"
#include "meshmotion/movers/dgm.hpp"
#include "meshmotion/movers/dgrbf.hpp"
#include "meshmotion/movers/dgrbf2.hpp"
#include "meshmotion/movers/elasticity.hpp"
#include "meshmotion/movers/improved_dgm.hpp"
#include "meshmotion/movers/nonlinear_elasticity.hpp"
#include "meshmotion/movers/rbf.hpp"
#include "meshmotion/movers/registry.hpp"
#include "meshmotion/movers/spring.hpp"
#include "meshmotion/movers/torsion_spring.hpp"

#include <array>
#include <cstddef>
#include <span>
#include <string_view>
#include <tuple>
#include <type_traits>
#include <utility>
#include <variant>

namespace meshmotion {

namespace detail {

/// One registered method: the mover it builds, its options type, its name, a line saying
/// what it is, whether setup reads the cells, and what its defaults change in the options
/// struct's own (nullptr: nothing).
template <class Mover, class Options>
struct RegisteredMover {
  using mover_type = Mover;
  using options_type = Options;
  std::string_view name;
  std::string_view summary;
  bool needs_cells = true;
  void (*tune)(Options&) = nullptr;
};

/// Every method make_mover() builds, in the order programs list them: the one table.
template <int Dim>
[[nodiscard]] constexpr auto registered_movers() {
  return std::tuple{
      RegisteredMover<RbfMover<Dim>, RbfOptions>{"rbf", "radial basis function interpolation (thesis 2.2.2)", false},
      RegisteredMover<DgmMover<Dim>, DgmOptions>{"dgm", "Delaunay graph mapping (thesis 2.2.1)"},
      RegisteredMover<ImprovedDgmMover<Dim>, ImprovedDgmOptions>{"idgm", "Delaunay graph mapping with an RBF-moved layer"},
      RegisteredMover<DgrbfMover<Dim>, DgrbfOptions>{"dgrbf", "Delaunay graph with per-simplex RBF (thesis 2.2.3)"},
      RegisteredMover<Dgrbf2Mover<Dim>, Dgrbf2Options<Dim>>{"dgrbf2", "DGRBF with rigid rotations exact (thesis 2.2.4)"},
      RegisteredMover<SpringMover<Dim>, SpringOptions>{"spring", "lineal springs (thesis 2.1.1)"},
      RegisteredMover<TorsionSpringMover<Dim>, TorsionSpringOptions>{"torsion", "torsion springs (thesis 2.1.2)"},
      RegisteredMover<ElasticityMover<Dim>, ElasticityOptions>{"le", "linear elasticity (thesis 2.1.3)"},
      RegisteredMover<ElasticityMover<Dim>, ElasticityOptions>{"sle", "stiffened linear elasticity, chi 2.75 (thesis table 4.2)",
                                                               true, [](ElasticityOptions& o) { o.stiffening_exponent = 2.75; }},
      RegisteredMover<NonlinearElasticityMover<Dim>, NonlinearElasticityOptions>{"nle",
                                                                                 "neo-Hookean nonlinear elasticity (thesis 2.1.4)"},
      RegisteredMover<BlendMover<Dim>, BlendOptions>{"blend", "wall-distance blending of the moving walls (no solve)", true,
                                                     [](BlendOptions& o) { o.blending_factor = 6.0; }},
      RegisteredMover<BoundaryOnlyMover<Dim>, BoundaryOnlyOptions>{"none", "the prescribed boundary nodes alone", false},
  };
}

template <int Dim, std::size_t I>
using registered_entry = std::tuple_element_t<I, decltype(registered_movers<Dim>())>;

template <int Dim, std::size_t I>
[[nodiscard]] MoverOptions<Dim> registered_defaults() {
  using Options = typename registered_entry<Dim, I>::options_type;
  static_assert(std::is_constructible_v<MoverOptions<Dim>, Options>,
                "a registered mover's options type must be an alternative of MoverOptions (movers/registry.hpp)");
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
[[nodiscard]] std::array<MoverMethod<Dim>, sizeof...(I)> method_array(std::index_sequence<I...>) {
  constexpr auto table = registered_movers<Dim>();
  return {MoverMethod<Dim>{std::get<I>(table).name, std::get<I>(table).summary, &registered_defaults<Dim, I>,
                           &registered_make<Dim, I>,
                           [] {
                             using Options = typename registered_entry<Dim, I>::options_type;
                             if constexpr (requires { Options::moves_interior; }) return Options::moves_interior;
                             else return true;
                           }(),
                           std::get<I>(table).needs_cells}...};
}

}  // namespace detail

template <int Dim>
std::span<const MoverMethod<Dim>> mover_methods() {
  static const auto methods =
      detail::method_array<Dim>(std::make_index_sequence<std::tuple_size_v<decltype(detail::registered_movers<Dim>())>>{});
  return methods;
}

}  // namespace meshmotion
