#pragma once
/// \file
/// OpenFOAM polyMesh reading (`constant/polyMesh/`: points, faces, owner, neighbour, boundary,
/// and the cellZones, faceZones and pointZones where the case has them):
/// ASCII and binary files (FoamFile header; `arch` label and scalar sizes), `faceList` and
/// `faceCompactList` faces, gzip-compressed files (`points.gz`, ...) when built with zlib.
/// read_polymesh() gives the face-based mesh as the files hold it, read_openfoam() the Mesh<3>
/// (io/openfoam_polymesh.hpp's to_mesh()). Malformed files give the file, the line (ASCII) or
/// byte offset (binary) and the entry; inconsistent lists (an owner list shorter than the
/// faces, a face index out of range, patches that do not cover the boundary faces) name the list.

#include "meshmotion/core/error.hpp"
#include "meshmotion/core/mesh.hpp"
#include "meshmotion/io/detail/foam_files.hpp"
#include "meshmotion/io/detail/raw_mesh.hpp"
#include "meshmotion/io/openfoam_polymesh.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace meshmotion {
namespace detail {

/// Reads the points file: "N ( (x y z) ... )" or its binary form.
[[nodiscard]] inline Points<3> read_foam_points(const std::filesystem::path& file) {
  const std::string text = read_foam_file(file);
  FoamCursor in(text, file);
  const FoamHeader h = read_foam_header(in);
  check_foam_class(in, h, {"vectorField"});
  const auto n = in.integer<Index>("point count", 0, std::numeric_limits<Index>::max());
  in.expect("(");
  // "(x y z)" takes seven bytes at least in ASCII.
  in.check_count(n, "point", h.binary ? static_cast<std::size_t>(3 * h.scalar_bytes) : 7);
  Points<3> points(3, n);
  if (h.binary && n > 0) {
    in.use_byte_offsets();
    const std::string_view bytes = in.raw(static_cast<std::size_t>(3 * n) * static_cast<std::size_t>(h.scalar_bytes), "points");
    for (Index k = 0; k < 3 * n; ++k) {
      double v = 0;
      if (h.scalar_bytes == 8) {
        std::memcpy(&v, bytes.data() + 8 * k, 8);
      } else {
        float f = 0;
        std::memcpy(&f, bytes.data() + 4 * k, 4);
        v = f;
      }
      if (!std::isfinite(v)) in.fail("point " + std::to_string(k / 3) + " has a non-finite coordinate");
      points.data()[k] = v;
    }
  } else {
    for (Index i = 0; i < n; ++i) {
      in.expect("(");
      for (int d = 0; d < 3; ++d) points(d, i) = in.real("a point coordinate");
      in.expect(")");
    }
  }
  in.expect(")");
  in.expect_end("point list");
  return points;
}

/// Reads the faces: faceList "N ( k(a b ...) ... )" or faceCompactList (offsets, then labels).
inline void read_foam_faces(const std::filesystem::path& file, PolyMesh& mesh) {
  const std::string text = read_foam_file(file);
  FoamCursor in(text, file);
  const FoamHeader h = read_foam_header(in);
  check_foam_class(in, h, {"faceList", "faceCompactList"});
  const auto cls = h.entries.find("class");
  if (h.binary || (cls != h.entries.end() && cls->second == "faceCompactList")) {
    // A uniform offset list cannot be increasing, nor a uniform vertex list name a face.
    std::vector<Index> offsets = read_label_list(in, h, "face offsets", 1);
    std::vector<Index> nodes = read_label_list(in, h, "face vertices", 3);
    if (offsets.empty() || offsets.front() != 0 || offsets.back() != static_cast<Index>(nodes.size()))
      in.fail("faceCompactList offsets do not span the vertex list (first " + std::to_string(offsets.empty() ? -1 : offsets.front()) +
              ", last " + std::to_string(offsets.empty() ? -1 : offsets.back()) + ", vertices " + std::to_string(nodes.size()) + ")");
    for (std::size_t k = 1; k < offsets.size(); ++k)
      if (offsets[k] < offsets[k - 1] + 3) in.fail("face " + std::to_string(k - 1) + " has fewer than 3 vertices");
    mesh.face_offsets = std::move(offsets);
    mesh.face_nodes = std::move(nodes);
    in.expect_end("face lists");
    return;
  }
  const auto n = in.integer<Index>("face count", 0, std::numeric_limits<Index>::max());
  in.expect("(");
  in.check_count(n, "face", 8);  // "3(a b c)"
  mesh.face_offsets.assign(1, 0);
  mesh.face_offsets.reserve(static_cast<std::size_t>(n) + 1);
  mesh.face_nodes.reserve(static_cast<std::size_t>(4 * n));
  for (Index f = 0; f < n; ++f) {
    const auto k = in.integer<Index>("a face's vertex count", 3, 1 << 20);
    in.expect("(");
    for (Index j = 0; j < k; ++j) mesh.face_nodes.push_back(in.integer<Index>("a face vertex", 0, std::numeric_limits<Index>::max()));
    in.expect(")");
    mesh.face_offsets.push_back(static_cast<Index>(mesh.face_nodes.size()));
  }
  in.expect(")");
  in.expect_end("face list");
}

/// Reads the boundary dictionary list: "N ( name { type T; nFaces N; startFace S; ... } ... )".
[[nodiscard]] inline std::vector<PolyMesh::Patch> read_foam_boundary(const std::filesystem::path& file) {
  const std::string text = read_foam_file(file);
  FoamCursor in(text, file);
  check_foam_class(in, read_foam_header(in), {"polyBoundaryMesh"});
  const auto n = in.integer<Index>("patch count", 0, 1 << 20);
  in.expect("(");
  std::vector<PolyMesh::Patch> patches;
  for (Index p = 0; p < n; ++p) {
    PolyMesh::Patch patch;
    patch.name = std::string(in.token("a patch name"));
    in.expect("{");
    bool have_faces = false, have_start = false;
    for (;;) {
      const std::string key(in.token("a patch entry or '}'"));
      if (key == "}") break;
      if (key == "nFaces") {
        patch.size = in.integer<Index>("nFaces", 0, std::numeric_limits<Index>::max());
        have_faces = true;
        in.expect(";");
      } else if (key == "startFace") {
        patch.start = in.integer<Index>("startFace", 0, std::numeric_limits<Index>::max());
        have_start = true;
        in.expect(";");
      } else {
        int depth = 0;
        std::string value;
        for (std::string_view t = in.token("';'"); depth > 0 || t != ";"; t = in.token("';'")) {
          if (t == "(" || t == "{") ++depth;
          if (t == ")" || t == "}") --depth;
          if (key == "type") value += std::string(t);
          // "inGroups List<word> 1(wall);": the words inside the parentheses.
          if (key == "inGroups" && depth == 1 && t != "(") patch.groups.emplace_back(t);
        }
        if (key == "type") patch.type = value;
      }
    }
    if (!have_faces || !have_start) in.fail("patch '" + patch.name + "' lacks " + (have_faces ? "startFace" : "nFaces"));
    patches.push_back(std::move(patch));
  }
  in.expect(")");
  in.expect_end("patch list");
  return patches;
}

/// Reads a zones file (cellZones, faceZones or pointZones: "N ( name { type ...Zone;
/// <kind>Labels List<label> M(...); flipMap List<bool> M(...); } ... )"); `kind` is "cell",
/// "face" or "point". Entries other than the labels and the flip map are skipped.
[[nodiscard]] inline std::vector<PolyMesh::Zone> read_foam_zones(const std::filesystem::path& file, const std::string& kind) {
  const std::string text = read_foam_file(file);
  FoamCursor in(text, file);
  const FoamHeader h = read_foam_header(in);
  check_foam_class(in, h, {"regIOobject", kind + "ZoneMesh"});
  const auto n = in.integer<Index>("zone count", 0, 1 << 20);
  in.expect("(");
  const std::string labels_key = kind + "Labels";
  // "List<label> 3(0 1 2)": the type word is optional before the list.
  const auto list_start = [&](std::string_view type) {
    if (in.peek() < '0' || in.peek() > '9') {
      const std::string_view word = in.token(type);
      if (word != type) in.fail("expected " + std::string(type) + " or a list (got '" + shorten_token(word) + "')");
    }
  };
  std::vector<PolyMesh::Zone> zones;
  for (Index z = 0; z < n; ++z) {
    PolyMesh::Zone zone;
    zone.name = std::string(in.token("a zone name"));
    in.expect("{");
    bool have_labels = false;
    for (;;) {
      const std::string key(in.token("a zone entry or '}'"));
      if (key == "}") break;
      if (key == labels_key) {
        list_start("List<label>");
        zone.labels = read_label_list(in, h, labels_key, 0);
        have_labels = true;
      } else if (key == "flipMap" && kind == "face") {
        list_start("List<bool>");
        const auto m = in.integer<Index>("flipMap count", 0, std::numeric_limits<Index>::max());
        if (in.peek() == '{') {
          // Uniform: allocated only for the labels already read.
          if (!have_labels || m != static_cast<Index>(zone.labels.size()))
            in.fail("face zone '" + zone.name + "': a uniform flipMap of " + std::to_string(m) + " entries where " +
                    (have_labels ? std::to_string(zone.labels.size()) + " faceLabels" : std::string("no faceLabels")) + " came before");
          in.expect("{");
          zone.flip.assign(static_cast<std::size_t>(m), static_cast<char>(in.integer<int>("a flip (0 or 1)", 0, 1)));
          in.expect("}");
        } else {
          in.expect("(");
          in.check_count(m, "flipMap", h.binary ? 1 : 2);
          zone.flip.resize(static_cast<std::size_t>(m));
          if (h.binary && m > 0) {
            in.use_byte_offsets();
            const std::string_view bytes = in.raw(static_cast<std::size_t>(m), "flipMap");
            for (std::size_t k = 0; k < zone.flip.size(); ++k) zone.flip[k] = bytes[k] != 0 ? 1 : 0;
          } else {
            for (auto& f : zone.flip) f = static_cast<char>(in.integer<int>("a flip (0 or 1)", 0, 1));
          }
          in.expect(")");
        }
      } else {
        int depth = 0;
        for (std::string_view t = in.token("';'"); depth > 0 || t != ";"; t = in.token("';'")) {
          if (t == "(" || t == "{") ++depth;
          if (t == ")" || t == "}") --depth;
        }
        continue;
      }
      in.expect(";");
    }
    if (!have_labels) in.fail(kind + " zone '" + zone.name + "' lacks " + labels_key);
    if (!zone.flip.empty() && zone.flip.size() != zone.labels.size())
      in.fail("face zone '" + zone.name + "' has " + std::to_string(zone.flip.size()) + " flipMap entries for " +
              std::to_string(zone.labels.size()) + " faces");
    zones.push_back(std::move(zone));
  }
  in.expect(")");
  in.expect_end("zone list");
  return zones;
}

/// Calls fail(message) for the first cell whose faces, each turned out of the cell, do not close
/// (OpenFOAM's checkMesh "open cells", with its threshold): a face listed the wrong way round,
/// or given to the wrong cell. Names the face whose reversal would close the cell when one does.
template <class Fail>
void check_closed_cells(const PolyMesh& mesh, Fail&& fail) {
  const auto n = static_cast<std::size_t>(mesh.num_cells);
  std::vector<Vec<3>> sum(n, Vec<3>::Zero());
  std::vector<double> total(n, 0.0);
  for (Index f = 0; f < mesh.num_faces(); ++f) {
    const auto i = static_cast<std::size_t>(f);
    const Vec<3> area = mesh.face_area(f);
    const double size = area.norm();
    const auto o = static_cast<std::size_t>(mesh.owner[i]);
    sum[o] += area;
    total[o] += size;
    if (f < mesh.num_internal_faces()) {
      const auto nb = static_cast<std::size_t>(mesh.neighbour[i]);
      sum[nb] -= area;
      total[nb] += size;
    }
  }
  constexpr double closed = 1e-6;
  for (std::size_t c = 0; c < n; ++c) {
    if (sum[c].norm() <= closed * total[c]) continue;
    std::string culprit;
    for (Index f = 0; f < mesh.num_faces() && culprit.empty(); ++f) {
      const auto i = static_cast<std::size_t>(f);
      const bool owned = static_cast<std::size_t>(mesh.owner[i]) == c;
      if (!owned && !(f < mesh.num_internal_faces() && static_cast<std::size_t>(mesh.neighbour[i]) == c)) continue;
      if ((sum[c] - (owned ? 2.0 : -2.0) * mesh.face_area(f)).norm() <= closed * total[c])
        culprit = "; face " + std::to_string(f) + " points into it, as if listed the wrong way round";
    }
    fail("cell " + std::to_string(c) + " is open: its faces' area vectors, turned out of the cell, sum to " +
         std::to_string(sum[c].norm() / total[c]) + " of their total (at most 1e-06)" + culprit);
  }
}

/// The label list of a polyMesh file (owner, neighbour).
[[nodiscard]] inline std::vector<Index> read_foam_labels(const std::filesystem::path& file, std::string_view what, Index max_uniform) {
  const std::string text = read_foam_file(file);
  FoamCursor in(text, file);
  const FoamHeader h = read_foam_header(in);
  check_foam_class(in, h, {"labelList"});
  std::vector<Index> labels = read_label_list(in, h, what, max_uniform);
  in.expect_end(std::string(what) + " list");
  return labels;
}

}  // namespace detail

namespace detail {

// read_polymesh(), a template of nothing: a program built on meshmotion::compiled links the
// reader instead of compiling it.
template <int = 0>
[[nodiscard]] PolyMesh read_polymesh_of(const std::filesystem::path& path) {
  std::filesystem::path dir = detail::polymesh_folder(path), points = dir / "points";
  std::error_code ec;
  if (const auto time = dir.empty() && std::filesystem::is_directory(path, ec) ? detail::foam_time_folder(path) : std::nullopt) {
    dir = time->constant;
    points = time->current_points();
  }
  if (dir.empty() && std::filesystem::is_directory(path / "processor0", ec))
    throw IoError(path.string() + ": a decomposed case without its whole mesh in constant/polyMesh (reconstructParMesh "
                                  "-constant makes it; or move the case inside OpenFOAM with the meshmotion plugin and -parallel): "
                                  "one processor folder moved alone would leave its interface points apart from its neighbours'");
  if (dir.empty())
    throw IoError(path.string() + ": not an OpenFOAM case, polyMesh folder or time folder of a case (no constant/polyMesh/faces "
                                  "nor faces in it)");
  PolyMesh mesh;
  mesh.points = detail::read_foam_points(points);
  detail::read_foam_faces(dir / "faces", mesh);
  // Uniform lists hold at most one entry per face.
  mesh.owner = detail::read_foam_labels(dir / "owner", "owner", mesh.num_faces());
  mesh.neighbour = detail::read_foam_labels(dir / "neighbour", "neighbour", mesh.num_faces());
  mesh.patches = detail::read_foam_boundary(dir / "boundary");

  const Index nf = mesh.num_faces(), np = mesh.points.cols();
  const auto fail = [&](const std::string& file, const std::string& what) { throw InputError((dir / file).string() + ": " + what); };
  std::vector<Index> sorted;
  for (Index f = 0; f < nf; ++f) {
    const auto face = mesh.face(f);
    for (const Index v : face)
      if (v < 0 || v >= np)
        fail("faces", "face " + std::to_string(f) + " has vertex " + std::to_string(v) + " (the mesh has " + std::to_string(np) +
                          " points, numbered from 0)");
    sorted.assign(face.begin(), face.end());
    std::sort(sorted.begin(), sorted.end());
    if (const auto twice = std::adjacent_find(sorted.begin(), sorted.end()); twice != sorted.end())
      fail("faces", "face " + std::to_string(f) + " lists vertex " + std::to_string(*twice) + " twice");
  }
  if (static_cast<Index>(mesh.owner.size()) != nf)
    fail("owner", "the owner list has " + std::to_string(mesh.owner.size()) + " entries for " + std::to_string(nf) + " faces");
  if (static_cast<Index>(mesh.neighbour.size()) > nf)
    fail("neighbour", "the neighbour list has " + std::to_string(mesh.neighbour.size()) + " entries for " + std::to_string(nf) + " faces");
  // A cell has four faces at least and a face two cells at most: no label reaches nf / 2, and
  // a corrupt one is refused here, before anything is allocated per cell.
  const Index max_cells = nf / 2;
  for (std::size_t f = 0; f < mesh.owner.size(); ++f)
    if (mesh.owner[f] < 0 || mesh.owner[f] >= max_cells)
      fail("owner", "face " + std::to_string(f) + " has owner " + std::to_string(mesh.owner[f]) + " (" + std::to_string(nf) +
                        " faces bound at most " + std::to_string(max_cells) + " cells, numbered from 0)");
  for (std::size_t f = 0; f < mesh.neighbour.size(); ++f) {
    if (mesh.neighbour[f] < 0 || mesh.neighbour[f] >= max_cells || mesh.neighbour[f] == mesh.owner[f])
      fail("neighbour", "internal face " + std::to_string(f) + " has neighbour " + std::to_string(mesh.neighbour[f]) + " (owner " +
                            std::to_string(mesh.owner[f]) + ", at most " + std::to_string(max_cells) + " cells)");
    // The face's orientation is the owner's: a swapped pair turns it into the other cell.
    if (mesh.neighbour[f] < mesh.owner[f])
      fail("neighbour", "internal face " + std::to_string(f) + " has owner " + std::to_string(mesh.owner[f]) + " and neighbour " +
                            std::to_string(mesh.neighbour[f]) + " (OpenFOAM's owner is the lower-numbered cell)");
  }
  Index cells = 0;
  for (const Index c : mesh.owner) cells = std::max(cells, c + 1);
  for (const Index c : mesh.neighbour) cells = std::max(cells, c + 1);
  std::vector<Index> faces_of(static_cast<std::size_t>(cells), 0);
  for (const Index c : mesh.owner) ++faces_of[static_cast<std::size_t>(c)];
  for (const Index c : mesh.neighbour) ++faces_of[static_cast<std::size_t>(c)];
  for (Index c = 0; c < cells; ++c)
    if (faces_of[static_cast<std::size_t>(c)] < 4)
      fail("owner", "cell " + std::to_string(c) + " is bounded by " + std::to_string(faces_of[static_cast<std::size_t>(c)]) +
                        (faces_of[static_cast<std::size_t>(c)] == 1 ? " face" : " faces") +
                        " in the owner and neighbour lists (a cell has 4 at least)");
  mesh.num_cells = cells;
  detail::check_closed_cells(mesh, [&](const std::string& what) { fail("faces", what); });
  Index next = mesh.num_internal_faces();
  for (const auto& p : mesh.patches) {
    if (p.start != next || p.start + p.size > nf)
      fail("boundary", "patch '" + p.name + "' covers faces " + std::to_string(p.start) + ".." + std::to_string(p.start + p.size - 1) +
                           " (expected to start at face " + std::to_string(next) + " of " + std::to_string(nf) + ")");
    next = p.start + p.size;
  }
  if (next != nf)
    fail("boundary", "the patches end at face " + std::to_string(next) + " (the boundary faces run to " + std::to_string(nf) + ")");
  const auto read_zones = [&](const char* kind, std::vector<PolyMesh::Zone>& zones, Index count, const char* things) {
    const std::filesystem::path file = dir / (std::string(kind) + "Zones");
    if (!std::filesystem::exists(file, ec) && !std::filesystem::exists(file.string() + ".gz", ec)) return;
    zones = detail::read_foam_zones(file, kind);
    for (const auto& z : zones)
      for (const Index label : z.labels)
        if (label < 0 || label >= count)
          fail(file.filename().string(), std::string(kind) + " zone '" + z.name + "' holds " + kind + " " + std::to_string(label) +
                                             " (the mesh has " + std::to_string(count) + " " + things + ", numbered from 0)");
  };
  read_zones("cell", mesh.cell_zones, mesh.num_cells, "cells");
  read_zones("face", mesh.face_zones, nf, "faces");
  read_zones("point", mesh.point_zones, np, "points");
  return mesh;
}

}  // namespace detail

/// Reads an OpenFOAM polyMesh from a case folder (its constant/polyMesh), a polyMesh folder
/// (a region's: `case/constant/solid/polyMesh`), or a time folder of a case (`case/0.3`, or
/// `case/0.3/solid` for a region, as OpenFOAM's tools read `-time 0.3 [-region solid]`: the
/// points of the latest time up to 0.3 where the mesh moved, else the constant ones, on the
/// constant faces). Throws IoError for a missing file, ParseError for malformed content (file and line
/// or byte offset), InputError for lists that do not fit together (naming the list and the entry).
[[nodiscard]] inline PolyMesh read_polymesh(const std::filesystem::path& path) { return detail::read_polymesh_of(path); }

/// Reads an OpenFOAM case or polyMesh folder as a Mesh<3> (read_polymesh, then to_mesh).
[[nodiscard]] inline Mesh<3> read_openfoam(const std::filesystem::path& path) {
  Mesh<3> mesh = to_mesh(read_polymesh(path));
  detail::validate_read(mesh, path);
  return mesh;
}

}  // namespace meshmotion

// The compiled library (target meshmotion::compiled, src/io_quality.cpp) holds it.
#ifdef MESHMOTION_COMPILED
namespace meshmotion {
extern template PolyMesh detail::read_polymesh_of<0>(const std::filesystem::path&);
}  // namespace meshmotion
#endif
