// move_mesh: moves a mesh whose boundary group moves by a rotation, a translation or given
// displacements, and writes the moved mesh (same numbering). Prints time and quality (Knupp
// skew) before and after; --json prints one JSON object instead.
//
//   move_mesh wing.msh -o moved.msh --group wall --rotate 30 --center 0.25,0 --fixed farfield --steps 2
//   move_mesh wing.su2 -o moved.su2 --group wall --displacements wall.txt --method sle --option poisson_ratio=0.4
//
// Exit codes: 0 moved and valid, 1 error (nothing written), 2 written with invalid cells
// (the last line says so) or refused by --strict.

#include "meshmotion/core/fields.hpp"
#include "meshmotion/io.hpp"
#include "meshmotion/movers.hpp"
#include "meshmotion/quality.hpp"

#include "motion_arguments.hpp"
#include "mover_arguments.hpp"
#include "program.hpp"

#include <CLI/CLI.hpp>

#include <iostream>

using namespace meshmotion;

namespace {

struct Arguments {
  std::string input, output;
  examples::MotionArguments motion;
  int steps = 1;
  bool json = false, strict = false, overwrite = false, keep_orientation = false;
  examples::MoverArguments mover;
};

template <int Dim>
int run(const Arguments& a, Mesh<Dim> mesh) {
  int order = 1;
  for (const auto& b : mesh.cells) order = std::max(order, meshmotion::order(b.type));
  check_mesh_output(a.output, order);
  examples::handle_orientation(mesh, a.input, a.keep_orientation);
  // Files without physical names: `--group 3` addresses the facets tagged 3.
  name_unnamed_facet_groups(mesh);
  const BoundarySpec<Dim> spec = examples::boundary_spec<Dim>(a.motion, mesh);
  KeyValues given = examples::given_options(a.mover);
  // DGRBF2 rotates about the centre (and axis) of the rigid motion given here.
  if (a.mover.method == "dgrbf2") {
    if (!a.motion.center.empty()) given.emplace(given.begin(), "center", format_option_value(std::vector<double>(a.motion.center)));
    if (Dim == 3 && !a.motion.axis.empty())
      given.emplace(given.begin(), "axis", format_option_value(std::vector<double>(a.motion.axis)));
  }
  MoverConfig<Dim> config = mover_config<Dim>(a.mover.method, given);
  const std::optional<double> radius = examples::set_support_radius(config, a.motion, given, spec, mesh);
  AnyMover<Dim> mover = make_mover(config);
  examples::set_stage("moving " + a.input + " with " + a.mover.method);
  const QualityReport before = quality_report(mesh, Metric::skew);
  const StepResult<Dim> result = run_steps(mover, mesh, spec, StepOptions{a.steps, Metric::skew});
  const MoveReport report = move_report(a.mover.method, before, result);
  const QualityReport& after = report.after;
  const bool invalid = after.num_invalid > 0;
  if (invalid && a.strict)
    throw InvalidMeshError("move_mesh: " + std::to_string(after.num_invalid) + " of " + std::to_string(after.num_elements) +
                           " cells invalid after the motion (--strict: nothing written)");
  examples::write_output(a.output, result.mesh);
  if (a.json) {
    JsonWriter w(std::cout);
    w.begin_object().key("input").value(a.input).key("output").value(a.output);
    if (radius) w.key("support_radius").value(*radius);
    w.key("options").begin_object();
    for (const auto& [k, v] : config.values()) w.key(k).value(v);
    w.end_object();
    write_json_fields(w, report);
    w.end_object();
    std::cout << "\n";
  } else {
    std::cout << "moved " << mesh.num_nodes() << " nodes with " << a.mover.method;
    if (radius) std::cout << " (support radius " << format_option_value(*radius) << ")";
    std::cout << "\n";
    write_text(std::cout, report, 2);
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
  meshmotion::tune_process_memory(argc, argv);  // may restart the program once (core/process_memory.hpp)
  CLI::App app{"Move a mesh whose boundary group rotates, translates or moves by given displacements"};
  examples::add_version_flag(app);
  Arguments a;
  app.add_option("input", a.input, "Input mesh (.msh, .su2, .cgns, .vtu) or OpenFOAM case folder")->check(CLI::ExistingPath);
  app.add_option("-o,--output", a.output, "Output mesh (.msh, .su2, .cgns, .vtu), or an OpenFOAM case (its points replaced; give --overwrite when it is the input) or a time folder of it (case/0.001: its polyMesh/points)");
  examples::add_motion_options(app, a.motion);
  examples::add_mover_options(app, a.mover, known_methods<3>());
  // More steps than this is a typing slip, not a motion: it would run for days.
  app.add_option("--steps", a.steps, "Number of steps (1 to 100000)")->check(CLI::Range(1, 100000));
  app.add_flag("--strict", a.strict, "write nothing when invalid cells remain (exit 2)");
  app.add_flag("--overwrite", a.overwrite, "allow the output to be the input file");
  app.add_flag("--keep-orientation", a.keep_orientation,
               "refuse a mesh whose cells are all negatively oriented instead of reorienting it");
  app.add_flag("--json", a.json, "Print one JSON object");
  if (const auto rc = meshmotion::examples::parse_command_line(app, argc, argv)) return *rc;
  return examples::guarded(a.json, [&] {
    if (examples::list_options<2>(a.mover)) return examples::exit_ok;
    if (a.input.empty() || a.output.empty()) throw InputError("move_mesh: give an input mesh and -o OUTPUT (see --help)");
    examples::require_motion(a.motion, "move_mesh");
    examples::check_output(a.input, a.output, 1, a.overwrite);
    return std::visit([&](auto& mesh) { return run(a, std::move(mesh)); }, *std::make_unique<AnyMesh>(examples::read_input(a.input)));
  });
}
