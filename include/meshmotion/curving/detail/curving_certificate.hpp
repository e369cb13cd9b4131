#pragma once
/// \file
/// The curving pipeline's verdicts: cells the snapping turned over, invalid cells and facets
/// off their geometry refused in strict mode, and progress lines.

#include "meshmotion/curving/curve_report.hpp"

namespace meshmotion {

namespace detail {

inline void report_progress(const std::function<void(const std::string&)>& progress, const std::string& line) {
  if (progress) progress(line);
}

/// A cell (block and element) and whether its straight shape's measure was positive.
struct CellSign {
  std::size_t block = 0;
  Index element = 0;
  bool positive = true;
};

/// The cells with a vertex that `snapped` moves, each with the sign of its straight measure now.
template <int Dim>
[[nodiscard]] std::vector<CellSign> cells_at_moved_vertices(const Mesh<Dim>& mesh, const SnappedBoundary<Dim>& snapped) {
  std::vector<CellSign> out;
  if (snapped.moved_vertices == 0) return out;
  std::vector<char> moved(static_cast<std::size_t>(mesh.num_nodes()), 0);
  for (std::size_t k = 0; k < snapped.nodes.size(); ++k)
    if (snapped.displacements.col(static_cast<Index>(k)).squaredNorm() > 0.0) moved[static_cast<std::size_t>(snapped.nodes[k])] = 1;
  for (std::size_t b = 0; b < mesh.cells.size(); ++b) {
    const ElementBlock& block = mesh.cells[b];
    const int nv = num_vertices(block.type);
    for (Index e = 0; e < block.size(); ++e) {
      const auto el = block.element(e);
      if (std::any_of(el.begin(), el.begin() + nv, [&](Index v) { return moved[static_cast<std::size_t>(v)] != 0; }))
        out.push_back({b, e, signed_measure(mesh, block.type, el) > 0.0});
    }
  }
  return out;
}

/// How many of `cells` have a straight measure of the other sign in `mesh`.
template <int Dim>
[[nodiscard]] Index count_reversed(const Mesh<Dim>& mesh, const std::vector<CellSign>& cells) {
  return static_cast<Index>(std::count_if(cells.begin(), cells.end(), [&](const CellSign& c) {
    const ElementBlock& block = mesh.cells[c.block];
    return (signed_measure(mesh, block.type, block.element(c.element)) > 0.0) != c.positive;
  }));
}

/// Throws InvalidMeshError when the snapping turned cells over (CurveResult::reversed_cells).
template <int Dim>
void refuse_reversed(const CurveResult<Dim>& result) {
  if (result.reversed_cells == 0) return;
  throw InvalidMeshError("curve_mesh: " + std::to_string(result.reversed_cells) + " cells were turned over by moving " +
                         std::to_string(result.moved_vertices) + " vertices onto the geometry (up to " +
                         format_option_value(result.max_boundary_displacement) +
                         "; the certificate measures a cell against its orientation in the input); expected none: the mesh does "
                         "not fit the geometry there");
}

/// Throws InvalidMeshError naming the count and the worst cell when `result` has invalid cells.
template <int Dim>
void refuse_invalid(const CurveResult<Dim>& result) {
  if (result.quality.num_invalid == 0) return;
  const WorstElement& w = result.quality.worst.front();
  std::ostringstream where;
  where << "(" << w.centroid[0] << ", " << w.centroid[1] << (Dim == 3 ? ", " + std::to_string(w.centroid[2]) : "") << ")";
  throw InvalidMeshError("curve_mesh: " + std::to_string(result.quality.num_invalid) + " of " +
                         std::to_string(result.quality.num_elements) + " cells are invalid after " + result.method +
                         " regularization (worst: " + std::string(name(w.type)) + " cell " + std::to_string(w.id) +
                         ", file id " + std::to_string(w.file_id) + ", at " + where.str() +
                         ", certified scaled Jacobian " + std::to_string(w.value) + "; expected > 0)");
}

/// Throws InvalidMeshError naming the count and the farthest facet when `result` has curved
/// facets off their geometry.
template <int Dim>
void refuse_off_geometry(const CurveResult<Dim>& result, double tolerance) {
  if (result.off_geometry() == 0) return;
  const auto worst = std::max_element(result.geometry_distance.begin(), result.geometry_distance.end(),
                                      [](const GeometryDistance& a, const GeometryDistance& b) {
                                        return a.max_relative_distance < b.max_relative_distance;
                                      });
  std::ostringstream where;
  where << "(" << worst->worst_at[0] << ", " << worst->worst_at[1];
  if (Dim == 3) where << ", " << worst->worst_at[2];
  where << ")";
  throw InvalidMeshError("curve_mesh: " + std::to_string(result.off_geometry()) + " curved facets are off their geometry (worst: group '" +
                         worst->group + "', a facet at " + where.str() + " up to " + format_option_value(worst->max_relative_distance) +
                         " x its size from its " + worst->geometry + "; expected at most geometry_tolerance " +
                         format_option_value(tolerance) + ")");
}

}  // namespace detail

}  // namespace meshmotion
