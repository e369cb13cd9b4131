#pragma once
/// \file
/// Exact floating-point expansion arithmetic (Shewchuk, "Adaptive Precision Floating-Point
/// Arithmetic and Fast Robust Geometric Predicates", DCG 18, 1997). An expansion is a sum of
/// non-overlapping doubles stored in increasing magnitude; its sign is the sign of its last
/// (largest) component. Needs IEEE round-to-nearest double arithmetic: never compile this
/// with -ffast-math or on x87 extended precision.

#include <cmath>
#include <cstddef>
#include <vector>

namespace meshmotion::detail {

/// a + b = x + y exactly, with x = fl(a + b).
inline void two_sum(double a, double b, double& x, double& y) {
  x = a + b;
  const double b_virtual = x - a;
  const double a_virtual = x - b_virtual;
  y = (a - a_virtual) + (b - b_virtual);
}

/// a * b = x + y exactly, with x = fl(a * b) (the fused multiply-add gives the error term).
inline void two_product(double a, double b, double& x, double& y) {
  x = a * b;
  y = std::fma(a, b, -x);
}

/// An exact real number as a non-overlapping expansion of doubles, increasing magnitude,
/// zero components eliminated. Only used where the floating-point filter cannot decide, so
/// clarity wins over avoiding allocation.
class Expansion {
 public:
  Expansion() = default;
  explicit Expansion(double value) {
    if (value != 0.0) terms_.push_back(value);
  }

  /// The exact difference a - b of two doubles.
  [[nodiscard]] static Expansion difference(double a, double b) {
    double x = 0.0;
    double y = 0.0;
    two_sum(a, -b, x, y);
    Expansion e;
    if (y != 0.0) e.terms_.push_back(y);
    if (x != 0.0) e.terms_.push_back(x);
    return e;
  }

  /// -1, 0 or +1.
  [[nodiscard]] int sign() const noexcept {
    if (terms_.empty()) return 0;
    return terms_.back() > 0.0 ? 1 : -1;
  }

  [[nodiscard]] Expansion operator-() const {
    Expansion e = *this;
    for (double& t : e.terms_) t = -t;
    return e;
  }

  /// Shewchuk's EXPANSION-SUM over the magnitude-merged components, with zero elimination.
  [[nodiscard]] friend Expansion operator+(const Expansion& e, const Expansion& f) {
    if (e.terms_.empty()) return f;
    if (f.terms_.empty()) return e;
    const std::vector<double>& et = e.terms_;
    const std::vector<double>& ft = f.terms_;
    std::size_t ei = 0;
    std::size_t fi = 0;
    auto next = [&]() {
      if (fi >= ft.size() || (ei < et.size() && std::abs(et[ei]) < std::abs(ft[fi]))) {
        return et[ei++];
      }
      return ft[fi++];
    };
    Expansion h;
    h.terms_.reserve(et.size() + ft.size());
    double q = next();
    while (ei < et.size() || fi < ft.size()) {
      double q_new = 0.0;
      double h_term = 0.0;
      two_sum(q, next(), q_new, h_term);
      q = q_new;
      if (h_term != 0.0) h.terms_.push_back(h_term);
    }
    if (q != 0.0) h.terms_.push_back(q);
    return h;
  }

  [[nodiscard]] friend Expansion operator-(const Expansion& e, const Expansion& f) {
    return e + (-f);
  }

  /// Shewchuk's SCALE-EXPANSION with zero elimination: e * b exactly.
  [[nodiscard]] Expansion scaled(double b) const {
    Expansion h;
    if (terms_.empty() || b == 0.0) return h;
    h.terms_.reserve(2 * terms_.size());
    double q = 0.0;
    double h_term = 0.0;
    two_product(terms_[0], b, q, h_term);
    if (h_term != 0.0) h.terms_.push_back(h_term);
    for (std::size_t i = 1; i < terms_.size(); ++i) {
      double product_hi = 0.0;
      double product_lo = 0.0;
      two_product(terms_[i], b, product_hi, product_lo);
      double sum = 0.0;
      two_sum(q, product_lo, sum, h_term);
      if (h_term != 0.0) h.terms_.push_back(h_term);
      // FAST-TWO-SUM: |product_hi| >= |sum| by the non-overlapping property.
      q = product_hi + sum;
      h_term = sum - (q - product_hi);
      if (h_term != 0.0) h.terms_.push_back(h_term);
    }
    if (q != 0.0) h.terms_.push_back(q);
    return h;
  }

  /// e * f exactly: the sum of e scaled by each component of f.
  [[nodiscard]] friend Expansion operator*(const Expansion& e, const Expansion& f) {
    const Expansion& small = e.terms_.size() <= f.terms_.size() ? e : f;
    const Expansion& large = e.terms_.size() <= f.terms_.size() ? f : e;
    Expansion h;
    for (double t : small.terms_) h = h + large.scaled(t);
    return h;
  }

  [[nodiscard]] const std::vector<double>& terms() const noexcept { return terms_; }

 private:
  std::vector<double> terms_;
};

}  // namespace meshmotion::detail
