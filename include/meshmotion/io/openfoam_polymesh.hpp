#pragma once
/// \file
/// The conversions between OpenFOAM's polyhedral model (core/poly_mesh.hpp) and Mesh<3>:
/// to_mesh() gives the Mesh<3> (standard elements when every cell is one, else tetrahedra
/// around auxiliary centre nodes), to_polymesh() the polyMesh of a linear Mesh<3>.
/// Reading and writing the files: io/openfoam_reader.hpp, io/openfoam_writer.hpp.

#include "meshmotion/core/element.hpp"
#include "meshmotion/core/error.hpp"
#include "meshmotion/core/mesh.hpp"
#include "meshmotion/core/poly_mesh.hpp"
#include "meshmotion/core/topology.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <map>
#include <span>
#include <string>
#include <unordered_map>
#include <vector>

namespace meshmotion {
namespace detail {

/// The faces of a cell that may be a standard element: at most six, of three or four
/// vertices, each turned outward. Fixed storage: to_mesh() fills one per cell.
struct SmallCell {
  std::array<std::array<Index, 4>, 6> faces{};
  std::array<int, 6> sizes{};
  int count = 0;

  /// Adds face `v` (reversed when `flip`); false when the cell can no longer be standard.
  bool add(std::span<const Index> v, bool flip) {
    if (count == 6 || v.size() < 3 || v.size() > 4) return false;
    auto& f = faces[static_cast<std::size_t>(count)];
    for (std::size_t k = 0; k < v.size(); ++k) f[k] = flip ? v[v.size() - 1 - k] : v[k];
    sizes[static_cast<std::size_t>(count++)] = static_cast<int>(v.size());
    return true;
  }
};

/// A cell as one of the catalogue's linear types, from its faces turned outward; false when
/// the cell is not a tetrahedron, pyramid, prism or hexahedron.
[[nodiscard]] inline bool match_cell(const SmallCell& cell, ElementType& type, std::array<Index, 8>& nodes) {
  int tris = 0, quads = 0;
  std::array<Index, 24> all{};
  std::size_t n_all = 0;
  for (int i = 0; i < cell.count; ++i) {
    (cell.sizes[static_cast<std::size_t>(i)] == 3 ? tris : quads) += 1;
    for (int k = 0; k < cell.sizes[static_cast<std::size_t>(i)]; ++k) all[n_all++] = cell.faces[static_cast<std::size_t>(i)][static_cast<std::size_t>(k)];
  }
  std::sort(all.begin(), all.begin() + static_cast<std::ptrdiff_t>(n_all));
  const auto num_vertices_of_cell = static_cast<std::size_t>(std::unique(all.begin(), all.begin() + static_cast<std::ptrdiff_t>(n_all)) - all.begin());
  const auto face = [&](int i) { return std::span<const Index>(cell.faces[static_cast<std::size_t>(i)].data(), static_cast<std::size_t>(cell.sizes[static_cast<std::size_t>(i)])); };
  const auto first_with = [&](int size) {
    for (int i = 0; i < cell.count; ++i)
      if (cell.sizes[static_cast<std::size_t>(i)] == size) return face(i);
    return face(0);
  };
  // For each vertex of `base`, the vertex joined to it by an edge of the cell and not on
  // `base`, in one pass over the edges; -1 where there is none or more than one.
  const auto up = [&](std::span<const Index> base, std::array<Index, 4>& tops) {
    tops.fill(-2);
    const auto on_base = [&](Index v) {
      for (std::size_t k = 0; k < base.size(); ++k)
        if (base[k] == v) return static_cast<int>(k);
      return -1;
    };
    const auto link = [&](int k, Index other) {
      Index& t = tops[static_cast<std::size_t>(k)];
      t = t == -2 || t == other ? other : -1;
    };
    for (int i = 0; i < cell.count; ++i) {
      const auto f = face(i);
      for (std::size_t k = 0; k < f.size(); ++k) {
        const Index a = f[k], b = f[(k + 1) % f.size()];
        const int ka = on_base(a), kb = on_base(b);
        if (ka >= 0 && kb < 0) link(ka, b);
        if (kb >= 0 && ka < 0) link(kb, a);
      }
    }
  };
  std::array<Index, 4> tops{};
  if (tris == 4 && quads == 0 && num_vertices_of_cell == 4) {
    const auto b = face(0);  // outward (a, b, c) is our facet (0, 2, 1)
    up(b, tops);
    nodes = {b[0], b[2], b[1], tops[0], 0, 0, 0, 0};
    type = ElementType::tet4;
  } else if (tris == 0 && quads == 6 && num_vertices_of_cell == 8) {
    const auto b = face(0);  // outward (a, b, c, d) is our facet (0, 3, 2, 1)
    up(b, tops);
    nodes = {b[0], b[3], b[2], b[1], tops[0], tops[3], tops[2], tops[1]};
    type = ElementType::hex8;
  } else if (tris == 2 && quads == 3 && num_vertices_of_cell == 6) {
    const auto b = first_with(3);  // outward (a, b, c) is our facet (0, 2, 1)
    up(b, tops);
    nodes = {b[0], b[2], b[1], tops[0], tops[2], tops[1], 0, 0};
    type = ElementType::prism6;
  } else if (tris == 4 && quads == 1 && num_vertices_of_cell == 5) {
    const auto b = first_with(4);  // outward (a, b, c, d) is our facet (0, 3, 2, 1)
    Index apex = -1;
    for (std::size_t k = 0; k < num_vertices_of_cell; ++k)
      if (std::find(b.begin(), b.end(), all[k]) == b.end()) apex = all[k];
    nodes = {b[0], b[3], b[2], b[1], apex, 0, 0, 0};
    type = ElementType::pyramid5;
  } else {
    return false;
  }
  for (int k = 0; k < num_vertices(type); ++k)
    if (nodes[static_cast<std::size_t>(k)] < 0) return false;
  return true;
}

}  // namespace detail

/// The Mesh<3> of a polyMesh: its cells as tetrahedra, pyramids, prisms and hexahedra when
/// they all are, else every cell cut into tetrahedra around auxiliary centre nodes; patches as
/// facet groups; each cell, face or point zone as a group of dimension 0 holding its nodes
/// (point elements in `lower`; a cell zone's and a face zone's include the auxiliary nodes
/// inside them), named as the zone unless a patch or another zone has that name, then
/// `cellZone:NAME`, `faceZone:NAME` or `pointZone:NAME`. See the file comment. The auxiliary nodes are, in this order, the centres of
/// the faces of more than three points, in face order, then every cell's centre, in cell order.
/// `cut_every_cell` cuts them even when every cell has a standard shape: a rank of a decomposed
/// case must cut its cells as the whole case is cut, whatever shapes the rank itself holds.
[[nodiscard]] inline Mesh<3> to_mesh(const PolyMesh& poly, bool cut_every_cell = false) {
  const Index nc = poly.num_cells, nf = poly.num_faces(), np = poly.points.cols();
  // Cell -> faces (CSR), each face oriented out of the cell.
  std::vector<Index> start(static_cast<std::size_t>(nc) + 1, 0);
  for (Index f = 0; f < nf; ++f) {
    ++start[static_cast<std::size_t>(poly.owner[static_cast<std::size_t>(f)]) + 1];
    if (f < poly.num_internal_faces()) ++start[static_cast<std::size_t>(poly.neighbour[static_cast<std::size_t>(f)]) + 1];
  }
  for (std::size_t c = 0; c < static_cast<std::size_t>(nc); ++c) start[c + 1] += start[c];
  std::vector<Index> cell_faces(static_cast<std::size_t>(start.back()));  // face index, negative-1 when reversed
  {
    std::vector<Index> fill(start.begin(), start.end() - 1);
    for (Index f = 0; f < nf; ++f) {
      cell_faces[static_cast<std::size_t>(fill[static_cast<std::size_t>(poly.owner[static_cast<std::size_t>(f)])]++)] = f;
      if (f < poly.num_internal_faces())
        cell_faces[static_cast<std::size_t>(fill[static_cast<std::size_t>(poly.neighbour[static_cast<std::size_t>(f)])]++)] = -f - 1;
    }
  }
  const auto outward = [&](Index entry) {
    const Index f = entry >= 0 ? entry : -entry - 1;
    const auto v = poly.face(f);
    std::vector<Index> out(v.begin(), v.end());
    if (entry < 0) std::reverse(out.begin(), out.end());
    return out;
  };

  Mesh<3> mesh;
  mesh.points = poly.points;
  mesh.first_node_id = 0;  // OpenFOAM's point labels
  std::vector<ElementType> types(static_cast<std::size_t>(nc));
  std::vector<std::array<Index, 8>> matched(static_cast<std::size_t>(nc));
  bool all_matched = !cut_every_cell;
  for (Index c = 0; c < nc && all_matched; ++c) {
    detail::SmallCell cell;
    for (Index k = start[static_cast<std::size_t>(c)]; k < start[static_cast<std::size_t>(c) + 1] && all_matched; ++k) {
      const Index entry = cell_faces[static_cast<std::size_t>(k)];
      all_matched = cell.add(poly.face(entry >= 0 ? entry : -entry - 1), entry < 0);
    }
    all_matched = all_matched && cell.count > 0 &&
                  detail::match_cell(cell, types[static_cast<std::size_t>(c)], matched[static_cast<std::size_t>(c)]);
  }
  for (std::size_t p = 0; p < poly.patches.size(); ++p) {
    const PolyMesh::Patch& patch = poly.patches[p];
    PhysicalGroup g{2, static_cast<int>(p) + 1, patch.name, patch.groups};
    if (!patch.type.empty() && patch.type != "patch" && std::find(g.in_groups.begin(), g.in_groups.end(), patch.type) == g.in_groups.end())
      g.in_groups.push_back(patch.type);
    mesh.groups.push_back(std::move(g));
  }
  const auto patch_tag = [&](Index f) {
    for (std::size_t p = 0; p < poly.patches.size(); ++p)
      if (f >= poly.patches[p].start && f < poly.patches[p].start + poly.patches[p].size) return static_cast<int>(p) + 1;
    return 0;
  };

  // Each zone as a group of the nodes it holds: point elements in `lower`, tagged after the
  // patches; `add_nodes(kind, label, out)` gives a cell's or a face's nodes.
  const auto add_zones = [&](auto&& add_nodes) {
    const auto taken = [&](const std::string& name) {
      return std::count_if(mesh.groups.begin(), mesh.groups.end(), [&](const PhysicalGroup& g) { return g.name == name; }) +
             std::count_if(poly.cell_zones.begin(), poly.cell_zones.end(), [&](const PolyMesh::Zone& z) { return z.name == name; }) +
             std::count_if(poly.face_zones.begin(), poly.face_zones.end(), [&](const PolyMesh::Zone& z) { return z.name == name; }) +
             std::count_if(poly.point_zones.begin(), poly.point_zones.end(), [&](const PolyMesh::Zone& z) { return z.name == name; });
    };
    std::vector<std::string> names;  // decided before any zone's group is added
    for (const auto* zones : {&poly.cell_zones, &poly.face_zones, &poly.point_zones})
      for (const auto& z : *zones) {
        const char* kind = zones == &poly.cell_zones ? "cellZone:" : zones == &poly.face_zones ? "faceZone:" : "pointZone:";
        names.push_back(taken(z.name) > 1 ? kind + z.name : z.name);
      }
    std::size_t k = 0;
    std::vector<Index> nodes;
    for (const auto* zones : {&poly.cell_zones, &poly.face_zones, &poly.point_zones})
      for (const auto& z : *zones) {
        nodes.clear();
        for (const Index label : z.labels) add_nodes(zones == &poly.cell_zones ? 3 : zones == &poly.face_zones ? 2 : 0, label, nodes);
        std::sort(nodes.begin(), nodes.end());
        nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
        const int tag = static_cast<int>(mesh.groups.size()) + 1;
        mesh.groups.push_back({0, tag, names[k++]});
        ElementBlock& b = mesh.block(ElementType::point1);
        for (const Index v : nodes) b.add(std::span<const Index>(&v, 1), tag);
      }
  };

  if (all_matched) {
    for (Index c = 0; c < nc; ++c) {
      ElementBlock& b = mesh.block(types[static_cast<std::size_t>(c)]);
      b.add(std::span<const Index>(matched[static_cast<std::size_t>(c)].data(), static_cast<std::size_t>(num_nodes(b.type))));
      b.ids.push_back(c + 1);
    }
    for (Index f = poly.num_internal_faces(); f < nf; ++f) {
      const auto v = poly.face(f);
      ElementBlock& b = mesh.block(v.size() == 3 ? ElementType::tri3 : ElementType::quad4);
      b.add(v, patch_tag(f));
      b.ids.push_back(nc + f + 1);
    }
    add_zones([&](int kind, Index label, std::vector<Index>& out) {
      if (kind == 3) {
        const auto& m = matched[static_cast<std::size_t>(label)];
        out.insert(out.end(), m.begin(), m.begin() + num_nodes(types[static_cast<std::size_t>(label)]));
      } else if (kind == 2) {
        const auto v = poly.face(label);
        out.insert(out.end(), v.begin(), v.end());
      } else {
        out.push_back(label);
      }
    });
    if (ElementBlock* points = mesh.lower.empty() ? nullptr : &mesh.block(ElementType::point1))
      for (Index e = 0; e < points->size(); ++e) points->ids.push_back(nc + nf + 1 + e);
    return mesh;
  }

  // Tetrahedra around each cell's centre; faces of more than three vertices around theirs.
  std::vector<Index> face_centre(static_cast<std::size_t>(nf), -1);
  std::vector<Vec<3>> extra;
  for (Index f = 0; f < nf; ++f) {
    const auto v = poly.face(f);
    if (v.size() == 3) continue;
    Vec<3> sum = Vec<3>::Zero();
    for (const Index i : v) sum += poly.points.col(i);
    face_centre[static_cast<std::size_t>(f)] = np + static_cast<Index>(extra.size());
    extra.push_back(sum / static_cast<double>(v.size()));
  }
  ElementBlock& tets = mesh.block(ElementType::tet4);
  std::vector<Index> cell_centre(static_cast<std::size_t>(nc));
  for (Index c = 0; c < nc; ++c) {
    std::vector<Index> vertices;
    for (Index k = start[static_cast<std::size_t>(c)]; k < start[static_cast<std::size_t>(c) + 1]; ++k) {
      const Index entry = cell_faces[static_cast<std::size_t>(k)];
      const auto v = poly.face(entry >= 0 ? entry : -entry - 1);
      vertices.insert(vertices.end(), v.begin(), v.end());
    }
    std::sort(vertices.begin(), vertices.end());
    vertices.erase(std::unique(vertices.begin(), vertices.end()), vertices.end());
    Vec<3> sum = Vec<3>::Zero();
    for (const Index i : vertices) sum += poly.points.col(i);
    const Index centre = np + static_cast<Index>(extra.size());
    cell_centre[static_cast<std::size_t>(c)] = centre;
    extra.push_back(sum / static_cast<double>(vertices.size()));
    for (Index k = start[static_cast<std::size_t>(c)]; k < start[static_cast<std::size_t>(c) + 1]; ++k) {
      const Index entry = cell_faces[static_cast<std::size_t>(k)];
      const std::vector<Index> f = outward(entry);
      if (f.size() == 3) {
        tets.add({f[0], f[2], f[1], centre});  // outward (a, b, c) is our facet (0, 2, 1)
        continue;
      }
      const Index fc = face_centre[static_cast<std::size_t>(entry >= 0 ? entry : -entry - 1)];
      for (std::size_t i = 0; i < f.size(); ++i) tets.add({fc, f[(i + 1) % f.size()], f[i], centre});
    }
  }
  for (Index f = poly.num_internal_faces(); f < nf; ++f) {
    const auto v = poly.face(f);
    ElementBlock& tris = mesh.block(ElementType::tri3);
    if (v.size() == 3) {
      tris.add(v, patch_tag(f));
      continue;
    }
    for (std::size_t i = 0; i < v.size(); ++i) tris.add({face_centre[static_cast<std::size_t>(f)], v[i], v[(i + 1) % v.size()]}, patch_tag(f));
  }
  // A zone holds the auxiliary nodes inside what it holds: moved with it as a body.
  const auto face_with_centre = [&](Index f, std::vector<Index>& out) {
    const auto v = poly.face(f);
    out.insert(out.end(), v.begin(), v.end());
    if (face_centre[static_cast<std::size_t>(f)] >= 0) out.push_back(face_centre[static_cast<std::size_t>(f)]);
  };
  add_zones([&](int kind, Index label, std::vector<Index>& out) {
    if (kind == 3) {
      for (Index k = start[static_cast<std::size_t>(label)]; k < start[static_cast<std::size_t>(label) + 1]; ++k) {
        const Index entry = cell_faces[static_cast<std::size_t>(k)];
        face_with_centre(entry >= 0 ? entry : -entry - 1, out);
      }
      out.push_back(cell_centre[static_cast<std::size_t>(label)]);
    } else if (kind == 2) {
      face_with_centre(label, out);
    } else {
      out.push_back(label);
    }
  });
  mesh.points.conservativeResize(3, np + static_cast<Index>(extra.size()));
  for (std::size_t k = 0; k < extra.size(); ++k) mesh.points.col(np + static_cast<Index>(k)) = extra[k];
  mesh.num_auxiliary_nodes = static_cast<Index>(extra.size());
  return mesh;
}

/// The polyMesh of a linear 3D mesh: its nodes as points, its cells as cells (same order), each
/// face once, oriented out of its owner (the lower-numbered cell), internal faces in upper
/// triangular order, then one patch per facet group holding the boundary faces its facets
/// cover (named after the group, in its sets as `inGroups`; type `patch`, or `wall`, `empty`,
/// `symmetryPlane`, `symmetry` or `wedge` where the group is in that set, as to_mesh() puts an
/// OpenFOAM patch), and `defaultFaces` for boundary faces no facet covers. Throws InputError for quadratic elements or a face shared by three cells.
[[nodiscard]] inline PolyMesh to_polymesh(const Mesh<3>& mesh) {
  validate(mesh);
  for (const auto* list : {&mesh.cells, &mesh.facets})
    for (const auto& b : *list)
      if (order(b.type) > 1) throw InputError("to_polymesh: OpenFOAM meshes are linear (the mesh has " + std::string(name(b.type)) + ")");
  const FacetTopology topo = unique_facets(mesh);
  PolyMesh poly;
  poly.points = mesh.points;
  poly.num_cells = mesh.num_cells();
  // Boundary faces by facet group: the tag of the facet element on each face.
  const auto key_of = [](std::span<const Index> v) {
    std::array<Index, 4> k{-1, -1, -1, -1};
    const std::size_t n = std::min<std::size_t>(v.size(), 4);
    for (std::size_t i = 0; i < n; ++i) {  // insertion sort of at most 4 vertices
      std::size_t j = i;
      for (; j > 0 && k[j - 1] > v[i]; --j) k[j] = k[j - 1];
      k[j] = v[i];
    }
    return k;
  };
  struct KeyHash {
    std::size_t operator()(const std::array<Index, 4>& k) const noexcept {
      std::size_t h = 0;
      for (const Index v : k) h = h * 0x9E3779B97F4A7C15ull + static_cast<std::size_t>(v);
      return h;
    }
  };
  std::unordered_map<std::array<Index, 4>, int, KeyHash> tag_of_face;
  for (const auto& b : mesh.facets)
    for (Index e = 0; e < b.size(); ++e) tag_of_face.emplace(key_of(b.element(e).first(static_cast<std::size_t>(num_vertices(b.type)))), b.tags[static_cast<std::size_t>(e)]);
  std::vector<int> tags;  // patch order: the named facet groups, then other tags, then 0
  for (const auto& g : mesh.groups)
    if (g.dim == 2 && std::find(tags.begin(), tags.end(), g.tag) == tags.end()) tags.push_back(g.tag);

  struct Face {
    Index owner, neighbour;  // neighbour -1 on the boundary
    int patch;
    Index facet;
    bool flip;
  };
  std::vector<Face> faces;
  faces.reserve(topo.vertices.size());
  for (Index f = 0; f < topo.size(); ++f) {
    const auto& e = topo.elements[static_cast<std::size_t>(f)];
    if (topo.count[static_cast<std::size_t>(f)] == 2) {
      faces.push_back({std::min(e[0], e[1]), std::max(e[0], e[1]), -1, f, e[0] > e[1]});
      continue;
    }
    const auto v = std::span<const Index>(topo.vertices[static_cast<std::size_t>(f)].data(), static_cast<std::size_t>(topo.num_vertices[static_cast<std::size_t>(f)]));
    const auto it = tag_of_face.find(key_of(v));
    const int tag = it == tag_of_face.end() ? 0 : it->second;
    auto at = std::find(tags.begin(), tags.end(), tag);
    if (at == tags.end()) at = tags.insert(tags.end(), tag);
    faces.push_back({e[0], -1, static_cast<int>(at - tags.begin()), f, false});
  }
  // Tag 0 (no group) last, as defaultFaces.
  if (const auto zero = std::find(tags.begin(), tags.end(), 0); zero != tags.end()) {
    const int old = static_cast<int>(zero - tags.begin());
    tags.erase(zero);
    tags.push_back(0);
    for (Face& f : faces)
      if (f.patch >= 0) f.patch = f.patch == old ? static_cast<int>(tags.size()) - 1 : f.patch > old ? f.patch - 1 : f.patch;
  }
  std::sort(faces.begin(), faces.end(), [](const Face& a, const Face& b) {
    if ((a.patch < 0) != (b.patch < 0)) return a.patch < 0;
    if (a.patch != b.patch) return a.patch < b.patch;
    return a.owner != b.owner ? a.owner < b.owner : a.neighbour < b.neighbour;
  });
  poly.face_nodes.reserve(4 * faces.size());
  for (const Face& f : faces) {
    const auto& v = topo.vertices[static_cast<std::size_t>(f.facet)];
    const int n = topo.num_vertices[static_cast<std::size_t>(f.facet)];
    for (int k = 0; k < n; ++k) poly.face_nodes.push_back(v[static_cast<std::size_t>(f.flip ? n - 1 - k : k)]);
    poly.face_offsets.push_back(static_cast<Index>(poly.face_nodes.size()));
    poly.owner.push_back(f.owner);
    if (f.patch < 0) poly.neighbour.push_back(f.neighbour);
  }
  Index start = poly.num_internal_faces();
  for (std::size_t p = 0; p < tags.size(); ++p) {
    const Index size = static_cast<Index>(std::count_if(faces.begin(), faces.end(), [&](const Face& f) { return f.patch == static_cast<int>(p); }));
    PolyMesh::Patch patch{tags[p] == 0 ? "defaultFaces" : "tag_" + std::to_string(tags[p]), "patch", start, size};
    for (const auto& g : mesh.groups)
      if (g.dim == 2 && g.tag == tags[p]) {
        patch.name = g.name;
        patch.groups = g.in_groups;
        // The types that need no entry beyond `type` come back from the sets to_mesh() put
        // them in; a cyclic or processor patch needs its partner, so it stays a patch.
        for (const char* type : {"wall", "empty", "symmetryPlane", "symmetry", "wedge"})
          if (std::find(g.in_groups.begin(), g.in_groups.end(), type) != g.in_groups.end()) patch.type = type;
      }
    poly.patches.push_back(std::move(patch));
    start += size;
  }
  return poly;
}

}  // namespace meshmotion
