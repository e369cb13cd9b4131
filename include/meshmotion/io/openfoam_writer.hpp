#pragma once
/// \file
/// OpenFOAM polyMesh writing. write_polymesh_points() replaces the `points` of a case,
/// atomically, keeping the case's own header, format (ASCII or binary) and compression; the
/// faces and the rest of the case are not touched. It writes the nodes before the auxiliary
/// ones and refuses a mesh whose node count differs from the case's. Targets: a case folder
/// (its constant/polyMesh), a polyMesh folder, or a time folder of a case (`case/0.001`: its
/// polyMesh/points, created, which is where OpenFOAM looks for moved points).
/// write_polymesh() writes a whole new case's polyMesh.

#include "meshmotion/core/element.hpp"
#include "meshmotion/core/error.hpp"
#include "meshmotion/core/mesh.hpp"
#include "meshmotion/core/detail/atomic_file.hpp"
#include "meshmotion/io/detail/foam_files.hpp"
#include "meshmotion/io/detail/number_format.hpp"
#include "meshmotion/io/openfoam_polymesh.hpp"
#include "meshmotion/io/openfoam_reader.hpp"

#include <algorithm>
#include <charconv>
#include <cstring>
#include <filesystem>
#include <string>
#include <system_error>
#include <tuple>
#include <utility>
#include <vector>

namespace meshmotion {
namespace detail {

/// Appends a points list ("N ( (x y z) ... )" or its binary form) to `out`: ASCII numbers with
/// `precision` significant digits, or (0) in their shortest exact form.
inline void append_foam_points(std::string& out, const Eigen::Ref<const Points<3>>& points, const FoamHeader& h,
                               int precision = 0) {
  const Index n = points.cols();
  out += "\n\n\n";
  append_number(out, n);
  out += "\n(";
  if (h.binary) {
    const std::size_t at = out.size();
    out.resize(at + static_cast<std::size_t>(3 * n) * static_cast<std::size_t>(h.scalar_bytes));
    for (Index i = 0; i < n; ++i)
      for (int d = 0; d < 3; ++d) {
        const double v = points(d, i);
        char* dst = out.data() + at + static_cast<std::size_t>(3 * i + d) * static_cast<std::size_t>(h.scalar_bytes);
        if (h.scalar_bytes == 8) {
          std::memcpy(dst, &v, 8);
        } else {
          const auto f = static_cast<float>(v);
          std::memcpy(dst, &f, 4);
        }
      }
    out += ")\n";
    return;
  }
  out += '\n';
  char buffer[32];
  for (Index i = 0; i < n; ++i) {
    out += '(';
    for (int d = 0; d < 3; ++d) {
      if (d > 0) out += ' ';
      if (precision > 0) {
        const auto r = std::to_chars(buffer, buffer + sizeof(buffer), points(d, i), std::chars_format::general, precision);
        out.append(buffer, static_cast<std::size_t>(r.ptr - buffer));
      } else {
        append_number(out, points(d, i));
      }
    }
    out += ")\n";
  }
  out += ")\n";
}

/// The `writePrecision` of `case_dir`'s system/controlDict (the significant digits OpenFOAM
/// writes the case's fields and moved points with), or 0 when there is none.
[[nodiscard]] inline int foam_write_precision(const std::filesystem::path& case_dir) {
  const std::filesystem::path file = case_dir / "system" / "controlDict";
  std::error_code ec;
  if (case_dir.empty() || !std::filesystem::is_regular_file(file, ec)) return 0;
  const std::string text = read_foam_file(file);
  FoamCursor in(text, file);
  int depth = 0;
  while (!in.at_end()) {
    const std::string_view t = in.token("a controlDict entry");
    if (t == "{") ++depth;
    if (t == "}") --depth;
    // More digits than a double holds write the same numbers.
    if (depth == 0 && t == "writePrecision") return std::min(17, in.integer<int>("writePrecision", 1, 1000));
  }
  return 0;
}

/// Writes `text` gzip-compressed to `gz` through a temporary file and a rename.
inline void write_gzip_file(const std::filesystem::path& gz, const std::string& text) {
#ifdef MESHMOTION_HAVE_ZLIB
  write_through_temporary(gz, [&](const std::filesystem::path& tmp) {
    gzFile out = gzopen(tmp.c_str(), "wb");
    if (out == nullptr) throw IoError(gz.string() + ": cannot create the temporary file " + tmp.string());
    std::size_t done = 0;
    bool ok = true;
    while (ok && done < text.size()) {
      const auto chunk = static_cast<unsigned>(std::min<std::size_t>(text.size() - done, std::size_t{1} << 30));
      ok = gzwrite(out, text.data() + done, chunk) == static_cast<int>(chunk);
      done += chunk;
    }
    if (gzclose(out) != Z_OK || !ok) throw IoError(gz.string() + ": compressed write failed");
  });
#else
  (void)text;
  throw InputError(gz.string() + ": compressed OpenFOAM files need zlib (meshmotion was built without it)");
#endif
}

/// Writes `text` to `file` (or `file`.gz, compressed) through a temporary file and a rename.
inline void write_foam_file(const std::filesystem::path& file, const std::string& text, bool compressed) {
  if (!compressed) return write_file_atomically(file, text);
  std::filesystem::path gz = file;
  gz += ".gz";
  write_gzip_file(gz, text);
}


/// Where write_polymesh_points() writes for `target` (see the file comment), and the points
/// file whose header and node count it follows; empty when `target` is no OpenFOAM folder.
struct FoamPointsTarget {
  std::filesystem::path points;     ///< the file to write (without .gz)
  std::filesystem::path reference;  ///< the case's existing points file (without .gz)
  std::filesystem::path case_dir;   ///< the case holding them, where known
};

[[nodiscard]] inline FoamPointsTarget foam_points_target(const std::filesystem::path& target) {
  std::filesystem::path dir = polymesh_folder(target);
  if (!dir.empty()) {
    // <case>/constant/polyMesh, or a region's <case>/constant/<region>/polyMesh.
    std::filesystem::path case_dir;
    for (const auto& up : {dir.parent_path(), dir.parent_path().parent_path()})
      if (case_dir.empty() && up.filename() == "constant")
        case_dir = up.parent_path().empty() ? std::filesystem::path(".") : up.parent_path();
    return {dir / "points", dir / "points", case_dir};
  }
  if (const auto time = foam_time_folder(target)) return {time->points(), time->constant / "points", time->case_dir};
  return {};
}

}  // namespace detail

/// Whether write_mesh() treats `path` as an OpenFOAM output whose points it replaces (a case,
/// polyMesh or time folder).
[[nodiscard]] inline bool is_openfoam_target(const std::filesystem::path& path) {
  return !detail::foam_points_target(path).points.empty();
}

/// Whether write_mesh() writes a whole new OpenFOAM case at `path`: a path without extension
/// that does not exist or is an empty folder.
[[nodiscard]] inline bool is_new_openfoam_case(const std::filesystem::path& path) {
  std::error_code ec;
  if (path.empty() || !path.extension().empty() || is_openfoam_target(path)) return false;
  if (!std::filesystem::exists(path, ec)) return true;
  return std::filesystem::is_directory(path, ec) && std::filesystem::is_empty(path, ec);
}

namespace detail {

/// A points file about to replace `file`: `reference`'s header (its format, its location set
/// to `location` when `file` is elsewhere) and compression, with `points`. InputError (naming
/// `target`) when the reference holds another number of points.
struct PreparedPoints {
  std::filesystem::path file;
  std::string text;
  bool compressed = false;
};
[[nodiscard]] inline PreparedPoints prepare_foam_points(const std::filesystem::path& file, const std::filesystem::path& reference,
                                                        const std::string& location, const Eigen::Ref<const Points<3>>& points,
                                                        int precision, const std::string& target) {
  const std::string reference_text = read_foam_file(reference);
  FoamCursor in(reference_text, reference);
  const FoamHeader h = read_foam_header(in);
  const auto expected = in.integer<Index>("point count", 0, Index{1} << 40);
  if (points.cols() != expected)
    throw InputError(target + ": the mesh has " + std::to_string(points.cols()) + " points, the case " + std::to_string(expected) +
                     " (" + reference.string() + "): not this case's mesh");
  std::string text(reference_text.substr(0, h.data_offset));
  if (file != reference) {
    const std::size_t at = text.find("location");
    if (at != std::string::npos) text.replace(at, text.find(';', at) - at, "location    \"" + location + "\"");
  }
  append_foam_points(text, points, h, precision);
  text += "\n\n// ************************************************************************* //\n";
  return {file, std::move(text), foam_file_is_compressed(reference)};
}

/// The processor folders of a decomposed case (processor0, processor1, ...), in rank order;
/// empty when it is not decomposed. InputError for a collated decomposition (processorsN).
[[nodiscard]] inline std::vector<std::filesystem::path> foam_processor_folders(const std::filesystem::path& case_dir) {
  std::vector<std::pair<long, std::filesystem::path>> found;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(case_dir, ec)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind("processors", 0) == 0 && entry.is_directory(ec))
      throw InputError(entry.path().string() + ": a collated decomposition, which meshmotion does not write into "
                       "(reconstructParMesh first, or decompose uncollated)");
    if (name.rfind("processor", 0) != 0 || name.size() == 9 || !entry.is_directory(ec)) continue;
    long rank = 0;
    const auto [end, bad] = std::from_chars(name.data() + 9, name.data() + name.size(), rank);
    if (bad == std::errc() && end == name.data() + name.size()) found.emplace_back(rank, entry.path());
  }
  std::sort(found.begin(), found.end());
  std::vector<std::filesystem::path> out;
  for (auto& [rank, path] : found) out.push_back(std::move(path));
  return out;
}

}  // namespace detail

/// Replaces the points of the OpenFOAM case at `target` by the mesh's nodes (those before the
/// auxiliary ones), atomically, with the case's header, format and compression. In a
/// decomposed case (processor0, processor1, ... beside the whole mesh), each processor's points
/// are replaced in its own folder as well, through its `pointProcAddressing`, so that a
/// `-parallel` run reads the moved mesh too; every file is checked before any is written.
/// Throws InputError when `target` is not an OpenFOAM folder, when it is a processor folder
/// (one rank's part moved alone would leave its interface points apart from its
/// neighbours'), when the mesh has high-order elements or a node count other than the case's,
/// or a processor's addressing does not fit; IoError when writing fails.
inline void write_polymesh_points(const std::filesystem::path& target, const Mesh<3>& mesh) {
  validate(mesh);
  const detail::FoamPointsTarget where = detail::foam_points_target(target);
  if (where.points.empty())
    throw InputError(target.string() + ": not an OpenFOAM case, polyMesh folder or time folder of a case (nowhere to write points)");
  for (const auto* list : {&mesh.cells, &mesh.facets})
    for (const auto& b : *list)
      if (order(b.type) > 1) throw InputError(target.string() + ": OpenFOAM meshes are linear (the mesh has " + std::string(name(b.type)) + ")");
  const std::string case_name = where.case_dir.filename().string();
  if (case_name.rfind("processor", 0) == 0 && case_name.size() > 9)
    throw InputError(target.string() + ": one processor folder of a decomposed case: moved alone, its interface points would "
                     "leave its neighbours' (move the whole case: its processor folders follow)");
  const Index n = mesh.num_nodes() - mesh.num_auxiliary_nodes;
  const int precision = detail::foam_write_precision(where.case_dir);
  const auto folder_of = [](const std::filesystem::path& file, const std::filesystem::path& base) {
    return file.parent_path().lexically_relative(base).generic_string();
  };
  std::vector<detail::PreparedPoints> files{detail::prepare_foam_points(
      where.points, where.reference, folder_of(where.points, where.case_dir), mesh.points.leftCols(n), precision, target.string())};
  if (!where.case_dir.empty()) {
    const std::filesystem::path constant = where.reference.parent_path().lexically_relative(where.case_dir);
    const std::filesystem::path moved = where.points.lexically_relative(where.case_dir);
    for (const std::filesystem::path& processor : detail::foam_processor_folders(where.case_dir)) {
      const std::filesystem::path addressing_file = processor / constant / "pointProcAddressing";
      std::error_code ec;
      if (!std::filesystem::exists(addressing_file, ec) && !std::filesystem::exists(addressing_file.string() + ".gz", ec))
        throw InputError(processor.string() + ": a processor folder without " + (constant / "pointProcAddressing").string() +
                         " (decomposePar writes it): its points cannot follow the case's");
      const std::vector<Index> addressing = detail::read_foam_labels(addressing_file, "pointProcAddressing", 0);
      Points<3> local(3, static_cast<Index>(addressing.size()));
      for (std::size_t i = 0; i < addressing.size(); ++i) {
        if (addressing[i] < 0 || addressing[i] >= n)
          throw InputError(addressing_file.string() + ": entry " + std::to_string(i) + " is point " + std::to_string(addressing[i]) +
                           " (the case has " + std::to_string(n) + ")");
        local.col(static_cast<Index>(i)) = mesh.points.col(addressing[i]);
      }
      files.push_back(detail::prepare_foam_points(processor / moved, processor / constant / "points", folder_of(processor / moved, processor),
                                                  local, precision, processor.string()));
    }
  }
  // Written as a set: a failed write (a full disk) leaves every points file as it was and
  // removes the folders it made, so no empty time folder is left for -latestTime to take.
  detail::OutputSet outputs;
  std::vector<std::filesystem::path> created;
  try {
    for (const detail::PreparedPoints& f : files) {
      std::error_code ec;
      std::filesystem::path first_new;
      for (std::filesystem::path p = f.file.parent_path(); !p.empty() && !std::filesystem::exists(p, ec); p = p.parent_path()) first_new = p;
      std::filesystem::create_directories(f.file.parent_path(), ec);
      if (!first_new.empty()) created.push_back(first_new);
      if (ec) throw IoError(f.file.parent_path().string() + ": cannot create the folder (" + ec.message() + ")");
      std::filesystem::path file = f.file;
      if (f.compressed) file += ".gz";
      outputs.stage(file, [&](const std::filesystem::path& tmp) {
        if (f.compressed) detail::write_gzip_file(tmp, f.text);
        else detail::write_file_atomically(tmp, f.text);
      });
    }
    outputs.commit();
  } catch (...) {
    for (const auto& folder : created) {
      std::error_code ignored;
      std::filesystem::remove_all(folder, ignored);
    }
    throw;
  }
}

/// Options of write_polymesh().
struct PolyMeshWriteOptions {
  bool binary = false;      ///< binary lists (faces as faceCompactList), else ASCII
  bool compressed = false;  ///< gzip every file (needs zlib)
};

/// Writes a whole polyMesh (points, faces, owner, neighbour, boundary, and its zones when it has
/// any) into `case_dir`'s
/// constant/polyMesh, each file through a temporary file and a rename. The faces must be
/// ordered as OpenFOAM requires (internal faces first, then each patch's); InputError otherwise.
inline void write_polymesh(const std::filesystem::path& case_dir, const PolyMesh& mesh, const PolyMeshWriteOptions& options = {}) {
  const Index nf = mesh.num_faces();
  if (static_cast<Index>(mesh.owner.size()) != nf || mesh.num_internal_faces() > nf)
    throw InputError("write_polymesh: " + std::to_string(mesh.owner.size()) + " owners and " + std::to_string(mesh.neighbour.size()) +
                     " neighbours for " + std::to_string(nf) + " faces");
  Index next = mesh.num_internal_faces();
  for (const auto& p : mesh.patches) {
    if (p.start != next) throw InputError("write_polymesh: patch '" + p.name + "' starts at face " + std::to_string(p.start) +
                                          " (expected " + std::to_string(next) + ")");
    next += p.size;
  }
  if (next != nf) throw InputError("write_polymesh: the patches end at face " + std::to_string(next) + " of " + std::to_string(nf));
  const auto check_word = [](const std::string& what, const std::string& word) {
    if (word.empty() || word.find_first_of(" \t\n\"';{}()/\\") != std::string::npos)
      throw InputError("write_polymesh: " + what + " name '" + word + "' is not an OpenFOAM word (no blanks, quotes, ;, braces, parentheses or slashes)");
  };
  for (const auto& p : mesh.patches) check_word("patch", p.name);
  for (const auto& [list, kind, count] : {std::tuple{&mesh.cell_zones, "cell", mesh.num_cells}, std::tuple{&mesh.face_zones, "face", nf},
                                          std::tuple{&mesh.point_zones, "point", mesh.points.cols()}})
    for (const auto& z : *list) {
      check_word(std::string(kind) + " zone", z.name);
      for (const Index label : z.labels)
        if (label < 0 || label >= count)
          throw InputError("write_polymesh: " + std::string(kind) + " zone '" + z.name + "' holds " + kind + " " + std::to_string(label) +
                           " (the mesh has " + std::to_string(count) + ")");
      if (!z.flip.empty() && z.flip.size() != z.labels.size())
        throw InputError("write_polymesh: face zone '" + z.name + "' has " + std::to_string(z.flip.size()) + " flips for " +
                         std::to_string(z.labels.size()) + " faces");
    }
#ifndef MESHMOTION_HAVE_ZLIB
  if (options.compressed) throw InputError("write_polymesh: compressed files need zlib (meshmotion was built without it)");
#endif
  const std::filesystem::path dir = case_dir / "constant" / "polyMesh";
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw IoError(dir.string() + ": cannot create the folder (" + ec.message() + ")");
  detail::FoamHeader h;
  h.binary = options.binary;
  h.label_bytes = 4;
  if (mesh.points.cols() > std::numeric_limits<std::int32_t>::max() || static_cast<Index>(mesh.face_nodes.size()) > std::numeric_limits<std::int32_t>::max())
    h.label_bytes = 8;
  const auto header = [&](const char* cls, const char* object, bool binary) {
    return std::string("FoamFile\n{\n    version     2.0;\n    format      ") + (binary ? "binary" : "ascii") +
           ";\n    arch        \"LSB;label=" + std::to_string(8 * h.label_bytes) + ";scalar=64\";\n    class       " + cls +
           ";\n    location    \"constant/polyMesh\";\n    object      " + object + ";\n}\n";
  };
  const auto end = std::string("\n\n// ************************************************************************* //\n");
  const auto labels = [&](std::string& out, std::span<const Index> v) {
    out += "\n";
    detail::append_number(out, static_cast<Index>(v.size()));
    out += "\n(";
    if (h.binary) {
      for (const Index x : v) {
        if (h.label_bytes == 4) {
          const auto i = static_cast<std::int32_t>(x);
          out.append(reinterpret_cast<const char*>(&i), 4);
        } else {
          const auto i = static_cast<std::int64_t>(x);
          out.append(reinterpret_cast<const char*>(&i), 8);
        }
      }
      out += ")\n";
    } else {
      out += '\n';
      for (const Index x : v) {
        detail::append_number(out, x);
        out += '\n';
      }
      out += ")\n";
    }
  };
  std::string points = header("vectorField", "points", h.binary);
  detail::append_foam_points(points, mesh.points, h);
  detail::write_foam_file(dir / "points", points + end, options.compressed);

  std::string faces = header(h.binary ? "faceCompactList" : "faceList", "faces", h.binary);
  if (h.binary) {
    labels(faces, mesh.face_offsets);
    labels(faces, mesh.face_nodes);
  } else {
    faces += "\n";
    detail::append_number(faces, nf);
    faces += "\n(\n";
    for (Index f = 0; f < nf; ++f) {
      const auto v = mesh.face(f);
      detail::append_number(faces, static_cast<Index>(v.size()));
      faces += '(';
      for (std::size_t k = 0; k < v.size(); ++k) {
        if (k > 0) faces += ' ';
        detail::append_number(faces, v[k]);
      }
      faces += ")\n";
    }
    faces += ")\n";
  }
  detail::write_foam_file(dir / "faces", faces + end, options.compressed);
  std::string owner = header("labelList", "owner", h.binary);
  labels(owner, mesh.owner);
  detail::write_foam_file(dir / "owner", owner + end, options.compressed);
  std::string neighbour = header("labelList", "neighbour", h.binary);
  labels(neighbour, mesh.neighbour);
  detail::write_foam_file(dir / "neighbour", neighbour + end, options.compressed);
  std::string boundary = header("polyBoundaryMesh", "boundary", false) + "\n" + std::to_string(mesh.patches.size()) + "\n(\n";
  for (const auto& p : mesh.patches) {
    boundary += "    " + p.name + "\n    {\n        type            " + (p.type.empty() ? std::string("patch") : p.type) + ";\n";
    if (!p.groups.empty()) {
      boundary += "        inGroups        List<word> " + std::to_string(p.groups.size()) + "(";
      for (std::size_t g = 0; g < p.groups.size(); ++g) boundary += (g == 0 ? "" : " ") + p.groups[g];
      boundary += ");\n";
    }
    boundary += "        nFaces          " + std::to_string(p.size) + ";\n        startFace       " + std::to_string(p.start) +
                ";\n    }\n";
  }
  detail::write_foam_file(dir / "boundary", boundary + ")\n" + end, options.compressed);
  // Zones in ASCII whatever the lists' format: small beside the faces, and readable.
  const auto zones = [&](const std::vector<PolyMesh::Zone>& list, const std::string& kind) {
    if (list.empty()) return;
    std::string text = header("regIOobject", (kind + "Zones").c_str(), false) + "\n" + std::to_string(list.size()) + "\n(\n";
    const auto values = [&](const char* key, const char* type, const auto& v) {
      text += std::string("    ") + key + " " + type + "\n";
      detail::append_number(text, static_cast<Index>(v.size()));
      text += "\n(\n";
      for (const auto x : v) {
        detail::append_number(text, static_cast<Index>(x));
        text += '\n';
      }
      text += ")\n;\n";
    };
    for (const auto& z : list) {
      text += z.name + "\n{\n    type " + kind + "Zone;\n";
      values((kind + "Labels").c_str(), "List<label>", z.labels);
      if (kind == "face") {
        if (z.flip.empty()) values("flipMap", "List<bool>", std::vector<char>(z.labels.size(), 0));
        else values("flipMap", "List<bool>", z.flip);
      }
      text += "}\n";
    }
    detail::write_foam_file(dir / (kind + "Zones"), text + ")\n" + end, options.compressed);
  };
  zones(mesh.cell_zones, "cell");
  zones(mesh.face_zones, "face");
  zones(mesh.point_zones, "point");
}

/// Refuses a new case inside an existing one (`case/0.3/polyMesh`, `case/latest`): OpenFOAM
/// reads nothing there, and a moved mesh meant for the case would be lost in it.
inline void check_not_inside_case(const std::filesystem::path& target) {
  std::error_code ec;
  const std::filesystem::path full = std::filesystem::absolute(target, ec);
  for (std::filesystem::path up = full.parent_path(); !up.empty() && up != up.root_path(); up = up.parent_path())
    if (!detail::polymesh_folder(up).empty())
      throw InputError(target.string() + ": inside the OpenFOAM case " + up.string() +
                       " (a new case is not written into another: give a time folder of it, such as " + (up / "0.3").string() +
                       ", or a folder outside it)");
}

/// Writes a whole new case at `case_dir`, a path that does not exist or an empty folder, as
/// one step: write_polymesh() into a temporary folder beside it, renamed into place once
/// complete, so a full disk or a killed run leaves no half case (points and faces without
/// owner). InputError when `case_dir` holds something or lies inside another case
/// (check_not_inside_case()), IoError when writing fails.
inline void write_new_polymesh_case(const std::filesystem::path& case_dir, const PolyMesh& mesh,
                                    const PolyMeshWriteOptions& options = {}) {
  // "out/" names the folder "out": its temporary goes beside it, not into it.
  const std::filesystem::path target = case_dir.has_filename() ? case_dir : case_dir.parent_path();
  std::error_code ec;
  if (std::filesystem::exists(target, ec) && !(std::filesystem::is_directory(target, ec) && std::filesystem::is_empty(target, ec)))
    throw InputError(target.string() + ": not empty (a new OpenFOAM case is written into a new or empty folder)");
  check_not_inside_case(target);
  detail::remove_stale_temporaries(target);
  const std::filesystem::path tmp = detail::temporary_path_for(target);
  try {
    write_polymesh(tmp, mesh, options);
    std::filesystem::remove(target, ec);  // the empty folder, if any
    std::filesystem::rename(tmp, target, ec);
    if (ec) throw IoError(target.string() + ": cannot rename the case written at " + tmp.string() + " into place (" + ec.message() + ")");
  } catch (...) {
    std::filesystem::remove_all(tmp, ec);
    throw;
  }
}

}  // namespace meshmotion
