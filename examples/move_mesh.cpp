// move_mesh: moves a mesh whose boundary group moves by a rotation, a translation or given
// displacements, and writes the moved mesh (same numbering). Prints time and quality (Knupp
// skew) before and after; --json prints one JSON object instead.
//
//   move_mesh wing.msh -o moved.msh --group wall --rotate 30 --center 0.25,0 --fixed farfield --steps 2

#include "meshmotion/io.hpp"
#include "meshmotion/movers.hpp"
#include "meshmotion/quality.hpp"

#include "mechanics_arguments.hpp"

#include <CLI/CLI.hpp>

#include <chrono>
#include <fstream>
#include <iostream>
#include <sstream>

using namespace meshmotion;

namespace {

struct Arguments {
  std::string input, output, group, displacements_file, method = "rbf", kernel = "wendland2";
  std::vector<std::string> fixed, sliding;
  std::optional<double> rotate, support_radius;
  std::vector<double> center, axis, translate;
  int steps = 1;
  bool json = false;
  examples::MechanicsArguments mechanics;
};

template <int Dim>
Vec<Dim> vec(const std::vector<double>& v, const char* what) {
  if (static_cast<int>(v.size()) != Dim)
    throw InputError(std::string("move_mesh: --") + what + " needs " + std::to_string(Dim) + " comma-separated values (got " +
                     std::to_string(v.size()) + ")");
  Vec<Dim> out;
  for (int d = 0; d < Dim; ++d) out[d] = v[static_cast<std::size_t>(d)];
  return out;
}

template <int Dim>
Points<Dim> read_displacements(const std::string& file, Index expected) {
  std::ifstream in(file);
  if (!in) throw IoError("move_mesh: cannot open " + file);
  std::vector<double> values;
  std::string line;
  int line_number = 0;
  while (std::getline(in, line)) {
    ++line_number;
    std::istringstream s(line);
    double x = 0.0;
    int count = 0;
    while (s >> x) {
      values.push_back(x);
      ++count;
    }
    if (count != 0 && count != Dim)
      throw ParseError(file, static_cast<std::uint64_t>(line_number), "expected " + std::to_string(Dim) + " numbers (got " + std::to_string(count) + ")");
  }
  const auto n = static_cast<Index>(values.size()) / Dim;
  if (n != expected)
    throw InputError("move_mesh: " + file + " has " + std::to_string(n) + " displacements (expected " + std::to_string(expected) +
                     ", one per node of the group in increasing node order)");
  return Eigen::Map<const Points<Dim>>(values.data(), Dim, n);
}

template <int Dim>
Motion<Dim> motion(const Arguments& a) {
  if (!a.translate.empty()) return Translation<Dim>{vec<Dim>(a.translate, "translate")};
  const double angle = radians(*a.rotate);
  const Vec<Dim> c = a.center.empty() ? Vec<Dim>::Zero() : vec<Dim>(a.center, "center");
  if constexpr (Dim == 2) {
    return Rotation2D{c, angle};
  } else {
    return Rotation3D{c, a.axis.empty() ? Vec<3>::UnitZ() : vec<3>(a.axis, "axis"), angle};
  }
}

template <int Dim>
int run(const Arguments& a, Mesh<Dim> mesh) {
  // Files without physical names: `--group 3` addresses the facets tagged 3.
  name_unnamed_facet_groups(mesh);
  BoundarySpec<Dim> spec;
  if (!a.displacements_file.empty())
    spec.moving(a.group, read_displacements<Dim>(a.displacements_file, static_cast<Index>(mesh.group_nodes(a.group).size())));
  else
    spec.moving(a.group, motion<Dim>(a));
  for (const auto& g : a.fixed) spec.fixed(g);
  for (const auto& g : a.sliding) spec.sliding(g);

  MoverParameters parameters;
  parameters.values["kernel"] = a.kernel;
  // DGRBF2 rotates about the centre (and axis) of the rigid motion given here.
  const auto joined = [](const std::vector<double>& v) {
    std::ostringstream text;
    text.precision(17);
    for (std::size_t k = 0; k < v.size(); ++k) text << (k ? "," : "") << v[k];
    return text.str();
  };
  if (!a.center.empty()) parameters.values["center"] = joined(a.center);
  if (!a.axis.empty()) parameters.values["axis"] = joined(a.axis);
  examples::add_mechanics_parameters(a.mechanics, parameters);
  if (a.support_radius) {
    parameters.values["support_radius"] = std::to_string(*a.support_radius);
  } else {
    const ResolvedBoundary<Dim> b = spec.resolve(mesh);
    Points<Dim> at(Dim, b.size());
    for (Index k = 0; k < b.size(); ++k) at.col(k) = mesh.points.col(b.nodes[static_cast<std::size_t>(k)]);
    parameters.values["support_radius"] = std::to_string(suggest_support_radius(at, b.displacements));
  }
  AnyMover<Dim> mover = make_mover<Dim>(a.method, parameters);
  const QualityReport before = quality_report(mesh, Metric::skew);
  const StepResult<Dim> result = run_steps(mover, mesh, spec, StepOptions{a.steps, Metric::skew});
  double setup = 0.0, move = 0.0;
  for (const auto& s : result.steps) {
    setup += s.stats.setup_seconds;
    move += s.stats.move_seconds;
  }
  const QualityReport& after = *result.steps.back().quality;
  write_mesh(a.output, result.mesh);
  if (a.json) {
    std::cout << "{\"input\":\"" << a.input << "\",\"output\":\"" << a.output << "\",\"method\":\"" << a.method
              << "\",\"support_radius\":" << parameters.values["support_radius"] << ",\"steps\":" << a.steps
              << ",\"nodes\":" << mesh.num_nodes() << ",\"setup_seconds\":" << setup << ",\"move_seconds\":" << move
              << ",\"before\":{\"min\":" << before.min << ",\"mean\":" << before.mean << ",\"invalid\":" << before.num_invalid
              << "},\"after\":{\"min\":" << after.min << ",\"mean\":" << after.mean << ",\"invalid\":" << after.num_invalid
              << "}}\n";
  } else {
    std::cout << "moved " << mesh.num_nodes() << " nodes with " << a.method << " (support radius "
              << parameters.values["support_radius"] << ", " << a.steps << " step(s))\n"
              << "  setup " << setup << " s, move " << move << " s\n"
              << "  skew before: min " << before.min << " mean " << before.mean << " invalid " << before.num_invalid << "\n"
              << "  skew after:  min " << after.min << " mean " << after.mean << " invalid " << after.num_invalid << "\n"
              << "  wrote " << a.output << "\n";
  }
  return after.num_invalid == 0 ? 0 : 2;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Move a mesh whose boundary group rotates, translates or moves by given displacements"};
  Arguments a;
  app.add_option("input", a.input, "Input mesh (.msh, .su2)")->required()->check(CLI::ExistingFile);
  app.add_option("-o,--output", a.output, "Output mesh (.msh, .su2, .vtu)")->required();
  app.add_option("--group", a.group, "Moving boundary group")->required();
  auto* rotate = app.add_option("--rotate", a.rotate, "Rotation angle in degrees");
  app.add_option("--center", a.center, "Rotation centre X,Y[,Z]")->delimiter(',');
  app.add_option("--axis", a.axis, "Rotation axis AX,AY,AZ (3D, default z)")->delimiter(',');
  auto* translate = app.add_option("--translate", a.translate, "Translation DX,DY[,DZ]")->delimiter(',');
  auto* file = app.add_option("--displacements", a.displacements_file,
                              "Text file: one displacement per line for the group's nodes in increasing node order");
  rotate->excludes(translate)->excludes(file);
  translate->excludes(file);
  app.add_option("--fixed", a.fixed, "Fixed groups");
  app.add_option("--sliding", a.sliding, "Groups sliding in their plane");
  app.add_option("--method", a.method, "Mover: rbf|dgm|idgm|dgrbf|dgrbf2|spring|torsion|le|sle|nle");
  app.add_option("--kernel", a.kernel, "RBF kernel: wendland0|wendland2|wendland4|wendland6|tps|gaussian|multiquadric|inverse_multiquadric");
  app.add_option("--support-radius", a.support_radius, "RBF support radius (default: heuristic from the boundary)");
  app.add_option("--steps", a.steps, "Number of steps")->check(CLI::PositiveNumber);
  examples::add_mechanics_options(app, a.mechanics);
  app.add_flag("--json", a.json, "Print one JSON object");
  CLI11_PARSE(app, argc, argv);
  try {
    if (!a.rotate && a.translate.empty() && a.displacements_file.empty())
      throw InputError("move_mesh: give one of --rotate, --translate, --displacements");
    return std::visit([&](auto& mesh) { return run(a, std::move(mesh)); }, *std::make_unique<AnyMesh>(read_mesh(a.input)));
  } catch (const Error& e) {
    std::cerr << e.what() << "\n";
    return 1;
  }
}
