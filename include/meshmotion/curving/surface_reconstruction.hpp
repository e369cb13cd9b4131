#pragma once
/// \file
/// SurfaceReconstruction: a high-order surface rebuilt from a linear triangle surface mesh
/// alone, by weighted averaging of local polynomial fittings (WALF: Jiao & Wang,
/// "Reconstructing high-order surfaces for meshing", Engineering with Computers 28, 2012;
/// thesis chapter 5, future work).
///
/// At every vertex a height function h(u, w) of degree 2 or 3 over the tangent plane is
/// fitted by weighted least squares to the vertex's two-ring neighbours, through the vertex
/// itself. A point of a triangle (or edge) is the barycentric blend of its vertices' fittings
/// evaluated at the linear point: the blended surface is C^0, passes through the vertices and
/// approximates a smooth surface to O(h^{degree+1}).
///
/// Sharp features: an edge whose two triangles' normals differ by more than `ridge_angle`
/// (or that has one or more than two triangles) is a ridge. Fittings never gather points
/// across a ridge: a vertex on a ridge gets one fitting per side ("sector"), so the surfaces
/// on either side stay sharp. Ridge edges themselves are rebuilt as curves: each ridge
/// vertex fits a space curve to the ridge polyline through it (one branch per ridge edge at
/// a corner, where three or more ridges meet, a ridge ends, or it turns by more than
/// `ridge_angle`: an open wall's border at a corner of the domain), blended the same way.
/// Setup is O(n) small dense least-squares problems; queries are O(1).

#include "meshmotion/core/error.hpp"
#include "meshmotion/core/types.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <Eigen/QR>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <span>
#include <string>
#include <utility>
#include <vector>

namespace meshmotion {

/// Options of SurfaceReconstruction.
struct SurfaceReconstructionOptions {
  /// Degree of the local height functions: 2 (error O(h^3)) or 3 (O(h^4)).
  int degree = 3;
  /// An edge is a ridge where the normals of its two triangles differ by more than this
  /// angle, in degrees. 180 or more disables ridge detection (open-surface borders and
  /// non-manifold edges are ridges all the same).
  double ridge_angle = 30.0;
};

// A template of nothing (SurfaceReconstruction is BasicSurfaceReconstruction<>): its least-squares
// fits are then compiled only where a reconstruction is (docs/compiled.md).
/// High-order reconstruction of a triangulated surface (WALF, with ridges kept sharp).
template <class = void>
class BasicSurfaceReconstruction {
 public:
  /// `points`: 3 × n_nodes; `triangles`: 3 node indices per triangle (flat, like
  /// ElementBlock::connectivity of a tri3 block). Throws InputError for a connectivity whose
  /// size is not a multiple of 3, an out-of-range node, a non-finite coordinate, a
  /// degenerate (zero-area) triangle, a degree other than 2 or 3 or a NaN ridge angle, and
  /// SolverError when a vertex has too few neighbours for its fitting.
  BasicSurfaceReconstruction(const Points<3>& points, std::span<const Index> triangles,
                        SurfaceReconstructionOptions options = {})
      : options_(options), triangles_(triangles.begin(), triangles.end()) {
    validate(points);
    points_ = points;
    build_faces();
    build_edges();
    build_vertex_faces();
    fit_surfaces();
    fit_ridges();
  }

  [[nodiscard]] Index num_triangles() const noexcept {
    return static_cast<Index>(triangles_.size() / 3);
  }
  /// Whether the edge (a, b) is a ridge (sharp edge, border or non-manifold edge).
  /// Throws InputError when (a, b) is not an edge of the surface.
  [[nodiscard]] bool is_ridge(Index a, Index b) const { return edges_[edge_index(a, b)].ridge; }

  /// Point of the reconstructed edge (a, b) at fraction s in [0, 1] from a. Conforming: the
  /// same for every triangle sharing the edge. Throws InputError when (a, b) is not an edge.
  [[nodiscard]] Vec<3> edge_point(Index a, Index b, double s) const {
    const Edge& e = edges_[edge_index(a, b)];
    const Vec<3> x = (1.0 - s) * points_.col(a) + s * points_.col(b);
    if (e.ridge) {
      const auto& fits = e.a == a ? e.curve : std::array<Index, 2>{e.curve[1], e.curve[0]};
      return (1.0 - s) * evaluate_curve(fits[0], x) + s * evaluate_curve(fits[1], x);
    }
    // A smooth edge lies inside one sector at each end: either triangle gives the same fits.
    const Index f = e.faces[0];
    return (1.0 - s) * evaluate_surface(corner_fit(f, a), x) +
           s * evaluate_surface(corner_fit(f, b), x);
  }
  /// The reconstructed midpoint of edge (a, b): where a P2 node goes.
  [[nodiscard]] Vec<3> edge_midpoint(Index a, Index b) const { return edge_point(a, b, 0.5); }

  /// Point of triangle t at barycentric coordinates `xi` (weights of its three nodes in
  /// order, summing to 1). Inside the triangle the blend of its corners' fittings; on a
  /// ridge edge use edge_point, which follows the ridge curve.
  [[nodiscard]] Vec<3> point(Index t, const Vec<3>& xi) const {
    if (t < 0 || t >= num_triangles())
      throw InputError("SurfaceReconstruction::point: triangle out of range (got " +
                       std::to_string(t) + ", expected 0.." + std::to_string(num_triangles() - 1) + ")");
    Vec<3> x = Vec<3>::Zero();
    for (int k = 0; k < 3; ++k) x += xi[k] * points_.col(node(t, k));
    Vec<3> result = Vec<3>::Zero();
    for (int k = 0; k < 3; ++k) result += xi[k] * evaluate_surface(corner_fits_[3 * t + k], x);
    return result;
  }

 private:
  /// A local fitting: frame (origin, two tangents, normal), length scale and coefficients of
  /// the height function(s) over the scaled tangent coordinates.
  struct Fit {
    Vec<3> origin, t1, t2, normal;
    double scale = 1.0;
    std::array<double, 9> c{};  // surface: monomials u^i w^j, 1 <= i + j <= degree
    std::array<double, 6> curve{};  // curve: heights along t2 and normal, powers 1..degree
  };
  struct Edge {
    Index a, b;  // a < b
    std::vector<Index> faces;
    bool ridge = false;
    std::array<Index, 2> curve{-1, -1};  // curve fits at a and at b
  };

  [[nodiscard]] Index node(Index t, int k) const {
    return triangles_[static_cast<std::size_t>(3 * t + k)];
  }

  void validate(const Points<3>& points) const {
    const std::string where = "SurfaceReconstruction";
    if (options_.degree != 2 && options_.degree != 3)
      throw InputError(where + ": invalid degree (got " + std::to_string(options_.degree) +
                       ", expected 2 or 3)");
    if (std::isnan(options_.ridge_angle))
      throw InputError(where + ": ridge_angle is NaN (expected degrees)");
    if (triangles_.size() % 3 != 0)
      throw InputError(where + ": connectivity size not a multiple of 3 (got " +
                       std::to_string(triangles_.size()) + ")");
    for (Index v : triangles_)
      if (v < 0 || v >= points.cols())
        throw InputError(where + ": node index out of range (got " + std::to_string(v) +
                         ", expected 0.." + std::to_string(points.cols() - 1) + ")");
    if (!points.allFinite()) throw InputError(where + ": non-finite coordinate");
  }

  void build_faces() {
    normals_.resize(static_cast<std::size_t>(num_triangles()));
    areas_.resize(normals_.size());
    for (Index t = 0; t < num_triangles(); ++t) {
      const Vec<3> n = (points_.col(node(t, 1)) - points_.col(node(t, 0)))
                           .cross(points_.col(node(t, 2)) - points_.col(node(t, 0)));
      const double twice_area = n.norm();
      if (!(twice_area > 0.0))
        throw InputError("SurfaceReconstruction: triangle " + std::to_string(t) +
                         " is degenerate (zero area)");
      normals_[static_cast<std::size_t>(t)] = n / twice_area;
      areas_[static_cast<std::size_t>(t)] = 0.5 * twice_area;
    }
  }

  void build_edges() {
    std::vector<std::array<Index, 3>> keyed;  // (min, max, face)
    keyed.reserve(triangles_.size());
    for (Index t = 0; t < num_triangles(); ++t)
      for (int k = 0; k < 3; ++k) {
        const Index a = node(t, k), b = node(t, (k + 1) % 3);
        keyed.push_back({std::min(a, b), std::max(a, b), t});
      }
    std::sort(keyed.begin(), keyed.end());
    const double cos_ridge = std::cos(options_.ridge_angle * std::numbers::pi / 180.0);
    for (std::size_t i = 0; i < keyed.size();) {
      Edge e{keyed[i][0], keyed[i][1], {}, false, {-1, -1}};
      for (; i < keyed.size() && keyed[i][0] == e.a && keyed[i][1] == e.b; ++i)
        e.faces.push_back(keyed[i][2]);
      e.ridge = e.faces.size() != 2 ||
                (options_.ridge_angle < 180.0 &&
                 normals_[static_cast<std::size_t>(e.faces[0])].dot(
                     normals_[static_cast<std::size_t>(e.faces[1])]) < cos_ridge);
      edges_.push_back(std::move(e));
    }
  }

  [[nodiscard]] std::size_t edge_index(Index a, Index b) const {
    const std::array<Index, 2> key{std::min(a, b), std::max(a, b)};
    const auto it = std::lower_bound(edges_.begin(), edges_.end(), key, [](const Edge& e, const auto& k) {
      return std::array<Index, 2>{e.a, e.b} < k;
    });
    if (it == edges_.end() || it->a != key[0] || it->b != key[1])
      throw InputError("SurfaceReconstruction: (" + std::to_string(a) + ", " + std::to_string(b) +
                       ") is not an edge of the surface");
    return static_cast<std::size_t>(it - edges_.begin());
  }

  void build_vertex_faces() {
    const auto n = static_cast<std::size_t>(points_.cols());
    vertex_face_start_.assign(n + 1, 0);
    for (Index v : triangles_) ++vertex_face_start_[static_cast<std::size_t>(v) + 1];
    for (std::size_t i = 0; i < n; ++i) vertex_face_start_[i + 1] += vertex_face_start_[i];
    vertex_faces_.resize(triangles_.size());
    std::vector<Index> fill(vertex_face_start_.begin(), vertex_face_start_.end() - 1);
    for (Index t = 0; t < num_triangles(); ++t)
      for (int k = 0; k < 3; ++k)
        vertex_faces_[static_cast<std::size_t>(fill[static_cast<std::size_t>(node(t, k))]++)] = t;
  }

  [[nodiscard]] std::span<const Index> faces_of(Index v) const {
    const auto begin = static_cast<std::size_t>(vertex_face_start_[static_cast<std::size_t>(v)]);
    const auto end = static_cast<std::size_t>(vertex_face_start_[static_cast<std::size_t>(v) + 1]);
    return {vertex_faces_.data() + begin, end - begin};
  }

  [[nodiscard]] int local_corner(Index t, Index v) const {
    for (int k = 0; k < 3; ++k)
      if (node(t, k) == v) return k;
    return -1;
  }
  [[nodiscard]] Index corner_fit(Index t, Index v) const {
    return corner_fits_[static_cast<std::size_t>(3 * t + local_corner(t, v))];
  }

  /// Faces sharing a non-ridge edge with face t (through any of its three edges).
  template <class Visit>
  void smooth_neighbours(Index t, Visit&& visit) const {
    for (int k = 0; k < 3; ++k) {
      const Edge& e = edges_[edge_index(node(t, k), node(t, (k + 1) % 3))];
      if (e.ridge) continue;
      for (Index f : e.faces)
        if (f != t) visit(f);
    }
  }

  static Eigen::Vector3d any_perpendicular(const Vec<3>& n) {
    const Vec<3> axis = std::abs(n.x()) < 0.6 ? Vec<3>::UnitX() : Vec<3>::UnitY();
    return (axis - axis.dot(n) * n).normalized();
  }

  [[nodiscard]] int surface_terms() const { return options_.degree == 2 ? 5 : 9; }

  /// Monomials u^i w^j, 1 <= i + j <= degree, in a fixed order.
  void monomials(double u, double w, double* out) const {
    out[0] = u; out[1] = w;
    out[2] = u * u; out[3] = u * w; out[4] = w * w;
    if (options_.degree == 3) {
      out[5] = u * u * u; out[6] = u * u * w; out[7] = u * w * w; out[8] = w * w * w;
    }
  }

  /// One fitting per (vertex, sector): sectors are the vertex's faces grouped across its
  /// non-ridge edges. Neighbours are gathered by a breadth-first walk over faces that never
  /// crosses a ridge, until at least 2 terms' worth of points (usually the two-ring).
  void fit_surfaces() {
    corner_fits_.assign(triangles_.size(), -1);
    std::vector<Index> sector, frontier, next, seen_faces, gathered;
    std::vector<char> face_seen(static_cast<std::size_t>(num_triangles()), 0);
    std::vector<char> node_seen(static_cast<std::size_t>(points_.cols()), 0);
    for (Index v = 0; v < points_.cols(); ++v) {
      for (Index start : faces_of(v)) {
        if (corner_fit(start, v) >= 0) continue;
        // The sector of `start` around v.
        sector.assign(1, start);
        corner_fits_[static_cast<std::size_t>(3 * start + local_corner(start, v))] =
            static_cast<Index>(fits_.size());
        for (std::size_t i = 0; i < sector.size(); ++i)
          smooth_neighbours(sector[i], [&](Index f) {
            if (local_corner(f, v) < 0 || corner_fit(f, v) >= 0) return;
            corner_fits_[static_cast<std::size_t>(3 * f + local_corner(f, v))] =
                static_cast<Index>(fits_.size());
            sector.push_back(f);
          });
        Fit fit;
        fit.origin = points_.col(v);
        Vec<3> normal = Vec<3>::Zero();
        for (Index f : sector) normal += areas_[static_cast<std::size_t>(f)] * normals_[static_cast<std::size_t>(f)];
        fit.normal = normal.normalized();
        fit.t1 = any_perpendicular(fit.normal);
        fit.t2 = fit.normal.cross(fit.t1);

        // Walk outwards from the sector until enough points are gathered.
        seen_faces.clear();
        gathered.clear();
        frontier = sector;
        auto take_face = [&](Index f) {
          face_seen[static_cast<std::size_t>(f)] = 1;
          seen_faces.push_back(f);
          for (int k = 0; k < 3; ++k) {
            const Index w = node(f, k);
            if (w == v || node_seen[static_cast<std::size_t>(w)]) continue;
            node_seen[static_cast<std::size_t>(w)] = 1;
            gathered.push_back(w);
          }
        };
        for (Index f : frontier) take_face(f);
        const auto needed = static_cast<std::size_t>(2 * surface_terms());
        for (int ring = 0; ring < 8 && gathered.size() < needed && !frontier.empty(); ++ring) {
          next.clear();
          // Rings by vertex: every non-seen face touching a gathered point, reached without
          // crossing a ridge (through a smooth edge of a face already taken).
          for (Index f : frontier)
            smooth_neighbours(f, [&](Index g) {
              if (face_seen[static_cast<std::size_t>(g)]) return;
              take_face(g);
              next.push_back(g);
            });
          std::swap(frontier, next);
        }
        for (Index f : seen_faces) face_seen[static_cast<std::size_t>(f)] = 0;
        for (Index w : gathered) node_seen[static_cast<std::size_t>(w)] = 0;

        const auto terms = static_cast<std::size_t>(surface_terms());
        if (gathered.size() < terms)
          throw SolverError("SurfaceReconstruction: vertex " + std::to_string(v) + " has " +
                            std::to_string(gathered.size()) + " neighbours on its side of the ridges (expected at least " +
                            std::to_string(terms) + " for degree " + std::to_string(options_.degree) + ")");
        double scale = 0.0;
        for (Index w : gathered) scale = std::max(scale, (points_.col(w) - fit.origin).norm());
        fit.scale = scale;
        Eigen::MatrixXd a(static_cast<Index>(gathered.size()), static_cast<Index>(terms));
        Eigen::VectorXd b(a.rows());
        for (Index i = 0; i < a.rows(); ++i) {
          const Vec<3> d = (points_.col(gathered[static_cast<std::size_t>(i)]) - fit.origin) / scale;
          // Far points weigh less: the fit is local (Jiao & Wang weight by distance too).
          const double weight = 1.0 / (1.0 + 4.0 * d.squaredNorm());
          double row[9];
          monomials(d.dot(fit.t1), d.dot(fit.t2), row);
          for (Index j = 0; j < a.cols(); ++j) a(i, j) = weight * row[j];
          b[i] = weight * d.dot(fit.normal);
        }
        const Eigen::VectorXd c = a.colPivHouseholderQr().solve(b);
        for (Index j = 0; j < c.size(); ++j) fit.c[static_cast<std::size_t>(j)] = c[j];
        fits_.push_back(fit);
      }
    }
  }

  [[nodiscard]] Vec<3> evaluate_surface(Index f, const Vec<3>& x) const {
    const Fit& fit = fits_[static_cast<std::size_t>(f)];
    const Vec<3> d = (x - fit.origin) / fit.scale;
    const double u = d.dot(fit.t1), w = d.dot(fit.t2);
    double row[9];
    monomials(u, w, row);
    double h = 0.0;
    for (int j = 0; j < surface_terms(); ++j) h += fit.c[static_cast<std::size_t>(j)] * row[j];
    return fit.origin + fit.scale * (u * fit.t1 + w * fit.t2 + h * fit.normal);
  }

  /// Ridge edges at vertex v.
  void ridge_edges_at(Index v, std::vector<std::size_t>& out) const {
    out.clear();
    for (Index t : faces_of(v))
      for (int k = 0; k < 3; ++k) {
        const Index a = node(t, k), b = node(t, (k + 1) % 3);
        if (a != v && b != v) continue;
        const std::size_t e = edge_index(a, b);
        if (edges_[e].ridge && std::find(out.begin(), out.end(), e) == out.end()) out.push_back(e);
      }
  }

  /// Whether v's ridge edges `ridges` continue each other: two of them, turning by no more than
  /// the ridge angle. A border turning at a corner of the face it bounds (an open wall's
  /// border where two sides of the domain meet) is a corner, not a point of one smooth curve.
  [[nodiscard]] bool smooth_ridge_point(Index v, const std::vector<std::size_t>& ridges) const {
    if (ridges.size() != 2) return false;
    const auto other = [&](std::size_t e) { return edges_[e].a == v ? edges_[e].b : edges_[e].a; };
    const Vec<3> in = points_.col(v) - points_.col(other(ridges[0]));
    const Vec<3> out = points_.col(other(ridges[1])) - points_.col(v);
    return in.dot(out) >= std::cos(options_.ridge_angle * std::numbers::pi / 180.0) * in.norm() * out.norm();
  }

  /// Curve fits along ridges: at a regular ridge vertex (two ridge edges continuing each
  /// other) one fit through both branches, at a corner one fit per ridge edge along that
  /// branch only.
  void fit_ridges() {
    std::vector<std::size_t> ridges, walk_ridges;
    std::vector<Index> samples;
    for (std::size_t e = 0; e < edges_.size(); ++e) {
      if (!edges_[e].ridge) continue;
      for (int end = 0; end < 2; ++end) {
        if (edges_[e].curve[static_cast<std::size_t>(end)] >= 0) continue;
        const Index v = end == 0 ? edges_[e].a : edges_[e].b;
        ridge_edges_at(v, ridges);
        const bool regular = smooth_ridge_point(v, ridges);
        samples.clear();
        const std::size_t branches = regular ? 2 : 1;
        std::array<Index, 2> nearest{v, v};  // first ridge neighbour of each branch
        for (std::size_t branch = 0; branch < branches; ++branch) {
          // Walk along the ridge from v through the branch's edge, stopping at corners.
          std::size_t edge = regular ? ridges[branch] : e;
          Index current = v;
          for (int step = 0; step < options_.degree + 1; ++step) {
            const Index other = edges_[edge].a == current ? edges_[edge].b : edges_[edge].a;
            if (other == v) break;  // a closed ridge loop shorter than the walk
            if (step == 0) nearest[branch] = other;
            samples.push_back(other);
            ridge_edges_at(other, walk_ridges);
            if (!smooth_ridge_point(other, walk_ridges)) break;
            edge = walk_ridges[0] == edge ? walk_ridges[1] : walk_ridges[0];
            current = other;
          }
        }
        // Tangent at v: the chord between its two ridge neighbours, or along the branch.
        const Vec<3> tangent = regular ? Vec<3>(points_.col(nearest[1]) - points_.col(nearest[0]))
                                       : Vec<3>(points_.col(nearest[0]) - points_.col(v));
        const Index id = fit_curve(v, samples, tangent);
        // A regular vertex's fit serves both its ridge edges.
        for (std::size_t r : regular ? ridges : std::vector<std::size_t>{e})
          edges_[r].curve[edges_[r].a == v ? 0 : 1] = id;
      }
    }
  }

  /// Space curve through v fitted to `samples` (ridge neighbours, at least one): two heights
  /// over the line through v along `tangent`, polynomials of degree <= options.degree without constant term (the
  /// degree drops when fewer samples are available; a single sample gives the chord).
  Index fit_curve(Index v, const std::vector<Index>& samples, const Vec<3>& tangent) {
    Fit fit;
    fit.origin = points_.col(v);
    double scale = 0.0;
    for (Index w : samples) scale = std::max(scale, (points_.col(w) - fit.origin).norm());
    fit.scale = scale;
    fit.t1 = tangent.normalized();
    fit.t2 = any_perpendicular(fit.t1);
    fit.normal = fit.t1.cross(fit.t2);
    const int degree = std::min<int>(options_.degree, static_cast<int>(samples.size()));
    Eigen::MatrixXd a(static_cast<Index>(samples.size()), degree);
    Eigen::MatrixXd b(a.rows(), 2);
    for (Index i = 0; i < a.rows(); ++i) {
      const Vec<3> d = (points_.col(samples[static_cast<std::size_t>(i)]) - fit.origin) / scale;
      const double s = d.dot(fit.t1);
      double power = 1.0;
      for (int j = 0; j < degree; ++j) a(i, j) = (power *= s);
      b(i, 0) = d.dot(fit.t2);
      b(i, 1) = d.dot(fit.normal);
    }
    const Eigen::MatrixXd c = a.colPivHouseholderQr().solve(b);
    for (int j = 0; j < degree; ++j) {
      fit.curve[static_cast<std::size_t>(j)] = c(j, 0);
      fit.curve[static_cast<std::size_t>(3 + j)] = c(j, 1);
    }
    fits_.push_back(fit);
    return static_cast<Index>(fits_.size()) - 1;
  }

  [[nodiscard]] Vec<3> evaluate_curve(Index f, const Vec<3>& x) const {
    const Fit& fit = fits_[static_cast<std::size_t>(f)];
    const double s = (x - fit.origin).dot(fit.t1) / fit.scale;
    double y = 0.0, z = 0.0, power = 1.0;
    for (std::size_t j = 0; j < 3; ++j) {
      power *= s;
      y += fit.curve[j] * power;
      z += fit.curve[3 + j] * power;
    }
    return fit.origin + fit.scale * (s * fit.t1 + y * fit.t2 + z * fit.normal);
  }

  SurfaceReconstructionOptions options_;
  std::vector<Index> triangles_;
  Points<3> points_;
  std::vector<Vec<3>> normals_;
  std::vector<double> areas_;
  std::vector<Edge> edges_;
  std::vector<Index> vertex_face_start_, vertex_faces_;
  std::vector<Index> corner_fits_;  // per triangle corner: its (vertex, sector) fit
  std::vector<Fit> fits_;
};
using SurfaceReconstruction = BasicSurfaceReconstruction<>;


}  // namespace meshmotion
