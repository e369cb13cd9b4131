#pragma once
/// \file
/// The one index type of the library and the point types built on Eigen.

// The exact predicates (delaunay/predicates.hpp) and the certified quality bounds rely on
// IEEE arithmetic: -ffast-math reorders and contracts it and silently breaks both.
#if defined(__FAST_MATH__)
#error "meshmotion cannot be compiled with -ffast-math (its exact predicates and certified bounds need IEEE arithmetic)"
#endif

#include <Eigen/Core>

#include <cstddef>

namespace meshmotion {

/// Node and element index everywhere in the library (same as Eigen::Index).
using Index = std::ptrdiff_t;

/// Coordinates of nodes, one column per node: dim × n_nodes.
template <int Dim>
using Points = Eigen::Matrix<double, Dim, Eigen::Dynamic>;
/// A read-only view of a caller's Dim × n array (a Points, an Eigen::Map over a solver's or
/// numpy's memory, a block of columns): movers take their displacements this way, without a copy.
template <int Dim>
using PointsView = Eigen::Ref<const Points<Dim>>;

/// One point or vector in Dim dimensions.
template <int Dim>
using Vec = Eigen::Matrix<double, Dim, 1>;

}  // namespace meshmotion
