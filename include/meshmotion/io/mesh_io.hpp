#pragma once
/// \file
/// Reading and writing meshes by file extension: .msh (Gmsh 2.2/4.1, ASCII or binary, detected
/// on reading), .su2 (SU2), and .vtu (VTK, write only).

#include "meshmotion/core/error.hpp"
#include "meshmotion/core/mesh.hpp"
#include "meshmotion/io/any_mesh.hpp"
#include "meshmotion/io/gmsh_reader.hpp"
#include "meshmotion/io/gmsh_writer.hpp"
#include "meshmotion/io/su2_reader.hpp"
#include "meshmotion/io/su2_writer.hpp"
#include "meshmotion/io/vtu_writer.hpp"

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

/// Reads a mesh, choosing the format by extension (.msh or .su2). The result is 3D if the file
/// holds 3D elements (SU2: NDIME 3), else 2D. The mesh is validated.
/// Throws InputError for an unknown extension, IoError for an unreadable file, ParseError (file
/// and line or byte offset) for malformed content, InputError for an invalid mesh (a 2D mesh
/// with nonzero z names the first such node).
[[nodiscard]] inline AnyMesh read_mesh(const std::filesystem::path& file) {
  const std::string ext = detail::lower_extension(file);
  if (ext == ".msh") return read_gmsh(file);
  if (ext == ".su2") return read_su2(file);
  throw InputError("read_mesh: " + file.string() + ": unknown mesh format '" + ext + "' (expected .msh or .su2)");
}

/// Reads a mesh that must have dimension Dim; throws InputError when the file's differs, and
/// as read_mesh() otherwise.
template <int Dim>
[[nodiscard]] Mesh<Dim> read_mesh_as(const std::filesystem::path& file) {
  AnyMesh any = read_mesh(file);
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

/// Writes a mesh, choosing the format by extension (.msh, .su2 or .vtu), through a temporary
/// file in the same folder and a rename. Throws InputError for an unknown extension or an
/// invalid mesh (nothing is written), IoError when the file cannot be written.
template <int Dim>
void write_mesh(const std::filesystem::path& file, const Mesh<Dim>& mesh, const WriteOptions& options = {}) {
  const std::string ext = detail::lower_extension(file);
  if (ext == ".msh") return write_gmsh(file, mesh, GmshWriteOptions{options.msh_version, options.binary});
  if (ext == ".su2") return write_su2(file, mesh);
  if (ext == ".vtu") return write_vtu(file, mesh, VtuFields{}, VtuOptions{options.vtu_facets});
  throw InputError("write_mesh: " + file.string() + ": unknown mesh format '" + ext + "' (expected .msh, .su2 or .vtu)");
}

/// Writes whichever mesh `mesh` holds, as write_mesh().
inline void write_mesh(const std::filesystem::path& file, const AnyMesh& mesh, const WriteOptions& options = {}) {
  std::visit([&](const auto& m) { write_mesh(file, m, options); }, mesh);
}

}  // namespace meshmotion
