// move_mesh: moves a mesh whose boundary group moves by a rotation, a translation or given
// displacements, and writes the moved mesh (same numbering). Prints time and quality (Knupp
// skew) before and after; --json prints one JSON object instead.
//
//   move_mesh wing.msh -o moved.msh --group wall --rotate 30 --center 0.25,0 --fixed farfield --steps 2
//   move_mesh wing.su2 -o moved.su2 --group wall --displacements wall.txt --method sle --option poisson_ratio=0.4
//
// Exit codes: 0 moved and valid, 1 error (nothing written), 2 written with invalid cells
// (the last line says so) or refused by --strict.

#include "meshmotion/core/json.hpp"
#include "meshmotion/io.hpp"
#include "meshmotion/movers.hpp"
#include "meshmotion/quality.hpp"

#include "mover_arguments.hpp"
#include "program.hpp"

#include <CLI/CLI.hpp>

#include <fstream>
#include <iostream>
#include <sstream>

using namespace meshmotion;

namespace {

struct Arguments {
  std::string input, output, group, displacements_file;
  std::vector<std::string> fixed, sliding;
  std::optional<double> rotate;
  std::optional<std::string> support_radius;
  std::vector<double> center, axis, translate;
  int steps = 1;
  bool json = false, strict = false, overwrite = false, keep_orientation = false;
  examples::MoverArguments mover;
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

// Lines "node dx dy [dz]": the node's id in the mesh file, then its displacement; '#' starts a
// comment. The nodes may come in any order; resolve() checks them against the group.
template <int Dim>
std::pair<std::vector<std::int64_t>, Points<Dim>> read_displacements(const std::string& file) {
  std::ifstream in(file);
  if (!in) throw IoError("move_mesh: cannot open " + file);
  std::vector<std::int64_t> ids;
  std::vector<double> values;
  std::string line;
  std::uint64_t line_number = 0;
  while (std::getline(in, line)) {
    ++line_number;
    if (line_number == 1 && line.starts_with("\xEF\xBB\xBF")) line.erase(0, 3);
    if (const auto hash = line.find('#'); hash != std::string::npos) line.erase(hash);
    std::istringstream s(line);
    std::vector<std::string> fields;
    for (std::string f; s >> f;) fields.push_back(f);
    if (fields.empty()) continue;
    if (static_cast<int>(fields.size()) != Dim + 1)
      throw ParseError(file, line_number,
                       "expected 'node " + std::string(Dim == 2 ? "dx dy" : "dx dy dz") + "' (the node's id in the mesh file, then " +
                           std::to_string(Dim) + " numbers; got " + std::to_string(fields.size()) + " fields)");
    std::int64_t id = 0;
    try {
      parse_option_value("node", fields[0], id);
      for (int d = 0; d < Dim; ++d) {
        double x = 0.0;
        parse_option_value("displacement", fields[static_cast<std::size_t>(d + 1)], x);
        values.push_back(x);
      }
    } catch (const InputError& e) {
      throw ParseError(file, line_number, e.what());
    }
    ids.push_back(id);
  }
  return {ids, Eigen::Map<const Points<Dim>>(values.data(), Dim, static_cast<Index>(ids.size()))};
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
  int order = 1;
  for (const auto& b : mesh.cells) order = std::max(order, meshmotion::order(b.type));
  check_mesh_output(a.output, order);
  examples::handle_orientation(mesh, a.input, a.keep_orientation);
  // Files without physical names: `--group 3` addresses the facets tagged 3.
  name_unnamed_facet_groups(mesh);
  BoundarySpec<Dim> spec;
  if (!a.displacements_file.empty()) {
    auto [ids, d] = read_displacements<Dim>(a.displacements_file);
    spec.moving(a.group, mesh.node_indices(ids), std::move(d));
  } else {
    spec.moving(a.group, motion<Dim>(a));
  }
  for (const auto& g : a.fixed) spec.fixed(g);
  for (const auto& g : a.sliding) spec.sliding(g);

  KeyValues given = examples::given_options(a.mover);
  // DGRBF2 rotates about the centre (and axis) of the rigid motion given here.
  if (a.mover.method == "dgrbf2") {
    if (!a.center.empty()) given.emplace(given.begin(), "center", format_option_value(std::vector<double>(a.center)));
    if (Dim == 3 && !a.axis.empty()) given.emplace(given.begin(), "axis", format_option_value(std::vector<double>(a.axis)));
  }
  MoverConfig<Dim> config = mover_config<Dim>(a.mover.method, given);
  std::optional<double> radius;
  std::visit(
      [&]<class O>(O& o) {
        if constexpr (TakesSupportRadius<O>) {
          if (a.support_radius) {
            parse_option_value("support_radius", *a.support_radius, o.support_radius);
          } else if (std::none_of(given.begin(), given.end(), [](const auto& kv) { return kv.first == "support_radius"; })) {
            const ResolvedBoundary<Dim> b = spec.resolve(mesh);
            Points<Dim> at(Dim, b.size());
            for (Index k = 0; k < b.size(); ++k) at.col(k) = mesh.points.col(b.nodes[static_cast<std::size_t>(k)]);
            o.support_radius = suggest_support_radius(at, b.displacements);
          }
          radius = o.support_radius;
        } else if (a.support_radius) {
          throw InputError("move_mesh: --support-radius: method '" + a.mover.method + "' takes no support radius");
        }
      },
      config.options);
  AnyMover<Dim> mover = make_mover(config);
  const QualityReport before = quality_report(mesh, Metric::skew);
  const StepResult<Dim> result = run_steps(mover, mesh, spec, StepOptions{a.steps, Metric::skew});
  double setup = 0.0, move = 0.0;
  for (const auto& s : result.steps) {
    setup += s.stats.setup_seconds;
    move += s.stats.move_seconds;
  }
  const QualityReport& after = *result.steps.back().quality;
  const bool invalid = after.num_invalid > 0;
  if (invalid && a.strict)
    throw InvalidMeshError("move_mesh: " + std::to_string(after.num_invalid) + " of " + std::to_string(after.num_elements) +
                           " cells invalid after the motion (--strict: nothing written)");
  write_mesh(a.output, result.mesh);
  if (a.json) {
    JsonWriter w(std::cout);
    w.begin_object().key("input").value(a.input).key("output").value(a.output).key("method").value(a.mover.method);
    if (radius) w.key("support_radius").value(*radius);
    w.key("options").begin_object();
    for (const auto& [k, v] : config.values()) w.key(k).value(v);
    w.end_object();
    w.key("steps").value(a.steps).key("nodes").value(mesh.num_nodes());
    w.key("setup_seconds").value(setup).key("move_seconds").value(move);
    w.key("before").begin_object().key("min").value(before.min).key("mean").value(before.mean);
    w.key("invalid").value(before.num_invalid).end_object();
    w.key("after").begin_object().key("min").value(after.min).key("mean").value(after.mean);
    w.key("invalid").value(after.num_invalid).end_object();
    w.end_object();
    std::cout << "\n";
  } else {
    std::cout << "moved " << mesh.num_nodes() << " nodes with " << a.mover.method;
    if (radius) std::cout << " (support radius " << format_option_value(*radius) << ")";
    std::cout << ", " << a.steps << " step(s)\n"
              << "  setup " << setup << " s, move " << move << " s\n"
              << "  skew before: min " << before.min << " mean " << before.mean << " invalid " << before.num_invalid << "\n"
              << "  skew after:  min " << after.min << " mean " << after.mean << " invalid " << after.num_invalid << "\n";
  }
  if (invalid) {
    std::cerr << "wrote " << a.output << " WITH " << after.num_invalid << " INVALID CELLS of " << after.num_elements << "\n";
    return examples::exit_invalid;
  }
  if (!a.json) std::cout << "wrote " << a.output << "\n";
  return examples::exit_ok;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Move a mesh whose boundary group rotates, translates or moves by given displacements"};
  examples::add_version_flag(app);
  Arguments a;
  app.add_option("input", a.input, "Input mesh (.msh, .su2)")->check(CLI::ExistingFile);
  app.add_option("-o,--output", a.output, "Output mesh (.msh, .su2, .vtu)");
  app.add_option("--group", a.group, "Moving boundary group");
  auto* rotate = app.add_option("--rotate", a.rotate, "Rotation angle in degrees");
  app.add_option("--center", a.center, "Rotation centre X,Y[,Z]")->delimiter(',');
  app.add_option("--axis", a.axis, "Rotation axis AX,AY,AZ (3D, default z)")->delimiter(',');
  auto* translate = app.add_option("--translate", a.translate, "Translation DX,DY[,DZ]")->delimiter(',');
  auto* file = app.add_option("--displacements", a.displacements_file,
                              "Text file: lines 'node dx dy [dz]', node = the node's id in the mesh file, any order; "
                              "every node of --group once");
  rotate->excludes(translate)->excludes(file);
  translate->excludes(file);
  app.add_option("--fixed", a.fixed, "Fixed groups");
  app.add_option("--sliding", a.sliding, "Groups sliding in their plane");
  examples::add_mover_options(app, a.mover, "");
  app.add_option("--support-radius", a.support_radius, "support radius of rbf (default: heuristic from the boundary)");
  app.add_option("--steps", a.steps, "Number of steps")->check(CLI::PositiveNumber);
  app.add_flag("--strict", a.strict, "write nothing when invalid cells remain (exit 2)");
  app.add_flag("--overwrite", a.overwrite, "allow the output to be the input file");
  app.add_flag("--keep-orientation", a.keep_orientation,
               "refuse a mesh whose cells are all negatively oriented instead of reorienting it");
  app.add_flag("--json", a.json, "Print one JSON object");
  CLI11_PARSE(app, argc, argv);
  return examples::guarded(a.json, [&] {
    if (examples::list_options<2>(a.mover)) return examples::exit_ok;
    if (a.input.empty() || a.output.empty() || a.group.empty())
      throw InputError("move_mesh: give an input mesh, -o OUTPUT and --group GROUP (see --help)");
    if (!a.rotate && a.translate.empty() && a.displacements_file.empty())
      throw InputError("move_mesh: give one of --rotate, --translate, --displacements");
    examples::check_output(a.input, a.output, 1, a.overwrite);
    return std::visit([&](auto& mesh) { return run(a, std::move(mesh)); }, *std::make_unique<AnyMesh>(read_mesh(a.input)));
  });
}
