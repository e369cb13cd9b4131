#pragma once
/// \file
/// Built-in meshes: structured rectangles and boxes of every linear element type (and mixed
/// ones), a boundary-layer O-mesh around an ellipse (a cylinder) or a square inside a
/// circular farfield, the gap between two circular walls with a layer each, the NASA
/// Turbulence Modeling Resource 3D bump-in-channel hex grid, and the extrusion of any linear
/// 2D mesh into a 3D slab (hexahedra and prisms).
/// Every generator returns positively oriented cells and the boundary
/// facets tagged with named groups.

#include "meshmotion/core/element.hpp"
#include "meshmotion/core/error.hpp"
#include "meshmotion/core/mesh.hpp"
#include "meshmotion/core/topology.hpp"
#include "meshmotion/core/types.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <span>
#include <string>
#include <vector>

namespace meshmotion {

/// Cell types of rectangle_mesh().
enum class RectangleCells {
  quad4,     ///< one quadrilateral per grid cell
  tri3,      ///< each grid cell split into two triangles
  tri_quad,  ///< triangles in the left half (i < nx/2), quadrilaterals elsewhere
};

/// Options of rectangle_mesh(): an nx × ny grid on [x_min, x_max] × [y_min, y_max].
struct RectangleOptions {
  Index nx = 10;
  Index ny = 10;
  double x_min = 0.0, x_max = 1.0;
  double y_min = 0.0, y_max = 1.0;
  RectangleCells cells = RectangleCells::quad4;
};

/// Cell types of box_mesh().
enum class BoxCells {
  hex8,               ///< one hexahedron per grid cell
  tet4,               ///< 6 tetrahedra per grid cell (Kuhn split along the main diagonal, conforming)
  prism6,             ///< 2 prisms per grid cell (triangles in x-y, extruded in z)
  pyramid5,           ///< 6 pyramids per grid cell around a new centre node
  hex_prism,          ///< prisms for i < nx/2, hexahedra elsewhere
  tet_pyramid_prism,  ///< prisms, then pyramids, then tetrahedra along x (thirds of nx); the
                      ///< pyramid cells next to the tetrahedra split their base into 2 tetrahedra
};

/// Options of box_mesh(): an nx × ny × nz grid on [x_min, x_max] × [y_min, y_max] × [z_min, z_max].
struct BoxOptions {
  Index nx = 4;
  Index ny = 4;
  Index nz = 4;
  double x_min = 0.0, x_max = 1.0;
  double y_min = 0.0, y_max = 1.0;
  double z_min = 0.0, z_max = 1.0;
  BoxCells cells = BoxCells::hex8;
};

/// The body of o_mesh().
enum class OMeshBody { ellipse, square };

/// Options of o_mesh(): a boundary-layer mesh around a body inside a circular farfield
/// (the README's demo case and the rotating-object benchmark, thesis fig. 4.11).
struct OMeshOptions {
  OMeshBody body = OMeshBody::ellipse;
  double semi_axis_x = 0.5;     ///< ellipse semi-axis along x, or half the square's side
  double semi_axis_y = 0.5;     ///< ellipse semi-axis along y (ignored for a square)
  Index n_around = 128;         ///< nodes around the body (a multiple of 4 for a square)
  Index n_radial = 64;          ///< cell layers from the wall to the farfield
  double first_height = 1e-5;   ///< height of the wall cells (1e-5 of the default diameter)
  double growth = 0.0;          ///< ratio of successive layer heights; 0: solved per ray so
                                ///< that the last layer reaches the farfield circle exactly
  double farfield_radius = 20.0;
  bool triangles = false;       ///< split each quadrilateral into two triangles
};

/// Options of annulus_mesh(): the gap between two concentric circular walls, each with its own
/// boundary layer (the gap of a journal bearing or a Taylor–Couette cell).
struct AnnulusOptions {
  double inner_radius = 0.5;
  double outer_radius = 1.5;
  Index n_around = 128;              ///< nodes around each circle
  double inner_first_height = 1e-4;  ///< height of the cells on the inner wall
  double inner_growth = 1.3;         ///< ratio of successive layer heights off the inner wall
  double outer_first_height = 2e-3;
  double outer_growth = 1.15;
  double core_spacing = 0.03;        ///< the layers grow up to this height; the core is uniform, about as fine
  bool triangles = false;            ///< split each quadrilateral into two triangles
};

/// Options of extrude_mesh(): `layers` cell layers evenly spaced from z = 0 to z = height.
struct ExtrudeOptions {
  Index layers = 1;
  double height = 1.0;
};

namespace detail {

/// Sets mesh.facets to the boundary facets, each tagged by classify(facet nodes) in
/// 1 .. names.size(), and names the groups.
template <int Dim, class Classify>
void add_boundary_groups(Mesh<Dim>& mesh, const std::vector<std::string>& names, Classify&& classify) {
  mesh.facets = boundary_facets(mesh);
  for (auto& block : mesh.facets)
    for (Index e = 0; e < block.size(); ++e) block.tags[static_cast<std::size_t>(e)] = classify(block.element(e));
  for (std::size_t g = 0; g < names.size(); ++g) mesh.groups.push_back({Dim - 1, static_cast<int>(g) + 1, names[g]});
}

/// Tags grid boundary facets by the box side all their nodes lie on: 2d + 1 for the minimum
/// of axis d, 2d + 2 for its maximum.
template <int Dim>
void add_box_groups(Mesh<Dim>& mesh, const std::array<double, Dim>& lo, const std::array<double, Dim>& hi) {
  const std::vector<std::string> names =
      Dim == 2 ? std::vector<std::string>{"left", "right", "bottom", "top"}
               : std::vector<std::string>{"left", "right", "front", "back", "bottom", "top"};
  add_boundary_groups(mesh, names, [&](std::span<const Index> nodes) {
    for (int d = 0; d < Dim; ++d) {
      const double tol = 1e-12 * (hi[static_cast<std::size_t>(d)] - lo[static_cast<std::size_t>(d)]);
      const auto on = [&](double value) {
        for (Index v : nodes)
          if (std::abs(mesh.points(d, v) - value) > tol) return false;
        return true;
      };
      if (on(lo[static_cast<std::size_t>(d)])) return 2 * d + 1;
      if (on(hi[static_cast<std::size_t>(d)])) return 2 * d + 2;
    }
    throw InvalidMeshError("box generator: a boundary facet lies on no side of the box");
  });
}

inline void require_cells(const char* where, std::initializer_list<Index> counts) {
  for (Index n : counts)
    if (n < 1) throw InputError(std::string(where) + ": cell counts must be positive (got " + std::to_string(n) + ")");
}

/// The cells between `rings` rings of n nodes each (ring j: nodes j n .. (j+1) n - 1, counter-
/// clockwise, outward with j): quadrilaterals, or each split into two triangles.
inline void add_ring_cells(Mesh<2>& mesh, Index n, Index rings, bool triangles) {
  for (Index j = 0; j + 1 < rings; ++j)
    for (Index i = 0; i < n; ++i) {
      const Index i1 = (i + 1) % n;
      const std::array<Index, 4> q{j * n + i, (j + 1) * n + i, (j + 1) * n + i1, j * n + i1};
      if (triangles) {
        mesh.block(ElementType::tri3).add({q[0], q[1], q[2]});
        mesh.block(ElementType::tri3).add({q[0], q[2], q[3]});
      } else {
        mesh.block(ElementType::quad4).add(q);
      }
    }
}

/// Appends a tetrahedron, swapping two nodes if needed so that it is positively oriented.
inline void add_positive_tet(ElementBlock& block, const Points<3>& p, std::array<Index, 4> t) {
  const Vec<3> a = p.col(t[1]) - p.col(t[0]);
  const Vec<3> b = p.col(t[2]) - p.col(t[0]);
  const Vec<3> c = p.col(t[3]) - p.col(t[0]);
  if (a.cross(b).dot(c) < 0) std::swap(t[1], t[2]);
  block.add(t);
}

}  // namespace detail

/// A structured rectangle mesh with groups "left", "right", "bottom", "top" (tags 1–4).
/// Nodes are numbered i + (nx + 1) j. Throws InputError for non-positive counts.
[[nodiscard]] inline Mesh<2> rectangle_mesh(const RectangleOptions& options = {}) {
  const Index nx = options.nx, ny = options.ny;
  detail::require_cells("rectangle_mesh", {nx, ny});
  Mesh<2> mesh;
  mesh.points.resize(2, (nx + 1) * (ny + 1));
  const auto node = [&](Index i, Index j) { return i + (nx + 1) * j; };
  for (Index j = 0; j <= ny; ++j)
    for (Index i = 0; i <= nx; ++i)
      mesh.points.col(node(i, j)) << options.x_min + (options.x_max - options.x_min) * static_cast<double>(i) / static_cast<double>(nx),
          options.y_min + (options.y_max - options.y_min) * static_cast<double>(j) / static_cast<double>(ny);
  for (Index j = 0; j < ny; ++j)
    for (Index i = 0; i < nx; ++i) {
      const std::array<Index, 4> q{node(i, j), node(i + 1, j), node(i + 1, j + 1), node(i, j + 1)};
      const bool split = options.cells == RectangleCells::tri3 || (options.cells == RectangleCells::tri_quad && 2 * i < nx);
      if (split) {
        mesh.block(ElementType::tri3).add({q[0], q[1], q[2]});
        mesh.block(ElementType::tri3).add({q[0], q[2], q[3]});
      } else {
        mesh.block(ElementType::quad4).add(q);
      }
    }
  detail::add_box_groups<2>(mesh, {options.x_min, options.y_min}, {options.x_max, options.y_max});
  return mesh;
}

/// A structured box mesh with groups "left", "right" (x), "front", "back" (y), "bottom",
/// "top" (z) (tags 1–6). Grid nodes are numbered i + (nx + 1)(j + (ny + 1) k); pyramid
/// centre nodes follow them. Throws InputError for non-positive counts.
[[nodiscard]] inline Mesh<3> box_mesh(const BoxOptions& options = {}) {
  const Index nx = options.nx, ny = options.ny, nz = options.nz;
  detail::require_cells("box_mesh", {nx, ny, nz});
  enum class Kind { hex, tet, prism, pyramid };
  const auto kind_of = [&](Index i) {
    switch (options.cells) {
      case BoxCells::hex8: return Kind::hex;
      case BoxCells::tet4: return Kind::tet;
      case BoxCells::prism6: return Kind::prism;
      case BoxCells::pyramid5: return Kind::pyramid;
      case BoxCells::hex_prism: return 2 * i < nx ? Kind::prism : Kind::hex;
      case BoxCells::tet_pyramid_prism: return 3 * i < nx ? Kind::prism : 3 * i < 2 * nx ? Kind::pyramid : Kind::tet;
    }
    return Kind::hex;
  };
  Index num_centres = 0;
  for (Index i = 0; i < nx; ++i)
    if (kind_of(i) == Kind::pyramid) num_centres += ny * nz;
  const Index num_grid = (nx + 1) * (ny + 1) * (nz + 1);
  Mesh<3> mesh;
  mesh.points.resize(3, num_grid + num_centres);
  const auto node = [&](Index i, Index j, Index k) { return i + (nx + 1) * (j + (ny + 1) * k); };
  const auto lerp = [](double a, double b, Index i, Index n) {
    return a + (b - a) * static_cast<double>(i) / static_cast<double>(n);
  };
  for (Index k = 0; k <= nz; ++k)
    for (Index j = 0; j <= ny; ++j)
      for (Index i = 0; i <= nx; ++i)
        mesh.points.col(node(i, j, k)) << lerp(options.x_min, options.x_max, i, nx),
            lerp(options.y_min, options.y_max, j, ny), lerp(options.z_min, options.z_max, k, nz);

  // Kuhn's 6 tetrahedra share the diagonal 0–6 and split every face along the diagonal from
  // its lowest to its highest corner, so neighbouring grid cells conform.
  static constexpr std::array<std::array<int, 4>, 6> kuhn{
      {{0, 1, 2, 6}, {0, 2, 3, 6}, {0, 3, 7, 6}, {0, 7, 4, 6}, {0, 4, 5, 6}, {0, 5, 1, 6}}};
  Index next_centre = num_grid;
  for (Index k = 0; k < nz; ++k)
    for (Index j = 0; j < ny; ++j)
      for (Index i = 0; i < nx; ++i) {
        const std::array<Index, 8> h{node(i, j, k),         node(i + 1, j, k),         node(i + 1, j + 1, k),
                                     node(i, j + 1, k),     node(i, j, k + 1),         node(i + 1, j, k + 1),
                                     node(i + 1, j + 1, k + 1), node(i, j + 1, k + 1)};
        switch (kind_of(i)) {
          case Kind::hex: mesh.block(ElementType::hex8).add(h); break;
          case Kind::tet:
            for (const auto& t : kuhn) detail::add_positive_tet(mesh.block(ElementType::tet4), mesh.points, {h[t[0]], h[t[1]], h[t[2]], h[t[3]]});
            break;
          case Kind::prism:
            mesh.block(ElementType::prism6).add({h[0], h[1], h[2], h[4], h[5], h[6]});
            mesh.block(ElementType::prism6).add({h[0], h[2], h[3], h[4], h[6], h[7]});
            break;
          case Kind::pyramid: {
            const Index c = next_centre++;
            mesh.points.col(c) = Vec<3>::Zero();
            for (Index v : h) mesh.points.col(c) += mesh.points.col(v) / 8.0;
            const bool tets_beyond = i + 1 < nx && kind_of(i + 1) == Kind::tet;
            for (int f = 0; f < 6; ++f) {
              const auto& out = facets(ElementType::hex8)[static_cast<std::size_t>(f)].vertices;
              // hexahedron facet 3 is the x-max side, which the tetrahedra split along 1–6.
              if (f == 3 && tets_beyond) {
                detail::add_positive_tet(mesh.block(ElementType::tet4), mesh.points, {h[1], h[2], h[6], c});
                detail::add_positive_tet(mesh.block(ElementType::tet4), mesh.points, {h[1], h[6], h[5], c});
                continue;
              }
              // The base's normal must point at the apex: the outward facet reversed.
              mesh.block(ElementType::pyramid5).add({h[out[0]], h[out[3]], h[out[2]], h[out[1]], c});
            }
            break;
          }
        }
      }
  detail::add_box_groups<3>(mesh, {options.x_min, options.y_min, options.z_min},
                            {options.x_max, options.y_max, options.z_max});
  return mesh;
}

/// A boundary-layer O-mesh: n_around radial lines from the body to the farfield circle,
/// wall-normal spacing growing geometrically from first_height. Groups "wall" (tag 1) and
/// "farfield" (tag 2). Ring j (0 at the wall) holds nodes j n_around .. (j+1) n_around - 1,
/// counter-clockwise; wall nodes lie exactly on the ellipse (a cos t, b sin t), t = 2πi/n,
/// or on the square. Throws InputError for sizes that cannot make a valid mesh (a farfield
/// not enclosing the body, first_height × n_radial beyond the farfield).
[[nodiscard]] inline Mesh<2> o_mesh(const OMeshOptions& options = {}) {
  const Index n = options.n_around, layers = options.n_radial;
  if (n < 3 || layers < 1)
    throw InputError("o_mesh: need n_around >= 3 and n_radial >= 1 (got " + std::to_string(n) + ", " +
                     std::to_string(layers) + ")");
  if (options.body == OMeshBody::square && n % 4 != 0)
    throw InputError("o_mesh: n_around must be a multiple of 4 for a square (got " + std::to_string(n) + ")");
  const double a = options.semi_axis_x, b = options.body == OMeshBody::square ? a : options.semi_axis_y;
  if (!(a > 0 && b > 0 && options.first_height > 0 && options.growth >= 0))
    throw InputError("o_mesh: semi-axes and first_height must be positive and growth non-negative");
  const double body_radius = options.body == OMeshBody::square ? a * std::numbers::sqrt2 : std::max(a, b);
  if (!(options.farfield_radius > body_radius))
    throw InputError("o_mesh: farfield_radius " + std::to_string(options.farfield_radius) +
                     " does not enclose the body (expected > " + std::to_string(body_radius) + ")");

  Mesh<2> mesh;
  mesh.points.resize(2, n * (layers + 1));
  const double h1 = options.first_height;
  // Sum of the first m layer heights for growth g.
  const auto distance = [&](double g, Index m) {
    return std::abs(g - 1.0) < 1e-12 ? h1 * static_cast<double>(m)
                                     : h1 * (std::pow(g, static_cast<double>(m)) - 1.0) / (g - 1.0);
  };
  for (Index i = 0; i < n; ++i) {
    Vec<2> wall;
    if (options.body == OMeshBody::ellipse) {
      const double t = 2.0 * std::numbers::pi * static_cast<double>(i) / static_cast<double>(n);
      wall << a * std::cos(t), b * std::sin(t);
    } else {
      // Uniform along the perimeter, counter-clockwise from the corner (a, -a).
      const Index per_side = n / 4;
      const Index side = i / per_side;
      const double u = 2.0 * a * static_cast<double>(i % per_side) / static_cast<double>(per_side);
      const std::array<Vec<2>, 4> start{Vec<2>(a, -a), Vec<2>(a, a), Vec<2>(-a, a), Vec<2>(-a, -a)};
      const std::array<Vec<2>, 4> along{Vec<2>(0, 1), Vec<2>(-1, 0), Vec<2>(0, -1), Vec<2>(1, 0)};
      wall = start[static_cast<std::size_t>(side)] + u * along[static_cast<std::size_t>(side)];
    }
    const Vec<2> far = options.farfield_radius * wall.normalized();
    const double length = (far - wall).norm();
    const Vec<2> dir = (far - wall) / length;
    double g = options.growth;
    if (g == 0.0) {
      if (h1 * static_cast<double>(layers) >= length)
        throw InputError("o_mesh: first_height × n_radial = " + std::to_string(h1 * static_cast<double>(layers)) +
                         " reaches past the farfield (expected < " + std::to_string(length) + ")");
      double lo = 1.0, hi = 2.0;
      while (distance(hi, layers) < length) hi *= 2.0;
      for (int it = 0; it < 200; ++it) {
        const double mid = 0.5 * (lo + hi);
        (distance(mid, layers) < length ? lo : hi) = mid;
      }
      g = 0.5 * (lo + hi);
    }
    for (Index j = 0; j <= layers; ++j) {
      // The farfield ring is placed exactly when the growth was solved for it.
      const double s = (options.growth == 0.0 && j == layers) ? length : distance(g, j);
      mesh.points.col(j * n + i) = j == 0 ? wall : Vec<2>(wall + s * dir);
    }
  }
  detail::add_ring_cells(mesh, n, layers + 1, options.triangles);
  detail::add_boundary_groups(mesh, {"wall", "farfield"}, [&](std::span<const Index> nodes) {
    return nodes[0] < n ? 1 : 2;
  });
  return mesh;
}


/// The gap between two concentric circles (centre 0), each wall with a boundary layer
/// growing geometrically from its first height to core_spacing, and a uniform core between
/// them. Groups "inner" (tag 1) and "outer" (tag 2); ring j (0 on the inner wall) holds nodes
/// j n_around .. (j+1) n_around - 1, counter-clockwise, every node of ring j on the circle of
/// its radius. Throws InputError for radii, heights or growths that cannot make a valid mesh,
/// or layers that do not fit in the gap.
[[nodiscard]] inline Mesh<2> annulus_mesh(const AnnulusOptions& o = {}) {
  if (!(o.inner_radius > 0.0 && o.outer_radius > o.inner_radius) || o.n_around < 3)
    throw InputError("annulus_mesh: need 0 < inner_radius < outer_radius and n_around >= 3 (got " +
                     std::to_string(o.inner_radius) + ", " + std::to_string(o.outer_radius) + ", " +
                     std::to_string(o.n_around) + ")");
  if (!(o.inner_first_height > 0.0 && o.outer_first_height > 0.0 && o.inner_growth > 1.0 && o.outer_growth > 1.0 &&
        o.core_spacing > 0.0))
    throw InputError("annulus_mesh: first heights and core_spacing must be positive and growths above 1");
  // Wall distances of each layer's rings, up to the first cell of core_spacing height.
  const auto layer = [&](double h, double growth) {
    std::vector<double> s{0.0};
    for (; h < o.core_spacing; h *= growth) s.push_back(s.back() + h);
    return s;
  };
  const std::vector<double> inner = layer(o.inner_first_height, o.inner_growth);
  const std::vector<double> outer = layer(o.outer_first_height, o.outer_growth);
  const double core = o.outer_radius - o.inner_radius - inner.back() - outer.back();
  if (!(core > 0.0))
    throw InputError("annulus_mesh: the two layers are " + std::to_string(inner.back() + outer.back()) +
                     " thick together, more than the gap (expected < " + std::to_string(o.outer_radius - o.inner_radius) + ")");
  const auto n_core = static_cast<Index>(std::ceil(core / o.core_spacing));
  std::vector<double> radii;
  for (const double s : inner) radii.push_back(o.inner_radius + s);
  for (Index k = 1; k < n_core; ++k)
    radii.push_back(o.inner_radius + inner.back() + core * static_cast<double>(k) / static_cast<double>(n_core));
  for (auto s = outer.rbegin(); s != outer.rend(); ++s) radii.push_back(o.outer_radius - *s);

  const Index n = o.n_around;
  const auto rings = static_cast<Index>(radii.size());
  Mesh<2> mesh;
  mesh.points.resize(2, rings * n);
  for (Index j = 0; j < rings; ++j)
    for (Index i = 0; i < n; ++i) {
      const double t = 2.0 * std::numbers::pi * static_cast<double>(i) / static_cast<double>(n);
      mesh.points.col(j * n + i) << radii[static_cast<std::size_t>(j)] * std::cos(t), radii[static_cast<std::size_t>(j)] * std::sin(t);
    }
  detail::add_ring_cells(mesh, n, rings, o.triangles);
  detail::add_boundary_groups(mesh, {"inner", "outer"}, [&](std::span<const Index> nodes) { return nodes[0] < n ? 1 : 2; });
  return mesh;
}

/// Height of the NASA Turbulence Modeling Resource bump-in-channel wall at streamwise
/// station x0: 0.05 sin^4(pi x0 / 0.9 - pi / 3) for 0.3 <= x0 <= 1.2, 0 elsewhere.
[[nodiscard]] inline double bump_channel_height(double x0) {
  if (x0 <= 0.3 || x0 >= 1.2) return 0.0;
  const double s = std::sin(std::numbers::pi * x0 / 0.9 - std::numbers::pi / 3.0);
  return 0.05 * s * s * s * s;
}

/// Spanwise shift of the 3D bump-in-channel: a station x0 sits at x = x0 + 0.3 sin^4(pi y),
/// y in [-1, 0], so the wall is z = bump_channel_height(x - bump_channel_shift(y)).
[[nodiscard]] inline double bump_channel_shift(double y) {
  const double s = std::sin(std::numbers::pi * y);
  return 0.3 * s * s * s * s;
}

/// The NASA Turbulence Modeling Resource 3D bump-in-channel grid family (thesis section
/// 4.2.2, table 4.3), structured hexahedra: level L has (4·2^L + 1) × (44·2^L + 1) ×
/// (20·2^L + 1) nodes (spanwise × streamwise × normal): 5×45×21, 9×89×41, 17×177×81,
/// 33×353×161 for L = 0..3; the P2 mesh of level L has the node count of level L + 1
/// (thesis: 32,841, 243,729, 1,875,489 for the P2 meshes of L = 0, 1, 2). Coarser levels
/// are every other line of finer ones.
///
/// Geometry: streamwise stations x0 in [-25, 26.5] (12·2^L cells upstream of the viscous
/// wall, 20·2^L on it, x0 in [0, 1.5], clustered towards its ends by a tanh map, and 12·2^L
/// downstream, growing geometrically and C^1 with the wall spacing); interior stations are
/// shifted spanwise to x = x0 + bump_channel_shift(y), the inflow and outflow ends are not.
/// y uniform in [-1, 0]; from the wall z = bump_channel_height(x0) to the top z = 5, the
/// normal spacing grows geometrically from about 2.5e-5 (L = 0; halved per level, growth
/// ratio e^(12 / (20·2^L))), so wall cells have aspect ratios of 10^3–10^4 as in RANS grids.
/// Wall nodes lie on the bump; facets between them are straight.
///
/// Nodes are numbered i + nx1 (j + ny1 k) (i streamwise, j spanwise, k normal; nx1, ny1 the
/// node counts along them). Groups (facet tags 1–7): "bump" (the viscous wall, 0 <= x0 <=
/// 1.5), "symmetry_lower" (the rest of z = 0), "inflow" (x = -25), "outflow" (x = 26.5),
/// "top" (z = 5), "side_y0" (y = -1), "side_y1" (y = 0). Throws InputError for a level
/// outside 0..4.
[[nodiscard]] inline Mesh<3> bump_channel_3d(int level) {
  if (level < 0 || level > 4)
    throw InputError("bump_channel_3d: level " + std::to_string(level) + " is out of range (expected 0 to 4)");
  const Index scale = Index{1} << level;
  const Index n_up = 12 * scale, n_wall = 20 * scale, nx = 2 * n_up + n_wall, ny = 4 * scale, nz = 20 * scale;
  constexpr double upstream = 25.0, wall_length = 1.5, top = 5.0, cluster = 3.0, normal_growth = 12.0;
  // Wall section x0 = L/2 (1 + tanh(c (t - 1/2)) / tanh(c / 2)), t in [0, 1]; its end slope
  // per cell sets the first cell of the geometric farfield sections x0 = -a (e^(b u) - 1)
  // (u in [0, 1] over n_up cells), b solved so both spacings agree at the wall's ends.
  const double tanh_half = std::tanh(cluster / 2.0);
  const double end_slope = 0.5 * wall_length * cluster * (1.0 - tanh_half * tanh_half) / tanh_half;
  const double target = end_slope * static_cast<double>(n_up) / static_cast<double>(n_wall);
  double lo = 1e-6, hi = 60.0;  // upstream * b / (e^b - 1) falls from `upstream` to 0
  for (int it = 0; it < 200; ++it) {
    const double mid = 0.5 * (lo + hi);
    (upstream * mid / std::expm1(mid) > target ? lo : hi) = mid;
  }
  const double b = 0.5 * (lo + hi), a = upstream / std::expm1(b);
  std::vector<double> x0(static_cast<std::size_t>(nx + 1));
  for (Index i = 0; i <= nx; ++i) {
    double x;
    if (i <= n_up) {
      x = -a * std::expm1(b * static_cast<double>(n_up - i) / static_cast<double>(n_up));
    } else if (i <= n_up + n_wall) {
      const double t = static_cast<double>(i - n_up) / static_cast<double>(n_wall);
      x = 0.5 * wall_length * (1.0 + std::tanh(cluster * (t - 0.5)) / tanh_half);
    } else {
      x = wall_length + a * std::expm1(b * static_cast<double>(i - n_up - n_wall) / static_cast<double>(n_up));
    }
    x0[static_cast<std::size_t>(i)] = x;
  }
  x0.front() = -upstream;  // exact ends and wall borders, whatever the rounding above
  x0[static_cast<std::size_t>(n_up)] = 0.0;
  x0[static_cast<std::size_t>(n_up + n_wall)] = wall_length;
  x0.back() = wall_length + upstream;

  const Index nx1 = nx + 1, ny1 = ny + 1;
  const auto node = [&](Index i, Index j, Index k) { return i + nx1 * (j + ny1 * k); };
  Mesh<3> mesh;
  mesh.points.resize(3, nx1 * ny1 * (nz + 1));
  const double normal_total = std::expm1(normal_growth);
  for (Index k = 0; k <= nz; ++k) {
    const double eta = k == nz ? 1.0 : std::expm1(normal_growth * static_cast<double>(k) / static_cast<double>(nz)) / normal_total;
    for (Index j = 0; j <= ny; ++j) {
      const double y = -1.0 + static_cast<double>(j) / static_cast<double>(ny);
      const double shift = bump_channel_shift(y);
      for (Index i = 0; i <= nx; ++i) {
        const double station = x0[static_cast<std::size_t>(i)];
        const double wall = bump_channel_height(station);
        const double x = (i == 0 || i == nx) ? station : station + shift;
        mesh.points.col(node(i, j, k)) << x, y, k == 0 ? wall : wall + (top - wall) * eta;
      }
    }
  }
  ElementBlock& hexes = mesh.block(ElementType::hex8);
  hexes.reserve(nx * ny * nz);
  for (Index k = 0; k < nz; ++k)
    for (Index j = 0; j < ny; ++j)
      for (Index i = 0; i < nx; ++i)
        hexes.add(std::array<Index, 8>{node(i, j, k), node(i + 1, j, k), node(i + 1, j + 1, k), node(i, j + 1, k),
                                       node(i, j, k + 1), node(i + 1, j, k + 1), node(i + 1, j + 1, k + 1),
                                       node(i, j + 1, k + 1)});
  detail::add_boundary_groups(
      mesh, {"bump", "symmetry_lower", "inflow", "outflow", "top", "side_y0", "side_y1"},
      [&](std::span<const Index> nodes) {
        // Grid index of a node along each axis; a boundary facet holds one of them constant.
        const auto all = [&](auto&& index, Index value) {
          for (const Index v : nodes)
            if (index(v) != value) return false;
          return true;
        };
        const auto i_of = [&](Index v) { return v % nx1; };
        const auto j_of = [&](Index v) { return (v / nx1) % ny1; };
        const auto k_of = [&](Index v) { return v / (nx1 * ny1); };
        if (all(k_of, 0)) {
          for (const Index v : nodes)
            if (i_of(v) < n_up || i_of(v) > n_up + n_wall) return 2;
          return 1;
        }
        if (all(k_of, nz)) return 5;
        if (all(i_of, 0)) return 3;
        if (all(i_of, nx)) return 4;
        if (all(j_of, 0)) return 6;
        if (all(j_of, ny)) return 7;
        throw InvalidMeshError("bump_channel_3d: a boundary facet lies on no side of the channel");
      });
  return mesh;
}

/// A 2D mesh of triangles and quadrilaterals extruded along z into prisms and hexahedra: node
/// v of the 2D mesh becomes nodes v + k n (n its node count, k = 0 .. layers at z = k height /
/// layers), and cell e of layer k keeps its 2D orientation, so positive 2D cells give positive
/// 3D cells. Each 2D facet group becomes the lateral group of the same name and tag (its
/// edges swept into quadrilaterals); the end caps are "z_min" (z = 0) and "z_max" (z = height),
/// tagged after the largest 2D tag. A boundary edge's tag carries over whether or not a group
/// names it; untagged edges give untagged facets. Throws InputError for cells other than tri3 and quad4, a 2D facet group whose name
/// is "z_min" or "z_max", layers < 1, or a height that is not positive.
[[nodiscard]] inline Mesh<3> extrude_mesh(const Mesh<2>& mesh, const ExtrudeOptions& options = {}) {
  if (options.layers < 1 || !(options.height > 0.0) || !std::isfinite(options.height))
    throw InputError("extrude_mesh: need layers >= 1 and a positive height (got " + std::to_string(options.layers) + ", " +
                     std::to_string(options.height) + ")");
  const Index n = mesh.num_nodes(), layers = options.layers;
  Mesh<3> out;
  out.points.resize(3, n * (layers + 1));
  for (Index k = 0; k <= layers; ++k)
    for (Index v = 0; v < n; ++v)
      out.points.col(k * n + v) << mesh.points.col(v), options.height * static_cast<double>(k) / static_cast<double>(layers);
  for (const auto& block : mesh.cells) {
    if (block.type != ElementType::tri3 && block.type != ElementType::quad4)
      throw InputError("extrude_mesh: cannot extrude " + std::string(name(block.type)) + " cells (expected tri3 or quad4)");
    ElementBlock& swept = out.block(block.type == ElementType::tri3 ? ElementType::prism6 : ElementType::hex8);
    const int nv = num_vertices(block.type);
    std::array<Index, 8> nodes{};
    for (Index k = 0; k < layers; ++k)
      for (Index e = 0; e < block.size(); ++e) {
        const auto el = block.element(e);
        for (int a = 0; a < nv; ++a) {
          nodes[static_cast<std::size_t>(a)] = k * n + el[static_cast<std::size_t>(a)];
          nodes[static_cast<std::size_t>(a + nv)] = (k + 1) * n + el[static_cast<std::size_t>(a)];
        }
        swept.add(std::span<const Index>(nodes.data(), static_cast<std::size_t>(2 * nv)), block.tags[static_cast<std::size_t>(e)]);
      }
  }
  // The 2D tag of each boundary edge, by its sorted vertex pair.
  std::vector<std::pair<std::array<Index, 2>, int>> edge_tags;
  int largest = 0;
  for (const auto& block : mesh.facets)
    for (Index e = 0; e < block.size(); ++e) {
      const auto el = block.element(e);
      const int tag = block.tags[static_cast<std::size_t>(e)];
      edge_tags.push_back({{std::min(el[0], el[1]), std::max(el[0], el[1])}, tag});
      largest = std::max(largest, tag);
    }
  std::sort(edge_tags.begin(), edge_tags.end());
  for (const auto& g : mesh.groups) {
    if (g.dim != 1) continue;
    if (g.name == "z_min" || g.name == "z_max")
      throw InputError("extrude_mesh: the 2D mesh has a facet group named '" + g.name +
                       "', the name of an end cap (expected other names)");
    out.groups.push_back({2, g.tag, g.name});
  }
  out.groups.push_back({2, largest + 1, "z_min"});
  out.groups.push_back({2, largest + 2, "z_max"});
  out.facets = boundary_facets(out);
  const auto layer_of = [&](Index v) { return v / n; };
  for (auto& block : out.facets)
    for (Index e = 0; e < block.size(); ++e) {
      const auto nodes = block.element(e);
      int& tag = block.tags[static_cast<std::size_t>(e)];
      if (std::all_of(nodes.begin(), nodes.end(), [&](Index v) { return layer_of(v) == 0; })) {
        tag = largest + 1;
      } else if (std::all_of(nodes.begin(), nodes.end(), [&](Index v) { return layer_of(v) == layers; })) {
        tag = largest + 2;
      } else {
        // A lateral quadrilateral: its nodes in the lower layer are the swept 2D edge.
        Index a = -1, b = -1;
        const Index lower = std::min(layer_of(nodes[0]), layer_of(nodes[2]));
        for (const Index v : nodes)
          if (layer_of(v) == lower) (a < 0 ? a : b) = v % n;
        const std::array<Index, 2> key{std::min(a, b), std::max(a, b)};
        const auto it = std::lower_bound(edge_tags.begin(), edge_tags.end(), std::pair{key, std::numeric_limits<int>::min()});
        tag = it != edge_tags.end() && it->first == key ? it->second : 0;
      }
    }
  return out;
}

}  // namespace meshmotion
