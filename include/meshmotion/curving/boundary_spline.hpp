#pragma once
/// \file
/// BoundarySpline: the C^2 cubic-spline reconstruction of a 2D boundary from the linear mesh
/// alone (thesis section 3.2 and appendix B). The boundary is given as chains of nodes; each
/// chain is split at its corners and every corner-to-corner run becomes an open spline
/// (eq. B.13, natural or not-a-knot ends), a closed chain without corners a cyclic spline
/// (eq. B.14). Each boundary facet i gets the cubic r_i(t) = a + b t + c t^2 + d t^3,
/// t in [0, 1] (eq. B.1), from its first node (t = 0) to its second (t = 1).
///
/// The systems are the symmetric, diagonally dominant (cyclic) tridiagonal systems of the
/// node tangents: solved in O(n) by the Thomas algorithm and a Sherman–Morrison correction
/// for the cyclic one. Setup cost is O(total chain length); every query is O(1) except
/// find_facet (O(log n)).

#include "meshmotion/core/error.hpp"
#include "meshmotion/core/topology.hpp"
#include "meshmotion/core/types.hpp"
#include "meshmotion/curving/detail/closest_point.hpp"
#include "meshmotion/curving/detail/tridiagonal.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

namespace meshmotion {

/// How the spline parameter advances over a facet. The first enumerator is the default, so
/// a value-initialized option means the default.
enum class SplineParametrization {
  centripetal,   ///< proportional to the square root of the facet's length (Lee 1989)
  chord_length,  ///< proportional to the facet's length: straight runs stay linear in t
  uniform,       ///< one unit per facet (thesis, eqs. B.13/B.14)
};

/// End conditions of an open (corner-to-corner) spline; the first enumerator is the default.
enum class SplineEndCondition {
  not_a_knot,  ///< continuous third derivative at the second and last-but-one nodes
  natural,     ///< zero second derivative at both ends (thesis eqs. B.11–B.12)
};

/// Options of BoundarySpline.
struct BoundarySplineOptions {
  /// A node is a corner when the directions of its two facets differ by more than this
  /// angle, in degrees (equivalently: their normals do). 180 or more disables detection.
  double corner_angle = 30.0;
  /// Nodes (indices into the point matrix) that are corners whatever their angle.
  std::vector<Index> corner_nodes;
  /// Centripetal is the default: on boundaries graded like boundary-layer walls (geometric
  /// spacing) it is 5 to 18 times more accurate than chord length and uniform, and never far
  /// from the best on smooth samplings (docs/curving_boundary.md gives the measurements).
  SplineParametrization parametrization = SplineParametrization::centripetal;
  /// Not-a-knot is the default: it keeps fourth-order accuracy up to the corners, where the
  /// natural condition forces a zero curvature the true boundary rarely has.
  SplineEndCondition end_condition = SplineEndCondition::not_a_knot;
};

namespace detail {

/// Work arrays of the spline systems, reused from one corner-to-corner run to the next.
struct SplineWorkspace {
  std::vector<double> sub, diag, sup;
  CyclicWorkspace cyclic;
};

/// Node tangents dr/ds (s the spline parameter) of the cubic spline through `values` with
/// parameter steps `steps` (steps[j] between values[j] and values[j+1], all > 0).
/// Open: values.size() == steps.size() + 1, `end` chooses the end conditions; cyclic
/// (`closed`): values.size() == steps.size() >= 3, the last step closing the loop.
/// Writes values.size() tangents into `tangents`.
inline void spline_tangents(std::span<const double> steps, std::span<const Vec<2>> values,
                            bool closed, SplineEndCondition end, std::span<Vec<2>> tangents,
                            SplineWorkspace& work) {
  const std::size_t n = values.size();
  const std::size_t facets = steps.size();
  auto slope = [&](std::size_t j) -> Vec<2> {
    return (values[(j + 1) % n] - values[j]) / steps[j];
  };
  work.sub.assign(n, 0.0);
  work.diag.assign(n, 0.0);
  work.sup.assign(n, 0.0);
  // Row j of the tangent equations is divided by h_{j-1} h_j, which makes the matrix
  // symmetric; with unit steps the rows are exactly those of eqs. B.13 and B.14.
  auto interior_row = [&](std::size_t j, std::size_t before) {
    const double w0 = 1.0 / steps[before];
    const double w1 = 1.0 / steps[j];
    work.sub[j] = w0;
    work.diag[j] = 2.0 * (w0 + w1);
    work.sup[j] = w1;
    tangents[j] = 3.0 * (slope(before) * w0 + slope(j) * w1);
  };
  if (closed) {
    for (std::size_t j = 0; j < n; ++j) interior_row(j, (j + n - 1) % n);
    const double corner = 1.0 / steps[n - 1];
    solve_cyclic_tridiagonal(std::span<const double>(work.sub),
                             std::span<const double>(work.diag),
                             std::span<const double>(work.sup), corner, corner, tangents,
                             work.cyclic);
    return;
  }
  if (facets == 1) {
    tangents[0] = tangents[1] = slope(0);
    return;
  }
  if (end == SplineEndCondition::not_a_knot && facets == 2) {
    // Not-a-knot on three nodes: the interpolating parabola.
    const double h0 = steps[0], h1 = steps[1];
    const Vec<2> second = (slope(1) - slope(0)) / (h0 + h1);
    tangents[0] = slope(0) - h0 * second;
    tangents[1] = slope(0) + h0 * second;
    tangents[2] = slope(0) + (h0 + 2.0 * h1) * second;
    return;
  }
  for (std::size_t j = 1; j + 1 < n; ++j) interior_row(j, j - 1);
  const std::size_t last = n - 1;
  if (end == SplineEndCondition::natural) {
    work.diag[0] = 2.0 / steps[0];
    work.sup[0] = 1.0 / steps[0];
    tangents[0] = 3.0 * slope(0) / steps[0];
    work.sub[last] = 1.0 / steps[last - 1];
    work.diag[last] = 2.0 / steps[last - 1];
    tangents[last] = 3.0 * slope(last - 1) / steps[last - 1];
  } else {
    // de Boor, "A Practical Guide to Splines", CUBSPL: d^3 r/ds^3 continuous at node 1 and
    // node n-2, written as a two-term row so the system stays tridiagonal.
    const double h0 = steps[0], h1 = steps[1];
    work.diag[0] = h1;
    work.sup[0] = h0 + h1;
    tangents[0] = ((h0 + 2.0 * (h0 + h1)) * h1 * slope(0) + h0 * h0 * slope(1)) / (h0 + h1);
    const double g0 = steps[last - 1], g1 = steps[last - 2];
    work.sub[last] = g0 + g1;
    work.diag[last] = g1;
    tangents[last] =
        ((g0 + 2.0 * (g0 + g1)) * g1 * slope(last - 1) + g0 * g0 * slope(last - 2)) / (g0 + g1);
  }
  solve_tridiagonal(std::span<const double>(work.sub), std::span<const double>(work.diag),
                    std::span<const double>(work.sup), tangents, work.cyclic.scratch);
}

}  // namespace detail

/// Piecewise C^2 cubic reconstruction of 2D boundary chains (thesis section 3.2, app. B).
class BoundarySpline {
 public:
  /// A facet and whether the asked node pair runs against its orientation.
  struct FacetRef {
    Index facet;
    bool reversed;
  };
  /// Result of closest_point: parameter on the facet, the point and its distance.
  struct ClosestPoint {
    double t;
    Vec<2> point;
    double distance;
  };

  /// Reconstructs every chain (BoundaryChain of core/topology.hpp: `nodes` and `closed` are
  /// used; an open chain of n nodes has n - 1 facets, a closed one n, the last closing the
  /// loop). `points`: 2 × n_nodes coordinates; chains index its columns.
  /// Facets are numbered chain by chain in chain order (see chain_first_facet).
  /// Throws InputError for an out-of-range node index, a non-finite coordinate, an open chain
  /// of fewer than 2 or a closed one of fewer than 3 nodes, two consecutive nodes at the
  /// same position, or a corner_angle that is NaN or outside 0 to 180 degrees.
  BoundarySpline(const Points<2>& points, std::span<const BoundaryChain> chains,
                 BoundarySplineOptions options = {})
      : options_(std::move(options)) {
    if (!(options_.corner_angle >= 0.0 && options_.corner_angle <= 180.0))
      throw InputError("BoundarySpline: invalid corner_angle (got " + std::to_string(options_.corner_angle) +
                       ", expected 0 to 180 degrees)");
    std::sort(options_.corner_nodes.begin(), options_.corner_nodes.end());
    Index total = 0;
    for (const BoundaryChain& chain : chains)
      total += static_cast<Index>(chain.nodes.size()) - (chain.closed ? 0 : 1);
    cubics_.reserve(static_cast<std::size_t>(std::max<Index>(total, 0)));
    facet_nodes_.reserve(cubics_.capacity());
    chain_first_facet_.reserve(chains.size() + 1);
    Scratch scratch;
    for (std::size_t c = 0; c < chains.size(); ++c) add_chain(points, chains[c], c, scratch);
    chain_first_facet_.push_back(num_facets());
    std::sort(corners_.begin(), corners_.end());
    corners_.erase(std::unique(corners_.begin(), corners_.end()), corners_.end());
    facet_lookup_.reserve(facet_nodes_.size());
    for (Index f = 0; f < num_facets(); ++f) {
      const auto [a, b] = facet_nodes_[static_cast<std::size_t>(f)];
      facet_lookup_.push_back({{std::min(a, b), std::max(a, b)}, f});
    }
    std::sort(facet_lookup_.begin(), facet_lookup_.end());
  }

  [[nodiscard]] Index num_facets() const noexcept { return static_cast<Index>(cubics_.size()); }
  [[nodiscard]] Index num_chains() const noexcept {
    return static_cast<Index>(chain_first_facet_.size()) - 1;
  }
  /// First facet of chain c; its facets are chain_first_facet(c) .. chain_first_facet(c+1)-1,
  /// facet chain_first_facet(c) + k running from chain.nodes[k] to the next node.
  [[nodiscard]] Index chain_first_facet(Index c) const {
    return chain_first_facet_.at(static_cast<std::size_t>(c));
  }
  /// The two nodes of facet f: t = 0 at the first, t = 1 at the second.
  [[nodiscard]] std::array<Index, 2> facet_nodes(Index f) const { return facet_nodes_.at(check(f)); }
  [[nodiscard]] SplineParametrization parametrization() const noexcept {
    return options_.parametrization;
  }
  [[nodiscard]] SplineEndCondition end_condition() const noexcept { return options_.end_condition; }
  /// Corner nodes (sorted): chain ends, nodes over the angle threshold, listed nodes.
  [[nodiscard]] std::span<const Index> corners() const noexcept { return corners_; }
  [[nodiscard]] bool is_corner(Index node) const {
    return std::binary_search(corners_.begin(), corners_.end(), node);
  }
  /// The facet joining nodes a and b (either order), if one of the chains has it.
  [[nodiscard]] std::optional<FacetRef> find_facet(Index a, Index b) const {
    const std::array<Index, 2> key{std::min(a, b), std::max(a, b)};
    const auto it = std::lower_bound(
        facet_lookup_.begin(), facet_lookup_.end(), key,
        [](const auto& entry, const std::array<Index, 2>& k) { return entry.first < k; });
    if (it == facet_lookup_.end() || it->first != key) return std::nullopt;
    return FacetRef{it->second, facet_nodes_[static_cast<std::size_t>(it->second)][0] != a};
  }

  /// r_f(t), eq. B.1. t in [0, 1] interpolates the facet; outside it extrapolates.
  [[nodiscard]] Vec<2> point(Index f, double t) const {
    const Cubic& q = cubics_[check(f)];
    return q.a + t * (q.b + t * (q.c + t * q.d));
  }
  /// dr_f/dt: the (unnormalized) tangent, pointing from the first node to the second.
  [[nodiscard]] Vec<2> tangent(Index f, double t) const {
    const Cubic& q = cubics_[check(f)];
    return q.b + t * (2.0 * q.c + 3.0 * t * q.d);
  }
  /// d^2 r_f/dt^2.
  [[nodiscard]] Vec<2> second_derivative(Index f, double t) const {
    const Cubic& q = cubics_[check(f)];
    return 2.0 * q.c + 6.0 * t * q.d;
  }
  /// The facet's parameter midpoint r_f(1/2): where the thesis puts the P2 node.
  [[nodiscard]] Vec<2> midpoint(Index f) const { return point(f, 0.5); }

  /// Length of r_f between t0 and t1 (Gauss–Legendre, 4 panels of 5 points: relative error
  /// far below the reconstruction error for any facet that is not folded).
  [[nodiscard]] double arc_length(Index f, double t0 = 0.0, double t1 = 1.0) const {
    static constexpr std::array<double, 5> nodes{0.0, -0.5384693101056831, 0.5384693101056831,
                                                 -0.9061798459386640, 0.9061798459386640};
    static constexpr std::array<double, 5> weights{0.5688888888888889, 0.4786286704993665,
                                                   0.4786286704993665, 0.2369268850561891,
                                                   0.2369268850561891};
    constexpr int panels = 4;
    const double width = (t1 - t0) / panels;
    double length = 0.0;
    for (int p = 0; p < panels; ++p) {
      const double centre = t0 + (p + 0.5) * width;
      for (std::size_t k = 0; k < nodes.size(); ++k)
        length += weights[k] * tangent(f, centre + 0.5 * width * nodes[k]).norm();
    }
    return 0.5 * width * length;
  }
  /// Parameter t at which the arc length from t = 0 is `fraction` of the facet's length.
  /// Throws InputError when fraction is outside [0, 1].
  [[nodiscard]] double arc_length_parameter(Index f, double fraction) const {
    if (!(fraction >= 0.0 && fraction <= 1.0))
      throw InputError("BoundarySpline::arc_length_parameter: fraction out of range (got " +
                       std::to_string(fraction) + ", expected [0, 1])");
    const double target = fraction * arc_length(f);
    double lo = 0.0, hi = 1.0, t = fraction;
    for (int iteration = 0; iteration < 60; ++iteration) {
      const double residual = arc_length(f, 0.0, t) - target;
      if (residual > 0.0) hi = t; else lo = t;
      const double speed = tangent(f, t).norm();
      double next = speed > 0.0 ? t - residual / speed : 0.5 * (lo + hi);
      if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
      if (std::abs(next - t) < 1e-14) return next;
      t = next;
    }
    return t;
  }
  /// The point halving the facet's arc length (an alternative to midpoint()).
  [[nodiscard]] Vec<2> arc_length_midpoint(Index f) const {
    return point(f, arc_length_parameter(f, 0.5));
  }

  /// Closest point of r_f(t), t in [0, 1], to p. Throws InputError for a non-finite p.
  [[nodiscard]] ClosestPoint closest_point(Index f, const Vec<2>& p) const {
    if (!p.allFinite())
      throw InputError("BoundarySpline::closest_point: point is not finite");
    const double t = detail::closest_parameter<2>(
        [&](double s) {
          return detail::CurveSample<2>{point(f, s), tangent(f, s), second_derivative(f, s)};
        },
        p, 0.0, 1.0, 8, "BoundarySpline::closest_point");
    const Vec<2> q = point(f, t);
    return {t, q, (q - p).norm()};
  }

 private:
  struct Cubic {
    Vec<2> a, b, c, d;
  };

  [[nodiscard]] std::size_t check(Index f) const {
    if (f < 0 || f >= num_facets())
      throw InputError("BoundarySpline: facet index out of range (got " + std::to_string(f) +
                       ", expected 0.." + std::to_string(num_facets() - 1) + ")");
    return static_cast<std::size_t>(f);
  }

  /// Work arrays of the setup, reused from one chain and run to the next.
  struct Scratch {
    std::vector<Vec<2>> positions, run_values, run_tangents;
    std::vector<double> run_steps;
    std::vector<std::size_t> corner_positions;
    detail::SplineWorkspace spline;
  };

  void add_chain(const Points<2>& points, const BoundaryChain& chain, std::size_t c,
                 Scratch& scratch) {
    auto& positions = scratch.positions;
    auto& corner_positions = scratch.corner_positions;
    const std::string where = "BoundarySpline: chain " + std::to_string(c);
    const std::size_t n = chain.nodes.size();
    const std::size_t minimum = chain.closed ? 3 : 2;
    if (n < minimum)
      throw InputError(where + ": too few nodes (got " + std::to_string(n) + ", expected at least " +
                       std::to_string(minimum) + (chain.closed ? " for a closed chain)" : ")"));
    positions.resize(n);
    for (std::size_t k = 0; k < n; ++k) {
      const Index node = chain.nodes[k];
      if (node < 0 || node >= points.cols())
        throw InputError(where + ": node index out of range (got " + std::to_string(node) +
                         ", expected 0.." + std::to_string(points.cols() - 1) + ")");
      positions[k] = points.col(node);
      if (!positions[k].allFinite())
        throw InputError(where + ": node " + std::to_string(node) + " has a non-finite coordinate");
    }
    const std::size_t facets = chain.closed ? n : n - 1;
    for (std::size_t k = 0; k < facets; ++k)
      if ((positions[(k + 1) % n] - positions[k]).norm() == 0.0)
        throw InputError(where + ": nodes " + std::to_string(chain.nodes[k]) + " and " +
                         std::to_string(chain.nodes[(k + 1) % n]) +
                         " coincide (expected distinct consecutive nodes)");

    const Index first_facet = num_facets();
    chain_first_facet_.push_back(first_facet);
    for (std::size_t k = 0; k < facets; ++k) {
      facet_nodes_.push_back({chain.nodes[k], chain.nodes[(k + 1) % n]});
      cubics_.emplace_back();
    }

    // Corners, as positions along the chain.
    const double cos_threshold = std::cos(options_.corner_angle * std::numbers::pi / 180.0);
    corner_positions.clear();
    for (std::size_t k = 0; k < n; ++k) {
      bool corner = std::binary_search(options_.corner_nodes.begin(),
                                       options_.corner_nodes.end(), chain.nodes[k]);
      if (!chain.closed && (k == 0 || k + 1 == n)) {
        corner = true;
      } else if (options_.corner_angle < 180.0) {
        const Vec<2> incoming = (positions[k] - positions[(k + n - 1) % n]).normalized();
        const Vec<2> outgoing = (positions[(k + 1) % n] - positions[k]).normalized();
        corner = corner || incoming.dot(outgoing) < cos_threshold;
      }
      if (corner) {
        corner_positions.push_back(k);
        corners_.push_back(chain.nodes[k]);
      }
    }

    if (corner_positions.empty()) {  // smooth closed chain: one cyclic spline (eq. B.14)
      fit_run(first_facet, 0, n, n, true, scratch);
      return;
    }
    const std::size_t runs = chain.closed ? corner_positions.size() : corner_positions.size() - 1;
    for (std::size_t r = 0; r < runs; ++r) {
      const std::size_t start = corner_positions[r];
      const std::size_t stop = r + 1 < corner_positions.size() ? corner_positions[r + 1]
                                                                : corner_positions[0] + n;
      fit_run(first_facet, start, stop - start, n, false, scratch);
    }
  }

  /// Fits the facets start .. start+count-1 (positions modulo n) of the current chain.
  void fit_run(Index first_facet, std::size_t start, std::size_t count, std::size_t n,
               bool closed, Scratch& scratch) {
    const auto& positions = scratch.positions;
    auto& run_values = scratch.run_values;
    auto& run_steps = scratch.run_steps;
    auto& run_tangents = scratch.run_tangents;
    const std::size_t values = closed ? count : count + 1;
    run_values.resize(values);
    run_steps.resize(count);
    run_tangents.resize(values);
    for (std::size_t j = 0; j < values; ++j) run_values[j] = positions[(start + j) % n];
    for (std::size_t j = 0; j < count; ++j) {
      const double chord = (positions[(start + j + 1) % n] - positions[(start + j) % n]).norm();
      switch (options_.parametrization) {
        case SplineParametrization::uniform: run_steps[j] = 1.0; break;
        case SplineParametrization::chord_length: run_steps[j] = chord; break;
        case SplineParametrization::centripetal: run_steps[j] = std::sqrt(chord); break;
      }
    }
    detail::spline_tangents(run_steps, run_values, closed, options_.end_condition,
                            run_tangents, scratch.spline);
    for (std::size_t j = 0; j < count; ++j) {
      // Hermite form of facet j with t = (s - s_j) / h_j, so that t runs over [0, 1].
      const double h = run_steps[j];
      const Vec<2>& p0 = run_values[j];
      const Vec<2>& p1 = run_values[(j + 1) % values];
      const Vec<2> m0 = h * run_tangents[j];
      const Vec<2> m1 = h * run_tangents[(j + 1) % values];
      Cubic& q = cubics_[static_cast<std::size_t>(first_facet) + (start + j) % n];
      q.a = p0;
      q.b = m0;
      q.c = 3.0 * (p1 - p0) - 2.0 * m0 - m1;
      q.d = 2.0 * (p0 - p1) + m0 + m1;
    }
  }

  BoundarySplineOptions options_;
  std::vector<Cubic> cubics_;
  std::vector<std::array<Index, 2>> facet_nodes_;
  std::vector<Index> chain_first_facet_;
  std::vector<Index> corners_;
  std::vector<std::pair<std::array<Index, 2>, Index>> facet_lookup_;
};

}  // namespace meshmotion
