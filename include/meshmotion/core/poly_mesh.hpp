#pragma once
/// \file
/// A polyhedral mesh stored by faces, as OpenFOAM's polyMesh files hold it. Read and written by
/// io/openfoam_reader.hpp and io/openfoam_writer.hpp, converted by io/openfoam_polymesh.hpp,
/// measured by quality/foam_quality.hpp.

#include "meshmotion/core/types.hpp"

#include <Eigen/Geometry>  // cross()

#include <span>
#include <string>
#include <vector>

namespace meshmotion {

/// An OpenFOAM polyMesh as its files hold it: faces as vertex lists (outward from their owner
/// cell), owner and neighbour cells per face (internal faces first), patches as face ranges.
struct PolyMesh {
  struct Patch {
    std::string name;
    std::string type;  ///< patch, wall, empty, symmetryPlane, ...
    Index start = 0;   ///< first face
    Index size = 0;    ///< number of faces
    std::vector<std::string> groups{};  ///< the boundary file's inGroups
  };
  /// A named set of cells, faces or points: OpenFOAM's cellZones, faceZones and pointZones,
  /// by which a solver (and a motion: a zone moved as a body) addresses part of the mesh.
  struct Zone {
    std::string name;
    std::vector<Index> labels;  ///< cell, face or point labels
    std::vector<char> flip{};   ///< faceZones: whether each face is turned (flipMap); else empty
  };
  Points<3> points;
  std::vector<Index> face_offsets{0};  ///< face f: face_nodes[face_offsets[f] .. face_offsets[f+1])
  std::vector<Index> face_nodes;
  std::vector<Index> owner;      ///< one per face
  std::vector<Index> neighbour;  ///< one per internal face
  std::vector<Patch> patches;
  Index num_cells = 0;
  std::vector<Zone> cell_zones{}, face_zones{}, point_zones{};

  [[nodiscard]] Index num_faces() const noexcept { return static_cast<Index>(face_offsets.size()) - 1; }
  [[nodiscard]] Index num_internal_faces() const noexcept { return static_cast<Index>(neighbour.size()); }
  [[nodiscard]] std::span<const Index> face(Index f) const {
    return {face_nodes.data() + face_offsets[static_cast<std::size_t>(f)],
            static_cast<std::size_t>(face_offsets[static_cast<std::size_t>(f) + 1] - face_offsets[static_cast<std::size_t>(f)])};
  }
  /// The vector area of face f (half the sum of its edges' cross products), pointing out of
  /// its owner. Exact for warped faces too: a closed cell's faces sum to zero, each edge
  /// counted once each way. Zero for a face of fewer than three vertices.
  [[nodiscard]] Vec<3> face_area(Index f) const {
    const auto v = face(f);
    if (v.size() < 3) return Vec<3>::Zero();
    const Vec<3> first = points.col(v[0]);
    Vec<3> sum = Vec<3>::Zero();
    for (std::size_t i = 1; i + 1 < v.size(); ++i) sum += (points.col(v[i]) - first).cross(points.col(v[i + 1]) - first);
    return 0.5 * sum;
  }
};

}  // namespace meshmotion
