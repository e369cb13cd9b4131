#pragma once
/// \file
/// Reading and writing meshes by file extension, from one table (mesh_file_formats): .msh
/// (Gmsh 2.2/4.1, ASCII or binary, detected on reading), .su2 (SU2), .cgns (CGNS, when built
/// with the CGNS library: io/cgns.hpp) and .vtu (VTK XML); a folder is an OpenFOAM case
/// (io/openfoam.hpp): read as its polyMesh, written by replacing its points.

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

#include "meshmotion/io/detail/read_file.hpp"

#include <array>
#include <concepts>
#include <filesystem>
#include <string>
#include <string_view>
#include <variant>

namespace meshmotion {

/// The file formats read_mesh() and write_mesh() choose by extension.
enum class MeshFormat { gmsh, su2, cgns, vtu };

/// One row of the format table.
struct MeshFormatEntry {
  MeshFormat format;
  std::string_view extension;  ///< lower case, with its dot
  int max_write_order;         ///< the highest element order written; 0: any
  std::string_view library;    ///< the library it needs, empty for none
  bool available;              ///< false when the build lacks that library
};

/// Every format a file extension selects, in the order error messages list them. Adding a
/// format is one row here and one case in read_mesh() and write_mesh().
inline constexpr std::array<MeshFormatEntry, 4> mesh_file_formats{{
    {MeshFormat::gmsh, ".msh", 0, "", true},
    {MeshFormat::su2, ".su2", 0, "", true},
    {MeshFormat::cgns, ".cgns", 4, "CGNS", have_cgns},  // the orders CGNS names
    {MeshFormat::vtu, ".vtu", 0, "", true},
}};

/// The format row of `file`'s extension (any case); nullptr when none has it.
[[nodiscard]] inline const MeshFormatEntry* mesh_format_of(const std::filesystem::path& file) {
  const std::string ext = detail::lower_extension(file);
  for (const auto& f : mesh_file_formats)
    if (f.extension == ext) return &f;
  return nullptr;
}

namespace detail {

/// The extensions of the formats that write elements of `order` (of every format for order
/// 0), as "one of .msh, .su2, ..." for messages.
[[nodiscard]] inline std::string format_extensions(int order = 0) {
  std::string list = "one of";
  bool first = true;
  for (const auto& f : mesh_file_formats)
    if (order == 0 || f.max_write_order == 0 || order <= f.max_write_order) {
      list += first ? " " : ", ";
      list += f.extension;
      first = false;
    }
  return list;
}

/// "unknown mesh format '.xyz' (expected one of .msh, ..." for messages, left open for the
/// caller's alternatives and closing parenthesis.
[[nodiscard]] inline std::string unknown_format(const std::filesystem::path& file) {
  return "unknown mesh format '" + lower_extension(file) + "' (expected " + format_extensions();
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

namespace detail {

// read_mesh(), a template of nothing: a program built on meshmotion::compiled links every
// reader from src/io_quality.cpp instead of compiling them all for its one call.
template <int = 0>
[[nodiscard]] AnyMesh read_any_mesh(const std::filesystem::path& file, const ReadOptions& options) {
  AnyMesh mesh = [&]() -> AnyMesh {
    std::error_code ec;
    if (std::filesystem::is_directory(file, ec)) return read_openfoam(file);
    const MeshFormatEntry* format = mesh_format_of(file);
    if (format == nullptr)
      throw InputError("read_mesh: " + file.string() + ": " + detail::unknown_format(file) + ", or an OpenFOAM case folder)");
    switch (format->format) {
      case MeshFormat::gmsh: return read_gmsh(file);
      case MeshFormat::su2: return read_su2(file);
      case MeshFormat::cgns: return read_cgns(file);
      case MeshFormat::vtu: return read_vtu(file);
    }
    throw InputError("read_mesh: " + file.string() + ": no reader for its format");
  }();
  std::visit([&](auto& m) { detail::apply_orientation(m, file, options.orientation); }, mesh);
  return mesh;
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
  return detail::read_any_mesh(file, options);
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
      return write_new_polymesh_case(file, to_polymesh(mesh));
    } else {
      throw InputError("write_mesh: " + file.string() + ": an OpenFOAM case holds a 3D mesh (got a 2D one)");
    }
  }
  const MeshFormatEntry* format = mesh_format_of(file);
  if (format == nullptr) throw InputError("write_mesh: " + file.string() + ": " + detail::unknown_format(file) + ")");
  switch (format->format) {
    case MeshFormat::gmsh: return write_gmsh(file, mesh, GmshWriteOptions{options.msh_version, options.binary});
    case MeshFormat::su2: return write_su2(file, mesh);
    case MeshFormat::cgns: return write_cgns(file, mesh);
    case MeshFormat::vtu: return write_vtu(file, mesh, VtuFields{}, VtuOptions{options.vtu_facets});
  }
}

/// Checks, before any work, that the folder `file` is to be written into exists (an SVG
/// picture, a report); InputError naming the folder otherwise.
inline void check_output_folder(const std::filesystem::path& file) {
  const std::filesystem::path folder = file.has_parent_path() ? file.parent_path() : std::filesystem::path(".");
  std::error_code ec;
  if (!std::filesystem::is_directory(folder, ec))
    throw InputError("output " + file.string() + ": folder " + folder.string() + " does not exist");
}

/// Checks, before any work, that write_mesh() can write a mesh of element order `order` (1:
/// linear, 2: quadratic) to `file`: a known extension whose format holds that order, and an
/// existing folder. Throws InputError saying which formats would do, or naming the folder.
inline void check_mesh_output(const std::filesystem::path& file, int order = 1) {
  if (is_openfoam_target(file) || is_new_openfoam_case(file)) {
    if (order > 1)
      throw InputError("output " + file.string() + ": an OpenFOAM case holds linear cells only (expected " +
                       detail::format_extensions(order) + " for order " + std::to_string(order) + ")");
    if (!is_openfoam_target(file)) check_not_inside_case(file);
    return;
  }
  const MeshFormatEntry* format = mesh_format_of(file);
  if (format == nullptr) throw InputError("output " + file.string() + ": " + detail::unknown_format(file) + ")");
  if (!format->available)
    throw InputError("output " + file.string() + ": writing " + std::string(format->extension) + " needs the " +
                     std::string(format->library) + " library (meshmotion was built without it)");
  if (format->max_write_order != 0 && order > format->max_write_order)
    throw InputError("output " + file.string() + ": " + std::string(format->extension) + " files are written up to order " +
                     std::to_string(format->max_write_order) + " (expected " + detail::format_extensions(order) + " for order " +
                     std::to_string(order) + ")");
  check_output_folder(file);
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
extern template AnyMesh detail::read_any_mesh<0>(const std::filesystem::path&, const ReadOptions&);
extern template Mesh<2> read_mesh_as<2>(const std::filesystem::path&, const ReadOptions&);
extern template Mesh<3> read_mesh_as<3>(const std::filesystem::path&, const ReadOptions&);
extern template void write_mesh<2>(const std::filesystem::path&, const Mesh<2>&, const WriteOptions&);
extern template void write_mesh<3>(const std::filesystem::path&, const Mesh<3>&, const WriteOptions&);
}  // namespace meshmotion
#endif
