// Tutorial 3: grid velocities for an ALE solver.
//
// An arbitrary Lagrangian–Eulerian solver moves its mesh with the body and needs, at every
// step, each node's velocity as well as its position: the fluxes through moving faces take
// the grid velocity, and the geometric conservation law asks that it be the rate of change
// of the positions the solver uses. Here an ellipse pitches about its quarter chord,
// angle(t) = A sin(2π t / T), inside a held far field. The pattern shown:
//
//   1. set the mover up ONCE on the reference, before anything moves;
//   2. each step: the wall's displacement d(t) gives the positions X + move(d(t)); the wall's
//      velocity ḋ(t) gives every node's velocity, velocity(ḋ(t)), through the same linear map
//      (for the positions X + J d(t), the velocity is J ḋ(t): exact, not a difference);
//   3. write both per step (VTU files with a "velocity" point array, and a .pvd series);
//   4. check the velocities against a central difference of the positions in time.
//
//   tutorial_3_grid_velocity --steps 40 --out-dir frames
//   tutorial_3_grid_velocity --steps 40 --json

#include "meshmotion/core/generators.hpp"
#include "meshmotion/core/json.hpp"
#include "meshmotion/io/vtu_writer.hpp"
#include "meshmotion/movers/any_mover.hpp"
#include "meshmotion/movers/boundary.hpp"
#include "meshmotion/movers/registry.hpp"
#include "meshmotion/quality/quality_report.hpp"

#include "program.hpp"

#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <numbers>
#include <string>

namespace {

using namespace meshmotion;

struct Settings {
  int steps = 40;
  int period_steps = 40;   // time steps per pitch period
  double period = 1.0;     // seconds
  double amplitude = 15.0; // degrees
  std::string method = "rbf";
  std::string out_dir;     // empty: write nothing
  bool json = false;
};

/// The pitching wall: its displacement and velocity at time t for the wall nodes at `x`.
struct Pitch {
  Vec<2> centre{-0.25, 0.0};  // the quarter chord of a chord-1 ellipse centred at 0
  double amplitude = 0.0, omega = 0.0;

  [[nodiscard]] double angle(double t) const { return amplitude * std::sin(omega * t); }
  [[nodiscard]] double rate(double t) const { return amplitude * omega * std::cos(omega * t); }
  [[nodiscard]] Vec<2> displacement(const Vec<2>& x, double t) const {
    return Eigen::Rotation2Dd(angle(t)) * (x - centre) + centre - x;
  }
  [[nodiscard]] Vec<2> velocity(const Vec<2>& x, double t) const {
    const Vec<2> r = Eigen::Rotation2Dd(angle(t)) * (x - centre);
    return rate(t) * Vec<2>(-r.y(), r.x());
  }
};

int run(const Settings& s) {
  OMeshOptions o;
  o.semi_axis_x = 0.5;
  o.semi_axis_y = 0.06;
  o.n_around = 96;
  o.n_radial = 32;
  o.first_height = 2e-3;
  o.farfield_radius = 10.0;
  const Mesh<2> mesh = o_mesh(o);
  BoundarySpec<2> spec;
  spec.moving("wall", Translation<2>{Vec<2>::Zero()}).fixed("farfield");
  ResolvedBoundary<2> boundary = spec.resolve(mesh);
  AnyMover<2> mover = make_mover(mover_config<2>(s.method, {}));
  mover.setup(mesh, boundary);  // once, with no displacement yet

  const Pitch pitch{{-0.25, 0.0}, s.amplitude * std::numbers::pi / 180.0, 2.0 * std::numbers::pi / s.period};
  const double dt = s.period / s.period_steps;
  const auto wall = [&](double t, bool rate) {
    Points<2> out = Points<2>::Zero(2, boundary.size());
    for (Index k = 0; k < boundary.size(); ++k) {
      if (boundary.kinds[static_cast<std::size_t>(k)] != BoundaryKind::prescribed) continue;
      const Vec<2> x = mesh.points.col(boundary.nodes[static_cast<std::size_t>(k)]);
      out.col(k) = rate ? pitch.velocity(x, t) : pitch.displacement(x, t);
    }
    return out;
  };
  const auto positions = [&](double t) { return Points<2>(mesh.points + mover.move(wall(t, false))); };

  if (!s.out_dir.empty()) std::filesystem::create_directories(s.out_dir);
  std::ofstream series;
  if (!s.out_dir.empty()) {
    series.open(std::filesystem::path(s.out_dir) / "motion.pvd");
    series << "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n<Collection>\n";
  }
  double worst_gap = 0.0, fastest = 0.0, min_quality = 1.0;
  if (!s.json) std::printf("%6s %10s %12s %14s %12s\n", "step", "t", "angle_deg", "max_speed", "min_sj");
  for (int n = 0; n <= s.steps; ++n) {
    const double t = n * dt;
    Mesh<2> moved = mesh;
    moved.points = positions(t);
    const Points<2> velocity = mover.velocity(wall(t, true));
    // The positions' rate of change by a central difference, h small against the step.
    const double h = 1e-5 * s.period;
    const Points<2> difference = (positions(t + h) - positions(t - h)) / (2.0 * h);
    worst_gap = std::max(worst_gap, (velocity - difference).colwise().norm().maxCoeff());
    const double speed = velocity.colwise().norm().maxCoeff();
    fastest = std::max(fastest, speed);
    const double quality = quality_report(moved, Metric::scaled_jacobian).min;
    min_quality = std::min(min_quality, quality);
    if (!s.out_dir.empty()) {
      const std::string name = "motion_" + std::to_string(n) + ".vtu";
      write_vtu(std::filesystem::path(s.out_dir) / name, moved, VtuFields{{{"velocity", velocity}}, {}});
      series << "<DataSet timestep=\"" << t << "\" file=\"" << name << "\"/>\n";
    }
    if (!s.json && n % 5 == 0)
      std::printf("%6d %10.4f %12.4f %14.6g %12.4f\n", n, t, pitch.angle(t) * 180.0 / std::numbers::pi, speed, quality);
  }
  if (series.is_open()) series << "</Collection>\n</VTKFile>\n";
  const double relative = worst_gap / std::max(fastest, 1e-300);
  if (s.json) {
    JsonWriter w(std::cout);
    w.begin_object().key("method").value(s.method).key("steps").value(s.steps).key("nodes").value(mesh.num_nodes());
    w.key("max_speed").value(fastest).key("velocity_vs_difference").value(relative);
    w.key("min_scaled_jacobian").value(min_quality).end_object();
    std::cout << "\n";
  } else {
    std::printf("velocity against the central difference of the positions: %.3g of the fastest node's speed\n", relative);
  }
  return relative <= 1e-8 ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Tutorial 3: grid velocities for an ALE solver (a pitching ellipse, positions and velocities per step, "
               "checked against a central difference of the positions)"};
  meshmotion::examples::add_version_flag(app);
  Settings s;
  app.add_option("--steps", s.steps, "time steps")->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--period-steps", s.period_steps, "time steps per pitch period")->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--amplitude", s.amplitude, "pitch amplitude in degrees")->check(CLI::Range(0.0, 60.0))->capture_default_str();
  app.add_option("--method", s.method, "a mover with derivatives: rbf, spring, torsion, le, sle, dgm, idgm, dgrbf")
      ->capture_default_str();
  app.add_option("--out-dir", s.out_dir, "write motion_N.vtu (positions and a velocity point array) and motion.pvd here");
  app.add_flag("--json", s.json, "print one JSON object instead of the table");
  if (const auto rc = meshmotion::examples::parse_command_line(app, argc, argv)) return *rc;
  return meshmotion::examples::guarded(s.json, [&] { return run(s); });
}
