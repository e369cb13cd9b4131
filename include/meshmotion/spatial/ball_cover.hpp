#pragma once
/// \file
/// BallCover<Dim>: a conservative test whether a point may lie in one of a set of balls, in
/// constant time. A bitmap over a uniform grid marks every cell that meets a ball's bounding
/// box: a point in an unmarked cell lies in no ball; a point in a marked one may (within a
/// cell's width of one). It answers "can this node be within reach of the wall?" for every node
/// of a mesh before the k-d search that finds out, where each wall vertex has its own reach
/// (the 30P30N's largest wall facet is 14 times its median one).

#include "meshmotion/core/error.hpp"
#include "meshmotion/core/types.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <vector>

namespace meshmotion {

template <int Dim>
class BallCover {
 public:
  /// Most grid cells: a bitmap of half a megabyte.
  static constexpr double max_cells = double(std::int64_t{1} << 22);

  BallCover() = default;

  /// Balls of `centres` (Dim × n) and `radii` (n; a radius ≤ 0 is no ball). The cells are about
  /// the median radius wide, wider when the balls' box would need more than max_cells. When
  /// marking would visit more than 16 cells per cell of the grid and per ball (radii spread over
  /// orders of magnitude), the cover keeps only the box: contains() is then true within it.
  /// Throws InputError when the sizes differ or a radius or centre is not finite.
  BallCover(const Points<Dim>& centres, std::span<const double> radii) {
    if (static_cast<std::size_t>(centres.cols()) != radii.size())
      throw InputError("BallCover: " + std::to_string(radii.size()) + " radii for " + std::to_string(centres.cols()) +
                       " centres");
    std::vector<double> positive;
    for (Index i = 0; i < centres.cols(); ++i) {
      const double r = radii[static_cast<std::size_t>(i)];
      if (!std::isfinite(r) || !centres.col(i).allFinite())
        throw InputError("BallCover: ball " + std::to_string(i) + " has a non-finite centre or radius");
      if (r <= 0.0) continue;
      positive.push_back(r);
      lower_ = lower_.cwiseMin(centres.col(i).array() - r);
      upper_ = upper_.cwiseMax(centres.col(i).array() + r);
    }
    if (positive.empty()) return;
    const auto middle = positive.begin() + static_cast<std::ptrdiff_t>(positive.size() / 2);
    std::nth_element(positive.begin(), middle, positive.end());
    double width = *middle;
    const Eigen::Array<double, Dim, 1> extent = upper_ - lower_;
    double cells = (extent / width).ceil().max(1.0).prod();
    if (cells > max_cells) width *= std::pow(cells / max_cells, 1.0 / Dim) * (1.0 + 1e-9);
    inverse_width_ = 1.0 / width;
    for (int d = 0; d < Dim; ++d) size_[d] = std::max<Index>(1, static_cast<Index>(std::ceil(extent[d] * inverse_width_)));
    double visits = 0.0;
    for (std::size_t i = 0; i < radii.size(); ++i)
      if (radii[i] > 0.0) visits += std::pow(2.0 * radii[i] * inverse_width_ + 2.0, Dim);
    cells = 1.0;
    for (int d = 0; d < Dim; ++d) cells *= static_cast<double>(size_[d]);
    if (visits > 16.0 * (cells + static_cast<double>(positive.size()))) return;  // box only
    bits_.assign(static_cast<std::size_t>((cells + 63.0) / 64.0), 0);
    for (Index i = 0; i < centres.cols(); ++i) {
      const double r = radii[static_cast<std::size_t>(i)];
      if (r <= 0.0) continue;
      std::array<Index, 3> first{}, last{};
      for (int d = 0; d < Dim; ++d) {
        first[d] = cell(d, centres(d, i) - r);
        last[d] = cell(d, centres(d, i) + r);
      }
      mark(first, last);
    }
  }

  /// False when p lies in no ball; true when it may lie in one (always within the balls' box
  /// when the cover kept only the box).
  [[nodiscard]] bool contains(const Vec<Dim>& p) const {
    if ((p.array() < lower_).any() || (p.array() > upper_).any()) return false;
    if (bits_.empty()) return inverse_width_ > 0.0;
    std::size_t index = 0;
    for (int d = Dim - 1; d >= 0; --d) index = index * static_cast<std::size_t>(size_[d]) + static_cast<std::size_t>(cell(d, p[d]));
    return (bits_[index / 64] >> (index % 64)) & 1U;
  }

 private:
  [[nodiscard]] Index cell(int d, double x) const {
    const double c = std::floor((x - lower_[d]) * inverse_width_);
    return static_cast<Index>(std::clamp(c, 0.0, static_cast<double>(size_[d] - 1)));
  }

  void mark(const std::array<Index, 3>& first, const std::array<Index, 3>& last) {
    std::array<Index, 3> at = first;
    while (true) {
      std::size_t index = 0;
      for (int d = Dim - 1; d >= 0; --d) index = index * static_cast<std::size_t>(size_[d]) + static_cast<std::size_t>(at[d]);
      bits_[index / 64] |= std::uint64_t{1} << (index % 64);
      int d = 0;
      while (d < Dim && at[d] == last[d]) at[d] = first[d], ++d;
      if (d == Dim) return;
      ++at[d];
    }
  }

  Eigen::Array<double, Dim, 1> lower_ = Eigen::Array<double, Dim, 1>::Constant(std::numeric_limits<double>::infinity());
  Eigen::Array<double, Dim, 1> upper_ = Eigen::Array<double, Dim, 1>::Constant(-std::numeric_limits<double>::infinity());
  double inverse_width_ = 0.0;  // 0: no ball
  std::array<Index, Dim> size_{};
  std::vector<std::uint64_t> bits_;
};

}  // namespace meshmotion
