#pragma once
/// \file
/// Exact floating-point expansion arithmetic (Shewchuk, "Adaptive Precision Floating-Point
/// Arithmetic and Fast Robust Geometric Predicates", DCG 18, 1997). An expansion is a sum of
/// non-overlapping doubles stored in increasing magnitude; its sign is the sign of its last
/// (largest) component. Needs IEEE round-to-nearest double arithmetic: never compile this
/// with -ffast-math or on x87 extended precision.

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <memory>
#include <utility>

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

/// h = e + f exactly (Shewchuk's EXPANSION-SUM over the magnitude-merged components, zero
/// components eliminated). h needs room for e_size + f_size terms; returns h's size.
inline std::size_t expansion_sum(const double* e, std::size_t e_size, const double* f,
                                 std::size_t f_size, double* h) {
  if (e_size == 0 || f_size == 0) {
    const double* only = e_size == 0 ? f : e;
    const std::size_t size = e_size + f_size;
    std::copy(only, only + size, h);
    return size;
  }
  std::size_t ei = 0;
  std::size_t fi = 0;
  auto next = [&]() {
    if (fi >= f_size || (ei < e_size && std::abs(e[ei]) < std::abs(f[fi]))) return e[ei++];
    return f[fi++];
  };
  std::size_t h_size = 0;
  double q = next();
  while (ei < e_size || fi < f_size) {
    double q_new = 0.0;
    double h_term = 0.0;
    two_sum(q, next(), q_new, h_term);
    q = q_new;
    if (h_term != 0.0) h[h_size++] = h_term;
  }
  if (q != 0.0) h[h_size++] = q;
  return h_size;
}

/// h = e * b exactly (Shewchuk's SCALE-EXPANSION, zero components eliminated). h needs room
/// for 2 e_size terms; returns h's size.
inline std::size_t expansion_scale(const double* e, std::size_t e_size, double b, double* h) {
  if (e_size == 0 || b == 0.0) return 0;
  std::size_t h_size = 0;
  double q = 0.0;
  double h_term = 0.0;
  two_product(e[0], b, q, h_term);
  if (h_term != 0.0) h[h_size++] = h_term;
  for (std::size_t i = 1; i < e_size; ++i) {
    double product_hi = 0.0;
    double product_lo = 0.0;
    two_product(e[i], b, product_hi, product_lo);
    double sum = 0.0;
    two_sum(q, product_lo, sum, h_term);
    if (h_term != 0.0) h[h_size++] = h_term;
    // FAST-TWO-SUM: |product_hi| >= |sum| by the non-overlapping property.
    q = product_hi + sum;
    h_term = sum - (q - product_hi);
    if (h_term != 0.0) h[h_size++] = h_term;
  }
  if (q != 0.0) h[h_size++] = q;
  return h_size;
}

/// An expansion in a fixed-capacity array (no allocation), for the exact stages whose sizes
/// are bounded at compile time.
template <std::size_t Capacity>
struct FixedExpansion {
  double terms[Capacity > 0 ? Capacity : 1];
  std::size_t size = 0;

  [[nodiscard]] int sign() const noexcept {
    return size == 0 ? 0 : (terms[size - 1] > 0.0 ? 1 : -1);
  }
};

/// a * b - c * d exactly, for doubles.
[[nodiscard]] inline FixedExpansion<4> two_by_two(double a, double b, double c, double d) {
  double plus[2];
  double minus[2];
  two_product(a, b, plus[1], plus[0]);
  two_product(-c, d, minus[1], minus[0]);
  FixedExpansion<4> h;
  h.size = expansion_sum(plus, 2, minus, 2, h.terms);
  return h;
}

template <std::size_t A, std::size_t B>
[[nodiscard]] FixedExpansion<A + B> operator+(const FixedExpansion<A>& e,
                                              const FixedExpansion<B>& f) {
  FixedExpansion<A + B> h;
  h.size = expansion_sum(e.terms, e.size, f.terms, f.size, h.terms);
  return h;
}

template <std::size_t A>
[[nodiscard]] FixedExpansion<2 * A> scaled(const FixedExpansion<A>& e, double b) {
  FixedExpansion<2 * A> h;
  h.size = expansion_scale(e.terms, e.size, b, h.terms);
  return h;
}

/// e * f exactly, accumulating e scaled by each component of f.
template <std::size_t A, std::size_t B>
[[nodiscard]] FixedExpansion<2 * A * B> operator*(const FixedExpansion<A>& e,
                                                  const FixedExpansion<B>& f) {
  FixedExpansion<2 * A * B> h;
  FixedExpansion<2 * A * B> partial;
  double part[2 * A];
  for (std::size_t k = 0; k < f.size; ++k) {
    const std::size_t part_size = expansion_scale(e.terms, e.size, f.terms[k], part);
    partial.size = expansion_sum(h.terms, h.size, part, part_size, partial.terms);
    std::copy(partial.terms, partial.terms + partial.size, h.terms);
    h.size = partial.size;
  }
  return h;
}

/// Storage of expansion components: inline up to 16, on the heap beyond. On co-circular and
/// co-spherical inputs (grids) the exact path runs for a large share of the tests, and its
/// expansions are short, so avoiding the allocator there matters.
class TermBuffer {
 public:
  static constexpr std::size_t inline_capacity = 16;

  TermBuffer() = default;
  TermBuffer(const TermBuffer& other) { *this = other; }
  TermBuffer(TermBuffer&& other) noexcept { *this = std::move(other); }
  TermBuffer& operator=(const TermBuffer& other) {
    if (this == &other) return *this;
    size_ = 0;
    reserve(other.size_);
    std::copy(other.data(), other.data() + other.size_, data());
    size_ = other.size_;
    return *this;
  }
  TermBuffer& operator=(TermBuffer&& other) noexcept {
    if (this == &other) return *this;
    if (other.heap_) {
      heap_ = std::move(other.heap_);
      capacity_ = other.capacity_;
    } else {
      heap_.reset();
      capacity_ = inline_capacity;
      std::copy(other.inline_, other.inline_ + other.size_, inline_);
    }
    size_ = other.size_;
    other.size_ = 0;
    other.capacity_ = inline_capacity;
    return *this;
  }
  ~TermBuffer() = default;

  void reserve(std::size_t n) {
    if (n <= capacity_) return;
    auto grown = std::make_unique<double[]>(n);
    std::copy(data(), data() + size_, grown.get());
    heap_ = std::move(grown);
    capacity_ = n;
  }
  /// Size n with unspecified contents (to be written through begin()).
  void resize_for_overwrite(std::size_t n) {
    reserve(n);
    size_ = n;
  }
  void shrink_to(std::size_t n) noexcept { size_ = n; }
  void push_back(double value) {
    if (size_ == capacity_) reserve(2 * capacity_);
    data()[size_++] = value;
  }
  [[nodiscard]] std::size_t size() const noexcept { return size_; }
  [[nodiscard]] bool empty() const noexcept { return size_ == 0; }
  [[nodiscard]] double back() const noexcept { return data()[size_ - 1]; }
  [[nodiscard]] double operator[](std::size_t i) const noexcept { return data()[i]; }
  [[nodiscard]] double* begin() noexcept { return data(); }
  [[nodiscard]] double* end() noexcept { return data() + size_; }
  [[nodiscard]] const double* begin() const noexcept { return data(); }
  [[nodiscard]] const double* end() const noexcept { return data() + size_; }

 private:
  [[nodiscard]] double* data() noexcept { return heap_ ? heap_.get() : inline_; }
  [[nodiscard]] const double* data() const noexcept { return heap_ ? heap_.get() : inline_; }

  std::size_t size_ = 0;
  std::size_t capacity_ = inline_capacity;
  double inline_[inline_capacity] = {};
  std::unique_ptr<double[]> heap_;
};

/// An exact real number as a non-overlapping expansion of doubles, increasing magnitude,
/// zero components eliminated. Only used where the floating-point filter cannot decide.
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

  /// e + f exactly.
  [[nodiscard]] friend Expansion operator+(const Expansion& e, const Expansion& f) {
    Expansion h;
    h.terms_.resize_for_overwrite(e.terms_.size() + f.terms_.size());
    h.terms_.shrink_to(expansion_sum(e.terms_.begin(), e.terms_.size(), f.terms_.begin(),
                                     f.terms_.size(), h.terms_.begin()));
    return h;
  }

  [[nodiscard]] friend Expansion operator-(const Expansion& e, const Expansion& f) {
    return e + (-f);
  }

  /// e * b exactly.
  [[nodiscard]] Expansion scaled(double b) const {
    Expansion h;
    h.terms_.resize_for_overwrite(2 * terms_.size());
    h.terms_.shrink_to(expansion_scale(terms_.begin(), terms_.size(), b, h.terms_.begin()));
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

  [[nodiscard]] const TermBuffer& terms() const noexcept { return terms_; }

 private:
  TermBuffer terms_;
};

}  // namespace meshmotion::detail
