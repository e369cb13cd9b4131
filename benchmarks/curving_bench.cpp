// curving_bench: thesis table 4.2 on the 30P30N RANS mesh (three-element high-lift airfoil,
// all quads, and the same mesh split into triangles): RBF (Wendland C2) at the thesis's
// support radii scaled to the chord, 1 and 2 steps; the layer-based default radius; the
// blending regularizer; snapping alone. Then two walls with layers of their own (one radius
// against a radius per wall), and a wall-resolution study (what limits RBF on thin layers).
// Gmsh has no CAD of the 30P30N, so it cannot curve that mesh: the comparison with Gmsh runs
// on cases where it has the true geometry (gmsh_peer.hpp): a NACA0012 boundary-layer mesh that gmsh itself makes (triangles, and
// quads), and the RAE2822 and sphere meshes with their STEP files, at orders 2, 3 and 4. Gmsh's
// `-order N` snapping and each Mesh.HighOrderOptimize variant curve the linear mesh it saved;
// our pipeline curves the same linear mesh with the analytic geometry (NACA0012) or the same
// STEP file (through the CAD component); every curved mesh is judged by our certified scaled
// Jacobian and by gmsh's AnalyseMeshQuality plugin. Prints tables and one JSON line per row;
// each JSON line holds the "histogram" of our certified scaled Jacobian (valid cells in 10
// equal bins on [0, 1]; the invalid ones are counted by "invalid" alone), which
// plot_results.py draws per mesh.
// Times are this machine's; the thesis's are beside ours for reference.
//
// usage: curving_bench [--no-gmsh] [--gmsh-only] [--quick] [--orders=234] [--cases=naca,rae,sphere]
//                      [path/to/su2_30p30n_rans_L1_coarse.su2]
//   --no-gmsh    only the 30P30N, two-wall and wall-resolution tables
//   --gmsh-only  only the Gmsh comparison
//   --quick      Gmsh comparison without gmsh's slow variants (HighOrderOptimize 1 and 2, and 3
//                with more layers), which take minutes of CPU each


#include "bench_memory.hpp"
#include "gmsh_peer.hpp"

#include "meshmotion/core/generators.hpp"
#include "meshmotion/curving/curve_mesh.hpp"
#include "meshmotion/curving/geometry.hpp"
#include "meshmotion/curving/naca_section.hpp"
#include "meshmotion/io/mesh_io.hpp"
#include "meshmotion/quality/quality_report.hpp"

#ifdef MESHMOTION_HAVE_CAD
#include "meshmotion/cad/cad_model.hpp"
#endif

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <exception>
#include <filesystem>
#include <functional>
#include <limits>
#include <numbers>
#include <string>
#include <tuple>
#include <vector>

namespace {

using namespace meshmotion;
namespace fs = std::filesystem;

struct Case {
  std::string label;
  std::string method;
  double radius_fraction = 0.0;  // of the chord; 0: the pipeline's default
  int steps = 1;
  const char* thesis = "";       // thesis table 4.2 (66.5k triangles, its own hardware)
};

// Each quadrilateral into two triangles along its 0-2 diagonal (the thesis's mesh is all
// triangles).
Mesh<2> split_quads(const Mesh<2>& mesh) {
  Mesh<2> out = mesh;
  out.cells.clear();
  ElementBlock& tris = out.block(ElementType::tri3);
  for (const auto& b : mesh.cells)
    for (Index e = 0; e < b.size(); ++e) {
      const auto el = b.element(e);
      const int tag = b.tags[static_cast<std::size_t>(e)];
      if (b.type == ElementType::quad4) {
        tris.add({el[0], el[1], el[2]}, tag);
        tris.add({el[0], el[2], el[3]}, tag);
      } else {
        tris.add(el, tag);
      }
    }
  return out;
}

// The valid cells of a report per bin, as a JSON array. make_report puts invalid cells
// (value ≤ 0) into the first bin; they are taken out so that the plot shows them apart.
[[nodiscard]] std::string histogram_json(const QualityReport& q) {
  std::string out = "[";
  for (std::size_t b = 0; b < q.histogram.size(); ++b) {
    const Index count = b == 0 ? std::max<Index>(0, q.histogram[0] - q.num_invalid) : q.histogram[b];
    if (b > 0) out += ',';
    out += std::to_string(count);
  }
  return out + "]";
}

void print_row(const std::string& mesh_name, const std::string& label, double radius, int steps, const QualityReport& q,
               double seconds, Index iterations, double baseline_seconds, const char* thesis) {
  std::printf("%-10s %-22s %9.5f %5d %8.4f %9.6f %7lld %9.3f %8.2f %7lld   %s\n", mesh_name.c_str(), label.c_str(), radius,
              steps, q.min, q.mean, static_cast<long long>(q.num_invalid), seconds,
              baseline_seconds > 0 ? seconds / baseline_seconds : 0.0, static_cast<long long>(iterations), thesis);
  std::printf(
      "{\"bench\":\"curving\",\"mesh\":\"%s\",\"case\":\"%s\",\"support_radius\":%.6g,\"steps\":%d,\"min\":%.6f,"
      "\"mean\":%.6f,\"invalid\":%lld,\"seconds\":%.6f,\"ratio_to_baseline\":%.4f,\"iterations\":%lld,\"thesis\":\"%s\","
      "\"histogram\":%s}\n",
      mesh_name.c_str(), label.c_str(), radius, steps, q.min, q.mean, static_cast<long long>(q.num_invalid), seconds,
      baseline_seconds > 0 ? seconds / baseline_seconds : 0.0, static_cast<long long>(iterations), thesis,
      histogram_json(q).c_str());
}

void thesis_table(const fs::path& file) {
  if (!fs::exists(file)) {
    std::printf("curving_bench: %s not found, 30P30N table skipped\n", file.string().c_str());
    return;
  }
  const Mesh<2> quads = read_mesh_as<2>(file);
  const auto wall = quads.group_nodes("wall");
  double x_min = 1e300, x_max = -1e300;
  for (const Index v : wall) {
    x_min = std::min(x_min, quads.points(0, v));
    x_max = std::max(x_max, quads.points(0, v));
  }
  const double chord = x_max - x_min;  // the thesis's 18.3 is the extent of its three elements
  std::printf("30P30N: %lld nodes, %lld quads, wall extent (chord) %.4f m. No Gmsh rows: Gmsh has no CAD of this\n"
              "mesh, and `gmsh -order 2` on a discrete mesh adds straight-sided nodes only.\n",
              static_cast<long long>(quads.num_nodes()), static_cast<long long>(quads.num_cells()), chord);

  const std::vector<Case> cases{
      {"none (snap only)", "none", 0.0, 1, ""},
      {"rbf r=0.04/18.3", "rbf", 0.04 / 18.3, 1, "0.640 / 0.991093, 1.86 s, 365x2 it"},
      {"rbf r=0.08/18.3", "rbf", 0.08 / 18.3, 1, "0.639 / 0.991562, 1.88 s, 1150x2 it"},
      {"rbf r=0.12/18.3", "rbf", 0.12 / 18.3, 1, "0.637 / 0.99159, 1.89 s, 2295x2 it"},
      {"rbf r=0.04/18.3", "rbf", 0.04 / 18.3, 2, "0.641 / 0.991099, 2.58 s, 365x4 it"},
      {"rbf r=layer", "rbf", 0.0, 1, ""},
      {"blend (default)", "blend", 0.0, 1, ""},
  };
  std::printf("\n%-10s %-22s %9s %5s %8s %9s %7s %9s %8s %7s   %s\n", "mesh", "case", "radius", "steps", "min", "mean",
              "invalid", "seconds", "ratio", "iters", "thesis (min / mean, time, iterations)");
  for (const auto& [mesh_name, linear] : {std::pair{std::string("quads"), quads}, std::pair{std::string("triangles"), split_quads(quads)}}) {
    double baseline = 0.0;
    for (const Case& c : cases) {
      CurveOptions<2> options;
      options.method = c.method;
      options.support_radius = c.radius_fraction * chord;
      options.steps = c.steps;
      options.geometry.emplace("farfield", BoundaryGeometry<2>::straight());
      const CurveResult<2> r = curve_mesh(linear, options);
      const double seconds = r.seconds.total - r.seconds.certify;
      if (c.method == "none") baseline = seconds;
      print_row(mesh_name, c.label, r.support_radius, c.steps, r.quality, seconds, r.solver_iterations, baseline, c.thesis);
    }
  }
  std::printf("\nseconds: P2 conversion + snapping + layer estimate + regularization (certification excluded);\n"
              "ratio: to snapping alone (the first row) on the same mesh.\n");
}

// Two walls with layers of different thickness (annulus_mesh: a journal bearing's gap): RBF
// with the thickest layer's radius for both walls (the thesis's one radius) against a radius
// per wall (the default), blending, and snapping alone.
void two_walls_table() {
  std::printf("\nTwo walls: the gap between a shaft (r = 0.5, first cell 1e-4) and a housing (r = 1.5, first cell\n"
              "2e-3), 256 cells around; both walls projected on their circles.\n");
  std::printf("\n%-10s %-22s %9s %5s %8s %9s %7s %9s %8s %7s\n", "mesh", "case", "radius", "steps", "min", "mean", "invalid",
              "seconds", "ratio", "iters");
  for (const bool triangles : {false, true}) {
    const Mesh<2> linear = annulus_mesh({.n_around = 256, .triangles = triangles});
    const std::string mesh_name = triangles ? "gap_tri" : "gap_quad";
    double baseline = 0.0;
    for (const auto& [label, method, per_wall] : {std::tuple{"none (snap only)", "none", true},
                                                  std::tuple{"rbf one radius", "rbf", false},
                                                  std::tuple{"rbf radius per wall", "rbf", true},
                                                  std::tuple{"blend L=6 layers", "blend", true}}) {
      CurveOptions<2> options;
      options.method = method;
      options.per_wall_radius = per_wall;
      options.geometry.emplace("inner", BoundaryGeometry<2>::project(SphereProjection<2>(Vec<2>::Zero(), 0.5)));
      options.geometry.emplace("outer", BoundaryGeometry<2>::project(SphereProjection<2>(Vec<2>::Zero(), 1.5)));
      const CurveResult<2> r = curve_mesh(linear, options);
      const double seconds = r.seconds.total - r.seconds.certify;
      if (std::string(method) == "none") baseline = seconds;
      print_row(mesh_name, label, r.support_radius, 1, r.quality, seconds, r.solver_iterations, baseline, "");
      if (r.wall_support_radii.size() == 2)
        std::printf("%-10s   layers %.4g (shaft) and %.4g (housing): radii %.4g and %.4g\n", "", r.layers[0].thickness,
                    r.layers[1].thickness, r.wall_support_radii[0], r.wall_support_radii[1]);
    }
  }
  std::printf("\nradius: the largest support; ratio: time to snapping alone on the same mesh.\n");
}

// Why RBF stops short of 1 on thin layers: the O-mesh triangles around a circle (diameter 1,
// first cell 1e-5, 64 layers) at 64–512 wall facets. Curving bows a facet's edge node by
// b ≈ h²/(8ρ) while its vertices stay, a displacement of period h along the wall; an isotropic
// kernel loses that part within a fraction of h off the wall, whatever its radius, so a layer
// cell's top edge no longer bows like its bottom one and the minimum falls by c·h/ρ. Blending
// carries the wall's own displacement up and loses b·|φ'|/L, smaller as L grows.
void wall_resolution_table() {
  std::printf("\nWall resolution: O-mesh triangles around a circle of radius rho = 0.5 (first cell 1e-5, 64 layers);\n"
              "h: wall facet length; loss = 1 - min; the defaults: RBF radius 4 layers, blending length 6 layers.\n");
  std::printf("\n%-9s %8s %-26s %9s %8s %10s %11s\n", "n_around", "h", "case", "length", "min", "loss", "loss/(h/rho)");
  constexpr double rho = 0.5;
  double rbf_lowest = std::numeric_limits<double>::infinity(), rbf_highest = 0.0;  // of loss / (h / rho)
  for (const Index n : {64, 128, 256, 512}) {
    const Mesh<2> linear = o_mesh({.n_around = n, .n_radial = 64, .triangles = true});
    const double h = 2.0 * rho * std::sin(std::numbers::pi / static_cast<double>(n));
    double layer = 0.0;
    for (const auto& [label, method, factor] : {std::tuple{"rbf, 4 layers (default)", "rbf", 0.0},
                                                std::tuple{"rbf, 1 layer", "rbf", 1.0},
                                                std::tuple{"rbf, 16 layers", "rbf", 16.0},
                                                std::tuple{"blend, 1 layer", "blend", 1.0},
                                                std::tuple{"blend, 6 layers (default)", "blend", 0.0}}) {
      CurveOptions<2> options;
      options.method = method;
      options.geometry.emplace("wall", BoundaryGeometry<2>::project(SphereProjection<2>(Vec<2>::Zero(), rho)));
      options.geometry.emplace("farfield", BoundaryGeometry<2>::project(SphereProjection<2>(Vec<2>::Zero(), 20.0)));
      if (std::string(method) == "rbf") options.support_radius = factor * layer;
      else if (factor > 0.0) set_curve_options(options, {{"blending_factor", format_option_value(factor)}});
      const CurveResult<2> r = curve_mesh(linear, options);
      if (layer == 0.0) layer = r.layers.front().thickness;
      const double blending_factor =
          factor > 0.0 ? factor : std::get<BlendOptions>(mover_config<2>("blend").options).blending_factor;
      const double length = std::string(method) == "rbf" ? r.wall_support_radii.empty() ? r.support_radius : r.wall_support_radii.front()
                                                         : blending_factor * layer;
      const double loss = 1.0 - r.quality.min;
      if (std::string(method) == "rbf") {
        rbf_lowest = std::min(rbf_lowest, loss / (h / rho));
        rbf_highest = std::max(rbf_highest, loss / (h / rho));
      }
      std::printf("%-9lld %8.5f %-26s %9.5f %8.5f %10.3e %11.3f\n", static_cast<long long>(n), h, label, length, r.quality.min, loss,
                  loss / (h / rho));
      std::printf("{\"bench\":\"curving_wall_resolution\",\"n_around\":%lld,\"h\":%.6g,\"case\":\"%s\",\"length\":%.6g,"
                  "\"min\":%.6f,\"loss\":%.6g,\"loss_per_h_over_rho\":%.4f,\"invalid\":%lld}\n",
                  static_cast<long long>(n), h, label, length, r.quality.min, loss, loss / (h / rho),
                  static_cast<long long>(r.quality.num_invalid));
    }
  }
  std::printf("\nRBF at every radius and resolution: loss between %.2f and %.2f times h/rho.\n", rbf_lowest, rbf_highest);
}

// ---- Gmsh comparison ------------------------------------------------------------------

// One P2 mesh of the comparison: who made it, its cost, and both judges' verdicts.
struct PeerRow {
  std::string tool;     // "gmsh" or "meshmotion"
  std::string method;
  double cpu = 0.0;     // CPU seconds of the high-order step (gmsh's timer; ours: process CPU)
  double wall = 0.0;
  QualityReport ours;   // certified scaled Jacobian
  bench::GmshQuality gmsh;
  double geometry_error = 0.0;  // max distance of the wall's P2 nodes to the true geometry
  std::string note;
};

[[nodiscard]] double process_cpu_seconds() { return static_cast<double>(std::clock()) / CLOCKS_PER_SEC; }

// Maximum distance of the nodes of facet group `tag` to the true geometry.
template <int Dim>
[[nodiscard]] double geometry_error(const Mesh<Dim>& mesh, int tag, const BoundaryProjection<Dim>& projection) {
  double worst = 0.0;
  for (const Index v : mesh.group_nodes(tag)) {
    const Vec<Dim> p = mesh.points.col(v);
    worst = std::max(worst, (projection(p) - p).norm());
  }
  return worst;
}

// A case of the comparison: the CAD gmsh reads, the linear mesh both curve, the geometry we
// are given, and the high-order variants gmsh runs.
template <int Dim>
struct PeerCase {
  std::string name;
  std::string cad_lines;       // script lines that load gmsh's geometry
  fs::path linear;             // the linear mesh (parametric coordinates: gmsh merges it onto the CAD)
  int wall_tag = 0;
  BoundaryProjection<Dim> wall;
  CurveOptions<Dim> base;      // geometry and sliding groups of our pipeline
  std::vector<bench::GmshVariant> variants;
  std::vector<std::string> methods;
  double layer_thickness = 0.0;  // when known (the layer gmsh was asked for): one more blend row with it
  int order = 2;
};

void print_peer_header() {
  std::printf("\n%-13s %-11s %-36s %8s %8s %7s %8s %8s %7s %8s %8s %7s %9s  %s\n", "case", "tool", "method", "cpu s", "wall s",
              "ratio", "min", "mean", "invalid", "g.worst", "g.avg", "g.inv", "geo err", "note");
  std::printf("%s\n", std::string(156, '-').c_str());
}

void print_peer_row(const std::string& name, const PeerRow& r, double reference_cpu) {
  std::string note = r.note;  // JSON-safe: messages may quote names
  std::replace(note.begin(), note.end(), '"', '\'');
  std::replace(note.begin(), note.end(), '\\', '/');
  const double ratio = reference_cpu > 0.0 ? r.cpu / reference_cpu : 0.0;
  std::printf("%-13s %-11s %-36s %8.3f %8.3f %7.2f %8.4f %8.4f %7lld %8.4f %8.4f %7ld %9.2e  %s\n", name.c_str(),
              r.tool.c_str(), r.method.c_str(), r.cpu, r.wall, ratio, r.ours.min, r.ours.mean,
              static_cast<long long>(r.ours.num_invalid), r.gmsh.worst, r.gmsh.average, r.gmsh.invalid, r.geometry_error,
              r.note.c_str());
  std::printf(
      "{\"bench\":\"curving_vs_gmsh\",\"case\":\"%s\",\"tool\":\"%s\",\"method\":\"%s\",\"cpu_seconds\":%.6f,"
      "\"wall_seconds\":%.6f,\"ratio_to_best_gmsh_cpu\":%.4f,\"min\":%.6f,\"mean\":%.6f,\"invalid\":%lld,"
      "\"gmsh_minJ_maxJ_worst\":%.6f,\"gmsh_minJ_maxJ_avg\":%.6f,\"gmsh_invalid\":%ld,\"geometry_error\":%.3e,"
      "\"note\":\"%s\",\"histogram\":%s}\n",
      name.c_str(), r.tool.c_str(), r.method.c_str(), r.cpu, r.wall, ratio, r.ours.min, r.ours.mean,
      static_cast<long long>(r.ours.num_invalid), r.gmsh.worst, r.gmsh.average, r.gmsh.invalid, r.geometry_error,
      note.c_str(), histogram_json(r.ours).c_str());
  std::fflush(stdout);
}

// Runs gmsh's variants and our methods on one case; prints a table (ratio: CPU time to the
// gmsh variant with the best certified minimum).
// The label of our default's row (method "blend" with its default length).
constexpr const char* default_label = "blend (default)";

template <int Dim>
void compare_case(const PeerCase<Dim>& c, const fs::path& scratch) {
  const Mesh<Dim> linear = read_mesh_as<Dim>(c.linear);
  std::printf("\n%s: %lld nodes, %lld cells (linear mesh %s)\n", c.name.c_str(), static_cast<long long>(linear.num_nodes()),
              static_cast<long long>(linear.num_cells()), c.linear.string().c_str());
  std::vector<PeerRow> rows;
  for (const auto& v : c.variants) {
    const fs::path out = scratch / (c.name + "_gmsh_" + std::to_string(rows.size()) + ".msh");
    const fs::path script = scratch / (c.name + "_gmsh_" + std::to_string(rows.size()) + ".geo");
    bench::write_text(script, c.cad_lines + "Merge \"" + c.linear.string() + "\";\n" + bench::high_order_commands(v) +
                                  "Save \"" + out.string() + "\";\n");
    const bench::GmshRun run = bench::run_gmsh(script);
    PeerRow r;
    r.tool = "gmsh";
    r.method = v.label;
    r.cpu = run.high_order.cpu;
    r.wall = run.high_order.wall;
    if (!fs::exists(out)) {
      r.note = "gmsh failed (exit " + std::to_string(run.exit_code) + ", log " + script.string() + ".log)";
      rows.push_back(r);
      continue;
    }
    // The optimizer logs an Error (and gmsh exits 1) when some elements miss its target, but it
    // still saves its result: that mesh is judged like the others, with the message noted.
    if (!run.errors.empty())
      r.note = "gmsh exit " + std::to_string(run.exit_code) + ": " + run.errors.front().substr(0, 70);
    const Mesh<Dim> curved = read_mesh_as<Dim>(out);
    r.ours = quality_report(curved, Metric::scaled_jacobian);
    r.gmsh = bench::gmsh_analyse(out, scratch);
    r.geometry_error = geometry_error(curved, c.wall_tag, c.wall);
    rows.push_back(r);
    fs::remove(out);
  }
  std::vector<std::pair<std::string, double>> runs;  // method, blending length (0: the default)
  for (const auto& method : c.methods) runs.emplace_back(method, 0.0);
  if (c.layer_thickness > 0.0) runs.emplace_back("blend", c.layer_thickness);
  for (const auto& [method, blending_length] : runs) {
    CurveOptions<Dim> options = c.base;
    options.order = c.order;
    options.method = method;
    if (blending_length > 0.0) set_curve_options(options, {{"blending_length", format_option_value(blending_length)}});
    double cpu_start = 0.0, cpu_end = 0.0;
    std::chrono::steady_clock::time_point wall_start, wall_end;
    options.progress = [&](const std::string& line) {  // the clocks stop when certification starts
      if (line.rfind("certifying", 0) == 0) {
        cpu_end = process_cpu_seconds();
        wall_end = std::chrono::steady_clock::now();
      }
    };
    wall_start = std::chrono::steady_clock::now();
    cpu_start = process_cpu_seconds();
    PeerRow r;
    r.tool = "meshmotion";
    char blend_label[64];
    std::snprintf(blend_label, sizeof blend_label, "blend (L = %g, given layer)", blending_length);
    r.method = method == "none"    ? "snap only"
               : method == "rbf"   ? "rbf (r = layer, or 2 spacings)"
               : method == "blend" ? (blending_length > 0.0 ? blend_label : std::string(default_label))
                                   : method + " (stiffened elasticity)";
    try {
      const CurveResult<Dim> result = curve_mesh(linear, options);
      // The untangling runs after the first certification (serial: its CPU time is its wall time).
      r.cpu = cpu_end - cpu_start + result.seconds.untangle;
      r.wall = std::chrono::duration<double>(wall_end - wall_start).count() + result.seconds.untangle;
      if (result.untangle.cells_below > 0 || result.untangle.raise_rounds > 0) {
        char untangled[128];
        std::snprintf(untangled, sizeof untangled, "untangled %lld cells below 0.1, raised %d rounds: %.3f -> %.3f",
                      static_cast<long long>(result.untangle.cells_below), result.untangle.raise_rounds, result.untangle.min_before,
                      result.untangle.min_after);
        r.note = untangled;
      }
      r.ours = result.quality;
      r.geometry_error = geometry_error(result.curved, c.wall_tag, c.wall);
      const fs::path out = scratch / (c.name + "_ours_" + method + ".msh");
      write_mesh(out, result.curved);
      r.gmsh = bench::gmsh_analyse(out, scratch);
      fs::remove(out);
    } catch (const Error& e) {
      r.note = std::string("failed: ") + e.what();
    }
    rows.push_back(r);
  }
  // the reference: the gmsh variant with the best certified minimum (then the cheaper one)
  const PeerRow* best = nullptr;
  for (const auto& r : rows)
    if (r.tool == "gmsh" && r.ours.num_elements > 0 &&
        (!best || r.ours.min > best->ours.min || (r.ours.min == best->ours.min && r.cpu < best->cpu)))
      best = &r;
  const double reference = best ? best->cpu : 0.0;
  print_peer_header();
  for (const auto& r : rows) print_peer_row(c.name, r, reference);
  if (!best) return;
  std::printf("best gmsh variant (by certified min): %s, %.4f in %.3f s CPU\n", best->method.c_str(), best->ours.min, best->cpu);
  // Issue 20's target: our default at least Gmsh's best minimum, in at most its time.
  const auto ours = std::find_if(rows.begin(), rows.end(), [](const PeerRow& r) { return r.method == default_label; });
  if (ours == rows.end() || ours->ours.num_elements == 0) return;
  const bool quality = ours->ours.min >= best->ours.min, time = ours->cpu <= best->cpu;
  std::printf("target: our default %.4f %s %.4f, %.3f s %s %.3f s CPU: %s\n", ours->ours.min, quality ? ">=" : "<",
              best->ours.min, ours->cpu, time ? "<=" : ">", best->cpu, quality && time ? "met" : "not met");
  std::printf("{\"bench\":\"curving_vs_gmsh_target\",\"case\":\"%s\",\"default_min\":%.6f,\"gmsh_best_min\":%.6f,"
              "\"default_cpu_seconds\":%.6f,\"gmsh_best_cpu_seconds\":%.6f,\"gmsh_best\":\"%s\",\"met\":%s}\n",
              c.name.c_str(), ours->ours.min, best->ours.min, ours->cpu, best->cpu, best->method.c_str(),
              quality && time ? "true" : "false");
}

template <int Dim>
void compare(const PeerCase<Dim>& c, const fs::path& scratch) {
  try {
    compare_case(c, scratch);
  } catch (const std::exception& e) {
    std::printf("%s: comparison failed: %s\n", c.name.c_str(), e.what());
    std::printf("{\"bench\":\"curving_vs_gmsh\",\"case\":\"%s\",\"status\":\"failed\"}\n", c.name.c_str());
  }
  std::fflush(stdout);
}

// The gmsh variants of a case: -order N alone, then HighOrderOptimize 1..4 at gmsh's
// defaults, and (when `layers` > 0) again with Mesh.HighOrderNumLayers covering the layer.
std::vector<bench::GmshVariant> gmsh_variants(int layers, bool quick, int order = 2) {
  std::vector<bench::GmshVariant> out{{"-order " + std::to_string(order) + " (snap, HOO=0)", 0, 0, order}};
  const std::vector<std::pair<int, std::string>> optimize{
      {1, "optimization (HOO=1)"}, {2, "elastic+optimization (HOO=2)"}, {3, "elastic (HOO=3)"}, {4, "fast curving (HOO=4)"}};
  for (const int num_layers : layers > 0 ? std::vector<int>{0, layers} : std::vector<int>{0})
    for (const auto& [value, label] : optimize) {
      if (quick && (value == 1 || value == 2 || (value == 3 && num_layers > 0))) continue;
      out.push_back({num_layers > 0 ? label + " nl=" + std::to_string(num_layers) : label, value, num_layers, order});
    }
  return out;
}

void gmsh_comparison(bool quick, const std::vector<int>& orders, const std::string& cases) {
  const auto wanted = [&](const char* name) { return cases.empty() || cases.find(name) != std::string::npos; };
  const fs::path scratch = fs::temp_directory_path() / "curving_bench_gmsh";
  fs::create_directories(scratch);
  const std::string version = bench::gmsh_version(scratch);
  if (version.empty()) {
    std::printf("\nGmsh comparison: gmsh is not installed (peer missing; `apt-get install gmsh`), no Gmsh rows.\n");
    std::printf("{\"bench\":\"curving_vs_gmsh\",\"peer\":\"gmsh\",\"status\":\"missing\"}\n");
    return;
  }
  std::printf("\nGmsh comparison (gmsh %s, one thread). gmsh's time: its own timers of SetOrder 2 and the\n"
              "OptimizeMesh calls (CPU and wall); ours: curve_mesh from the linear mesh to the regularized P2 mesh\n"
              "(process CPU, all threads; certification excluded). ratio: CPU time to the best gmsh variant.\n"
              "min/mean/invalid: our certified scaled Jacobian (min det J / det J of the straight element);\n"
              "g.worst/g.avg/g.inv: gmsh's AnalyseMeshQuality min(J)/max(J) per element (g.inv: <= 0);\n"
              "geo err: max distance of the wall's nodes to the analytic geometry.\n",
              version.c_str());

  for (const int order : wanted("naca") ? orders : std::vector<int>{})
    for (const bool quads : {false, true}) {
      bench::NacaGeo geo;
      geo.quads = quads;
      const std::string name = quads ? "naca0012_quad" : "naca0012_tri";
      const fs::path cad = scratch / (name + ".geo");
      const fs::path linear = scratch / (name + "_linear.msh");
      bench::write_text(cad, bench::naca_geo(geo));
      const fs::path script = scratch / (name + "_mesh.geo");
      bench::write_text(script, "Include \"" + cad.string() + "\";\nMesh.SaveParametric = 1;\nMesh 2;\nSave \"" +
                                    linear.string() + "\";\n");
      const bench::GmshRun run = bench::run_gmsh(script);
      const bench::GmshTimer meshing = bench::sum_timers(run.log, {"Done meshing 1D", "Done meshing 2D"});
      if (run.exit_code != 0 || !fs::exists(linear)) {
        std::printf("%s: gmsh could not mesh the geometry (exit %d, log %s.log)\n", name.c_str(), run.exit_code,
                    script.string().c_str());
        continue;
      }
      std::printf("\n%s: gmsh made the linear mesh in %.3f s CPU (%.3f s wall): NACA0012, unit chord, first cell %g,\n"
                  "growth %g, %d layers (%g thick), farfield circle R = %g; %s.\n",
                  name.c_str(), meshing.cpu, meshing.wall, geo.first_height, geo.growth, geo.layers(), geo.layer_thickness,
                  geo.farfield_radius, quads ? "recombined into quads" : "triangles");
      PeerCase<2> c;
      c.name = name + "_p" + std::to_string(order);
      c.order = order;
      c.cad_lines = "Include \"" + cad.string() + "\";\n";
      c.linear = linear;
      c.wall_tag = 1;
      c.wall = NacaProjection(naca4("0012"));
      c.base.geometry.emplace("wall", BoundaryGeometry<2>::project(c.wall));
      c.base.geometry.emplace("farfield", BoundaryGeometry<2>::project(SphereProjection<2>(Vec<2>(0.5, 0.0), geo.farfield_radius)));
      c.variants = gmsh_variants(2 * geo.layers(), quick, order);
      c.layer_thickness = geo.layer_thickness;
      c.methods = {"none", "rbf", "blend", "sle"};
      compare(c, scratch);
    }

  const fs::path data = fs::path(MESHMOTION_SHARED_DATA_DIR);
  const fs::path sphere = data / "meshopt_sphere_symmetry_linear_tet.msh", step = data / "meshopt_Sphere25CSymmetry.stp";
  const fs::path rae = data / "meshopt_rae2822_linear_tri.msh", rae_step = data / "meshopt_rae2822Square.stp";
#ifdef MESHMOTION_HAVE_CAD
  // Both tools on the STEP files: ours through the CAD component, every group the model fits.
  if (!wanted("rae")) {
  } else if (fs::exists(rae) && fs::exists(rae_step)) {
    static const CadModel model = CadModel::read(rae_step);
    Mesh<2> mesh = read_mesh_as<2>(rae);
    name_unnamed_facet_groups(mesh);  // the file names no group: its tags are the groups
    const auto matches = match_cad_groups(mesh, model);
    std::printf("\nrae2822: the linear mesh of the data folder (made by gmsh from the STEP file, parametric\n"
                "coordinates kept) merged onto that STEP file; ours: the same STEP file through OpenCASCADE:\n%s",
                describe_cad_matches(matches).c_str());
    for (const int order : orders) {
      PeerCase<2> c;
      c.name = "rae2822_p" + std::to_string(order);
      c.order = order;
      c.cad_lines = "Merge \"" + rae_step.string() + "\";\nMesh.SaveAll = 1;\n";
      c.linear = rae;
      // The wall (for the geometry error column): the smallest matched group, the airfoil.
      double smallest = std::numeric_limits<double>::infinity();
      for (const auto& m : matches)
        if (m.matched()) {
          c.base.geometry.insert_or_assign(m.group, cad_boundary<2>(model, m));
          const std::vector<Index> nodes = mesh.group_nodes(m.group);
          Points<2> at(2, static_cast<Index>(nodes.size()));
          for (std::size_t k = 0; k < nodes.size(); ++k) at.col(static_cast<Index>(k)) = mesh.points.col(nodes[k]);
          const double size = (at.rowwise().maxCoeff() - at.rowwise().minCoeff()).norm();
          if (size < smallest) {
            smallest = size;
            c.wall_tag = mesh.group(m.group).tag;
            c.wall = c.base.geometry.at(m.group).projection;
          }
        }
      c.variants = gmsh_variants(0, quick, order);
      c.methods = {"none", "rbf", "blend"};
      compare(c, scratch);
    }
  } else {
    std::printf("\nrae2822: %s or its STEP file not found, skipped\n", rae.string().c_str());
  }
#else
  std::printf("\nrae2822: skipped (built without the CAD component: OpenCASCADE not found)\n");
#endif
  if (!wanted("sphere")) return;
  if (!fs::exists(sphere) || !fs::exists(step)) {
    std::printf("\nsphere: %s or its STEP file not found, skipped\n", sphere.string().c_str());
    return;
  }
  std::printf("\nsphere_tet: the linear mesh of the data folder (made by gmsh from the STEP file, parametric\n"
              "coordinates kept) merged onto that STEP file; ours: %s on group 7, group 20 sliding.\n",
#ifdef MESHMOTION_HAVE_CAD
              "the same STEP file through OpenCASCADE"
#else
              "the sphere of radius 0.5 (built without the CAD component)"
#endif
  );
  for (const int order : orders) {
    PeerCase<3> c;
    c.name = "sphere_tet_p" + std::to_string(order);
    c.order = order;
    c.cad_lines = "Merge \"" + step.string() + "\";\nMesh.SaveAll = 1;\n";  // the tets have no physical group
    c.linear = sphere;
    c.wall_tag = 7;
#ifdef MESHMOTION_HAVE_CAD
    static const CadModel model = CadModel::read(step);
    static const Mesh<3> mesh = [&] {
      Mesh<3> m = read_mesh_as<3>(sphere);
      name_unnamed_facet_groups(m);
      return m;
    }();
    static const auto matches = match_cad_groups(mesh, model, 0.0, {"7"});
    c.base.geometry.emplace("7", cad_boundary<3>(model, matches.front()));
    c.wall = c.base.geometry.at("7").projection;
#else
    c.wall = SphereProjection<3>(Vec<3>::Zero(), 0.5);
    c.base.geometry.emplace("7", BoundaryGeometry<3>::project(c.wall));
#endif
    c.base.sliding = {"20"};
    c.variants = gmsh_variants(0, quick, order);
    c.methods = {"none", "rbf", "blend", "sle"};
    compare(c, scratch);
  }
}

}  // namespace

int main(int argc, char** argv) {
  bench::tune_memory(argc, argv);
  bool with_gmsh = true, with_thesis = true, quick = false;
  std::vector<int> orders{2, 3, 4};
  std::string cases;
  fs::path file = fs::path(MESHMOTION_SHARED_DATA_DIR) / "su2_30p30n_rans_L1_coarse.su2";
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--no-gmsh") with_gmsh = false;
    else if (a == "--gmsh-only") with_thesis = false;
    else if (a == "--quick") quick = true;
    else if (a.rfind("--cases=", 0) == 0) cases = a.substr(8);
    else if (a.rfind("--orders=", 0) == 0) {
      orders.clear();
      for (const char ch : a.substr(9))
        if (ch >= '2' && ch <= '4') orders.push_back(ch - '0');
    }
    else if (a == "--help" || a == "-h") {
      std::printf("usage: curving_bench [--no-gmsh] [--gmsh-only] [--quick] [--orders=234] [--cases=naca,rae,sphere] [30p30n.su2]\n");
      return 0;
    } else file = a;
  }
  if (with_thesis) {
    thesis_table(file);
    two_walls_table();
    wall_resolution_table();
  }
  if (with_gmsh) gmsh_comparison(quick, orders, cases);
  return 0;
}
