// move_mesh: moves a mesh whose boundary group moves by a rotation, a translation or given
// displacements, and writes the moved mesh (same numbering). Prints time and quality (Knupp
// skew) before and after; --json prints one JSON object instead.
//
//   move_mesh wing.msh -o moved.msh --group wall --rotate 30 --center 0.25,0 --fixed farfield --steps 2
//   move_mesh wing.su2 -o moved.su2 --group wall --displacements wall.txt --method sle --option poisson_ratio=0.4
//
// Exit codes: 0 moved and valid, 1 error (nothing written), 2 written with invalid cells
// (the last line says so) or refused by --strict.

#include "meshmotion/core/extrusion.hpp"
#include "meshmotion/core/fields.hpp"
#include "meshmotion/io.hpp"
#include "meshmotion/movers/registry.hpp"
#include "meshmotion/movers/step_driver.hpp"
#include "meshmotion/movers/section_mover.hpp"
#include "meshmotion/quality.hpp"

#include "motion_arguments.hpp"
#include "mover_arguments.hpp"
#include "program.hpp"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

using namespace meshmotion;

namespace {

struct Arguments {
  std::string input, output;
  examples::MotionArguments motion;
  int steps = 1;
  bool json = false, strict = false, overwrite = false, keep_orientation = false, keep_3d = false;
  examples::MoverArguments mover;
  examples::FoamSelection foam;
};

// A method whose options take a rotation's centre (and axis), as DGRBF2's do, rotates about
// those of the rigid motion given here: in the section's coordinates when a 2D case stored in
// 3D moves as its section.
template <int MoverDim>
KeyValues mover_options(const Arguments& a, const examples::MotionArguments& motion, const Extrusion* section) {
  KeyValues given = examples::given_options(a.mover);
  const std::vector<std::string> keys = mover_config<MoverDim>(a.mover.method).keys();
  if (std::find(keys.begin(), keys.end(), "center") == keys.end()) return given;
  std::vector<double> center = motion.center;
  if (section != nullptr && center.size() == 3) {
    const Vec<2> uv = section->project(Vec<3>(center[0], center[1], center[2]));
    center = {uv(0), uv(1)};
  }
  if (!center.empty()) given.emplace(given.begin(), "center", format_option_value(center));
  if (MoverDim == 3 && !motion.axis.empty()) given.emplace(given.begin(), "axis", format_option_value(motion.axis));
  return given;
}

// `section`: the extrusion of a 2D case stored in 3D, moved as its section, and the section's
// boundary; null to move the mesh in its own dimension.
template <int Dim>
int move_and_write(const Arguments& a, const Mesh<Dim>& mesh, const examples::MotionArguments& motion,
                   const BoundarySpec<Dim>& spec, const std::pair<Extrusion, SectionBoundary>* section) {
  KeyValues values;
  const auto make = [&]<int MoverDim>() {
    const MoverConfig<MoverDim> config =
        mover_config<MoverDim>(a.mover.method, mover_options<MoverDim>(a, motion, section != nullptr ? &section->first : nullptr));
    for (const auto& kv : config.values()) values.emplace_back(kv);
    return make_mover(config);
  };
  std::optional<AnyMover<Dim>> mover;
  if constexpr (Dim == 3) {
    if (section != nullptr) mover.emplace(SectionMover(make.template operator()<2>(), section->first));
  }
  if (!mover) mover.emplace(make.template operator()<Dim>());
  examples::set_stage("moving " + a.input + " with " + a.mover.method);
  const QualityReport before = quality_report(mesh, Metric::skew);
  const StepResult<Dim> result = run_steps(*mover, mesh, spec, StepOptions{a.steps, Metric::skew});
  // What the mover chose (the default radius, the rigid part), as the last setup took it.
  const MoverStats& chosen = result.steps.back().stats;
  examples::note_mover_choices(chosen);
  const double radius = chosen.support_radius;  // 0: the method has none
  const MoveReport report = move_report(a.mover.method, before, result);
  const QualityReport& after = report.after;
  const examples::MovedVerdict verdict = examples::moved_verdict(result.mesh, after, a.input);
  const std::optional<FoamQuality>& foam_after = verdict.foam;
  const Index invalid_cells = verdict.invalid, cells = verdict.cells;
  const bool invalid = invalid_cells > 0;
  if (invalid && a.strict)
    throw InvalidMeshError("move_mesh: " + std::to_string(invalid_cells) + " of " + std::to_string(cells) +
                           " cells invalid after the motion (--strict: nothing written)");
  examples::write_output(a.output, result.mesh, a.input);
  if (a.json) {
    JsonWriter w(std::cout);
    w.begin_object().key("input").value(a.input).key("output").value(a.output);
    if (radius > 0.0) w.key("support_radius").value(radius);
    if (section != nullptr) w.key("section_axis").value(std::string(1, section->first.axis_name()));
    w.key("options").begin_object();
    for (const auto& [k, v] : values) w.key(k).value(v);
    w.end_object();
    write_json_fields(w, report);
    if (foam_after) {
      w.key("checkmesh_after");
      write_json(w, *foam_after);
    }
    w.end_object();
    std::cout << "\n";
  } else {
    std::cout << "moved " << mesh.num_nodes() << " nodes with " << a.mover.method;
    if (radius > 0.0) std::cout << " (support radius " << format_option_value(radius) << ")";
    if (section != nullptr)
      std::cout << " as a 2D case: one cell thick along " << section->first.axis_name() << ", moved in its section (--keep-3d moves it in 3D)";
    std::cout << "\n";
    write_text(std::cout, report, 2);
    if (foam_after) {
      std::cout << "  the case's own cells (checkMesh's measures; the validity verdict):\n";
      write_text(std::cout, *foam_after, 4);
    }
  }
  if (invalid) {
    std::cerr << "wrote " << a.output << " WITH " << invalid_cells << " INVALID CELLS of " << cells << "\n";
    return examples::exit_invalid;
  }
  if (!a.json) std::cout << "wrote " << a.output << "\n";
  return examples::exit_ok;
}

template <int Dim>
int run(const Arguments& a, Mesh<Dim> mesh) {
  int order = 1;
  for (const auto& b : mesh.cells) order = std::max(order, meshmotion::order(b.type));
  check_mesh_output(a.output, order);
  examples::handle_orientation(mesh, a.input, a.keep_orientation);
  // Files without physical names: `--group 3` addresses the facets tagged 3.
  name_unnamed_facet_groups(mesh);
  if constexpr (Dim == 3) {
    // A 2D case stored in 3D moves as its section, so that every method keeps it 2D; a motion
    // that is not in its plane moves it in 3D.
    if (std::optional<Extrusion> section = a.keep_3d ? std::nullopt : find_extrusion(mesh)) {
      const examples::MotionArguments motion = examples::section_motion(a.motion, *section);
      const BoundarySpec<3> spec = examples::boundary_spec<3>(motion, mesh);
      const ResolvedBoundary<3> resolved = spec.resolve(mesh);
      std::optional<std::pair<Extrusion, SectionBoundary>> planar;
      try {
        SectionBoundary boundary = section_boundary(*section, mesh, resolved);
        planar.emplace(std::move(*section), std::move(boundary));
      } catch (const NotTwoDimensional& e) {
        std::cerr << "note: moving in 3D: " << std::string(e.what()).substr(std::string_view("meshmotion: ").size()) << "\n";
      }
      examples::note_unlisted_groups(mesh, resolved, planar ? planar->first.plane_groups : std::vector<std::string>{});
      return move_and_write<3>(a, mesh, motion, spec, planar ? &*planar : nullptr);
    }
  }
  const BoundarySpec<Dim> spec = examples::boundary_spec<Dim>(a.motion, mesh);
  examples::note_unlisted_groups(mesh, spec.resolve(mesh));
  return move_and_write<Dim>(a, mesh, a.motion, spec, nullptr);
}

}  // namespace

int main(int argc, char** argv) {
  meshmotion::tune_process_memory(argc, argv);  // may restart the program once (core/process_memory.hpp)
  CLI::App app{"Move a mesh whose boundary group rotates, translates or moves by given displacements"};
  examples::add_version_flag(app);
  Arguments a;
  app.add_option("input", a.input, "Input mesh (.msh, .su2, .cgns, .vtu) or OpenFOAM case folder")->check(CLI::ExistingPath);
  app.add_option("-o,--output", a.output, "Output mesh (.msh, .su2, .cgns, .vtu), or an OpenFOAM case (its points replaced; give --overwrite when it is the input) or a time folder of it (case/0.001: its polyMesh/points), or a new folder (a new case: the input case's cells, patches and zones, moved)");
  examples::add_motion_options(app, a.motion);
  examples::add_mover_options(app, a.mover, known_methods<3>());
  // More steps than this is a typing slip, not a motion: it would run for days.
  app.add_option("--steps", a.steps, "Number of steps (1 to 100000)")->check(CLI::Range(1, 100000));
  app.add_flag("--strict", a.strict, "write nothing when invalid cells remain (exit 2)");
  app.add_flag("--overwrite", a.overwrite, "allow the output to be the input file");
  app.add_flag("--keep-orientation", a.keep_orientation,
               "refuse a mesh whose cells are all negatively oriented instead of reorienting it");
  app.add_flag("--keep-3d", a.keep_3d,
               "move a mesh one cell thick between two planes (a 2D case stored in 3D) in 3D, not as its 2D section");
  app.add_flag("--json", a.json, "Print one JSON object");
  examples::add_foam_options(app, a.foam);
  if (const auto rc = meshmotion::examples::parse_command_line(app, argc, argv)) return *rc;
  return examples::guarded(a.json, [&] {
    if (examples::list_options<2>(a.mover)) return examples::exit_ok;
    if (a.input.empty() || a.output.empty()) throw InputError("move_mesh: give an input mesh and -o OUTPUT (see --help)");
    examples::require_motion(a.motion, "move_mesh");
    a.input = examples::foam_input(a.input, a.foam).string();
    a.output = examples::foam_output(a.output, a.foam).string();
    examples::check_output(a.input, a.output, 1, a.overwrite);
    return std::visit([&](auto& mesh) { return run(a, std::move(mesh)); }, *std::make_unique<AnyMesh>(examples::read_input(a.input)));
  });
}
