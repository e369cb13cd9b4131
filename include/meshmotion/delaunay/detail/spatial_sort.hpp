#pragma once
/// \file
/// Insertion order for incremental Delaunay construction: a biased randomized insertion order
/// (BRIO, Amenta, Choi and Rote 2003) whose rounds are each sorted along a Hilbert curve, so
/// consecutive points are close (short walks, cache locality) while the rounds keep the
/// randomized expected complexity. The points are normalized to the unit box only to compute
/// the curve keys (thesis appendix A, "scale entries of pointList to normalize the data").

#include "meshmotion/core/types.hpp"

#include <algorithm>
#include <bit>
#include <cstdint>
#include <random>
#include <vector>

namespace meshmotion::detail {

/// The bits of x (up to 16 for Dim = 2, 10 for Dim = 3) moved to every Dim-th position.
template <int Dim>
[[nodiscard]] constexpr std::uint64_t spread_bits(std::uint32_t x) noexcept {
  std::uint64_t v = x;
  if constexpr (Dim == 2) {
    v = (v | (v << 8)) & 0x00FF00FFull;
    v = (v | (v << 4)) & 0x0F0F0F0Full;
    v = (v | (v << 2)) & 0x33333333ull;
    v = (v | (v << 1)) & 0x55555555ull;
  } else {
    v = (v | (v << 16)) & 0x030000FFull;
    v = (v | (v << 8)) & 0x0300F00Full;
    v = (v | (v << 4)) & 0x030C30C3ull;
    v = (v | (v << 2)) & 0x09249249ull;
  }
  return v;
}

/// Position of a grid cell along the Hilbert curve (Skilling, "Programming the Hilbert curve",
/// AIP Conf. Proc. 707, 2004). `cell` holds Dim coordinates of Bits bits each.
template <int Dim, int Bits>
[[nodiscard]] std::uint64_t hilbert_key(std::uint32_t cell[Dim]) {
  constexpr std::uint32_t top = 1u << (Bits - 1);
  for (std::uint32_t q = top; q > 1; q >>= 1) {
    const std::uint32_t p = q - 1;
    for (int i = 0; i < Dim; ++i) {
      // Branch-free form of: bit set ? invert low bits of cell[0] : exchange them with cell[i]
      // (random points would mispredict the branch half of the time).
      const std::uint32_t set = 0u - static_cast<std::uint32_t>((cell[i] & q) != 0);
      const std::uint32_t t = (cell[0] ^ cell[i]) & p & ~set;
      cell[0] ^= (p & set) | t;
      cell[i] ^= t;
    }
  }
  for (int i = 1; i < Dim; ++i) cell[i] ^= cell[i - 1];
  std::uint32_t t = 0;
  for (std::uint32_t q = top; q > 1; q >>= 1) {
    if (cell[Dim - 1] & q) t ^= q - 1;
  }
  for (int i = 0; i < Dim; ++i) cell[i] ^= t;
  // Interleave the bits, cell[0] most significant at each level.
  std::uint64_t key = 0;
  for (int i = 0; i < Dim; ++i) key |= spread_bits<Dim>(cell[i]) << (Dim - 1 - i);
  return key;
}

/// A BRIO with Hilbert-sorted rounds: each point is drawn into a round at random (the last
/// round holds about 3/4 of the points, each earlier one 1/4 of the next, the first at least
/// `first_round` points), and each round is sorted along a Hilbert curve of the unit-box
/// normalized points. Returns a permutation of 0..n-1. One sequential pass and one integer
/// sort: no random access to the points.
template <int Dim>
[[nodiscard]] std::vector<Index> brio_order(const Points<Dim>& points, std::uint64_t seed,
                                            std::size_t first_round = 1000) {
  const auto n = static_cast<std::size_t>(points.cols());
  std::vector<Index> ids(n);
  if (n == 0) return ids;
  const Vec<Dim> lower = points.rowwise().minCoeff();
  const Vec<Dim> upper = points.rowwise().maxCoeff();
  const double extent = (upper - lower).maxCoeff();
  const double inverse_extent = extent > 0.0 ? 1.0 / extent : 0.0;
  int last_round = 0;
  for (std::size_t size = n; size > first_round; size /= 4) ++last_round;
  constexpr int bits = 32 / Dim;
  const double cells = static_cast<double>((1u << bits) - 1u);
  std::mt19937_64 rng(seed);
  struct Keyed {
    std::uint64_t key;
    std::uint64_t id;
    bool operator<(const Keyed& other) const noexcept { return key < other.key; }
  };
  std::vector<Keyed> keyed(n);
  for (std::size_t i = 0; i < n; ++i) {
    std::uint32_t cell[Dim];
    for (int d = 0; d < Dim; ++d) {
      const double unit = (points(d, static_cast<Index>(i)) - lower[d]) * inverse_extent;
      cell[d] = static_cast<std::uint32_t>(std::clamp(unit, 0.0, 1.0) * cells);
    }
    // P(round <= last_round - k) = 4^-k: two zero random bits per round moved back.
    const int back = std::countr_zero(rng() | (std::uint64_t{1} << 63)) / 2;
    const int round = std::max(0, last_round - back);
    keyed[i] = Keyed{static_cast<std::uint64_t>(round) << 40 | hilbert_key<Dim, bits>(cell),
                     static_cast<std::uint64_t>(i)};
  }
  std::sort(keyed.begin(), keyed.end());
  for (std::size_t i = 0; i < n; ++i) ids[i] = static_cast<Index>(keyed[i].id);
  return ids;
}

}  // namespace meshmotion::detail
