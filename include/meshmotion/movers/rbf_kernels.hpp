#pragma once
/// \file
/// Radial basis functions of the RBF mover (thesis section 2.2.2): Wendland's compactly
/// supported C0, C2 (thesis eq. 2.14), C4 and C6 functions, and the globally supported thin
/// plate spline, Gaussian, multiquadric and inverse multiquadric. All take the distance r and
/// a radius: the support radius of the compact kernels, the shape scale of the global ones.

#include "meshmotion/core/error.hpp"

#include <array>
#include <cmath>
#include <string>
#include <string_view>

namespace meshmotion {

enum class RbfKernel {
  wendland0,              ///< (1-ξ)^2                                   ξ = r / r_s, zero for ξ ≥ 1
  wendland2,              ///< (1-ξ)^4 (4ξ+1)                            thesis eq. 2.14
  wendland4,              ///< (1-ξ)^6 (35ξ^2+18ξ+3) / 3
  wendland6,              ///< (1-ξ)^8 (32ξ^3+25ξ^2+8ξ+1)
  thin_plate_spline,      ///< ξ^2 log ξ                                 ξ = r / scale; needs polynomial augmentation
  gaussian,               ///< exp(-ξ^2)
  multiquadric,           ///< sqrt(1+ξ^2)
  inverse_multiquadric,   ///< 1 / sqrt(1+ξ^2)
};

inline constexpr std::array<RbfKernel, 8> all_rbf_kernels{
    RbfKernel::wendland0,         RbfKernel::wendland2, RbfKernel::wendland4,    RbfKernel::wendland6,
    RbfKernel::thin_plate_spline, RbfKernel::gaussian,  RbfKernel::multiquadric, RbfKernel::inverse_multiquadric};

/// Whether the kernel is only conditionally positive definite (the thin plate spline of order
/// 2, the multiquadric of order 1): its interpolation system is well posed only with the
/// polynomial, which RbfMover therefore always adds for it.
[[nodiscard]] constexpr bool needs_polynomial(RbfKernel kernel) {
  return kernel == RbfKernel::thin_plate_spline || kernel == RbfKernel::multiquadric;
}

/// Name used on command lines: "wendland0", ..., "tps", "gaussian", "multiquadric", "inverse_multiquadric".
[[nodiscard]] constexpr std::string_view name(RbfKernel kernel) {
  switch (kernel) {
    case RbfKernel::wendland0: return "wendland0";
    case RbfKernel::wendland2: return "wendland2";
    case RbfKernel::wendland4: return "wendland4";
    case RbfKernel::wendland6: return "wendland6";
    case RbfKernel::thin_plate_spline: return "tps";
    case RbfKernel::gaussian: return "gaussian";
    case RbfKernel::multiquadric: return "multiquadric";
    case RbfKernel::inverse_multiquadric: return "inverse_multiquadric";
  }
  return "unknown";
}

/// Every kernel, for the option parser (core/option_text.hpp).
[[nodiscard]] constexpr const std::array<RbfKernel, 8>& option_choices(RbfKernel) { return all_rbf_kernels; }

/// The kernel of that name; throws InputError listing the names otherwise.
[[nodiscard]] inline RbfKernel rbf_kernel_from_name(std::string_view kernel_name) {
  std::string known;
  for (const RbfKernel k : all_rbf_kernels) {
    if (name(k) == kernel_name) return k;
    known += (known.empty() ? "" : ", ") + std::string(name(k));
  }
  throw InputError("rbf_kernel_from_name: unknown kernel '" + std::string(kernel_name) + "' (expected one of " +
                   known + ")");
}

/// True for the Wendland functions, zero beyond the support radius (sparse systems).
[[nodiscard]] constexpr bool is_compact(RbfKernel kernel) {
  return kernel == RbfKernel::wendland0 || kernel == RbfKernel::wendland2 || kernel == RbfKernel::wendland4 ||
         kernel == RbfKernel::wendland6;
}

/// φ(r) for radius `radius` (> 0). Compact kernels are 1 at r = 0 and 0 for r ≥ radius.
[[nodiscard]] inline double rbf_value(RbfKernel kernel, double r, double radius) {
  const double x = r / radius;
  if (is_compact(kernel) && x >= 1.0) return 0.0;
  const double s = 1.0 - x;
  switch (kernel) {
    case RbfKernel::wendland0: return s * s;
    case RbfKernel::wendland2: { const double s2 = s * s; return s2 * s2 * (4.0 * x + 1.0); }
    case RbfKernel::wendland4: {
      const double s2 = s * s;
      return s2 * s2 * s2 * (35.0 * x * x + 18.0 * x + 3.0) / 3.0;
    }
    case RbfKernel::wendland6: {
      const double s4 = s * s * s * s;
      return s4 * s4 * (((32.0 * x + 25.0) * x + 8.0) * x + 1.0);
    }
    case RbfKernel::thin_plate_spline: return x > 0.0 ? x * x * std::log(x) : 0.0;
    case RbfKernel::gaussian: return std::exp(-x * x);
    case RbfKernel::multiquadric: return std::sqrt(1.0 + x * x);
    case RbfKernel::inverse_multiquadric: return 1.0 / std::sqrt(1.0 + x * x);
  }
  return 0.0;
}

}  // namespace meshmotion
