#pragma once
/// \file
/// The cell and face measures OpenFOAM users read in `checkMesh`, on a polyMesh as it is
/// (polyhedra included), computed as OpenFOAM computes them so that the numbers agree:
/// - face centres and area vectors from the triangles joining each edge to the face's vertex
///   average (a triangle directly); cell centres and volumes from the face pyramids on the
///   average of the cell's face centres;
/// - non-orthogonality: the angle between the owner-to-neighbour vector and the face area
///   vector of each internal face, its largest, and the angle of the average cosine (the
///   average checkMesh prints); severe above 70 degrees, an error from 90;
/// - skewness: the distance from the face centre to where the line between the cell centres
///   (the face normal through the owner's centre on boundary faces) crosses the face, over a
///   face size in that direction; high above 4;
/// - aspect ratio: the largest over the smallest Cartesian component of the cell's summed
///   absolute face areas, in the mesh's geometric directions (`empty` patches remove the
///   directions they face, `wedge` patches the direction of their centre normal), and in 3D at
///   least the area-to-volume ratio of a cube; high above 1000;
/// - cell volumes: smallest, largest, total, and the cells of zero or negative volume;
/// - face pyramids: the pyramid of each face on its owner's centre, and on its neighbour's,
///   must have a positive volume (above -1e-15, checkMesh's bound);
/// - the verdict: how many of these checks fail as checkMesh counts failures (faces of
///   non-orthogonality 90 degrees or more, highly skewed faces, cells of high aspect ratio,
///   cells of non-positive volume, inverted face pyramids). checkMesh's open-cell and
///   topological checks are not among them.
/// Validated against checkMesh (Debian `openfoam`) in tests/io/openfoam_test.cpp. Polyhedra: core/poly_mesh.hpp.

#include "meshmotion/core/types.hpp"
#include "meshmotion/core/poly_mesh.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

namespace meshmotion {

/// checkMesh's measures of a polyMesh (see the file comment).
struct FoamQuality {
  int solution_directions = 3;  ///< 3, or 2 when `empty` patches remove a direction
  int geometric_directions = 3;  ///< the solution directions, less a `wedge` case's normal one
  double min_volume = 0, max_volume = 0, total_volume = 0;
  Index num_nonpositive_volumes = 0;   ///< cells of volume below 1e-300 (checkMesh's VSMALL)
  double max_non_orthogonality = 0;    ///< degrees
  double average_non_orthogonality = 0;  ///< degrees: the angle of the average cosine, as checkMesh prints it
  Index num_severely_non_orthogonal = 0;  ///< internal faces above 70 degrees and below 90
  Index num_non_orthogonality_errors = 0;  ///< internal faces at 90 degrees or more (the cell centres cross)
  double max_skewness = 0;
  Index num_highly_skewed = 0;  ///< faces above 4
  double max_aspect_ratio = 0;
  Index num_high_aspect_ratio = 0;  ///< cells above 1000
  Index num_wrong_face_pyramids = 0;  ///< face pyramids on a cell centre of non-positive volume (a face once per cell)
  Index num_invalid_cells = 0;  ///< cells of non-positive volume or with a face pyramid inverted: what OpenFOAM refuses
  int failed_checks = 0;        ///< checks failed as checkMesh counts them (see the file comment)
  Index worst_non_orthogonal_face = -1, worst_skewed_face = -1, worst_aspect_ratio_cell = -1, smallest_cell = -1;
};

template <class F>
void visit_fields(const FoamQuality& q, F&& f) {
  f("solution_directions", q.solution_directions, "3, or 2 when empty patches remove a direction");
  f("geometric_directions", q.geometric_directions, "the solution directions, less a wedge case's normal one");
  f("max_non_orthogonality", q.max_non_orthogonality, "degrees, over internal faces");
  f("average_non_orthogonality", q.average_non_orthogonality, "degrees: the angle of the average cosine");
  f("severely_non_orthogonal_faces", q.num_severely_non_orthogonal, "internal faces above 70 degrees and below 90");
  f("non_orthogonality_errors", q.num_non_orthogonality_errors, "internal faces at 90 degrees or more");
  f("max_skewness", q.max_skewness, "checkMesh's face skewness");
  f("highly_skewed_faces", q.num_highly_skewed, "faces of skewness above 4");
  f("max_aspect_ratio", q.max_aspect_ratio, "checkMesh's cell aspect ratio");
  f("high_aspect_ratio_cells", q.num_high_aspect_ratio, "cells of aspect ratio above 1000");
  f("min_volume", q.min_volume, "smallest cell volume");
  f("max_volume", q.max_volume, "largest cell volume");
  f("total_volume", q.total_volume, "sum of the cell volumes");
  f("nonpositive_volume_cells", q.num_nonpositive_volumes, "cells of volume below 1e-300");
  f("wrong_face_pyramids", q.num_wrong_face_pyramids, "face pyramids on a cell centre of non-positive volume, a face once per cell");
  f("invalid_cells", q.num_invalid_cells, "cells of non-positive volume or with an inverted face pyramid");
  f("failed_checks", q.failed_checks, "checks failed as checkMesh counts them (0: Mesh OK)");
  f("worst_non_orthogonal_face", q.worst_non_orthogonal_face, "face of the largest non-orthogonality (-1: none)");
  f("worst_skewed_face", q.worst_skewed_face, "face of the largest skewness (-1: none)");
  f("worst_aspect_ratio_cell", q.worst_aspect_ratio_cell, "cell of the largest aspect ratio (-1: none)");
  f("smallest_cell", q.smallest_cell, "cell of the smallest volume (-1: none)");
}

namespace detail {

/// Face centres and area vectors, as OpenFOAM computes them.
inline void foam_face_geometry(const PolyMesh& mesh, std::vector<Vec<3>>& centres, std::vector<Vec<3>>& areas) {
  const Index nf = mesh.num_faces();
  centres.resize(static_cast<std::size_t>(nf));
  areas.resize(static_cast<std::size_t>(nf));
  for (Index f = 0; f < nf; ++f) {
    const auto v = mesh.face(f);
    const auto p = [&](std::size_t k) { return Vec<3>(mesh.points.col(v[k])); };
    if (v.size() == 3) {
      centres[static_cast<std::size_t>(f)] = (p(0) + p(1) + p(2)) / 3.0;
      areas[static_cast<std::size_t>(f)] = 0.5 * (p(1) - p(0)).cross(p(2) - p(0));
      continue;
    }
    Vec<3> average = Vec<3>::Zero();
    for (std::size_t k = 0; k < v.size(); ++k) average += p(k);
    average /= static_cast<double>(v.size());
    Vec<3> sum_n = Vec<3>::Zero(), sum_ac = Vec<3>::Zero();
    double sum_a = 0;
    for (std::size_t k = 0; k < v.size(); ++k) {
      const Vec<3> a = p(k), b = p((k + 1) % v.size());
      const Vec<3> n = (b - a).cross(average - a);
      const double mag = n.norm();
      sum_n += n;
      sum_a += mag;
      sum_ac += mag * (a + b + average);
    }
    constexpr double root_vsmall = 1e-150;
    if (sum_a < root_vsmall) {
      centres[static_cast<std::size_t>(f)] = average;
      areas[static_cast<std::size_t>(f)] = Vec<3>::Zero();
    } else {
      centres[static_cast<std::size_t>(f)] = sum_ac / (3.0 * sum_a);
      areas[static_cast<std::size_t>(f)] = 0.5 * sum_n;
    }
  }
}

}  // namespace detail

/// checkMesh's measures of `mesh` (see the file comment).
[[nodiscard]] inline FoamQuality foam_quality(const PolyMesh& mesh) {
  constexpr double vsmall = 1e-300, root_vsmall = 1e-150;
  const Index nf = mesh.num_faces(), ni = mesh.num_internal_faces(), nc = mesh.num_cells;
  std::vector<Vec<3>> fc, fa;
  detail::foam_face_geometry(mesh, fc, fa);
  const auto own = [&](Index f) { return static_cast<std::size_t>(mesh.owner[static_cast<std::size_t>(f)]); };
  const auto nei = [&](Index f) { return static_cast<std::size_t>(mesh.neighbour[static_cast<std::size_t>(f)]); };

  // Cell centres and volumes from face pyramids on the average of the face centres.
  std::vector<Vec<3>> estimate(static_cast<std::size_t>(nc), Vec<3>::Zero()), cc(static_cast<std::size_t>(nc), Vec<3>::Zero());
  std::vector<int> faces_of(static_cast<std::size_t>(nc), 0);
  std::vector<double> volume(static_cast<std::size_t>(nc), 0.0);
  for (Index f = 0; f < nf; ++f) {
    estimate[own(f)] += fc[static_cast<std::size_t>(f)];
    ++faces_of[own(f)];
    if (f < ni) {
      estimate[nei(f)] += fc[static_cast<std::size_t>(f)];
      ++faces_of[nei(f)];
    }
  }
  for (std::size_t c = 0; c < estimate.size(); ++c) estimate[c] /= std::max(1, faces_of[c]);
  for (Index f = 0; f < nf; ++f) {
    const Vec<3>& centre = fc[static_cast<std::size_t>(f)];
    const Vec<3>& area = fa[static_cast<std::size_t>(f)];
    const double owner_part = area.dot(centre - estimate[own(f)]);
    cc[own(f)] += owner_part * (0.75 * centre + 0.25 * estimate[own(f)]);
    volume[own(f)] += owner_part;
    if (f < ni) {
      const double neighbour_part = area.dot(estimate[nei(f)] - centre);
      cc[nei(f)] += neighbour_part * (0.75 * centre + 0.25 * estimate[nei(f)]);
      volume[nei(f)] += neighbour_part;
    }
  }
  for (std::size_t c = 0; c < cc.size(); ++c) {
    cc[c] = std::abs(volume[c]) > vsmall ? Vec<3>(cc[c] / volume[c]) : estimate[c];
    volume[c] /= 3.0;
  }

  FoamQuality q;
  q.min_volume = nc > 0 ? std::numeric_limits<double>::max() : 0.0;
  q.max_volume = nc > 0 ? -std::numeric_limits<double>::max() : 0.0;
  for (Index c = 0; c < nc; ++c) {
    const double v = volume[static_cast<std::size_t>(c)];
    if (v < q.min_volume) {
      q.min_volume = v;
      q.smallest_cell = c;
    }
    q.max_volume = std::max(q.max_volume, v);
    q.total_volume += v;
    if (v < vsmall) ++q.num_nonpositive_volumes;
  }

  // Face pyramids on the cell centres: a third of the area vector dotted with the height.
  constexpr double min_pyramid = -1e-15;
  std::vector<char> invalid(static_cast<std::size_t>(nc), 0);
  for (Index c = 0; c < nc; ++c) invalid[static_cast<std::size_t>(c)] = volume[static_cast<std::size_t>(c)] < vsmall ? 1 : 0;
  for (Index f = 0; f < nf; ++f) {
    const Vec<3>& centre = fc[static_cast<std::size_t>(f)];
    const Vec<3>& area = fa[static_cast<std::size_t>(f)];
    const bool owner_wrong = area.dot(centre - cc[own(f)]) / 3.0 < min_pyramid;
    const bool neighbour_wrong = f < ni && area.dot(cc[nei(f)] - centre) / 3.0 < min_pyramid;
    // Once per cell, as checkMesh counts "faces incorrectly oriented".
    q.num_wrong_face_pyramids += static_cast<Index>(owner_wrong) + static_cast<Index>(neighbour_wrong);
    if (owner_wrong) invalid[own(f)] = 1;
    if (neighbour_wrong) invalid[nei(f)] = 1;
  }
  q.num_invalid_cells = static_cast<Index>(std::count(invalid.begin(), invalid.end(), 1));

  // Non-orthogonality of the internal faces.
  const double severe = std::cos(70.0 * std::numbers::pi / 180.0);
  double min_cos = 1.0, sum_cos = 0.0;
  for (Index f = 0; f < ni; ++f) {
    const Vec<3> d = cc[nei(f)] - cc[own(f)];
    const Vec<3>& s = fa[static_cast<std::size_t>(f)];
    const double ortho = d.dot(s) / (d.norm() * s.norm() + root_vsmall);
    constexpr double small = 1e-15;
    if (ortho < severe) ++(ortho > small ? q.num_severely_non_orthogonal : q.num_non_orthogonality_errors);
    if (ortho < min_cos) {
      min_cos = ortho;
      q.worst_non_orthogonal_face = f;
    }
    sum_cos += ortho;
  }
  const auto degrees = [](double c) { return std::acos(std::clamp(c, -1.0, 1.0)) * 180.0 / std::numbers::pi; };
  q.max_non_orthogonality = degrees(min_cos);
  q.average_non_orthogonality = ni > 0 ? degrees(sum_cos / static_cast<double>(ni)) : 0.0;

  // Skewness, internal and boundary faces.
  for (Index f = 0; f < nf; ++f) {
    const Vec<3>& centre = fc[static_cast<std::size_t>(f)];
    const Vec<3>& area = fa[static_cast<std::size_t>(f)];
    const Vec<3> cpf = centre - cc[own(f)];
    Vec<3> d;
    double floor_factor = 0.2;
    if (f < ni) {
      d = cc[nei(f)] - cc[own(f)];
    } else {
      const Vec<3> normal = area / (area.norm() + root_vsmall);
      d = normal * normal.dot(cpf);
      floor_factor = 0.4;
    }
    const Vec<3> sv = cpf - (area.dot(cpf) / (area.dot(d) + root_vsmall)) * d;
    const Vec<3> sv_hat = sv / (sv.norm() + root_vsmall);
    double fd = floor_factor * d.norm() + root_vsmall;
    for (const Index v : mesh.face(f)) fd = std::max(fd, std::abs(sv_hat.dot(Vec<3>(mesh.points.col(v)) - centre)));
    const double skew = sv.norm() / fd;
    if (skew > 4.0) ++q.num_highly_skewed;
    if (skew > q.max_skewness) {
      q.max_skewness = skew;
      q.worst_skewed_face = f;
    }
  }

  // Solution directions: `empty` patches remove the directions their faces face.
  Vec<3> empty_dir = Vec<3>::Zero();
  bool any_empty = false;
  for (const auto& p : mesh.patches) {
    if (p.type != "empty" || p.size == 0) continue;
    any_empty = true;
    for (Index f = p.start; f < p.start + p.size; ++f) empty_dir += fa[static_cast<std::size_t>(f)].cwiseAbs();
  }
  std::array<bool, 3> solved{true, true, true};
  if (any_empty && empty_dir.norm() > 0) {
    empty_dir /= empty_dir.norm();
    for (int d = 0; d < 3; ++d) solved[static_cast<std::size_t>(d)] = !(empty_dir[d] > 1e-6);
  }
  q.solution_directions = static_cast<int>(std::count(solved.begin(), solved.end(), true));
  // Geometric directions: a wedge patch's centre normal (its first face's normal with each
  // component's magnitude less a half, kept where positive, as OpenFOAM defines it) removes
  // the direction it leans on.
  Vec<3> wedge_dir = Vec<3>::Zero();
  for (const auto& p : mesh.patches) {
    if (p.type != "wedge" || p.size == 0) continue;
    const Vec<3> n = fa[static_cast<std::size_t>(p.start)].normalized();
    Vec<3> centre_normal;
    for (int d = 0; d < 3; ++d) centre_normal[d] = std::copysign(std::max(std::abs(n[d]), 0.5) - 0.5, n[d]);
    if (centre_normal.norm() > 0) wedge_dir += (centre_normal / centre_normal.norm()).cwiseAbs();
  }
  std::array<bool, 3> geometric = solved;
  if (wedge_dir.norm() > 0) {
    wedge_dir /= wedge_dir.norm();
    for (int d = 0; d < 3; ++d) geometric[static_cast<std::size_t>(d)] = geometric[static_cast<std::size_t>(d)] && !(wedge_dir[d] > 1e-6);
  }
  q.geometric_directions = static_cast<int>(std::count(geometric.begin(), geometric.end(), true));

  // Aspect ratio from the summed absolute face areas of each cell.
  std::vector<Vec<3>> summed(static_cast<std::size_t>(nc), Vec<3>::Zero());
  for (Index f = 0; f < nf; ++f) {
    summed[own(f)] += fa[static_cast<std::size_t>(f)].cwiseAbs();
    if (f < ni) summed[nei(f)] += fa[static_cast<std::size_t>(f)].cwiseAbs();
  }
  for (Index c = 0; c < nc; ++c) {
    const Vec<3>& s = summed[static_cast<std::size_t>(c)];
    double lo = std::numeric_limits<double>::max(), hi = -std::numeric_limits<double>::max();
    for (int d = 0; d < 3; ++d)
      if (geometric[static_cast<std::size_t>(d)]) {
        lo = std::min(lo, s[d]);
        hi = std::max(hi, s[d]);
      }
    double ratio = hi / (lo + root_vsmall);
    if (q.geometric_directions == 3) {
      const double v = std::max(root_vsmall, volume[static_cast<std::size_t>(c)]);
      ratio = std::max(ratio, s.sum() / 6.0 / std::pow(v, 2.0 / 3.0));
    }
    if (ratio > 1000.0) ++q.num_high_aspect_ratio;
    if (ratio > q.max_aspect_ratio) {
      q.max_aspect_ratio = ratio;
      q.worst_aspect_ratio_cell = c;
    }
  }
  q.failed_checks = static_cast<int>(q.num_non_orthogonality_errors > 0) + static_cast<int>(q.num_highly_skewed > 0) +
                    static_cast<int>(q.num_high_aspect_ratio > 0) + static_cast<int>(q.num_nonpositive_volumes > 0) +
                    static_cast<int>(q.num_wrong_face_pyramids > 0);
  return q;
}

}  // namespace meshmotion
