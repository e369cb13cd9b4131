#pragma once
/// \file
/// The one index type of the library and the point types built on Eigen.

#include <Eigen/Core>

#include <cstddef>

namespace meshmotion {

/// Node and element index everywhere in the library (same as Eigen::Index).
using Index = std::ptrdiff_t;

/// Coordinates of nodes, one column per node: dim × n_nodes.
template <int Dim>
using Points = Eigen::Matrix<double, Dim, Eigen::Dynamic>;

/// One point or vector in Dim dimensions.
template <int Dim>
using Vec = Eigen::Matrix<double, Dim, 1>;

}  // namespace meshmotion
