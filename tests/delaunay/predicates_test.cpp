#include "meshmotion/delaunay/predicates.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <random>

using namespace meshmotion;

namespace {

__extension__ using Int = __int128;  // exact reference arithmetic (GCC/Clang)

int sign(Int v) { return (v > 0) - (v < 0); }

// Exact references on integer coordinates (|coordinate differences| < 2^21).
int orient2d_ref(const std::int64_t* a, const std::int64_t* b, const std::int64_t* c) {
  return sign(Int(a[0] - c[0]) * (b[1] - c[1]) - Int(a[1] - c[1]) * (b[0] - c[0]));
}

Int det3(const Int m[3][3]) {
  return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
         m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
         m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
}

int orient3d_ref(const std::int64_t* a, const std::int64_t* b, const std::int64_t* c,
                 const std::int64_t* d) {
  Int m[3][3];
  for (int k = 0; k < 3; ++k) {
    m[0][k] = b[k] - a[k];
    m[1][k] = c[k] - a[k];
    m[2][k] = d[k] - a[k];
  }
  return sign(det3(m));
}

int incircle_ref(const std::int64_t* a, const std::int64_t* b, const std::int64_t* c,
                 const std::int64_t* d) {
  Int m[3][3];
  const std::int64_t* p[3] = {a, b, c};
  for (int r = 0; r < 3; ++r) {
    const Int x = p[r][0] - d[0], y = p[r][1] - d[1];
    m[r][0] = x;
    m[r][1] = y;
    m[r][2] = x * x + y * y;
  }
  return sign(det3(m));
}

int insphere_ref(const std::int64_t* a, const std::int64_t* b, const std::int64_t* c,
                 const std::int64_t* d, const std::int64_t* e) {
  // det of the 4x4 [p - e, |p - e|^2] rows, expanded along the lift column; positive inside
  // for Shewchuk's orientation, so negated for ours.
  Int rows[4][4];
  const std::int64_t* p[4] = {a, b, c, d};
  for (int r = 0; r < 4; ++r) {
    Int lift = 0;
    for (int k = 0; k < 3; ++k) {
      rows[r][k] = p[r][k] - e[k];
      lift += rows[r][k] * rows[r][k];
    }
    rows[r][3] = lift;
  }
  Int det = 0;
  for (int r = 0; r < 4; ++r) {
    Int minor[3][3];
    for (int i = 0, mi = 0; i < 4; ++i) {
      if (i == r) continue;
      for (int k = 0; k < 3; ++k) minor[mi][k] = rows[i][k];
      ++mi;
    }
    const Int term = rows[r][3] * det3(minor);
    det += ((r + 3) % 2 == 0) ? term : -term;
  }
  return -sign(det);
}

// Coordinates offset + m * 2^-20 are exact doubles; the offset makes the floating-point
// evaluation cancel, so the filter often fails and the exact path decides.
constexpr double offset = 1024.0;
constexpr double unit = 0x1p-20;

struct Random {
  std::mt19937_64 rng{12345};
  std::int64_t coordinate(std::int64_t range) {
    return std::uniform_int_distribution<std::int64_t>(-range, range)(rng);
  }
};

void to_double(const std::int64_t* in, double* out, int dim) {
  for (int k = 0; k < dim; ++k) out[k] = offset + static_cast<double>(in[k]) * unit;
}

}  // namespace

TEST_CASE("orient2d is exact on nearly collinear points", "[delaunay]") {
  // Shewchuk's example: p near (0.5, 0.5), q and r on the line y = x; the true sign is
  // sign(py - px), which naive floating point gets wrong for many of these points.
  const double q[2] = {12.0, 12.0};
  const double r[2] = {24.0, 24.0};
  int naive_wrong = 0;
  for (int i = 0; i < 64; ++i) {
    for (int j = 0; j < 64; ++j) {
      double p[2] = {0.5, 0.5};
      for (int k = 0; k < i; ++k) p[0] = std::nextafter(p[0], 1.0);
      for (int k = 0; k < j; ++k) p[1] = std::nextafter(p[1], 1.0);
      const int expected = (j > i) - (j < i);
      CHECK(orient2d(p, q, r) == expected);
      const double naive = (p[0] - r[0]) * (q[1] - r[1]) - (p[1] - r[1]) * (q[0] - r[0]);
      if (((naive > 0) - (naive < 0)) != expected) ++naive_wrong;
    }
  }
  CHECK(naive_wrong > 0);  // the test exercises the exact path
}

TEST_CASE("predicates return zero on exactly degenerate inputs", "[delaunay]") {
  SECTION("collinear and coplanar") {
    const double a[2] = {0.1, 0.1}, b[2] = {0.7, 0.7}, c[2] = {1e10, 1e10};
    CHECK(orient2d(a, b, c) == 0);
    CHECK(orient2d(b, a, c) == 0);
    // Plane x + y + z = 1 with dyadic coordinates.
    const double p[3] = {0.25, 0.5, 0.25}, q[3] = {1.0, 0.0, 0.0}, r[3] = {0.0, 1.0, 0.0},
                 s[3] = {0.125, 0.375, 0.5};
    CHECK(orient3d(p, q, r, s) == 0);
    double above[3] = {s[0], s[1], std::nextafter(s[2], 1.0)};
    double below[3] = {s[0], s[1], std::nextafter(s[2], 0.0)};
    const int up = orient3d(p, q, r, above);
    CHECK(up != 0);
    CHECK(orient3d(p, q, r, below) == -up);
  }
  SECTION("co-circular") {
    // Radius-5 Pythagorean points shifted by a power of two: exactly co-circular.
    const double shift = 4096.0;
    const double a[2] = {shift + 5, shift}, b[2] = {shift + 3, shift + 4},
                 c[2] = {shift - 4, shift + 3}, d[2] = {shift + 4, shift - 3};
    CHECK(orient2d(a, b, c) > 0);
    CHECK(incircle(a, b, c, d) == 0);
    const double inside[2] = {std::nextafter(d[0], shift), d[1]};
    const double outside[2] = {std::nextafter(d[0], 1e9), d[1]};
    CHECK(incircle(a, b, c, inside) == 1);
    CHECK(incircle(a, b, c, outside) == -1);
    CHECK(incircle(b, a, c, inside) == -1);  // clockwise flips the sign
  }
  SECTION("co-spherical") {
    // Radius-3 integer points: (1,2,2), (2,-1,2), (0,0,3), (3,0,0), (-2,2,1).
    const double a[3] = {1, 2, 2}, b[3] = {2, -1, 2}, c[3] = {0, 0, 3}, d[3] = {3, 0, 0},
                 e[3] = {-2, 2, 1};
    const int o = orient3d(a, b, c, d);
    REQUIRE(o != 0);
    CHECK(insphere(a, b, c, d, e) == 0);
    const double inside[3] = {std::nextafter(-2.0, 0.0), 2, 1};
    const double outside[3] = {std::nextafter(-2.0, -3.0), 2, 1};
    CHECK(insphere(a, b, c, d, inside) == o);
    CHECK(insphere(a, b, c, d, outside) == -o);
    const double centre[3] = {0, 0, 0};
    CHECK(insphere(a, b, c, d, centre) == o);
  }
  SECTION("positive orientation conventions") {
    const double a[3] = {0, 0, 0}, b[3] = {1, 0, 0}, c[3] = {0, 1, 0}, d[3] = {0, 0, 1};
    CHECK(orient3d(a, b, c, d) == 1);
    const double centre[3] = {0.25, 0.25, 0.25};
    CHECK(insphere(a, b, c, d, centre) == 1);
    CHECK(orient2d(a, b, c) == 1);  // the x-y coordinates of a, b, c
    const double middle[2] = {0.25, 0.25};
    CHECK(incircle(a, b, c, middle) == 1);
  }
}

TEST_CASE("predicates agree with exact integer arithmetic", "[delaunay]") {
  Random random;
  constexpr std::int64_t range = 1 << 19;
  int zeros = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    std::int64_t p[5][3];
    // Half the trials are degenerate or nearly so: the last point is an integer
    // combination of the others plus a tiny offset.
    for (auto& point : p) {
      for (auto& x : point) x = random.coordinate(range);
    }
    if (trial % 2 == 0) {
      for (int k = 0; k < 3; ++k) {
        const std::int64_t t = random.coordinate(2);
        p[2][k] = p[0][k] + t * (p[1][k] - p[0][k]) / 2 + random.coordinate(1);
        p[3][k] = p[0][k] + (p[1][k] - p[0][k]) + (p[2][k] - p[0][k]) - random.coordinate(1);
      }
      if (trial % 4 == 0) {
        // Mirror a point through the centre-ish: many co-circular/co-spherical quadruples
        // come from symmetric (rectangle/box) configurations.
        for (int k = 0; k < 3; ++k) p[4][k] = p[0][k] + p[1][k] - p[2][k];
      }
    }
    double q[5][3];
    for (int i = 0; i < 5; ++i) to_double(p[i], q[i], 3);
    const int o2 = orient2d_ref(p[0], p[1], p[2]);
    const int o3 = orient3d_ref(p[0], p[1], p[2], p[3]);
    const int ic = incircle_ref(p[0], p[1], p[2], p[3]);
    const int is = insphere_ref(p[0], p[1], p[2], p[3], p[4]);
    zeros += (o2 == 0) + (o3 == 0) + (ic == 0) + (is == 0);
    REQUIRE(orient2d(q[0], q[1], q[2]) == o2);
    REQUIRE(orient3d(q[0], q[1], q[2], q[3]) == o3);
    REQUIRE(incircle(q[0], q[1], q[2], q[3]) == ic);
    REQUIRE(insphere(q[0], q[1], q[2], q[3], q[4]) == is);
  }
  CHECK(zeros > 100);
}

TEST_CASE("predicates on rectangle and box corners are exactly degenerate", "[delaunay]") {
  // Corners of axis-aligned rectangles/boxes with arbitrary (non-dyadic) coordinates are
  // exactly co-circular/co-spherical, the situation of every structured grid.
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1e3, 1e3);
  for (int trial = 0; trial < 1000; ++trial) {
    const double x0 = u(rng), x1 = u(rng), y0 = u(rng), y1 = u(rng), z0 = u(rng), z1 = u(rng);
    const double a[2] = {x0, y0}, b[2] = {x1, y0}, c[2] = {x1, y1}, d[2] = {x0, y1};
    REQUIRE(incircle(a, b, c, d) == 0);
    const double p[3] = {x0, y0, z0}, q[3] = {x1, y0, z0}, r[3] = {x0, y1, z0}, s[3] = {x0, y0, z1},
                 t[3] = {x1, y1, z1};
    REQUIRE(insphere(p, q, r, s, t) == 0);
    const double w[3] = {x1, y1, z0};
    REQUIRE(orient3d(p, q, r, w) == 0);
  }
}

TEST_CASE("exact stages agree with each other", "[delaunay]") {
  // The allocation-free stage for exact differences and the general expansion stage must
  // give the same sign; points near a common sphere/circle make both paths do real work.
  std::mt19937_64 rng(21);
  std::uniform_real_distribution<double> angle(0.0, 6.283185307179586);
  std::uniform_int_distribution<int> ulps(-2, 2);
  int nonzero = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    double p[5][3];
    for (auto& point : p) {
      const double t = angle(rng), s = angle(rng);
      point[0] = 1.5 + 0.4 * std::cos(t) * std::sin(s);
      point[1] = 1.5 + 0.4 * std::sin(t) * std::sin(s);
      point[2] = 1.5 + 0.4 * std::cos(s);
      for (double& x : point) {
        for (int k = ulps(rng); k != 0; k += k > 0 ? -1 : 1)
          x = std::nextafter(x, k > 0 ? 9.0 : 0.0);
      }
    }
    const int staged = detail::insphere_exact_differences(p[0], p[1], p[2], p[3], p[4]);
    REQUIRE(staged != 2);  // coordinates in [1.1, 1.9]: differences are exact (Sterbenz)
    REQUIRE(staged == detail::insphere_shewchuk_exact(p[0], p[1], p[2], p[3], p[4]));
    const int o3 = detail::orient3d_exact_differences(p[0], p[1], p[2], p[3]);
    REQUIRE(o3 == detail::orient3d_shewchuk_exact(p[0], p[1], p[2], p[3]));
    const int ic = detail::incircle_exact_differences(p[0], p[1], p[2], p[3]);
    REQUIRE(ic == detail::incircle_exact(p[0], p[1], p[2], p[3]));
    nonzero += staged != 0;
  }
  CHECK(nonzero > 0);
}
