#pragma once
// The boundary motion options move_mesh and move_mesh_mpi share: the moving group and its
// rotation, translation or displacement file, and the fixed and sliding groups. The mover
// chooses what is not given (the support radius, the rigid part); the programs report it.

#include "meshmotion/core/extrusion.hpp"
#include "meshmotion/core/option_text.hpp"
#include "meshmotion/io/detail/read_file.hpp"
#include "meshmotion/movers/boundary.hpp"
#include "meshmotion/movers/motion.hpp"
#include "meshmotion/movers/mover.hpp"
#include "meshmotion/io/openfoam.hpp"
#include "meshmotion/quality/foam_quality.hpp"
#include "meshmotion/quality/quality_report.hpp"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <iostream>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace meshmotion::examples {

struct MotionArguments {
  std::string group, displacements_file;
  std::vector<std::string> fixed, sliding;
  std::optional<double> rotate;
  std::vector<double> center, axis, translate;
};

inline void add_motion_options(CLI::App& app, MotionArguments& a) {
  app.add_option("--group", a.group, "Moving boundary group");
  auto* rotate = app.add_option("--rotate", a.rotate, "Rotation angle in degrees");
  app.add_option("--center", a.center, "Rotation centre X,Y[,Z]")->delimiter(',');
  app.add_option("--axis", a.axis, "Rotation axis AX,AY,AZ (3D, default z)")->delimiter(',');
  auto* translate = app.add_option("--translate", a.translate, "Translation DX,DY[,DZ]")->delimiter(',');
  auto* file = app.add_option("--displacements", a.displacements_file,
                              "Text file: lines 'node dx dy [dz]', node = the node's id as the mesh file numbers it (from 0 in "
                              ".su2, .vtu and OpenFOAM cases, the file's ids in .msh, from 1 in .cgns), any order; every node of "
                              "--group once");
  rotate->excludes(translate)->excludes(file);
  translate->excludes(file);
  app.add_option("--fixed", a.fixed, "Fixed groups");
  app.add_option("--sliding", a.sliding,
                 "Groups sliding in their plane; NAME:NX,NY[,NZ] gives the plane's normal (each node slides in its own "
                 "plane of that normal: an OpenFOAM 'empty' patch holding the front and the back of a 2D case)");
}

/// Throws InputError unless a group and one motion are given.
inline void require_motion(const MotionArguments& a, const std::string& program) {
  if (a.group.empty()) throw InputError(program + ": give --group GROUP (see --help)");
  if (!a.rotate && a.translate.empty() && a.displacements_file.empty())
    throw InputError(program + ": give one of --rotate, --translate, --displacements");
}

template <int Dim>
Vec<Dim> vec(const std::vector<double>& v, const char* what) {
  if (static_cast<int>(v.size()) != Dim)
    throw InputError(std::string("--") + what + " needs " + std::to_string(Dim) + " comma-separated values (got " +
                     std::to_string(v.size()) + ")");
  Vec<Dim> out;
  for (int d = 0; d < Dim; ++d) out[d] = v[static_cast<std::size_t>(d)];
  return out;
}

// Lines "node dx dy [dz]": the node's id in the mesh file, then its displacement; '#' starts a
// comment. The nodes may come in any order; resolve() checks them against the group.
template <int Dim>
std::pair<std::vector<std::int64_t>, Points<Dim>> read_displacements(const std::string& file) {
  // Read whole and bounded by the file's size: a device or pipe given by mistake is refused.
  std::istringstream in(detail::read_whole_file(file));
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
Motion<Dim> motion(const MotionArguments& a) {
  if (!a.translate.empty()) return Translation<Dim>{vec<Dim>(a.translate, "translate")};
  const double angle = radians(*a.rotate);
  const Vec<Dim> c = a.center.empty() ? Vec<Dim>::Zero() : vec<Dim>(a.center, "center");
  if constexpr (Dim == 2) {
    if (!a.axis.empty()) throw InputError("--axis: a 2D mesh rotates in its plane (give --axis with a 3D mesh only)");
    return Rotation2D{c, angle};
  } else {
    return Rotation3D{c, a.axis.empty() ? Vec<3>::UnitZ() : vec<3>(a.axis, "axis"), angle};
  }
}

/// A --sliding entry: the group's name and, after its last ':', the normal when one is given
/// ("defaultFaces:0,0,1"). A name holding ':' with no normal after it stays whole.
template <int Dim>
std::pair<std::string, std::optional<Vec<Dim>>> sliding_entry(const std::string& entry) {
  const auto colon = entry.rfind(':');
  if (colon == std::string::npos) return {entry, std::nullopt};
  const std::string tail = entry.substr(colon + 1);
  if (tail.empty() || tail.find_first_not_of("0123456789+-.eE,") != std::string::npos) return {entry, std::nullopt};
  std::vector<double> normal;
  std::istringstream in(tail);
  for (std::string field; std::getline(in, field, ',');) {
    double x = 0.0;
    parse_option_value("--sliding " + entry.substr(0, colon) + " normal", field, x);
    normal.push_back(x);
  }
  return {entry.substr(0, colon), vec<Dim>(normal, "sliding NAME:normal")};
}

/// The arguments for a 2D case stored in 3D (`ext`), in 3D: a centre X,Y and a translation
/// DX,DY in the section's coordinates (x, y for a case one cell thick along z), the rotation
/// about the axis when none is given, and a group holding the front and the back sliding in
/// planes normal to the axis when no normal is given.
inline MotionArguments section_motion(MotionArguments a, const Extrusion& ext) {
  const auto lift = [&](std::vector<double>& v, double along) {
    if (v.size() != 2) return;
    Vec<3> x = ext.lift(Vec<2>(v[0], v[1]));
    x(ext.axis) = along;
    v.assign(x.data(), x.data() + 3);
  };
  lift(a.center, ext.front);
  lift(a.translate, 0.0);
  if (a.rotate && a.axis.empty()) {
    a.axis.assign(3, 0.0);
    a.axis[static_cast<std::size_t>(ext.axis)] = 1.0;
  }
  for (auto& entry : a.sliding)
    if (!sliding_entry<3>(entry).second &&
        std::find(ext.plane_groups.begin(), ext.plane_groups.end(), entry) != ext.plane_groups.end())
      entry += ext.axis == 0 ? ":1,0,0" : ext.axis == 1 ? ":0,1,0" : ":0,0,1";
  return a;
}

/// Says on stderr which facet groups no condition reaches (their nodes move with the interior,
/// as a patch a solver's case leaves out would not): OpenFOAM fixes a patch it is not told to
/// move, move_mesh lets it deform, so the user must see it. `excluded`: groups that are meant
/// to be free (a 2D case's front and back, moved as its section).
template <int Dim>
void note_unlisted_groups(const Mesh<Dim>& mesh, const ResolvedBoundary<Dim>& boundary, const std::vector<std::string>& excluded = {}) {
  std::vector<char> constrained(static_cast<std::size_t>(mesh.num_nodes()), 0);
  for (const Index v : boundary.nodes) constrained[static_cast<std::size_t>(v)] = 1;
  for (const PhysicalGroup& g : mesh.groups) {
    if (g.dim != Dim - 1 || std::find(excluded.begin(), excluded.end(), g.name) != excluded.end()) continue;
    const std::vector<Index> nodes = mesh.group_nodes(g.tag, g.dim);
    const auto free = std::count_if(nodes.begin(), nodes.end(), [&](Index v) { return constrained[static_cast<std::size_t>(v)] == 0; });
    if (free > 0)
      std::cerr << "note: group '" << g.name << "' has no condition: " << free << " of its " << nodes.size()
                << " nodes move with the interior (give --fixed " << g.name << " or --sliding " << g.name << " to keep it)\n";
  }
}

/// The boundary conditions the arguments give, on `mesh`.
template <int Dim>
BoundarySpec<Dim> boundary_spec(const MotionArguments& a, const Mesh<Dim>& mesh) {
  BoundarySpec<Dim> spec;
  if (!a.displacements_file.empty()) {
    auto [ids, d] = read_displacements<Dim>(a.displacements_file);
    spec.moving(a.group, mesh.node_indices(ids), std::move(d));
  } else {
    spec.moving(a.group, motion<Dim>(a));
  }
  for (const auto& g : a.fixed) spec.fixed(g);
  for (const auto& entry : a.sliding) {
    auto [group, normal] = sliding_entry<Dim>(entry);
    spec.sliding(std::move(group), normal);
  }
  for (const auto& o : spec.overlaps(mesh))
    std::cerr << "note: " << o.nodes << " node" << (o.nodes == 1 ? "" : "s") << " of '" << o.winner << "' (" << name(o.winner_kind)
              << ") " << (o.nodes == 1 ? "is" : "are") << " also in '" << o.other << "' (" << name(o.other_kind) << "): "
              << name(o.winner_kind) << " wins (prescribed over fixed over sliding)\n";
  return spec;
}

/// The verdict on a moved mesh: its cells, and how many are invalid. A polyhedral OpenFOAM
/// case (`input` a case folder whose cells were cut around centres) is judged as checkMesh
/// judges it, on its own cells (`foam`): the tetrahedra they were cut into are the library's,
/// and one of them may fold inside a cell that OpenFOAM finds sound (a triangle of a warped
/// face). Any other mesh by `after` (certified for high-order cells).
struct MovedVerdict {
  Index cells = 0, invalid = 0;
  std::optional<FoamQuality> foam;
};

template <int Dim>
[[nodiscard]] MovedVerdict moved_verdict(const Mesh<Dim>& moved, const QualityReport& after, const std::filesystem::path& input) {
  MovedVerdict out{after.num_elements, after.num_invalid, std::nullopt};
  if constexpr (Dim == 3) {
    std::error_code ec;
    if (moved.num_auxiliary_nodes > 0 && std::filesystem::is_directory(input, ec)) {
      PolyMesh poly = read_polymesh(input);
      poly.points = moved.points.leftCols(poly.points.cols());
      out.foam = foam_quality(poly);
      out.invalid = out.foam->num_invalid_cells;
      out.cells = poly.num_cells;
    }
  }
  return out;
}

/// Says on stderr what the mover chose that changes what a user gets: the rigid part taken
/// out, a default radius cut to the memory budget.
inline void note_mover_choices(const MoverStats& stats) {
  if (stats.rigid_part)
    std::cerr << "note: the moving group's rigid motion is blended into the volume and the RBF carries the rest "
                 "(rigid_part; rigid_part=none interpolates it all; docs/interpolation.md)\n";
  else if (stats.radius_reduced)
    std::cerr << "note: support radius reduced to " << format_option_value(stats.support_radius)
              << " to keep the system and the evaluation operator within the memory budget "
                 "(max_memory_bytes; docs/interpolation.md)\n";
}

}  // namespace meshmotion::examples
