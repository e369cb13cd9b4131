#pragma once
/// \file
/// FoamCaseSummary: what mesh_info prints about an OpenFOAM case, as checkMesh shows it — its
/// points, faces and cells, the cells by shape (polyhedra, not the tetrahedra the library cuts
/// them into), its patches with their types and groups, and its zones. A report
/// (visit_fields): text, JSON and Python dicts come from one description.

#include "meshmotion/core/poly_mesh.hpp"
#include "meshmotion/core/types.hpp"

#include <algorithm>
#include <array>
#include <string>
#include <utility>
#include <vector>

namespace meshmotion {

/// One patch of the boundary file.
struct FoamPatchSummary {
  std::string name, type;
  Index faces = 0;
  std::vector<std::string> in_groups;
};

template <class F>
void visit_fields(const FoamPatchSummary& p, F&& f) {
  f("name", p.name, "the patch's name");
  f("type", p.type, "its type (patch, wall, empty, symmetryPlane, ...)");
  f("faces", p.faces, "its faces");
  f("in_groups", p.in_groups, "the boundary file's inGroups");
}

/// One cell, face or point zone.
struct FoamZoneSummary {
  std::string name, kind;
  Index size = 0;
};

template <class F>
void visit_fields(const FoamZoneSummary& z, F&& f) {
  f("name", z.name, "the zone's name");
  f("kind", z.kind, "cellZone, faceZone or pointZone");
  f("size", z.size, "its cells, faces or points");
}

/// An OpenFOAM case's own mesh (see summarize(const PolyMesh&)).
struct FoamCaseSummary {
  Index points = 0, faces = 0, internal_faces = 0, cells = 0;
  std::vector<std::pair<std::string, Index>> cell_shapes;  ///< checkMesh's shapes, in its order
  std::vector<FoamPatchSummary> patches;
  std::vector<FoamZoneSummary> zones;  ///< cell zones, then face zones, then point zones
};

template <class F>
void visit_fields(const FoamCaseSummary& s, F&& f) {
  f("points", s.points, "points");
  f("faces", s.faces, "faces");
  f("internal_faces", s.internal_faces, "of the faces: those between two cells");
  f("cells", s.cells, "cells");
  f("cell_shapes", s.cell_shapes, "cells by checkMesh's shapes: hexahedra, prisms, pyramids, tetrahedra, polyhedra");
  f("patches", s.patches, "the boundary file's patches");
  f("zones", s.zones, "cell zones, then face zones, then point zones");
}

/// The case's summary. A cell's shape is checkMesh's: by its faces' vertex counts and its own
/// vertex count (a hexahedron: six quadrilaterals on eight points); any other is a polyhedron.
[[nodiscard]] inline FoamCaseSummary summarize(const PolyMesh& poly) {
  FoamCaseSummary out{poly.points.cols(), poly.num_faces(), poly.num_internal_faces(), poly.num_cells, {}, {}, {}};
  const auto nc = static_cast<std::size_t>(poly.num_cells);
  std::vector<std::array<int, 3>> faces(nc, {0, 0, 0});  // triangles, quadrilaterals, others
  std::vector<std::vector<Index>> vertices(nc);
  const auto add = [&](Index cell, Index f) {
    const auto v = poly.face(f);
    auto& count = faces[static_cast<std::size_t>(cell)];
    ++count[v.size() == 3 ? 0 : v.size() == 4 ? 1 : 2];
    vertices[static_cast<std::size_t>(cell)].insert(vertices[static_cast<std::size_t>(cell)].end(), v.begin(), v.end());
  };
  for (Index f = 0; f < poly.num_faces(); ++f) {
    add(poly.owner[static_cast<std::size_t>(f)], f);
    if (f < poly.num_internal_faces()) add(poly.neighbour[static_cast<std::size_t>(f)], f);
  }
  // (triangles, quadrilaterals, points) of each named shape.
  constexpr std::array<std::array<int, 3>, 4> shapes{{{0, 6, 8}, {2, 3, 6}, {4, 1, 5}, {4, 0, 4}}};
  std::array<Index, 5> counts{};
  for (std::size_t c = 0; c < nc; ++c) {
    std::vector<Index>& v = vertices[c];
    std::sort(v.begin(), v.end());
    const auto points = static_cast<int>(std::unique(v.begin(), v.end()) - v.begin());
    const auto [tris, quads, others] = faces[c];
    std::size_t shape = 4;
    for (std::size_t k = 0; k < shapes.size() && others == 0; ++k)
      if (shapes[k] == std::array<int, 3>{tris, quads, points}) shape = k;
    ++counts[shape];
  }
  constexpr std::array<const char*, 5> names{"hexahedra", "prisms", "pyramids", "tetrahedra", "polyhedra"};
  for (std::size_t k = 0; k < names.size(); ++k) out.cell_shapes.emplace_back(names[k], counts[k]);
  for (const auto& p : poly.patches) out.patches.push_back({p.name, p.type, p.size, p.groups});
  const auto zones = [&](const std::vector<PolyMesh::Zone>& list, const char* kind) {
    for (const auto& z : list) out.zones.push_back({z.name, kind, static_cast<Index>(z.labels.size())});
  };
  zones(poly.cell_zones, "cellZone");
  zones(poly.face_zones, "faceZone");
  zones(poly.point_zones, "pointZone");
  return out;
}

}  // namespace meshmotion
