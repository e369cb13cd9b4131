#pragma once
// Gmsh as a curving peer for curving_bench: writes .geo scripts, runs the gmsh command line,
// reads gmsh's own timers of its high-order steps from its log, and judges any .msh file
// with gmsh's AnalyseMeshQuality plugin (min(J)/max(J) per element, J = det of the Jacobian).
//
// Gmsh curves a mesh only when it knows the geometry: each case hands it the CAD (a .geo or
// a STEP file) and the linear mesh saved with parametric coordinates, merged onto that CAD,
// so that `SetOrder 2` snaps the new boundary nodes to the true curves/surfaces. This is
// what `gmsh -order 2` does after meshing; Mesh.HighOrderOptimize = 1..4 runs, after it,
// (1) "HighOrder": the optimizer (OptHOM, untangling + distortion objective),
// (2) "HighOrderElastic" then "HighOrder", (3) "HighOrderElastic": the elastic analogy,
// (4) "HighOrderFastCurving": the boundary-layer fast curving — the same OptimizeMesh calls
// as gmsh's GenerateMesh (Generator.cpp, gmsh 4.8), written into the script.

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace bench {

using namespace meshmotion;

/// Gmsh's "(Wall Xs, CPU Ys)" timers, summed over the lines that carry one.
struct GmshTimer {
  double wall = 0.0;
  double cpu = 0.0;
};

/// One gmsh invocation: exit code, log, timers of the high-order steps, error lines.
struct GmshRun {
  int exit_code = -1;
  double process_seconds = 0.0;  ///< the whole process (reading CAD and mesh, writing)
  GmshTimer high_order;          ///< "Done meshing order 2" + "Done optimizing mesh"
  std::vector<std::string> errors;
  std::string log;
};

/// gmsh's quality of the highest-dimension elements of a mesh file.
struct GmshQuality {
  bool ok = false;
  double worst = 0.0;    ///< min over elements of min(J)/max(J)
  double average = 0.0;  ///< mean over elements of min(J)/max(J)
  long invalid = -1;     ///< elements with min(J)/max(J) <= 0
};

[[nodiscard]] inline std::string read_text(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

inline void write_text(const std::filesystem::path& file, const std::string& text) {
  std::ofstream(file) << text;
}

/// gmsh's version line, or "" when gmsh is not on PATH.
[[nodiscard]] inline std::string gmsh_version(const std::filesystem::path& scratch) {
  const auto out = scratch / "gmsh_version.txt";
  if (std::system(("gmsh -version > " + out.string() + " 2>&1").c_str()) != 0) return "";
  std::string v = read_text(out);
  while (!v.empty() && (v.back() == '\n' || v.back() == '\r')) v.pop_back();
  return v;
}

/// Sums the "(Wall Xs, CPU Ys)" of every log line that starts with one of `prefixes`.
[[nodiscard]] inline GmshTimer sum_timers(const std::string& log, const std::vector<std::string>& prefixes) {
  GmshTimer t;
  std::istringstream in(log);
  for (std::string line; std::getline(in, line);) {
    bool match = false;
    for (const auto& p : prefixes) match = match || line.find(p) != std::string::npos;
    const auto at = line.find("(Wall ");
    if (!match || at == std::string::npos) continue;
    double wall = 0.0, cpu = 0.0;
    if (std::sscanf(line.c_str() + at, "(Wall %lfs, CPU %lfs)", &wall, &cpu) == 2) {
      t.wall += wall;
      t.cpu += cpu;
    }
  }
  return t;
}

/// Runs `gmsh SCRIPT -parse_and_exit` single-threaded, the log into SCRIPT.log.
[[nodiscard]] inline GmshRun run_gmsh(const std::filesystem::path& script) {
  GmshRun run;
  auto log = script;
  log += ".log";
  const std::string command = "gmsh " + script.string() + " -nt 1 -parse_and_exit > " + log.string() + " 2>&1";
  const auto start = std::chrono::steady_clock::now();
  const int status = std::system(command.c_str());
  run.process_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  run.exit_code = status;
  run.log = read_text(log);
  run.high_order = sum_timers(run.log, {"Done meshing order", "Done optimizing mesh"});
  std::istringstream in(run.log);
  for (std::string line; std::getline(in, line);)
    if (line.rfind("Error", 0) == 0) run.errors.push_back(line);
  return run;
}

/// Counts the entries <= 0 of the first $ElementData block of a view saved as .msh.
[[nodiscard]] inline long count_nonpositive_element_data(const std::string& text) {
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line) && line.rfind("$ElementData", 0) != 0) {
  }
  if (!in) return -1;
  long count = 0;
  for (int tags = 0; tags < 3; ++tags) {  // string, real, integer tags: a count, then the tags
    int n = 0;
    in >> n;
    std::getline(in, line);
    long last = 0;
    for (int k = 0; k < n; ++k) {
      std::getline(in, line);
      last = std::atol(line.c_str());
    }
    if (tags == 2) count = last;  // the third integer tag is the number of entries
  }
  long invalid = 0;
  for (long k = 0; k < count; ++k) {
    long tag = 0;
    double value = 0.0;
    if (!(in >> tag >> value)) return -1;
    invalid += value <= 0.0 ? 1 : 0;
  }
  return invalid;
}

/// gmsh's AnalyseMeshQuality plugin (JacobianDeterminant) on a mesh file: worst and average
/// min(J)/max(J) from its log, invalid count from the per-element view it creates.
[[nodiscard]] inline GmshQuality gmsh_analyse(const std::filesystem::path& mesh, const std::filesystem::path& scratch) {
  const auto script = scratch / (mesh.stem().string() + "_analyse.geo");
  const auto view = scratch / (mesh.stem().string() + "_jacobian_view.msh");
  write_text(script, "Merge \"" + mesh.string() +
                         "\";\n"
                         "Plugin(AnalyseMeshQuality).JacobianDeterminant = 1;\n"
                         "Plugin(AnalyseMeshQuality).CreateView = 1;\n"
                         "Plugin(AnalyseMeshQuality).DimensionOfElements = -1;\n"
                         "Plugin(AnalyseMeshQuality).Run;\n"
                         "PostProcessing.SaveMesh = 0;\n"
                         "Save View[0] \"" + view.string() + "\";\n");
  const GmshRun run = run_gmsh(script);
  GmshQuality q;
  std::istringstream in(run.log);
  for (std::string line; std::getline(in, line);) {
    const auto at = line.find("minJ/maxJ =");
    if (at == std::string::npos || line.find("(worst, avg, best)") == std::string::npos) continue;
    double best = 0.0;
    q.ok = std::sscanf(line.c_str() + at, "minJ/maxJ = %lf, %lf, %lf", &q.worst, &q.average, &best) == 3;
  }
  if (q.ok) q.invalid = count_nonpositive_element_data(read_text(view));
  std::filesystem::remove(view);
  return q;
}

/// A gmsh high-order variant: the script lines run after the linear mesh is merged.
struct GmshVariant {
  std::string label;
  int high_order_optimize = 0;  ///< the Mesh.HighOrderOptimize value it reproduces
  int num_layers = 0;           ///< Mesh.HighOrderNumLayers (0: gmsh's default, 6)
  int order = 2;                ///< SetOrder
};

/// Script lines of a variant: `SetOrder N` and the OptimizeMesh calls of GenerateMesh for
/// Mesh.HighOrderOptimize = v.high_order_optimize.
[[nodiscard]] inline std::string high_order_commands(const GmshVariant& v) {
  std::string s;
  if (v.num_layers > 0) s += "Mesh.HighOrderNumLayers = " + std::to_string(v.num_layers) + ";\n";
  s += "SetOrder " + std::to_string(v.order) + ";\n";
  if (v.high_order_optimize == 2 || v.high_order_optimize == 3) s += "OptimizeMesh \"HighOrderElastic\";\n";
  if (v.high_order_optimize == 1 || v.high_order_optimize == 2) s += "OptimizeMesh \"HighOrder\";\n";
  if (v.high_order_optimize == 4) s += "OptimizeMesh \"HighOrderFastCurving\";\n";
  return s;
}

/// Parameters of the NACA 4-digit boundary-layer case gmsh meshes.
struct NacaGeo {
  double thickness = 0.12;        ///< symmetric section 00TT, unit chord, leading edge at the origin
  int points_per_side = 200;      ///< spline points, cosine-spaced in x
  double first_height = 1e-6;     ///< first cell height of the boundary layer
  double growth = 1.2;            ///< layer growth ratio
  double layer_thickness = 0.06;  ///< boundary-layer thickness
  double trailing_edge_size = 0.001;
  double mid_chord_size = 0.015;
  int curvature_points = 100;     ///< Mesh.MeshSizeFromCurvature (elements per 2 pi)
  double farfield_radius = 20.0;  ///< circle centred at mid-chord (0.5, 0)
  bool quads = false;             ///< recombine the layer and the rest into quadrilaterals

  /// Number of layers the field builds (the smallest n with h (g^n - 1)/(g - 1) >= thickness).
  [[nodiscard]] int layers() const {
    return static_cast<int>(std::ceil(std::log(1.0 + layer_thickness * (growth - 1.0) / first_height) / std::log(growth)));
  }
};

/// The .geo text: OpenCASCADE interpolating splines through the closed-trailing-edge NACA
/// points (thickness law with -0.1036, as NacaProjection's default), split at mid-chord on
/// both sides so the leading edge lies inside a C2 spline; a BoundaryLayer field with a fan
/// at the trailing edge; physical groups "wall", "farfield", "fluid".
[[nodiscard]] inline std::string naca_geo(const NacaGeo& g) {
  const double pi = std::acos(-1.0);
  const auto half_thickness = [&](double x) {
    const double u = std::sqrt(x);
    return 5.0 * g.thickness * (0.2969 * u - 0.1260 * x - 0.3516 * x * x + 0.2843 * x * x * x - 0.1036 * x * x * x * x);
  };
  const int n = g.points_per_side;
  std::vector<std::pair<double, double>> ring;  // trailing edge, upper side, leading edge, lower side
  for (int k = n; k >= 0; --k) {
    const double x = 0.5 * (1.0 - std::cos(pi * k / n));
    ring.emplace_back(x, half_thickness(x));
  }
  for (int k = 1; k < n; ++k) {
    const double x = 0.5 * (1.0 - std::cos(pi * k / n));
    ring.emplace_back(x, -half_thickness(x));
  }
  const std::size_t upper_mid = static_cast<std::size_t>(n / 2), lower_mid = ring.size() - static_cast<std::size_t>(n / 2);
  std::ostringstream s;
  s.precision(17);
  s << "SetFactory(\"OpenCASCADE\");\n";
  for (std::size_t i = 0; i < ring.size(); ++i) {
    const double size = i == 0 ? g.trailing_edge_size : (i == upper_mid || i == lower_mid) ? g.mid_chord_size : 0.0;
    s << "Point(" << i + 1 << ") = {" << ring[i].first << ", " << ring[i].second << ", 0, " << size << "};\n";
  }
  const auto spline = [&](int tag, std::size_t from, std::size_t to) {  // points from..to, to == size(): back to 1
    s << "Spline(" << tag << ") = {";
    for (std::size_t i = from; i <= to; ++i) s << (i == from ? "" : ", ") << (i % ring.size()) + 1;
    s << "};\n";
  };
  spline(1, 0, upper_mid);
  spline(2, upper_mid, lower_mid);
  spline(3, lower_mid, ring.size());
  s << "Circle(4) = {0.5, 0, 0, " << g.farfield_radius << "};\n"
    << "Curve Loop(1) = {4};\nCurve Loop(2) = {1, 2, 3};\nPlane Surface(1) = {1, 2};\n"
    << "Physical Curve(\"wall\", 1) = {1, 2, 3};\nPhysical Curve(\"farfield\", 2) = {4};\n"
    << "Physical Surface(\"fluid\", 3) = {1};\n"
    << "MeshSize{PointsOf{Curve{4};}} = " << g.farfield_radius / 10.0 << ";\n"
    << "Mesh.MeshSizeFromCurvature = " << g.curvature_points << ";\n"
    << "Field[1] = BoundaryLayer;\nField[1].CurvesList = {1, 2, 3};\nField[1].Size = " << g.first_height
    << ";\nField[1].Ratio = " << g.growth << ";\nField[1].Thickness = " << g.layer_thickness
    << ";\nField[1].Quads = " << (g.quads ? 1 : 0) << ";\nField[1].FanPointsList = {1};\nBoundaryLayer Field = 1;\n";
  if (g.quads) s << "Recombine Surface{1};\n";
  return s.str();
}

}  // namespace bench
