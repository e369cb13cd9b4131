#pragma once
// Reproducible random fields for property tests (displacements, reverse-derivative seeds).

#include "meshmotion/core/types.hpp"

#include <random>

namespace meshmotion::test {

/// Dim × columns values uniform in [-scale, scale], the same for the same seed.
template <int Dim>
Points<Dim> random_displacements(Index columns, unsigned seed, double scale = 0.01) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-scale, scale);
  Points<Dim> d(Dim, columns);
  for (Index i = 0; i < columns; ++i)
    for (int k = 0; k < Dim; ++k) d(k, i) = u(rng);
  return d;
}

}  // namespace meshmotion::test
