// Mechanics movers on the 30P30N three-element airfoil (su2_30p30n_rans_L1_coarse.su2, 64k
// quads), beside RBF in the same run:
//
// 1. Thesis table 4.2: curving the viscous mesh to P2 (quad9) and regularizing the interior
//    with stiffened linear elasticity (χ = 2.75 and 2.9) and with RBF (the curving pipeline's
//    default). SLE rows: the direct solver on the active region 4 × the wall layer (the
//    pipeline's RBF default radius), the whole mesh (the reference that must match),
//    and the thesis's solver settings (Jacobi-CG, tolerance 1e-6, now on the diagonally
//    scaled system). Thesis: SLE 19.3 s / 24.4 s, 324 / 423 CG iterations, min quality 0.632;
//    RBF 1.86 s, min 0.640 (on its own 66k-triangle mesh and hardware). Ratio column: time /
//    RBF time of this run. Wall time and the process CPU time of the step are both given:
//    on a loaded machine the wall time is mostly waiting.
// 2. Thesis figs. 4.1–4.5: the flap (the wall loop with x in [0.398, 0.517]) rotated 60°
//    counter-clockwise about its leading edge, slat and main element and farfield fixed, on the
//    linear mesh: torsion springs and linear elasticity in one step (as the thesis), RBF in 3
//    steps (support 0.45, the thesis's 15/18.3 of the chord) and neo-Hookean elasticity with a
//    bounded budget (3 load steps, at most 8 Newton iterations each, Newton tolerance 1e-6:
//    a row within minutes, "failed: ..." with its time when the budget is not enough). Min
//    skew-quality, invalid cells, time; ratio = time / RBF time.
//
// One JSON line per case. Skips with a message when the data file is absent.
//
//   elasticity_bench [--quick]   (--quick: the default SLE rows of part 1 and part 2 without
//                                 neo-Hookean)

#include "bench_memory.hpp"
#include "meshmotion/core/json.hpp"
#include "meshmotion/core/topology.hpp"
#include "meshmotion/curving/curve_mesh.hpp"
#include "meshmotion/io/mesh_io.hpp"
#include "meshmotion/movers.hpp"
#include "meshmotion/movers/step_driver.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

using namespace meshmotion;

namespace {

struct Row {
  std::string part, method, parameters;
  double min_quality = 0.0, mean_quality = 0.0;
  Index invalid = 0;
  double seconds = 0.0;
  double cpu_seconds = 0.0;  ///< process CPU time (all threads) over the same span
  Index iterations = 0;
  std::string thesis;
  std::string note;
};

void print(const Row& r, double baseline_seconds) {
  std::printf("%-8s %-8s %-34s %8.4f %9.6f %7lld %9.3f %8.3f %7.2f %8lld  %s %s\n", r.part.c_str(), r.method.c_str(),
              r.parameters.c_str(), r.min_quality, r.mean_quality, static_cast<long long>(r.invalid), r.seconds,
              r.cpu_seconds, baseline_seconds > 0.0 ? r.seconds / baseline_seconds : 0.0, static_cast<long long>(r.iterations),
              r.thesis.c_str(), r.note.c_str());
  JsonWriter w(std::cout);
  w.begin_object()
      .key("benchmark").value("elasticity")
      .key("part").value(r.part)
      .key("method").value(r.method)
      .key("parameters").value(r.parameters)
      .key("min_quality").value(r.min_quality)
      .key("mean_quality").value(r.mean_quality)
      .key("invalid").value(r.invalid)
      .key("seconds").value(r.seconds)
      .key("cpu_seconds").value(r.cpu_seconds)
      .key("ratio_to_rbf").value(baseline_seconds > 0.0 ? r.seconds / baseline_seconds : 0.0)
      .key("iterations").value(r.iterations)
      .key("thesis").value(r.thesis)
      .key("note").value(r.note)
      .end_object();
  std::cout << std::endl;
}

void header() {
  std::printf("%-8s %-8s %-34s %8s %9s %7s %9s %8s %7s %8s  %s\n", "part", "method", "parameters", "min q", "mean q",
              "invalid", "seconds", "cpu s", "/rbf", "iters", "thesis");
}

/// Process CPU seconds (all threads).
double cpu_now() { return static_cast<double>(std::clock()) / CLOCKS_PER_SEC; }

Row start_row(const std::string& part, const std::string& method, const std::string& label, const std::string& thesis) {
  Row r;
  r.part = part;
  r.method = method;
  r.parameters = label;
  r.thesis = thesis;
  return r;
}

// `active_factor`: the active region of elasticity in support radii of the walls (0: whole mesh).
Row curve(const Mesh<2>& linear, const std::string& method, const KeyValues& options, const std::string& label,
          const std::string& thesis, double active_factor = 4.0) {
  CurveOptions<2> o;
  o.method = method;
  o.mover_options = mover_config<2>(method, options).options;
  o.active_radius_factor = active_factor;
  Row r = start_row("tab4.2", method, label, thesis);
  o.progress = [&](const std::string& line) {
    // The regularize step's CPU time: from its progress line to the certification's.
    if (line.rfind("regularizing", 0) == 0) r.cpu_seconds = -cpu_now();
    if (line.rfind("certifying", 0) == 0) r.cpu_seconds += cpu_now();
  };
  try {
    const CurveResult<2> c = curve_mesh(linear, o);
    r.min_quality = c.quality.min;
    r.mean_quality = c.quality.mean;
    r.invalid = c.quality.num_invalid;
    r.seconds = c.seconds.regularize;
    r.iterations = c.solver_iterations;
  } catch (const Error& e) {
    r.note = std::string("failed: ") + e.what();
  }
  return r;
}

Row flap(const Mesh<2>& mesh, const BoundarySpec<2>& spec, const GroupNodes& groups, const std::string& method,
         const KeyValues& parameters, int steps, const std::string& label, const std::string& thesis) {
  Row r = start_row("fig4.1-5", method, label, thesis);
  const auto start = std::chrono::steady_clock::now();
  const double cpu_start = cpu_now();
  const auto finish = [&] {
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    r.cpu_seconds = cpu_now() - cpu_start;
  };
  try {
    AnyMover<2> mover = make_mover<2>(method, parameters);
    StepOptions so;
    so.steps = steps;
    so.report_quality = false;
    const StepResult<2> result = run_steps(mover, mesh, spec, so, groups);
    finish();
    const QualityReport q = quality_report(result.mesh, Metric::skew);
    r.min_quality = q.min;
    r.mean_quality = q.mean;
    r.invalid = q.num_invalid;
    for (const auto& s : result.steps) r.iterations += s.stats.iterations;
  } catch (const Error& e) {
    finish();
    r.note = std::string("failed: ") + e.what();
  }
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  bench::tune_memory(argc, argv);
  const bool quick = argc > 1 && std::strcmp(argv[1], "--quick") == 0;
  const std::filesystem::path file = std::filesystem::path(MESHMOTION_SHARED_DATA_DIR) / "su2_30p30n_rans_L1_coarse.su2";
  if (!std::filesystem::exists(file)) {
    std::printf("elasticity_bench: skipped, %s not found\n", file.string().c_str());
    return 0;
  }
  const Mesh<2> mesh = read_mesh_as<2>(file);
  std::printf("30P30N: %lld nodes, %lld cells\n", static_cast<long long>(mesh.num_nodes()),
              static_cast<long long>(mesh.num_cells()));
  header();

  {
    const Row rbf = curve(mesh, "rbf", {}, "default radius", "1.86s min 0.640 avg 0.9911");
    print(rbf, rbf.seconds);
    for (const auto& [chi, thesis] : {std::pair{"2.75", "19.3s 324 it min 0.632 avg 0.9949"},
                                      std::pair{"2.9", "24.4s 423 it min 0.632 avg 0.9945"}}) {
      // Active region: 4 × the pipeline's support radius (its wall-layer estimate), the default.
      const KeyValues p{{"stiffening_exponent", chi}, {"youngs_modulus", "1e6"}, {"poisson_ratio", "0.4"}};
      print(curve(mesh, "sle", p, std::string("chi=") + chi + " direct, region 4x layer", thesis), rbf.seconds);
      if (quick) continue;
      print(curve(mesh, "sle", p, std::string("chi=") + chi + " direct, whole mesh", thesis, 0.0), rbf.seconds);
      KeyValues cg = p;
      cg.insert(cg.end(), {{"solver", "cg_jacobi"}, {"tolerance", "1e-6"}});
      print(curve(mesh, "sle", cg, std::string("chi=") + chi + " cg_jacobi 1e-6, region", thesis), rbf.seconds);
      cg[3].second = "cg_incomplete_cholesky";
      print(curve(mesh, "sle", cg, std::string("chi=") + chi + " cg_ichol 1e-6, region", thesis), rbf.seconds);
    }
  }

  // The flap: the wall chain whose nodes all lie right of x = 0.398.
  const int wall_tag = mesh.group("wall").tag;
  std::vector<Index> flap_nodes, other_walls;
  for (const BoundaryChain& chain : boundary_chains(mesh, wall_tag)) {
    double x_min = 1e300;
    for (const Index v : chain.nodes) x_min = std::min(x_min, mesh.points(0, v));
    auto& list = x_min > 0.39 ? flap_nodes : other_walls;
    list.insert(list.end(), chain.nodes.begin(), chain.nodes.end());
  }
  Index leading = flap_nodes.front();
  for (const Index v : flap_nodes)
    if (mesh.points(0, v) < mesh.points(0, leading)) leading = v;
  GroupNodes groups{{"flap", flap_nodes}, {"walls", other_walls}, {"farfield", mesh.group_nodes("farfield")}};
  BoundarySpec<2> spec;
  spec.moving("flap", Rotation2D{mesh.points.col(leading), radians(60.0)});
  spec.fixed("walls");
  spec.fixed("farfield");
  const Row rbf = flap(mesh, spec, groups, "rbf", {{"support_radius", "0.45"}}, 3, "r=0.45, 3 steps", "valid, good (figs 4.8-4.10)");
  print(rbf, rbf.seconds);
  print(flap(mesh, spec, groups, "torsion", {}, 1, "1 step", "invalid cells (fig 4.2)"), rbf.seconds);
  print(flap(mesh, spec, groups, "le", {}, 1, "nu=0.3, 1 step", "valid, degenerate at flap TE (4.3-4.5)"), rbf.seconds);
  if (!quick) {
    const KeyValues nle{{"load_steps", "3"}, {"newton_iterations", "8"}, {"newton_tolerance", "1e-6"}};
    print(flap(mesh, spec, groups, "nle", nle, 1, "3 load steps, <= 8 Newton each", "-"), rbf.seconds);
  }
  return 0;
}
