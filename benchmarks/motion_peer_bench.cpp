// Mesh-motion peer comparisons, driven by benchmarks/openfoam_peer.sh and
// benchmarks/dense_rbf_peer.sh (which install and run the peers): this program exports each
// case to the peer, reads the peer's moved mesh back in our node order, runs our movers on
// the same displacement, judges every result with our quality layer (Knupp skew and scaled
// Jacobian) and prints a table and one JSON line per row.
//
//   motion_peer_bench foam-export CASE DIR [FROM_CASE] OpenFOAM polyMesh (2D cases extruded one
//                                                      cell thick) and 0/pointDisplacement
//                                                      (minus FROM_CASE's: one step of a motion)
//   motion_peer_bench foam-judge CASE DIR SECONDS [ITERATIONS]
//                                                      DIR/1/polyMesh/points vs our movers
//   motion_peer_bench rbf-export CASE DIR              points, centres, values (raw float64)
//   motion_peer_bench rbf-judge CASE DIR               DIR/scipy_<kernel>.f64 (+ .seconds) vs
//                                                      dense Eigen RBF vs our compact k-d tree RBF
//
// CASE: bump (the SU2 deforming bump channel; `interface` rises by A sin²(π s), A = 0.05,
// s ∈ [0, 1] along x, every other marker fixed), ellipse:<n_around>:<degrees> (the rotating
// ellipse O-mesh of rbf_bench, n_radial = n_around / 2, farfield fixed) or box:<n> (rbf_bench's
// 3D box, the bottom face rising as a bump, the top fixed, the sides free).

#include "bench_memory.hpp"
#include "meshmotion/core/generators.hpp"
// Where atomic writing lives moved (io/detail before issue 32); the baseline build has the old path.
#if __has_include("meshmotion/core/detail/atomic_file.hpp")
#include "meshmotion/core/detail/atomic_file.hpp"
#else
#include "meshmotion/io/detail/atomic_file.hpp"
#endif
#include "meshmotion/io/mesh_io.hpp"
#include "meshmotion/movers.hpp"
#include "meshmotion/quality.hpp"
#include "meshmotion/solvers/detail/stopwatch.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

using namespace meshmotion;
namespace fs = std::filesystem;

namespace {

constexpr double bump_amplitude = 0.05;

template <int Dim>
struct Case {
  std::string name;
  Mesh<Dim> mesh;
  BoundarySpec<Dim> spec;
  std::string moving_group;
  double rbf_radius = 1.0;  ///< support radius of our compact RBF mover
};

std::vector<std::string> split(const std::string& text, char separator) {
  std::vector<std::string> parts;
  std::stringstream s(text);
  for (std::string part; std::getline(s, part, separator);) parts.push_back(part);
  return parts;
}

long parse_long(const std::string& text, const std::string& where) {
  char* end = nullptr;
  const long value = std::strtol(text.c_str(), &end, 10);
  if (text.empty() || *end != '\0' || value < 1)
    throw InputError(where + ": expected a positive integer (got '" + text + "')");
  return value;
}

Case<2> bump_case() {
  Case<2> c{"bump", read_mesh_as<2>(fs::path(MESHMOTION_SHARED_DATA_DIR) / "su2_bump_channel_deforming_tri.su2"), {}, "interface", 0.0};
  const std::vector<Index> nodes = c.mesh.group_nodes("interface");
  double x0 = 1e300, x1 = -1e300;
  for (const Index i : nodes) x0 = std::min(x0, c.mesh.points(0, i)), x1 = std::max(x1, c.mesh.points(0, i));
  Points<2> d = Points<2>::Zero(2, static_cast<Index>(nodes.size()));
  for (std::size_t k = 0; k < nodes.size(); ++k) {
    const double s = std::sin(M_PI * (c.mesh.points(0, nodes[k]) - x0) / (x1 - x0));
    d(1, static_cast<Index>(k)) = bump_amplitude * s * s;
  }
  c.spec.moving("interface", d);
  for (const auto& g : c.mesh.groups)
    if (g.dim == 1 && g.name != "interface") c.spec.fixed(g.name);
  const ResolvedBoundary<2> b = c.spec.resolve(c.mesh);
  Points<2> at(2, b.size());
  for (Index k = 0; k < b.size(); ++k) at.col(k) = c.mesh.points.col(b.nodes[static_cast<std::size_t>(k)]);
  c.rbf_radius = suggest_support_radius(at, b.displacements);
  return c;
}

Case<2> ellipse_case(const std::vector<std::string>& parts) {
  if (parts.size() != 3) throw InputError("case ellipse: expected ellipse:<n_around>:<degrees> (got " + std::to_string(parts.size()) + " fields)");
  OMeshOptions o;
  o.semi_axis_x = 0.5;
  o.semi_axis_y = 0.25;
  o.n_around = parse_long(parts[1], "case ellipse n_around");
  o.n_radial = std::max<Index>(2, o.n_around / 2);
  const double degrees = std::stod(parts[2]);
  Case<2> c{"ellipse" + parts[1] + "_rot" + parts[2], o_mesh(o), {}, "wall", 8.0};  // radius as rbf_bench
  c.spec.moving("wall", Rotation2D{Vec<2>::Zero(), radians(degrees)}).fixed("farfield");
  return c;
}

Case<3> box_case(const std::vector<std::string>& parts) {
  if (parts.size() != 2) throw InputError("case box: expected box:<n> (got " + std::to_string(parts.size()) + " fields)");
  BoxOptions o;
  o.nx = o.ny = o.nz = parse_long(parts[1], "case box n");
  Case<3> c{"box" + parts[1], box_mesh(o), {}, "bottom", 6.0 / static_cast<double>(o.nx)};  // as rbf_bench
  const std::vector<Index> bottom = c.mesh.group_nodes("bottom");
  Points<3> d = Points<3>::Zero(3, static_cast<Index>(bottom.size()));
  for (std::size_t k = 0; k < bottom.size(); ++k)
    d(2, static_cast<Index>(k)) = 0.05 * std::sin(M_PI * c.mesh.points(0, bottom[k])) * std::sin(M_PI * c.mesh.points(1, bottom[k]));
  c.spec.moving("bottom", d).fixed("top");  // the top keeps the centres off one plane (the thin plate spline's polynomial needs it)
  return c;
}

struct Judged {
  double min_skew = 0.0, mean_skew = 0.0, min_scaled_jacobian = 0.0;
  Index invalid = 0;
};

template <int Dim>
Judged judge(const Mesh<Dim>& mesh, const Points<Dim>& displacement) {
  Mesh<Dim> moved = mesh;
  moved.points += displacement;
  const QualityReport skew = quality_report(moved, Metric::skew);
  const QualityReport jacobian = quality_report(moved, Metric::scaled_jacobian);
  return {skew.min, skew.mean, jacobian.min, skew.num_invalid};
}

/// One table row: a method's time, quality and ratio to the reference row of its table.
struct Row {
  std::string method;
  double seconds = 0.0;
  Judged q;
  std::string note;  ///< e.g. solver iterations, difference to a twin method
};

template <int Dim>
void print_rows(const Case<Dim>& c, const std::string& table, const std::vector<Row>& rows, const std::string& reference_name,
                double reference_seconds, Index centres) {
  std::printf("%s: case %s, %ld nodes, %ld cells, %ld boundary nodes; ratio = seconds / %s seconds\n", table.c_str(),
              c.name.c_str(), static_cast<long>(c.mesh.num_nodes()), static_cast<long>(c.mesh.num_cells()),
              static_cast<long>(centres), reference_name.c_str());
  std::printf("%-22s %10s %9s %9s %10s %9s %8s  %s\n", "method", "seconds", "ratio", "min_skew", "mean_skew", "min_sJ", "invalid",
              "note");
  for (const Row& r : rows) {
    const double ratio = reference_seconds > 0.0 ? r.seconds / reference_seconds : 0.0;
    std::printf("%-22s %10.4f %9.3f %9.4f %10.4f %9.4f %8ld  %s\n", r.method.c_str(), r.seconds, ratio, r.q.min_skew,
                r.q.mean_skew, r.q.min_scaled_jacobian, static_cast<long>(r.q.invalid), r.note.c_str());
  }
  for (const Row& r : rows)
    std::printf("{\"bench\":\"%s\",\"case\":\"%s\",\"method\":\"%s\",\"nodes\":%ld,\"boundary_nodes\":%ld,\"seconds\":%.6f,"
                "\"reference\":\"%s\",\"ratio_to_reference\":%.4f,\"min_skew\":%.6f,\"mean_skew\":%.6f,"
                "\"min_scaled_jacobian\":%.6f,\"invalid\":%ld,\"note\":\"%s\"}\n",
                table.c_str(), c.name.c_str(), r.method.c_str(), static_cast<long>(c.mesh.num_nodes()), static_cast<long>(centres),
                r.seconds, reference_name.c_str(), reference_seconds > 0.0 ? r.seconds / reference_seconds : 0.0, r.q.min_skew,
                r.q.mean_skew, r.q.min_scaled_jacobian, static_cast<long>(r.q.invalid), r.note.c_str());
  std::fflush(stdout);
}

/// Runs a registered mover of ours (setup + one move, timed) and judges the result.
template <int Dim>
Row our_mover(const Case<Dim>& c, const ResolvedBoundary<Dim>& b, const std::string& method, const KeyValues& p,
              const std::string& label) {
  AnyMover<Dim> mover = make_mover<Dim>(method, p);
  Points<Dim> u;
  const detail::Stopwatch watch;
  mover.setup(c.mesh, b);
  mover.move_into(b.displacements, u);
  const double seconds = watch.seconds();
  return {label, seconds, judge(c.mesh, u), mover.stats().iterations > 0 ? std::to_string(mover.stats().iterations) + " iterations" : ""};
}

// ---------------------------------------------------------------- OpenFOAM ----------------------

/// Extrusion thickness of 2D cases in OpenFOAM (one cell, `empty` front and back).
constexpr double foam_thickness = 1.0;

std::string foam_header(const char* cls, const char* object, const char* location) {
  return std::string("FoamFile\n{\n    version     2.0;\n    format      ascii;\n    class       ") + cls +
         ";\n    location    \"" + location + "\";\n    object      " + object + ";\n}\n\n";
}

/// A face of the extruded mesh with its owner and neighbour (-1 on the boundary).
struct FoamFace {
  std::vector<Index> nodes;
  Index owner = 0, neighbour = -1;
};

/// The polyMesh of a 2D mesh extruded one cell thick: points 0..n-1 at z = 0 and n..2n-1 at
/// z = thickness (so moved points map back to our nodes by index), internal faces in upper
/// triangular order, then one patch per facet group and an `empty` frontAndBack patch.
struct FoamMesh {
  std::vector<FoamFace> faces;
  std::vector<std::pair<std::string, Index>> patches;  ///< name, face count (faces follow in this order)
  Index internal_faces = 0;
};

FoamMesh foam_mesh(const Mesh<2>& mesh) {
  const Index n = mesh.num_nodes();
  struct Side {
    Index lo, hi, cell, a, b;
  };
  std::vector<Side> sides;
  std::vector<std::vector<Index>> cells;
  for (const auto& block : mesh.cells)
    for (Index e = 0; e < block.size(); ++e) {
      const auto el = block.element(e);
      if (block.type != ElementType::tri3 && block.type != ElementType::quad4)
        throw InputError("foam_mesh: only linear triangles and quadrilaterals are extruded (got " + std::string(name(block.type)) + ")");
      std::vector<Index> v(el.begin(), el.end());
      double area2 = 0.0;
      for (std::size_t k = 0; k < v.size(); ++k) {
        const Index p = v[k], q = v[(k + 1) % v.size()];
        area2 += mesh.points(0, p) * mesh.points(1, q) - mesh.points(0, q) * mesh.points(1, p);
      }
      if (!(area2 > 0.0))
        throw InvalidMeshError("foam_mesh: cell " + std::to_string(cells.size()) + " is not counter-clockwise (twice its area " +
                               std::to_string(area2) + ")");
      const auto cell = static_cast<Index>(cells.size());
      for (std::size_t k = 0; k < v.size(); ++k) {
        const Index a = v[k], b = v[(k + 1) % v.size()];
        sides.push_back({std::min(a, b), std::max(a, b), cell, a, b});
      }
      cells.push_back(std::move(v));
    }
  std::sort(sides.begin(), sides.end(),
            [](const Side& x, const Side& y) { return std::tie(x.lo, x.hi, x.cell) < std::tie(y.lo, y.hi, y.cell); });
  std::map<std::pair<Index, Index>, int> edge_tag;
  for (const auto& block : mesh.facets)
    for (Index e = 0; e < block.size(); ++e) {
      const auto el = block.element(e);
      edge_tag[{std::min(el[0], el[1]), std::max(el[0], el[1])}] = block.tags[static_cast<std::size_t>(e)];
    }
  // A side's quad face (a, b, b', a') points out of the cell whose counter-clockwise boundary runs a → b.
  const auto side_face = [n](const Side& s) { return std::vector<Index>{s.a, s.b, s.b + n, s.a + n}; };
  FoamMesh foam;
  std::map<int, std::vector<FoamFace>> boundary;
  for (std::size_t k = 0; k < sides.size();) {
    if (k + 1 < sides.size() && sides[k + 1].lo == sides[k].lo && sides[k + 1].hi == sides[k].hi) {
      if (k + 2 < sides.size() && sides[k + 2].lo == sides[k].lo && sides[k + 2].hi == sides[k].hi)
        throw InvalidMeshError("foam_mesh: edge " + std::to_string(sides[k].lo) + "-" + std::to_string(sides[k].hi) + " has more than two cells");
      foam.faces.push_back({side_face(sides[k]), sides[k].cell, sides[k + 1].cell});
      k += 2;
    } else {
      const auto it = edge_tag.find({sides[k].lo, sides[k].hi});
      if (it == edge_tag.end())
        throw InvalidMeshError("foam_mesh: boundary edge " + std::to_string(sides[k].lo) + "-" + std::to_string(sides[k].hi) + " is in no group");
      boundary[it->second].push_back({side_face(sides[k]), sides[k].cell, -1});
      k += 1;
    }
  }
  std::sort(foam.faces.begin(), foam.faces.end(),
            [](const FoamFace& x, const FoamFace& y) { return std::tie(x.owner, x.neighbour) < std::tie(y.owner, y.neighbour); });
  foam.internal_faces = static_cast<Index>(foam.faces.size());
  for (const auto& g : mesh.groups) {
    if (g.dim != 1 || !boundary.contains(g.tag)) continue;
    auto& list = boundary[g.tag];
    foam.patches.emplace_back(g.name, static_cast<Index>(list.size()));
    foam.faces.insert(foam.faces.end(), list.begin(), list.end());
    boundary.erase(g.tag);
  }
  if (!boundary.empty()) throw InvalidMeshError("foam_mesh: boundary edges tagged " + std::to_string(boundary.begin()->first) + " have no group name");
  for (std::size_t c = 0; c < cells.size(); ++c) {
    std::vector<Index> back(cells[c].rbegin(), cells[c].rend()), front;
    for (const Index v : cells[c]) front.push_back(v + n);
    foam.faces.push_back({back, static_cast<Index>(c), -1});
    foam.faces.push_back({front, static_cast<Index>(c), -1});
  }
  foam.patches.emplace_back("frontAndBack", static_cast<Index>(2 * cells.size()));
  return foam;
}

/// Points of the moving patch in OpenFOAM's order (first appearance in the patch's faces),
/// which a nonuniform pointPatchField value follows.
std::vector<Index> foam_patch_points(const FoamMesh& foam, const std::string& patch) {
  Index start = foam.internal_faces;
  for (const auto& [patch_name, count] : foam.patches) {
    if (patch_name == patch) {
      std::vector<Index> order;
      std::vector<bool> seen;
      for (Index f = start; f < start + count; ++f)
        for (const Index v : foam.faces[static_cast<std::size_t>(f)].nodes) {
          if (static_cast<std::size_t>(v) >= seen.size()) seen.resize(static_cast<std::size_t>(v) + 1, false);
          if (!seen[static_cast<std::size_t>(v)]) seen[static_cast<std::size_t>(v)] = true, order.push_back(v);
        }
      return order;
    }
    start += count;
  }
  throw InputError("foam_patch_points: no patch named '" + patch + "'");
}

/// `from`: a case on the same mesh whose displacement is subtracted on the moving patch, for one
/// increment of a motion spread over several moveMesh runs (the script then replaces the
/// exported points by the previous run's moved points).
void foam_export(const Case<2>& c, const fs::path& dir, const Case<2>* from = nullptr) {
  const FoamMesh foam = foam_mesh(c.mesh);
  const Index n = c.mesh.num_nodes();
  fs::create_directories(dir / "constant" / "polyMesh");
  fs::create_directories(dir / "0");
  const fs::path poly = dir / "constant" / "polyMesh";
  std::ostringstream s;
  s.precision(17);
  s << foam_header("vectorField", "points", "constant/polyMesh") << 2 * n << "\n(\n";
  for (int layer = 0; layer < 2; ++layer)
    for (Index i = 0; i < n; ++i) s << '(' << c.mesh.points(0, i) << ' ' << c.mesh.points(1, i) << ' ' << layer * foam_thickness << ")\n";
  s << ")\n";
  detail::write_file_atomically(poly / "points", s.str());
  s.str("");
  s << foam_header("faceList", "faces", "constant/polyMesh") << foam.faces.size() << "\n(\n";
  for (const auto& f : foam.faces) {
    s << f.nodes.size() << '(';
    for (std::size_t k = 0; k < f.nodes.size(); ++k) s << (k ? " " : "") << f.nodes[k];
    s << ")\n";
  }
  s << ")\n";
  detail::write_file_atomically(poly / "faces", s.str());
  s.str("");
  s << foam_header("labelList", "owner", "constant/polyMesh") << foam.faces.size() << "\n(\n";
  for (const auto& f : foam.faces) s << f.owner << '\n';
  s << ")\n";
  detail::write_file_atomically(poly / "owner", s.str());
  s.str("");
  s << foam_header("labelList", "neighbour", "constant/polyMesh") << foam.internal_faces << "\n(\n";
  for (Index f = 0; f < foam.internal_faces; ++f) s << foam.faces[static_cast<std::size_t>(f)].neighbour << '\n';
  s << ")\n";
  detail::write_file_atomically(poly / "neighbour", s.str());
  s.str("");
  s << foam_header("polyBoundaryMesh", "boundary", "constant/polyMesh") << foam.patches.size() << "\n(\n";
  Index start = foam.internal_faces;
  for (const auto& [patch, count] : foam.patches) {
    const bool empty = patch == "frontAndBack";
    s << "    " << patch << "\n    {\n        type            " << (empty ? "empty" : "patch") << ";\n"
      << (empty ? "        inGroups        List<word> 1(empty);\n" : "") << "        nFaces          " << count
      << ";\n        startFace       " << start << ";\n    }\n";
    start += count;
  }
  s << ")\n";
  detail::write_file_atomically(poly / "boundary", s.str());

  // The prescribed displacement on the moving patch (both layers), zero on the others.
  ResolvedBoundary<2> b = c.spec.resolve(c.mesh);
  if (from != nullptr) {
    const ResolvedBoundary<2> before = from->spec.resolve(from->mesh);
    if (from->mesh.num_nodes() != n || before.nodes != b.nodes)
      throw InputError("foam_export: case " + from->name + " is not on the mesh of " + c.name);
    b.displacements -= before.displacements;
  }
  std::vector<Index> slot(static_cast<std::size_t>(n), -1);
  for (Index k = 0; k < b.size(); ++k) slot[static_cast<std::size_t>(b.nodes[static_cast<std::size_t>(k)])] = k;
  s.str("");
  s << foam_header("pointVectorField", "pointDisplacement", "0") << "dimensions      [0 1 0 0 0 0 0];\n\n"
    << "internalField   uniform (0 0 0);\n\nboundaryField\n{\n";
  for (const auto& [patch, count] : foam.patches) {
    s << "    " << patch << "\n    {\n";
    if (patch == "frontAndBack") {
      s << "        type            empty;\n";
    } else if (patch == c.moving_group) {
      const std::vector<Index> order = foam_patch_points(foam, patch);
      s << "        type            fixedValue;\n        value           nonuniform List<vector>\n" << order.size() << "\n(\n";
      for (const Index v : order) {
        const Index k = slot[static_cast<std::size_t>(v % n)];
        if (k < 0) throw InvalidMeshError("foam_export: a node of patch " + patch + " has no prescribed displacement");
        s << '(' << b.displacements(0, k) << ' ' << b.displacements(1, k) << " 0)\n";
      }
      s << ");\n";
    } else {
      s << "        type            fixedValue;\n        value           uniform (0 0 0);\n";
    }
    s << "    }\n";
  }
  s << "}\n";
  detail::write_file_atomically(dir / "0" / "pointDisplacement", s.str());
  std::printf("exported %s to %s: %ld points, %zu faces (%ld internal), %zu patches, thickness %.1f\n", c.name.c_str(),
              dir.string().c_str(), static_cast<long>(2 * n), foam.faces.size(), static_cast<long>(foam.internal_faces),
              foam.patches.size(), foam_thickness);
}

/// Reads an ASCII OpenFOAM vectorField (polyMesh/points) as a 3 × count matrix.
Eigen::Matrix3Xd read_foam_points(const fs::path& file) {
  std::ifstream in(file);
  if (!in) throw IoError("read_foam_points: cannot open " + file.string());
  std::string line;
  std::uint64_t line_number = 0;
  long count = -1;
  bool in_header = false;
  while (count < 0 && std::getline(in, line)) {
    ++line_number;
    if (line.rfind("FoamFile", 0) == 0) in_header = true;
    if (in_header) {
      if (line.find('}') != std::string::npos) in_header = false;
      continue;
    }
    if (!line.empty() && line.find_first_not_of("0123456789") == std::string::npos) count = std::stol(line);
  }
  if (count < 0) throw ParseError(file.string(), line_number, "no point count (binary format? the case asks for ascii)");
  std::string rest((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::replace_if(rest.begin(), rest.end(), [](char ch) { return ch == '(' || ch == ')'; }, ' ');
  std::istringstream values(rest);
  Eigen::Matrix3Xd points(3, count);
  for (long i = 0; i < count; ++i)
    for (int d = 0; d < 3; ++d)
      if (!(values >> points(d, i)))
        throw ParseError(file.string(), line_number, "expected " + std::to_string(count) + " points (read " + std::to_string(i) + ")");
  return points;
}

void foam_judge(const Case<2>& c, const fs::path& dir, double foam_seconds, const std::string& foam_note) {
  const ResolvedBoundary<2> b = c.spec.resolve(c.mesh);
  const Index n = c.mesh.num_nodes();
  std::vector<Row> rows;
  const fs::path moved_file = dir / "1" / "polyMesh" / "points";
  double reference = 0.0;
  std::string reference_name = "openfoam";
  if (foam_seconds > 0.0 && fs::exists(moved_file)) {
    const Eigen::Matrix3Xd moved = read_foam_points(moved_file);
    if (moved.cols() != 2 * n)
      throw InputError("foam_judge: " + moved_file.string() + " has " + std::to_string(moved.cols()) + " points (expected " +
                       std::to_string(2 * n) + ")");
    const Points<2> u = moved.topLeftCorner(2, n) - c.mesh.points;
    // Checks of the mapping: both layers moved alike, and the boundary nodes reached their targets.
    const double layers = (moved.topLeftCorner(2, n) - moved.topRightCorner(2, n)).cwiseAbs().maxCoeff();
    double target = 0.0;
    for (Index k = 0; k < b.size(); ++k)
      target = std::max(target, (u.col(b.nodes[static_cast<std::size_t>(k)]) - b.displacements.col(k)).norm());
    char note[160];
    std::snprintf(note, sizeof note, "%s; layer gap %.1e, boundary error %.1e", foam_note.c_str(), layers, target);
    rows.push_back({"openfoam_laplacian_invdist", foam_seconds, judge(c.mesh, u), note});
    reference = foam_seconds;
  } else {
    std::printf("openfoam: MISSING (%s): no moved points at %s; our movers are reported without a peer\n", foam_note.c_str(),
                moved_file.string().c_str());
    reference_name = "openfoam(missing)";
  }
  rows.push_back(our_mover(c, b, "rbf", {{"support_radius", format_option_value(c.rbf_radius)}}, "ours_rbf_wendland2"));
  rows.push_back(our_mover(c, b, "le", {}, "ours_elasticity"));
  rows.push_back(our_mover(c, b, "sle", {}, "ours_stiff_elasticity"));
  rows.push_back(our_mover(c, b, "spring", {}, "ours_spring"));
  print_rows(c, "openfoam_peer", rows, reference_name, reference, b.size());
  std::printf("(our RBF support radius %.3f; OpenFOAM seconds = wall time of the moveMesh process)\n\n", c.rbf_radius);
}

// ---------------------------------------------------------------- dense RBF ---------------------

template <int Dim>
void write_raw(const fs::path& file, const Points<Dim>& m) {
  detail::write_file_atomically(file, std::string_view(reinterpret_cast<const char*>(m.data()), static_cast<std::size_t>(m.size()) * sizeof(double)));
}

template <int Dim>
void rbf_export(const Case<Dim>& c, const fs::path& dir) {
  const ResolvedBoundary<Dim> b = c.spec.resolve(c.mesh);
  fs::create_directories(dir);
  Points<Dim> centres(Dim, b.size());
  for (Index k = 0; k < b.size(); ++k) centres.col(k) = c.mesh.points.col(b.nodes[static_cast<std::size_t>(k)]);
  write_raw<Dim>(dir / "points.f64", c.mesh.points);
  write_raw<Dim>(dir / "centres.f64", centres);
  write_raw<Dim>(dir / "values.f64", b.displacements);
  detail::write_file_atomically(dir / "shape.txt", std::to_string(Dim) + " " + std::to_string(c.mesh.num_nodes()) + " " +
                                                       std::to_string(b.size()) + "\n");
  std::printf("exported %s: %ld nodes, %ld centres, dimension %d\n", c.name.c_str(), static_cast<long>(c.mesh.num_nodes()),
              static_cast<long>(b.size()), Dim);
}

/// The Wendland C2 interpolant of our compact mover built densely (m × m LU, n × m
/// evaluation): the same interpolant as the compact k-d tree path, without its sparsity.
template <int Dim>
Points<Dim> dense_wendland(const Mesh<Dim>& mesh, const ResolvedBoundary<Dim>& b, double radius) {
  const Index m = b.size(), n = mesh.num_nodes();
  Eigen::MatrixXd phi(m, m);
  for (Index j = 0; j < m; ++j)
    for (Index i = 0; i < m; ++i)
      phi(i, j) = rbf_value(RbfKernel::wendland2,
                            (mesh.points.col(b.nodes[static_cast<std::size_t>(i)]) - mesh.points.col(b.nodes[static_cast<std::size_t>(j)])).norm(), radius);
  const Eigen::MatrixXd alpha = phi.partialPivLu().solve(b.displacements.transpose());  // m × Dim
  // Evaluated in blocks of nodes so that memory stays O(block × m), like SciPy's evaluation.
  constexpr Index block = 2048;
  Points<Dim> u(Dim, n);
  Eigen::MatrixXd e(block, m);
  for (Index first = 0; first < n; first += block) {
    const Index rows = std::min(block, n - first);
    for (Index j = 0; j < m; ++j)
      for (Index i = 0; i < rows; ++i)
        e(i, j) = rbf_value(RbfKernel::wendland2,
                            (mesh.points.col(first + i) - mesh.points.col(b.nodes[static_cast<std::size_t>(j)])).norm(), radius);
    u.middleCols(first, rows) = (e.topRows(rows) * alpha).transpose();
  }
  return u;
}

template <int Dim>
void rbf_judge(const Case<Dim>& c, const fs::path& dir) {
  const ResolvedBoundary<Dim> b = c.spec.resolve(c.mesh);
  const Index n = c.mesh.num_nodes();
  std::vector<Row> rows;
  const auto difference = [](const Points<Dim>& x, const Points<Dim>& y) {
    char text[64];
    std::snprintf(text, sizeof text, "%.1e", (x - y).cwiseAbs().maxCoeff());
    return std::string(text);
  };
  // Times run() (which returns the displacements), judges and records the row; a method that
  // throws is reported as failed, not dropped silently.
  const auto attempt = [&](const std::string& label, auto&& run) -> std::optional<Points<Dim>> {
    try {
      const detail::Stopwatch watch;
      Points<Dim> u = run();
      rows.push_back({label, watch.seconds(), judge(c.mesh, u), ""});
      return u;
    } catch (const Error& e) {
      std::printf("%s: FAILED (%s)\n", label.c_str(), e.what());
      return std::nullopt;
    }
  };
  const auto rbf_mover = [&](const RbfOptions& options) {
    RbfMover<Dim> mover(options);
    Points<Dim> u;
    mover.setup(c.mesh, b);
    mover.move_into(b.displacements, u);
    return u;
  };
  // Ours: compact Wendland C2 with the k-d tree and sparse factorization (the reference row).
  RbfOptions compact;
  compact.support_radius = c.rbf_radius;
  const auto ours = attempt("ours_compact_wendland2", [&] { return rbf_mover(compact); });
  if (!ours) return;
  const double compact_seconds = rows.front().seconds;
  std::optional<Points<Dim>> eigen_tps;
  if (b.size() <= 8000 && static_cast<double>(n) * static_cast<double>(b.size()) <= 2e9) {
    if (const auto u = attempt("eigen_dense_wendland2", [&] { return dense_wendland(c.mesh, b, c.rbf_radius); }))
      rows.back().note = "max |u - ours| " + difference(*u, *ours);
    // The dense global path of our RbfMover: thin plate spline with its linear polynomial.
    RbfOptions tps;
    tps.kernel = RbfKernel::thin_plate_spline;
    tps.polynomial = true;
    tps.max_dense_centres = b.size();
    eigen_tps = attempt("eigen_dense_tps", [&] { return rbf_mover(tps); });
  } else {
    std::printf("eigen dense rows skipped: %ld centres x %ld nodes is beyond this benchmark's time budget\n",
                static_cast<long>(b.size()), static_cast<long>(n));
  }
  // SciPy's RBFInterpolator, run by dense_rbf_peer.sh before this command.
  for (const std::string kernel : {"thin_plate_spline"}) {
    const fs::path values = dir / ("scipy_" + kernel + ".f64"), seconds = dir / ("scipy_" + kernel + ".seconds");
    std::ifstream time_in(seconds);
    double s = 0.0;
    if (!fs::exists(values) || !(time_in >> s)) {
      std::printf("scipy_%s: MISSING (no %s; see dense_rbf_peer.sh output)\n", kernel.c_str(), values.string().c_str());
      continue;
    }
    std::ifstream in(values, std::ios::binary);
    Points<Dim> u(Dim, n);
    in.read(reinterpret_cast<char*>(u.data()), static_cast<std::streamsize>(u.size() * static_cast<Index>(sizeof(double))));
    if (!in) throw IoError("rbf_judge: " + values.string() + " is shorter than " + std::to_string(n) + " displacements");
    rows.push_back({"scipy_" + kernel, s, judge(c.mesh, u), eigen_tps ? "max |u - eigen_tps| " + difference(u, *eigen_tps) : ""});
  }
  print_rows(c, "dense_rbf_peer", rows, "ours_compact_wendland2", compact_seconds, b.size());
  std::printf("(compact support radius %.4f; SciPy has no compactly supported kernel: its rows are global)\n\n", c.rbf_radius);
}

int usage() {
  std::fprintf(stderr,
               "usage: motion_peer_bench foam-export CASE DIR [FROM_CASE] | foam-judge CASE DIR SECONDS [NOTE] | "
               "rbf-export CASE DIR | rbf-judge CASE DIR\n  CASE: bump | ellipse:<n_around>:<degrees> | box:<n>\n");
  return 1;
}

// The 2D case of a stepped foam-export's FROM_CASE.
Case<2> case_2d(const std::string& name) {
  const std::vector<std::string> parts = split(name, ':');
  if (!parts.empty() && parts[0] == "ellipse") return ellipse_case(parts);
  if (name == "bump") return bump_case();
  throw InputError("motion_peer_bench: FROM_CASE must be a 2D case, bump or ellipse:<n_around>:<degrees> (got '" + name + "')");
}

template <int Dim>
int run(const std::string& command, const Case<Dim>& c, const fs::path& dir, int argc, char** argv) {
  if (command == "rbf-export") return rbf_export(c, dir), 0;
  if (command == "rbf-judge") return rbf_judge(c, dir), 0;
  if constexpr (Dim == 2) {
    if (command == "foam-export" && argc >= 5) {
      const Case<2> from = case_2d(argv[4]);
      return foam_export(c, dir, &from), 0;
    }
    if (command == "foam-export") return foam_export(c, dir), 0;
    if (command == "foam-judge" && argc >= 5) return foam_judge(c, dir, std::atof(argv[4]), argc > 5 ? argv[5] : ""), 0;
  }
  return usage();
}

}  // namespace

int main(int argc, char** argv) {
  bench::tune_memory(argc, argv);
  if (argc < 4) return usage();
  try {
    const std::string command = argv[1];
    const std::vector<std::string> parts = split(argv[2], ':');
    const fs::path dir = argv[3];
    if (parts.empty()) return usage();
    if (parts[0] == "bump") return run(command, bump_case(), dir, argc, argv);
    if (parts[0] == "ellipse") return run(command, ellipse_case(parts), dir, argc, argv);
    if (parts[0] == "box") return run(command, box_case(parts), dir, argc, argv);
    return usage();
  } catch (const Error& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 1;
  }
}
