#pragma once
/// \file
/// OpenFOAM polyMesh (`constant/polyMesh/`: points, faces, owner, neighbour, boundary) in, and
/// moved points back out, in place.
///
/// Reading: ASCII and binary files (FoamFile header; `arch` label and scalar sizes),
/// `faceList` and `faceCompactList` faces, gzip-compressed files (`points.gz`, ...) when
/// built with zlib. read_polymesh() gives the face-based mesh as the files hold it;
/// to_mesh() turns it into a Mesh<3>:
/// - when every cell is a tetrahedron, pyramid, prism or hexahedron (4, 5, 6 or 8 vertices
///   with the faces of that shape), the cells are those elements, numbered as OpenFOAM's cells
///   (ids = cell + 1), and nothing is added;
/// - otherwise every cell is cut into tetrahedra around its centre, each face of more than
///   three vertices around its centre too (as OpenFOAM's own tet decomposition does); those
///   centres are appended after the points as auxiliary nodes (Mesh::num_auxiliary_nodes).
/// Patches become facet groups (tag = patch index + 1) of the boundary faces, oriented out of
/// the domain as OpenFOAM lists them; cell, face and point zones groups of dimension 0 holding
/// their nodes, by which a motion can address them (a cell zone moved as a body). Malformed files give the file, the line (ASCII) or byte
/// offset (binary) and the entry; inconsistent lists (an owner list shorter than the faces, a
/// face index out of range, patches that do not cover the boundary faces) name the list.
///
/// Writing: write_polymesh_points() replaces the `points` of a case, atomically, keeping the
/// case's own header, format (ASCII or binary) and compression; the faces and the rest of the
/// case are not touched. It writes the nodes before the auxiliary ones and refuses a mesh whose
/// node count differs from the case's. Targets: a case folder (its constant/polyMesh), a
/// polyMesh folder, or a time folder of a case (`case/0.001`: its polyMesh/points, created,
/// which is where OpenFOAM looks for moved points). write_moved_case() also writes a whole new
/// case: the source case's own cells, patches and zones with the moved points.
///
/// The pieces: io/openfoam_polymesh.hpp (the model and its conversions),
/// io/openfoam_reader.hpp, io/openfoam_writer.hpp, io/detail/foam_files.hpp (the files' syntax).

#include "meshmotion/io/openfoam_polymesh.hpp"
#include "meshmotion/io/openfoam_reader.hpp"
#include "meshmotion/io/openfoam_writer.hpp"

#include <algorithm>
#include <filesystem>
#include <optional>
#include <string>

namespace meshmotion {

namespace detail {

// write_moved_case(), a template of nothing: a program built on meshmotion::compiled links the
// writers instead of compiling them.
template <int = 0>
void write_moved_case_of(const std::filesystem::path& target, const std::filesystem::path& source, const Mesh<3>& moved) {
  if (!is_new_openfoam_case(target)) {
    // Another case of as many points must hold this mesh: its points would make no sense
    // on other faces (a moved mesh written over its neighbour's case).
    const detail::FoamPointsTarget where = detail::foam_points_target(target);
    std::error_code ec;
    std::filesystem::path source_folder = detail::polymesh_folder(source);
    if (const auto time = source_folder.empty() ? detail::foam_time_folder(source) : std::nullopt) source_folder = time->constant;
    if (!where.reference.empty() && !std::filesystem::equivalent(where.reference.parent_path(), source_folder, ec)) {
      // The source is read only here: its own case or time folder needs no comparison.
      const PolyMesh poly = read_polymesh(source), other = read_polymesh(where.reference.parent_path());
      const auto differs = [&]() -> std::string {
        if (other.num_faces() != poly.num_faces() || other.num_cells != poly.num_cells || other.points.cols() != poly.points.cols())
          return std::to_string(other.points.cols()) + " points, " + std::to_string(other.num_faces()) + " faces and " +
                 std::to_string(other.num_cells) + " cells against " + std::to_string(poly.points.cols()) + ", " +
                 std::to_string(poly.num_faces()) + " and " + std::to_string(poly.num_cells);
        for (Index f = 0; f < poly.num_faces(); ++f) {
          const auto a = poly.face(f), b = other.face(f);
          if (!std::equal(a.begin(), a.end(), b.begin(), b.end()) || other.owner[static_cast<std::size_t>(f)] != poly.owner[static_cast<std::size_t>(f)] ||
              (f < poly.num_internal_faces() && (f >= other.num_internal_faces() || other.neighbour[static_cast<std::size_t>(f)] != poly.neighbour[static_cast<std::size_t>(f)])))
            return "face " + std::to_string(f) + " differs";
        }
        if (other.patches.size() != poly.patches.size()) return std::to_string(other.patches.size()) + " patches against " + std::to_string(poly.patches.size());
        for (std::size_t p = 0; p < poly.patches.size(); ++p)
          if (other.patches[p].name != poly.patches[p].name || other.patches[p].start != poly.patches[p].start ||
              other.patches[p].size != poly.patches[p].size)
            return "patch " + std::to_string(p) + " is '" + other.patches[p].name + "' there, '" + poly.patches[p].name + "' here";
        return {};
      }();
      if (!differs.empty())
        throw InputError(target.string() + ": holds another mesh than " + source.string() + " (" + differs + "): its points were not replaced");
    }
    return write_polymesh_points(target, moved);
  }
  PolyMesh poly = read_polymesh(source);
  const Index n = moved.num_nodes() - moved.num_auxiliary_nodes;
  if (n != poly.points.cols())
    throw InputError(target.string() + ": the mesh has " + std::to_string(n) + " points, the case it comes from (" + source.string() +
                     ") " + std::to_string(poly.points.cols()));
  poly.points = moved.points.leftCols(n);
  write_new_polymesh_case(target, poly);
}

}  // namespace detail

/// Writes `moved`, the mesh read from the OpenFOAM case `source` (read_openfoam()) with its
/// nodes moved: into a case, polyMesh or time folder, its points (write_polymesh_points()); at
/// a new or empty folder, a whole case holding `source`'s own polyMesh (its cells, not the
/// tetrahedra a polyhedral case is cut into; its patches with their types and groups; its
/// zones) with the moved points. Throws as those functions do, and InputError when `moved` does
/// not have `source`'s point count, or when `target` is another case whose faces, cells or
/// patches are not `source`'s (nothing is written then).
inline void write_moved_case(const std::filesystem::path& target, const std::filesystem::path& source, const Mesh<3>& moved) {
  detail::write_moved_case_of(target, source, moved);
}

}  // namespace meshmotion

// The compiled library (target meshmotion::compiled, src/io_quality.cpp) holds it.
#ifdef MESHMOTION_COMPILED
namespace meshmotion {
extern template void detail::write_moved_case_of<0>(const std::filesystem::path&, const std::filesystem::path&, const Mesh<3>&);
}  // namespace meshmotion
#endif
