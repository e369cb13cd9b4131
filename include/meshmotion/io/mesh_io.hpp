#pragma once
/// \file
/// Reading and writing meshes by file extension: .msh (Gmsh 2.2/4.1, ASCII or binary, detected
/// on reading), .su2 (SU2), .cgns (CGNS, when built with the CGNS library: io/cgns.hpp) and
/// .vtu (VTK XML, io/vtu_reader.hpp and io/vtu_writer.hpp); a folder is an OpenFOAM case (io/openfoam.hpp): read as its
/// polyMesh, written by replacing its points.

#include "meshmotion/core/error.hpp"
#include "meshmotion/core/mesh.hpp"
#include "meshmotion/core/mesh_like.hpp"
#include "meshmotion/core/orientation.hpp"
#include "meshmotion/io/any_mesh.hpp"
#include "meshmotion/io/cgns.hpp"
#include "meshmotion/io/gmsh_reader.hpp"
#include "meshmotion/io/gmsh_writer.hpp"
#include "meshmotion/io/openfoam.hpp"
#include "meshmotion/io/su2_reader.hpp"
#include "meshmotion/io/su2_writer.hpp"
#include "meshmotion/io/vtu_reader.hpp"
#include "meshmotion/io/vtu_writer.hpp"

#include <concepts>
#include <algorithm>
#include <cctype>
#include <filesystem>
#include <string>
#include <variant>

namespace meshmotion {

namespace detail {
[[nodiscard]] inline std::string lower_extension(const std::filesystem::path& file) {
  std::string ext = file.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}
}  // namespace detail

/// What read_mesh() does with the orientation of the cells (core/orientation.hpp).
enum class ReadOrientation {
  keep,              ///< as the file lists them (default)
  fix_reversed,      ///< a mesh whose every cell is negative is mirrored (orient_consistently)
  require_positive,  ///< InputError for a negative cell, naming it
};

/// Options of read_mesh().
struct ReadOptions {
  ReadOrientation orientation = ReadOrientation::keep;
};

namespace detail {

template <int Dim>
void apply_orientation(Mesh<Dim>& mesh, const std::filesystem::path& file, ReadOrientation policy) {
  if (policy == ReadOrientation::keep) return;
  if (policy == ReadOrientation::fix_reversed) {
    orient_consistently(mesh);
    return;
  }
  const OrientationReport r = orientation_report(mesh);
  if (r.num_negative == 0) return;
  Index local = r.first_negative;
  for (const auto& b : mesh.cells) {
    if (local < b.size()) {
      throw InputError("read_mesh: " + file.string() + ": " + std::to_string(r.num_negative) + " of " +
                       std::to_string(r.num_cells) + " cells are negatively oriented (" +
                       (r.orientation() == CellOrientation::reversed ? "every cell: the file's convention is reversed"
                                                                                   : "mixed orientation") +
                       "; first: " + std::string(name(b.type)) + " element " +
                       std::to_string(msh_element_id(mesh, b, local)) + ")");
    }
    local -= b.size();
  }
}

}  // namespace detail

/// Reads a mesh, choosing the format by extension (.msh, .su2, .cgns or .vtu) or, for a folder, as an
/// OpenFOAM case. The result is 3D if the file
/// holds 3D elements (SU2: NDIME 3), else 2D. The mesh is validated, and its orientation
/// handled as `options` says.
/// Throws InputError for an unknown extension, IoError for an unreadable file, ParseError (file
/// and line or byte offset) for malformed content, InputError for an invalid mesh (a 2D mesh
/// with nonzero z names the first such node) or a negative cell under require_positive.
[[nodiscard]] inline AnyMesh read_mesh(const std::filesystem::path& file, const ReadOptions& options = {}) {
  const std::string ext = detail::lower_extension(file);
  AnyMesh mesh = [&]() -> AnyMesh {
    std::error_code ec;
    if (std::filesystem::is_directory(file, ec)) return read_openfoam(file);
    if (ext == ".msh") return read_gmsh(file);
    if (ext == ".su2") return read_su2(file);
    if (ext == ".cgns") return read_cgns(file);
    if (ext == ".vtu") return read_vtu(file);
    throw InputError("read_mesh: " + file.string() + ": unknown mesh format '" + ext +
                     "' (expected .msh, .su2, .cgns, .vtu or an OpenFOAM case folder)");
  }();
  std::visit([&](auto& m) { detail::apply_orientation(m, file, options.orientation); }, mesh);
  return mesh;
}

/// Reads a mesh that must have dimension Dim; throws InputError when the file's differs, and
/// as read_mesh() otherwise.
template <int Dim>
[[nodiscard]] Mesh<Dim> read_mesh_as(const std::filesystem::path& file, const ReadOptions& options = {}) {
  AnyMesh any = read_mesh(file, options);
  if (auto* mesh = std::get_if<Mesh<Dim>>(&any)) return std::move(*mesh);
  throw InputError("read_mesh_as: " + file.string() + " holds a " + std::to_string(dimension(any)) + "D mesh (expected " +
                   std::to_string(Dim) + "D)");
}

/// Options of write_mesh().
struct WriteOptions {
  MshVersion msh_version = MshVersion::v4_1;  ///< .msh only
  bool binary = false;                        ///< .msh only
  bool vtu_facets = false;                    ///< .vtu only: also write the facets
};

/// Writes a mesh, choosing the format by extension (.msh, .su2, .cgns or .vtu) or, for an
/// OpenFOAM case, polyMesh or time folder, replacing the case's points
/// (write_polymesh_points()), or, for a path without extension that does not exist or is an
/// empty folder, writing a new OpenFOAM case (to_polymesh(), write_polymesh()); through
/// temporary files in the same folder and renames. Throws InputError for an unknown extension or an
/// invalid mesh (nothing is written), IoError when the file cannot be written.
template <int Dim>
void write_mesh(const std::filesystem::path& file, const Mesh<Dim>& mesh, const WriteOptions& options = {}) {
  if (is_openfoam_target(file) || is_new_openfoam_case(file)) {
    if constexpr (Dim == 3) {
      if (is_openfoam_target(file)) return write_polymesh_points(file, mesh);
      return write_polymesh(file, to_polymesh(mesh));
    } else {
      throw InputError("write_mesh: " + file.string() + ": an OpenFOAM case holds a 3D mesh (got a 2D one)");
    }
  }
  const std::string ext = detail::lower_extension(file);
  if (ext == ".msh") return write_gmsh(file, mesh, GmshWriteOptions{options.msh_version, options.binary});
  if (ext == ".su2") return write_su2(file, mesh);
  if (ext == ".vtu") return write_vtu(file, mesh, VtuFields{}, VtuOptions{options.vtu_facets});
  if (ext == ".cgns") return write_cgns(file, mesh);
  throw InputError("write_mesh: " + file.string() + ": unknown mesh format '" + ext + "' (expected .msh, .su2, .cgns or .vtu)");
}

/// Checks, before any work, that write_mesh() can write a mesh of element order `order` (1:
/// linear, 2: quadratic) to `file`: a known extension whose format holds that order, and an
/// existing folder. Throws InputError saying which formats would do, or naming the folder.
inline void check_mesh_output(const std::filesystem::path& file, int order = 1) {
  if (is_openfoam_target(file) || is_new_openfoam_case(file)) {
    if (order > 1) throw InputError("output " + file.string() + ": an OpenFOAM case holds linear cells only (expected .msh, .cgns or .vtu for order " +
                                    std::to_string(order) + ")");
    return;
  }
  const std::string ext = detail::lower_extension(file);
  if (ext != ".msh" && ext != ".su2" && ext != ".vtu" && ext != ".cgns")
    throw InputError("output " + file.string() + ": unknown mesh format '" + ext + "' (expected .msh, .su2, .cgns or .vtu)");
  if (ext == ".cgns" && !have_cgns)
    throw InputError("output " + file.string() + ": writing CGNS needs the CGNS library (meshmotion was built without it)");
  if (ext == ".cgns" && order > 2)
    throw InputError("output " + file.string() + ": CGNS files are written up to order 2 (expected .msh or .vtu for order " +
                     std::to_string(order) + ")");
  const std::filesystem::path folder = file.has_parent_path() ? file.parent_path() : std::filesystem::path(".");
  std::error_code ec;
  if (!std::filesystem::is_directory(folder, ec))
    throw InputError("output " + file.string() + ": folder " + folder.string() + " does not exist");
}

/// Writes a solver's own mesh type (any MeshLike): its nodes and cells, copied into a
/// Mesh<Dim> first (a MeshLike carries no boundary groups).
template <MeshLike M>
  requires(!std::same_as<M, Mesh<mesh_dim<M>>>)
void write_mesh(const std::filesystem::path& file, const M& mesh, const WriteOptions& options = {}) {
  write_mesh(file, to_mesh(mesh), options);
}

/// Writes whichever mesh `mesh` holds, as write_mesh().
inline void write_mesh(const std::filesystem::path& file, const AnyMesh& mesh, const WriteOptions& options = {}) {
  std::visit([&](const auto& m) { write_mesh(file, m, options); }, mesh);
}

}  // namespace meshmotion

// The compiled library (target meshmotion::compiled, src/) holds these for Dim 2 and 3.
#ifdef MESHMOTION_COMPILED
namespace meshmotion {
extern template Mesh<2> read_mesh_as<2>(const std::filesystem::path&, const ReadOptions&);
extern template Mesh<3> read_mesh_as<3>(const std::filesystem::path&, const ReadOptions&);
extern template void write_mesh<2>(const std::filesystem::path&, const Mesh<2>&, const WriteOptions&);
extern template void write_mesh<3>(const std::filesystem::path&, const Mesh<3>&, const WriteOptions&);
}  // namespace meshmotion
#endif
