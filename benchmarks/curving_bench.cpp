// curving_bench: thesis table 4.2 on the 30P30N RANS mesh (three-element high-lift airfoil,
// all quads, and the same mesh split into triangles): RBF (Wendland C2) at the thesis's
// support radii scaled to the chord, 1 and 2 steps; the layer-based default radius; the
// blending regularizer; snapping alone; and, when gmsh is on PATH, `gmsh -order 2` on the
// same linear mesh, certified by the same scaled-Jacobian check. Prints a table and one JSON
// line per case. Times are this machine's; the thesis's are beside ours for reference.
//
// usage: curving_bench [path/to/su2_30p30n_rans_L1_coarse.su2]

#include "meshmotion/curving/curve_mesh.hpp"
#include "meshmotion/io/mesh_io.hpp"
#include "meshmotion/quality/quality_report.hpp"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace {

using namespace meshmotion;

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

void print_row(const std::string& mesh_name, const std::string& label, double radius, int steps, const QualityReport& q,
               double seconds, Index iterations, double baseline_seconds, const char* thesis) {
  std::printf("%-10s %-22s %9.5f %5d %8.4f %9.6f %7lld %9.3f %8.2f %7lld   %s\n", mesh_name.c_str(), label.c_str(), radius,
              steps, q.min, q.mean, static_cast<long long>(q.num_invalid), seconds,
              baseline_seconds > 0 ? seconds / baseline_seconds : 0.0, static_cast<long long>(iterations), thesis);
  std::printf(
      "{\"bench\":\"curving\",\"mesh\":\"%s\",\"case\":\"%s\",\"support_radius\":%.6g,\"steps\":%d,\"min\":%.6f,"
      "\"mean\":%.6f,\"invalid\":%lld,\"seconds\":%.6f,\"ratio_to_baseline\":%.4f,\"iterations\":%lld,\"thesis\":\"%s\"}\n",
      mesh_name.c_str(), label.c_str(), radius, steps, q.min, q.mean, static_cast<long long>(q.num_invalid), seconds,
      baseline_seconds > 0 ? seconds / baseline_seconds : 0.0, static_cast<long long>(iterations), thesis);
}

// gmsh -order 2 on the linear mesh written as .msh; returns its wall-clock seconds and the
// quality of its output, or nothing when gmsh is not on PATH or fails.
std::optional<std::pair<double, QualityReport>> gmsh_order2(const Mesh<2>& linear, const std::string& name) {
  if (std::system("gmsh --version > /dev/null 2>&1") != 0) return std::nullopt;
  const auto dir = std::filesystem::temp_directory_path();
  const auto in = dir / ("curving_bench_" + name + ".msh");
  const auto out = dir / ("curving_bench_" + name + "_p2.msh");
  write_mesh(in, linear, WriteOptions{MshVersion::v2_2, false, false});
  const std::string command = "gmsh " + in.string() + " -0 -order 2 -o " + out.string() + " > /dev/null 2>&1";
  const auto start = std::chrono::steady_clock::now();
  const int status = std::system(command.c_str());
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (status != 0 || !std::filesystem::exists(out)) return std::nullopt;
  const Mesh<2> curved = read_mesh_as<2>(out);
  std::filesystem::remove(in);
  std::filesystem::remove(out);
  return std::pair{seconds, quality_report(curved, Metric::scaled_jacobian)};
}

}  // namespace

int main(int argc, char** argv) {
  const std::filesystem::path file =
      argc > 1 ? std::filesystem::path(argv[1]) : std::filesystem::path(MESHMOTION_SHARED_DATA_DIR) / "su2_30p30n_rans_L1_coarse.su2";
  if (!std::filesystem::exists(file)) {
    std::printf("curving_bench: %s not found, skipped\n", file.string().c_str());
    return 0;
  }
  const Mesh<2> quads = read_mesh_as<2>(file);
  const auto wall = quads.group_nodes("wall");
  double x_min = 1e300, x_max = -1e300;
  for (const Index v : wall) {
    x_min = std::min(x_min, quads.points(0, v));
    x_max = std::max(x_max, quads.points(0, v));
  }
  const double chord = x_max - x_min;  // the thesis's 18.3 is the extent of its three elements
  std::printf("30P30N: %lld nodes, %lld quads, wall extent (chord) %.4f m\n", static_cast<long long>(quads.num_nodes()),
              static_cast<long long>(quads.num_cells()), chord);

  const std::vector<Case> cases{
      {"none (snap only)", "none", 0.0, 1, ""},
      {"rbf r=0.04/18.3", "rbf", 0.04 / 18.3, 1, "0.640 / 0.991093, 1.86 s, 365x2 it"},
      {"rbf r=0.08/18.3", "rbf", 0.08 / 18.3, 1, "0.639 / 0.991562, 1.88 s, 1150x2 it"},
      {"rbf r=0.12/18.3", "rbf", 0.12 / 18.3, 1, "0.637 / 0.99159, 1.89 s, 2295x2 it"},
      {"rbf r=0.04/18.3", "rbf", 0.04 / 18.3, 2, "0.641 / 0.991099, 2.58 s, 365x4 it"},
      {"rbf r=layer", "rbf", 0.0, 1, ""},
      {"blend L=layer", "blend", 0.0, 1, ""},
  };
  std::printf("\n%-10s %-22s %9s %5s %8s %9s %7s %9s %8s %7s   %s\n", "mesh", "case", "radius", "steps", "min", "mean",
              "invalid", "seconds", "ratio", "iters", "thesis (min / mean, time, iterations)");
  for (const auto& [mesh_name, linear] : {std::pair{std::string("quads"), quads}, std::pair{std::string("triangles"), split_quads(quads)}}) {
    const auto gmsh = gmsh_order2(linear, mesh_name);
    const double baseline = gmsh ? gmsh->first : 0.0;
    if (gmsh) print_row(mesh_name, "gmsh -order 2", 0.0, 1, gmsh->second, gmsh->first, 0, baseline, "");
    else std::printf("%-10s gmsh not on PATH: no baseline\n", mesh_name.c_str());
    for (const Case& c : cases) {
      CurveOptions<2> options;
      options.method = c.method;
      options.support_radius = c.radius_fraction * chord;
      options.steps = c.steps;
      options.geometry.emplace("farfield", BoundaryGeometry<2>::straight());
      const CurveResult<2> r = curve_mesh(linear, options);
      const double seconds = r.seconds.total - r.seconds.certify;
      print_row(mesh_name, c.label, r.support_radius, c.steps, r.quality, seconds, r.solver_iterations, baseline, c.thesis);
    }
  }
  std::printf("\nseconds: P2 conversion + snapping + layer estimate + regularization (certification excluded);\n"
              "ratio: to gmsh -order 2 on the same linear mesh (its process time, file I/O included).\n");
  return 0;
}
