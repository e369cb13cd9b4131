#pragma once
/// \file
/// Robust geometric predicates: orient2d, orient3d, incircle, insphere. Each returns the exact
/// sign (-1, 0, +1) of its determinant for double inputs. A floating-point evaluation decides
/// whenever its result exceeds Shewchuk's forward error bound (DCG 18, 1997, section 4); the
/// rest are evaluated exactly with expansion arithmetic (detail/expansion.hpp). Exact results
/// assume no overflow or underflow in the products (coordinates of magnitude between about
/// 1e-70 and 1e70). Requires IEEE double arithmetic: do not compile with -ffast-math.
///
/// Orientation conventions (these are what "positively oriented" means in the library):
/// - orient2d(a, b, c) > 0 when a, b, c turn counterclockwise;
/// - orient3d(a, b, c, d) > 0 when det[b - a, c - a, d - a] > 0 (Gmsh's positive tetrahedron:
///   d lies on the side of plane abc that (b - a) × (c - a) points to);
/// - incircle(a, b, c, d) > 0 when d lies strictly inside the circle through a, b, c and a, b,
///   c are counterclockwise (the sign flips for clockwise a, b, c);
/// - insphere(a, b, c, d, e) > 0 when e lies strictly inside the sphere through a, b, c, d
///   and orient3d(a, b, c, d) > 0 (the sign flips for negative orientation).

#include "meshmotion/delaunay/detail/expansion.hpp"

#include <Eigen/Core>

#include <array>
#include <cmath>

namespace meshmotion {

namespace detail {

/// Half an ulp of 1: the relative rounding error of one double operation.
inline constexpr double predicate_epsilon = 0x1p-53;

[[nodiscard]] inline int sign_of(double value) noexcept { return (value > 0.0) - (value < 0.0); }

/// Shewchuk's orient2d determinant: > 0 when a, b, c are counterclockwise.
[[nodiscard]] inline int orient2d_exact(const double* a, const double* b, const double* c) {
  const Expansion acx = Expansion::difference(a[0], c[0]);
  const Expansion acy = Expansion::difference(a[1], c[1]);
  const Expansion bcx = Expansion::difference(b[0], c[0]);
  const Expansion bcy = Expansion::difference(b[1], c[1]);
  return (acx * bcy - acy * bcx).sign();
}

/// The exact coordinate differences p - q of two 3D points.
[[nodiscard]] inline std::array<Expansion, 3> differences(const double* p, const double* q) {
  return {Expansion::difference(p[0], q[0]), Expansion::difference(p[1], q[1]),
          Expansion::difference(p[2], q[2])};
}

/// Shewchuk's orient3d determinant det[a - d; b - d; c - d] (the negative of ours).
[[nodiscard]] inline int orient3d_shewchuk_exact(const double* a, const double* b, const double* c,
                                                 const double* d) {
  const auto ad = differences(a, d);
  const auto bd = differences(b, d);
  const auto cd = differences(c, d);
  const Expansion det = ad[2] * (bd[0] * cd[1] - cd[0] * bd[1]) +
                        bd[2] * (cd[0] * ad[1] - ad[0] * cd[1]) +
                        cd[2] * (ad[0] * bd[1] - bd[0] * ad[1]);
  return det.sign();
}

[[nodiscard]] inline int incircle_exact(const double* a, const double* b, const double* c,
                                        const double* d) {
  const Expansion adx = Expansion::difference(a[0], d[0]);
  const Expansion ady = Expansion::difference(a[1], d[1]);
  const Expansion bdx = Expansion::difference(b[0], d[0]);
  const Expansion bdy = Expansion::difference(b[1], d[1]);
  const Expansion cdx = Expansion::difference(c[0], d[0]);
  const Expansion cdy = Expansion::difference(c[1], d[1]);
  const Expansion alift = adx * adx + ady * ady;
  const Expansion blift = bdx * bdx + bdy * bdy;
  const Expansion clift = cdx * cdx + cdy * cdy;
  const Expansion det = alift * (bdx * cdy - cdx * bdy) + blift * (cdx * ady - adx * cdy) +
                        clift * (adx * bdy - bdx * ady);
  return det.sign();
}

/// Shewchuk's insphere determinant (positive inside for his orientation, i.e. the negative of
/// ours).
[[nodiscard]] inline int insphere_shewchuk_exact(const double* a, const double* b, const double* c,
                                                 const double* d, const double* e) {
  const auto ae = differences(a, e);
  const auto be = differences(b, e);
  const auto ce = differences(c, e);
  const auto de = differences(d, e);
  const Expansion ab = ae[0] * be[1] - be[0] * ae[1];
  const Expansion bc = be[0] * ce[1] - ce[0] * be[1];
  const Expansion cd = ce[0] * de[1] - de[0] * ce[1];
  const Expansion da = de[0] * ae[1] - ae[0] * de[1];
  const Expansion ac = ae[0] * ce[1] - ce[0] * ae[1];
  const Expansion bd = be[0] * de[1] - de[0] * be[1];
  const Expansion abc = ae[2] * bc - be[2] * ac + ce[2] * ab;
  const Expansion bcd = be[2] * cd - ce[2] * bd + de[2] * bc;
  const Expansion cda = ce[2] * da + de[2] * ac + ae[2] * cd;
  const Expansion dab = de[2] * ab + ae[2] * bd + be[2] * da;
  auto lift = [](const std::array<Expansion, 3>& v) {
    return v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
  };
  const Expansion det = (lift(de) * abc - lift(ce) * dab) + (lift(be) * cda - lift(ae) * bcd);
  return det.sign();
}

/// The differences points[i][k] - origin[k] (k < N) into out[i] when all are exact doubles
/// (true for nearby points by Sterbenz's lemma, hence for most tests on grids); false
/// otherwise.
template <int N, std::size_t Count>
[[nodiscard]] inline bool exact_differences(const std::array<const double*, Count>& points,
                                            const double* origin, double (&out)[Count][N]) {
  for (std::size_t i = 0; i < Count; ++i) {
    for (int k = 0; k < N; ++k) {
      double tail = 0.0;
      two_sum(points[i][k], -origin[k], out[i][k], tail);
      if (tail != 0.0) return false;
    }
  }
  return true;
}

template <std::size_t A>
[[nodiscard]] FixedExpansion<A> negated(FixedExpansion<A> e) {
  for (std::size_t k = 0; k < e.size; ++k) e.terms[k] = -e.terms[k];
  return e;
}

/// Shewchuk's insphere determinant, exact, when the differences to e are exact doubles
/// (his stage B with zero tails): fixed arrays, no allocation. Returns 2 when they are not.
[[nodiscard]] inline int insphere_exact_differences(const double* a, const double* b,
                                                    const double* c, const double* d,
                                                    const double* e) {
  double to_e[4][3];
  if (!exact_differences<3, 4>({a, b, c, d}, e, to_e)) return 2;
  const double *ae = to_e[0], *be = to_e[1], *ce = to_e[2], *de = to_e[3];
  const auto ab = two_by_two(ae[0], be[1], be[0], ae[1]);
  const auto bc = two_by_two(be[0], ce[1], ce[0], be[1]);
  const auto cd = two_by_two(ce[0], de[1], de[0], ce[1]);
  const auto da = two_by_two(de[0], ae[1], ae[0], de[1]);
  const auto ac = two_by_two(ae[0], ce[1], ce[0], ae[1]);
  const auto bd = two_by_two(be[0], de[1], de[0], be[1]);
  const auto abc = scaled(bc, ae[2]) + scaled(ac, -be[2]) + scaled(ab, ce[2]);
  const auto bcd = scaled(cd, be[2]) + scaled(bd, -ce[2]) + scaled(bc, de[2]);
  const auto cda = scaled(da, ce[2]) + scaled(ac, de[2]) + scaled(cd, ae[2]);
  const auto dab = scaled(ab, de[2]) + scaled(bd, ae[2]) + scaled(da, be[2]);
  auto lift = [](const double* v) {
    FixedExpansion<2> squares[3];
    for (int k = 0; k < 3; ++k) {
      two_product(v[k], v[k], squares[k].terms[1], squares[k].terms[0]);
      squares[k].size = 2;
    }
    return squares[0] + squares[1] + squares[2];
  };
  const auto det =
      (lift(de) * abc + negated(lift(ce)) * dab) + (lift(be) * cda + negated(lift(ae)) * bcd);
  return det.sign();
}

/// The 3×3 determinant with rows (x_i, y_i, last_i), expanded along its last column:
/// Σ last_i (x_j y_k - x_k y_j) over cyclic (i, j, k), exact.
template <std::size_t L>
[[nodiscard]] FixedExpansion<24 * L> last_column_determinant(const double* const (&xy)[3],
                                                             const FixedExpansion<L> (&last)[3]) {
  FixedExpansion<8 * L> terms[3];
  for (int i = 0; i < 3; ++i) {
    const double* p = xy[(i + 1) % 3];
    const double* q = xy[(i + 2) % 3];
    terms[i] = last[i] * two_by_two(p[0], q[1], q[0], p[1]);
  }
  return terms[0] + terms[1] + terms[2];
}

/// Shewchuk's orient3d determinant, exact, when the differences to d are exact doubles.
/// Returns 2 when they are not.
[[nodiscard]] inline int orient3d_exact_differences(const double* a, const double* b,
                                                    const double* c, const double* d) {
  double to_d[3][3];
  if (!exact_differences<3, 3>({a, b, c}, d, to_d)) return 2;
  FixedExpansion<1> z[3];
  for (int i = 0; i < 3; ++i) {
    z[i].terms[0] = to_d[i][2];
    z[i].size = to_d[i][2] != 0.0 ? 1 : 0;
  }
  return last_column_determinant<1>({to_d[0], to_d[1], to_d[2]}, z).sign();
}

/// Shewchuk's incircle determinant, exact, when the differences to d are exact doubles.
/// Returns 2 when they are not.
[[nodiscard]] inline int incircle_exact_differences(const double* a, const double* b,
                                                    const double* c, const double* d) {
  double to_d[3][2];
  if (!exact_differences<2, 3>({a, b, c}, d, to_d)) return 2;
  FixedExpansion<4> lift[3];
  for (int i = 0; i < 3; ++i) {
    lift[i] = two_by_two(to_d[i][0], to_d[i][0], to_d[i][1], -to_d[i][1]);  // x^2 + y^2
  }
  return last_column_determinant<4>({to_d[0], to_d[1], to_d[2]}, lift).sign();
}

}  // namespace detail

/// Sign of the orientation of the triangle (a, b, c): +1 counterclockwise, -1 clockwise,
/// 0 collinear (exact). a, b, c point to 2 consecutive coordinates.
[[nodiscard]] inline int orient2d(const double* a, const double* b, const double* c) {
  const double detleft = (a[0] - c[0]) * (b[1] - c[1]);
  const double detright = (a[1] - c[1]) * (b[0] - c[0]);
  const double det = detleft - detright;
  constexpr double eps = detail::predicate_epsilon;
  constexpr double bound = (3.0 + 16.0 * eps) * eps;
  const double errbound = bound * (std::abs(detleft) + std::abs(detright));
  if (det > errbound || -det > errbound) return detail::sign_of(det);
  return detail::orient2d_exact(a, b, c);
}

/// Sign of det[b - a, c - a, d - a]: +1 for a positively oriented tetrahedron, 0 when the
/// four points are coplanar (exact). Arguments point to 3 consecutive coordinates.
[[nodiscard]] inline int orient3d(const double* a, const double* b, const double* c,
                                  const double* d) {
  const double adx = a[0] - d[0], bdx = b[0] - d[0], cdx = c[0] - d[0];
  const double ady = a[1] - d[1], bdy = b[1] - d[1], cdy = c[1] - d[1];
  const double adz = a[2] - d[2], bdz = b[2] - d[2], cdz = c[2] - d[2];
  const double bdxcdy = bdx * cdy, cdxbdy = cdx * bdy;
  const double cdxady = cdx * ady, adxcdy = adx * cdy;
  const double adxbdy = adx * bdy, bdxady = bdx * ady;
  const double det = adz * (bdxcdy - cdxbdy) + bdz * (cdxady - adxcdy) + cdz * (adxbdy - bdxady);
  const double permanent = (std::abs(bdxcdy) + std::abs(cdxbdy)) * std::abs(adz) +
                           (std::abs(cdxady) + std::abs(adxcdy)) * std::abs(bdz) +
                           (std::abs(adxbdy) + std::abs(bdxady)) * std::abs(cdz);
  constexpr double eps = detail::predicate_epsilon;
  constexpr double bound = (7.0 + 56.0 * eps) * eps;
  const double errbound = bound * permanent;
  // Shewchuk's determinant is det[a - d; b - d; c - d] = -det[b - a, c - a, d - a].
  if (det > errbound || -det > errbound) return -detail::sign_of(det);
  const int staged = detail::orient3d_exact_differences(a, b, c, d);
  return -(staged != 2 ? staged : detail::orient3d_shewchuk_exact(a, b, c, d));
}

/// +1 when d is strictly inside the circle through a, b, c (counterclockwise), 0 when the four
/// points are co-circular (exact), -1 outside; the sign flips when a, b, c are clockwise.
[[nodiscard]] inline int incircle(const double* a, const double* b, const double* c,
                                  const double* d) {
  const double adx = a[0] - d[0], bdx = b[0] - d[0], cdx = c[0] - d[0];
  const double ady = a[1] - d[1], bdy = b[1] - d[1], cdy = c[1] - d[1];
  const double bdxcdy = bdx * cdy, cdxbdy = cdx * bdy;
  const double cdxady = cdx * ady, adxcdy = adx * cdy;
  const double adxbdy = adx * bdy, bdxady = bdx * ady;
  const double alift = adx * adx + ady * ady;
  const double blift = bdx * bdx + bdy * bdy;
  const double clift = cdx * cdx + cdy * cdy;
  const double det =
      alift * (bdxcdy - cdxbdy) + blift * (cdxady - adxcdy) + clift * (adxbdy - bdxady);
  const double permanent = (std::abs(bdxcdy) + std::abs(cdxbdy)) * alift +
                           (std::abs(cdxady) + std::abs(adxcdy)) * blift +
                           (std::abs(adxbdy) + std::abs(bdxady)) * clift;
  constexpr double eps = detail::predicate_epsilon;
  constexpr double bound = (10.0 + 96.0 * eps) * eps;
  const double errbound = bound * permanent;
  if (det > errbound || -det > errbound) return detail::sign_of(det);
  const int staged = detail::incircle_exact_differences(a, b, c, d);
  return staged != 2 ? staged : detail::incircle_exact(a, b, c, d);
}

/// +1 when e is strictly inside the sphere through a, b, c, d with orient3d(a, b, c, d) > 0,
/// 0 when the five points are co-spherical (exact), -1 outside; the sign flips when
/// orient3d(a, b, c, d) < 0.
[[nodiscard]] inline int insphere(const double* a, const double* b, const double* c,
                                  const double* d, const double* e) {
  const double aex = a[0] - e[0], bex = b[0] - e[0], cex = c[0] - e[0], dex = d[0] - e[0];
  const double aey = a[1] - e[1], bey = b[1] - e[1], cey = c[1] - e[1], dey = d[1] - e[1];
  const double aez = a[2] - e[2], bez = b[2] - e[2], cez = c[2] - e[2], dez = d[2] - e[2];
  const double aexbey = aex * bey, bexaey = bex * aey;
  const double bexcey = bex * cey, cexbey = cex * bey;
  const double cexdey = cex * dey, dexcey = dex * cey;
  const double dexaey = dex * aey, aexdey = aex * dey;
  const double aexcey = aex * cey, cexaey = cex * aey;
  const double bexdey = bex * dey, dexbey = dex * bey;
  const double ab = aexbey - bexaey, bc = bexcey - cexbey, cd = cexdey - dexcey;
  const double da = dexaey - aexdey, ac = aexcey - cexaey, bd = bexdey - dexbey;
  const double abc = aez * bc - bez * ac + cez * ab;
  const double bcd = bez * cd - cez * bd + dez * bc;
  const double cda = cez * da + dez * ac + aez * cd;
  const double dab = dez * ab + aez * bd + bez * da;
  const double alift = aex * aex + aey * aey + aez * aez;
  const double blift = bex * bex + bey * bey + bez * bez;
  const double clift = cex * cex + cey * cey + cez * cez;
  const double dlift = dex * dex + dey * dey + dez * dez;
  const double det = (dlift * abc - clift * dab) + (blift * cda - alift * bcd);
  const double aez_abs = std::abs(aez), bez_abs = std::abs(bez);
  const double cez_abs = std::abs(cez), dez_abs = std::abs(dez);
  const double ab_abs = std::abs(aexbey) + std::abs(bexaey);
  const double bc_abs = std::abs(bexcey) + std::abs(cexbey);
  const double cd_abs = std::abs(cexdey) + std::abs(dexcey);
  const double da_abs = std::abs(dexaey) + std::abs(aexdey);
  const double ac_abs = std::abs(aexcey) + std::abs(cexaey);
  const double bd_abs = std::abs(bexdey) + std::abs(dexbey);
  const double permanent = (cd_abs * bez_abs + bd_abs * cez_abs + bc_abs * dez_abs) * alift +
                           (da_abs * cez_abs + ac_abs * dez_abs + cd_abs * aez_abs) * blift +
                           (ab_abs * dez_abs + bd_abs * aez_abs + da_abs * bez_abs) * clift +
                           (bc_abs * aez_abs + ac_abs * bez_abs + ab_abs * cez_abs) * dlift;
  constexpr double eps = detail::predicate_epsilon;
  constexpr double bound = (16.0 + 224.0 * eps) * eps;
  const double errbound = bound * permanent;
  // Shewchuk's insphere is positive inside for his (opposite) orientation convention.
  if (det > errbound || -det > errbound) return -detail::sign_of(det);
  const int staged = detail::insphere_exact_differences(a, b, c, d, e);
  return -(staged != 2 ? staged : detail::insphere_shewchuk_exact(a, b, c, d, e));
}

/// Eigen overloads of the predicates above.
[[nodiscard]] inline int orient2d(const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                                  const Eigen::Vector2d& c) {
  return orient2d(a.data(), b.data(), c.data());
}
[[nodiscard]] inline int orient3d(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                  const Eigen::Vector3d& c, const Eigen::Vector3d& d) {
  return orient3d(a.data(), b.data(), c.data(), d.data());
}
[[nodiscard]] inline int incircle(const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                                  const Eigen::Vector2d& c, const Eigen::Vector2d& d) {
  return incircle(a.data(), b.data(), c.data(), d.data());
}
[[nodiscard]] inline int insphere(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                  const Eigen::Vector3d& c, const Eigen::Vector3d& d,
                                  const Eigen::Vector3d& e) {
  return insphere(a.data(), b.data(), c.data(), d.data(), e.data());
}

}  // namespace meshmotion
