// Tutorial 2: a shape optimization loop with the RBF derivative product.
//
// The body is an ellipse whose semi-axes p = (a, b) are the design parameters. For every
// design the mesh is moved by RBF interpolation of the wall displacement, and an objective is
// evaluated on the whole volume mesh. Its gradient needs d objective / d p through the mesh
// motion:
//
//   dJ/dp = (dd/dp)ᵀ (du/dd)ᵀ (dJ/dx)
//
// where d is the wall displacement, u = move(d) the displacement of every node and x = x0 + u.
// The RBF mover gives (du/dd)ᵀ v in one call, derivative_reverse(v), at the cost of one
// transposed solve with the factorization made in setup — independent of the number of
// parameters. The tutorial checks that product against central finite differences at every
// iteration, printing both side by side, and exits with 2 when they disagree.
//
// Objective (an inverse-design problem with a known answer): the cell areas of the mesh of
// a target ellipse p* are recorded, and J(p) is the mean squared relative difference between
// the cell areas of design p and those targets, so J(p*) = 0. A few steps of gradient descent
// with backtracking walk from p0 towards p*.
//
//   tutorial_2_optimization_loop --iterations 8
//   tutorial_2_optimization_loop --json

#include "meshmotion/core/json.hpp"
#include "meshmotion/core/generators.hpp"
#include "meshmotion/movers/boundary.hpp"
#include "meshmotion/movers/rbf.hpp"

#include "program.hpp"

#include <CLI/CLI.hpp>

#include <array>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <limits>
#include <span>
#include <string>
#include <vector>

namespace {

using namespace meshmotion;
using Parameters = std::array<double, 2>;  // semi-axes (a, b)

struct Settings {
  Parameters start{0.5, 0.25};
  Parameters target{0.6, 0.18};
  Index n_around = 64, n_radial = 24;
  double support_radius = 2.0;
  double fd_step = 1e-6;
  double tolerance = 1e-5;
  int iterations = 8;
  bool json = false;
};

/// Signed area of a tri3/quad4 cell: the shoelace formula over its vertices, which Gmsh's
/// local order lists counter-clockwise.
double cell_area(const Points<2>& x, std::span<const Index> nodes) {
  double twice = 0.0;
  for (std::size_t k = 0; k < nodes.size(); ++k) {
    const Index i = nodes[k], j = nodes[(k + 1) % nodes.size()];
    twice += x(0, i) * x(1, j) - x(0, j) * x(1, i);
  }
  return 0.5 * twice;
}

/// Adds weight × d(cell_area)/dx to the columns of the cell's nodes in `v`.
void add_area_gradient(const Points<2>& x, std::span<const Index> nodes, double weight, Points<2>& v) {
  const std::size_t n = nodes.size();
  for (std::size_t k = 0; k < n; ++k) {
    const Index next = nodes[(k + 1) % n], prev = nodes[(k + n - 1) % n];
    v(0, nodes[k]) += weight * 0.5 * (x(1, next) - x(1, prev));
    v(1, nodes[k]) += weight * 0.5 * (x(0, prev) - x(0, next));
  }
}

/// The design problem: reference mesh, mover set up once on it, and the wall parametrization.
class EllipseDesign {
 public:
  explicit EllipseDesign(const Settings& s) : p0_(s.start) {
    OMeshOptions o;
    o.semi_axis_x = p0_[0];
    o.semi_axis_y = p0_[1];
    o.n_around = s.n_around;
    o.n_radial = s.n_radial;
    o.first_height = 1e-2;
    o.farfield_radius = 8.0;
    mesh_ = o_mesh(o);
    BoundarySpec<2> spec;
    spec.moving("wall", Translation<2>{}).fixed("farfield");
    boundary_ = spec.resolve(mesh_);
    // dd/dp: wall node (a0 cos θ, b0 sin θ) moves to (a cos θ, b sin θ), so its displacement
    // is linear in p with these columns; fixed nodes do not depend on p.
    const Index m = boundary_.size();
    dd_da_.setZero(2, m);
    dd_db_.setZero(2, m);
    for (Index k = 0; k < m; ++k) {
      if (boundary_.kinds[static_cast<std::size_t>(k)] != BoundaryKind::prescribed) continue;
      const Vec<2> x = mesh_.points.col(boundary_.nodes[static_cast<std::size_t>(k)]);
      dd_da_(0, k) = x[0] / p0_[0];
      dd_db_(1, k) = x[1] / p0_[1];
    }
    RbfOptions options;
    options.support_radius = s.support_radius;
    mover_ = RbfMover<2>(options);
    // The only setup of the whole optimization: every design below is a move from here.
    mover_.setup(mesh_, boundary_);
    reference_areas_ = areas(mesh_.points);
    target_areas_ = areas(positions(s.target));
  }

  [[nodiscard]] const Mesh<2>& mesh() const { return mesh_; }

  /// Node positions of design p: x0 + move(d(p)).
  [[nodiscard]] Points<2> positions(const Parameters& p) {
    const Points<2> d = (p[0] - p0_[0]) * dd_da_ + (p[1] - p0_[1]) * dd_db_;
    return mesh_.points + mover_.move(d);
  }

  /// J(p); +∞ when a cell folds, so that a line search steps back.
  [[nodiscard]] double objective(const Parameters& p) { return objective_at(positions(p)); }

  /// dJ/dp by the reverse product: v = dJ/dx on the volume nodes, g = (du/dd)ᵀ v on the
  /// boundary, then the chain with dd/dp.
  [[nodiscard]] Parameters gradient(const Parameters& p) {
    const Points<2> x = positions(p);
    Points<2> v = Points<2>::Zero(2, x.cols());
    const double scale = 2.0 / static_cast<double>(reference_areas_.size());
    std::size_t c = 0;
    for (const auto& block : mesh_.cells)
      for (Index e = 0; e < block.size(); ++e, ++c) {
        const double r = (cell_area(x, block.element(e)) - target_areas_[c]) / reference_areas_[c];
        add_area_gradient(x, block.element(e), scale * r / reference_areas_[c], v);
      }
    const Points<2> g = mover_.derivative_reverse(v);
    return {g.cwiseProduct(dd_da_).sum(), g.cwiseProduct(dd_db_).sum()};
  }

 private:
  [[nodiscard]] std::vector<double> areas(const Points<2>& x) const {
    std::vector<double> out;
    for (const auto& block : mesh_.cells)
      for (Index e = 0; e < block.size(); ++e) out.push_back(cell_area(x, block.element(e)));
    return out;
  }

  [[nodiscard]] double objective_at(const Points<2>& x) const {
    const std::vector<double> a = areas(x);
    double sum = 0.0;
    for (std::size_t c = 0; c < a.size(); ++c) {
      if (!(a[c] > 0.0)) return std::numeric_limits<double>::infinity();
      const double r = (a[c] - target_areas_[c]) / reference_areas_[c];
      sum += r * r;
    }
    return sum / static_cast<double>(a.size());
  }

  Parameters p0_;
  Mesh<2> mesh_;
  ResolvedBoundary<2> boundary_;
  Points<2> dd_da_, dd_db_;
  RbfMover<2> mover_;
  std::vector<double> reference_areas_, target_areas_;
};

/// Central finite differences of J, one parameter at a time.
Parameters finite_difference(EllipseDesign& design, const Parameters& p, double h) {
  Parameters g{};
  for (std::size_t j = 0; j < 2; ++j) {
    Parameters plus = p, minus = p;
    plus[j] += h;
    minus[j] -= h;
    g[j] = (design.objective(plus) - design.objective(minus)) / (2.0 * h);
  }
  return g;
}

double norm(const Parameters& g) { return std::hypot(g[0], g[1]); }

struct Iteration {
  Parameters p;
  double objective;
  Parameters reverse, fd;
  double relative_difference;
};

int run(const Settings& s) {
  EllipseDesign design(s);
  std::vector<Iteration> history;
  Parameters p = s.start;
  double j = design.objective(p);
  double step = 0.1;  // along the unit descent direction, in parameter units
  if (!s.json) {
    std::printf("%zu nodes, %lld cells; start (a, b) = (%.3f, %.3f), target (%.3f, %.3f)\n\n",
                static_cast<std::size_t>(design.mesh().num_nodes()), static_cast<long long>(design.mesh().num_cells()),
                s.start[0], s.start[1], s.target[0], s.target[1]);
    std::printf("%4s %9s %9s %12s | %13s %13s | %13s %13s | %9s\n", "iter", "a", "b", "J", "dJ/da reverse",
                "dJ/da FD", "dJ/db reverse", "dJ/db FD", "rel.diff");
  }
  for (int it = 0;; ++it) {
    const Parameters g = design.gradient(p);
    const Parameters fd = finite_difference(design, p, s.fd_step);
    const Parameters diff{g[0] - fd[0], g[1] - fd[1]};
    const double relative = norm(diff) / std::max(norm(fd), std::numeric_limits<double>::min());
    history.push_back({p, j, g, fd, relative});
    if (!s.json)
      std::printf("%4d %9.6f %9.6f %12.5e | %13.6e %13.6e | %13.6e %13.6e | %9.2e\n", it, p[0], p[1], j, g[0], fd[0],
                  g[1], fd[1], relative);
    if (it == s.iterations || norm(g) == 0.0) break;

    // Steepest descent with backtracking (Armijo): halve the step until J decreases enough.
    const double gn = norm(g);
    Parameters trial{};
    double j_trial = std::numeric_limits<double>::infinity();
    for (int halvings = 0; halvings < 40; ++halvings, step *= 0.5) {
      trial = {p[0] - step * g[0] / gn, p[1] - step * g[1] / gn};
      j_trial = design.objective(trial);
      if (j_trial <= j - 1e-4 * step * gn) break;
    }
    if (!(j_trial < j)) break;  // no descent left at this precision
    p = trial;
    j = j_trial;
    step = std::min(2.0 * step, 0.2);
  }

  double worst = 0.0;
  for (const auto& h : history) worst = std::max(worst, h.relative_difference);
  const bool passed = worst <= s.tolerance;
  const bool decreased = history.back().objective < history.front().objective;
  if (s.json) {
    JsonWriter w(std::cout);
    w.begin_object();
    w.key("nodes").value(design.mesh().num_nodes()).key("cells").value(design.mesh().num_cells());
    w.key("start").begin_array().value(s.start[0]).value(s.start[1]).end_array();
    w.key("target").begin_array().value(s.target[0]).value(s.target[1]).end_array();
    w.key("final").begin_array().value(p[0]).value(p[1]).end_array();
    w.key("objective_start").value(history.front().objective).key("objective_final").value(j);
    w.key("iterations").begin_array();
    for (const auto& h : history) {
      w.begin_object();
      w.key("a").value(h.p[0]).key("b").value(h.p[1]).key("objective").value(h.objective);
      w.key("reverse").begin_array().value(h.reverse[0]).value(h.reverse[1]).end_array();
      w.key("finite_difference").begin_array().value(h.fd[0]).value(h.fd[1]).end_array();
      w.key("relative_difference").value(h.relative_difference);
      w.end_object();
    }
    w.end_array();
    w.key("max_relative_difference").value(worst).key("tolerance").value(s.tolerance);
    w.key("gradient_check_passed").value(passed).key("objective_decreased").value(decreased);
    w.end_object();
    std::cout << "\n";
  } else {
    std::printf("\nJ: %.5e -> %.5e; (a, b) = (%.6f, %.6f), target (%.3f, %.3f)\n", history.front().objective, j, p[0],
                p[1], s.target[0], s.target[1]);
    std::printf("gradient check: largest relative difference %.2e (tolerance %.0e): %s\n", worst, s.tolerance,
                passed ? "passed" : "FAILED");
  }
  return passed && decreased ? 0 : 2;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Tutorial 2: shape optimization of an ellipse's semi-axes with the RBF reverse derivative, "
               "checked against finite differences"};
  meshmotion::examples::add_version_flag(app);
  Settings s;
  std::vector<double> start{s.start[0], s.start[1]}, target{s.target[0], s.target[1]};
  app.add_option("--start", start, "initial semi-axes A,B")->delimiter(',')->expected(2)->capture_default_str();
  app.add_option("--target", target, "semi-axes A,B of the target design")->delimiter(',')->expected(2)->capture_default_str();
  app.add_option("--n-around", s.n_around, "nodes around the ellipse")->check(CLI::Range(8, 100000))->capture_default_str();
  app.add_option("--n-radial", s.n_radial, "cell layers to the farfield")->check(CLI::Range(2, 100000))->capture_default_str();
  app.add_option("--support-radius", s.support_radius, "RBF support radius")->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--iterations", s.iterations, "gradient-descent iterations")->check(CLI::NonNegativeNumber)->capture_default_str();
  app.add_option("--fd-step", s.fd_step, "finite-difference step")->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--tolerance", s.tolerance, "largest accepted relative difference reverse vs FD")->check(CLI::PositiveNumber)->capture_default_str();
  app.add_flag("--json", s.json, "print one JSON object instead of the tables");
  if (const auto rc = meshmotion::examples::parse_command_line(app, argc, argv)) return *rc;
  return meshmotion::examples::guarded(s.json, [&] {
    s.start = {start[0], start[1]};
    s.target = {target[0], target[1]};
    if (!(s.start[0] > 0 && s.start[1] > 0 && s.target[0] > 0 && s.target[1] > 0))
      throw InputError("tutorial_2_optimization_loop: semi-axes must be positive (got start " + std::to_string(s.start[0]) +
                       "," + std::to_string(s.start[1]) + ", target " + std::to_string(s.target[0]) + "," +
                       std::to_string(s.target[1]) + ")");
    return run(s);
  });
}
