#pragma once
/// \file
/// Per-cell quality of a whole mesh for one metric: Knupp's relative size, shape, skew,
/// size-shape and size-skew (quality/knupp.hpp) or the certified scaled Jacobian
/// (quality/scaled_jacobian.hpp). Results are in cell order (blocks of mesh.cells in order,
/// elements in block order).

#include "meshmotion/core/element.hpp"
#include "meshmotion/core/error.hpp"
#include "meshmotion/core/mesh.hpp"
#include "meshmotion/core/threads.hpp"
#include "meshmotion/core/types.hpp"
#include "meshmotion/quality/knupp.hpp"
#include "meshmotion/quality/scaled_jacobian.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <string_view>
#include <vector>

namespace meshmotion {

/// The metrics a report can be made of.
enum class Metric { relative_size, shape, skew, size_shape, size_skew, scaled_jacobian };

inline constexpr std::array<Metric, 6> all_metrics{Metric::relative_size, Metric::shape,      Metric::skew,
                                                   Metric::size_shape,    Metric::size_skew, Metric::scaled_jacobian};

/// "relative_size", "shape", "skew", "size_shape", "size_skew", "scaled_jacobian".
[[nodiscard]] constexpr std::string_view metric_name(Metric m) {
  constexpr std::array<std::string_view, 6> names{"relative_size", "shape",     "skew",
                                                  "size_shape",    "size_skew", "scaled_jacobian"};
  return names[static_cast<std::size_t>(m)];
}
[[nodiscard]] constexpr std::string_view name(Metric m) { return metric_name(m); }

/// The metric of that name; also accepts "size", "size-shape", "size-skew", "jacobian" and
/// "scaled-jacobian". Throws InputError for other names.
[[nodiscard]] inline Metric metric_from_name(std::string_view s) {
  for (Metric m : all_metrics)
    if (metric_name(m) == s) return m;
  if (s == "size") return Metric::relative_size;
  if (s == "size-shape") return Metric::size_shape;
  if (s == "size-skew") return Metric::size_skew;
  if (s == "jacobian" || s == "scaled-jacobian") return Metric::scaled_jacobian;
  throw InputError("metric_from_name: unknown metric '" + std::string(s) +
                   "' (expected shape, skew, size, size-shape, size-skew or jacobian)");
}

/// Options of cell_quality() and evaluate_cells().
/// Options of the cell metrics; described once, in visit_options(ReportOptions&)
/// (quality/quality_report.hpp), whose keys they are.
struct QualityOptions {
  double reference_measure = 0.0;
  ScaledJacobianOptions jacobian{};
};

/// The value of one cell and whether the cell is valid (not inverted, not degenerate).
struct CellQuality {
  double value = 0.0;
  bool valid = false;
};

namespace detail {

template <int Dim>
ElementCoords<Dim> gather(const Mesh<Dim>& mesh, const ElementBlock& block, Index e) {
  const auto nodes = block.element(e);
  ElementCoords<Dim> x(Dim, static_cast<Index>(nodes.size()));
  for (std::size_t i = 0; i < nodes.size(); ++i) x.col(static_cast<Index>(i)) = mesh.points.col(nodes[i]);
  return x;
}

template <int Dim>
void check_cell_blocks(const Mesh<Dim>& mesh, std::string_view where) {
  for (const auto& block : mesh.cells)
    if (dimension(block.type) != Dim)
      throw InputError(std::string(where) + ": a " + std::to_string(Dim) + "D mesh has a cell block of " +
                       std::string(name(block.type)) + " (expected elements of dimension " + std::to_string(Dim) + ")");
}

inline double select(const KnuppQuality& q, Metric m) {
  switch (m) {
    case Metric::relative_size: return q.relative_size;
    case Metric::shape: return q.shape;
    case Metric::skew: return q.skew;
    case Metric::size_shape: return q.size_shape;
    case Metric::size_skew: return q.size_skew;
    case Metric::scaled_jacobian: break;
  }
  return 0.0;
}

}  // namespace detail

/// Mean Knupp measure (area or volume) of the valid cells; 0 when there are none.
template <int Dim>
[[nodiscard]] double mean_cell_measure(const Mesh<Dim>& mesh) {
  detail::check_cell_blocks(mesh, "mean_cell_measure");
  double sum = 0.0;
  Index count = 0;
  for (const auto& block : mesh.cells)
    for (Index e = 0; e < block.size(); ++e) {
      const auto q = knupp_quality(block.type, detail::gather(mesh, block, e), 0.0);
      if (q.valid) {
        sum += q.measure;
        ++count;
      }
    }
  return count > 0 ? sum / static_cast<double>(count) : 0.0;
}

/// Value and validity of every cell for `metric`, in cell order. Knupp values lie in [0, 1]
/// (0 for invalid cells); the scaled Jacobian is the certified minimum, signed (negative for
/// tangled cells, 0 for degenerate ones). Validity is the certificate's for every metric: a
/// Knupp metric measures a high-order cell by its corners, which say nothing of a mid-edge
/// node folded across the cell (its straight corners are fine) and may call a curved cell
/// inverted that the certificate finds valid, so its cells take the certified verdict (a
/// cell it finds invalid measures 0). Throws InputError when a cell block has the wrong
/// dimension. Precondition: node indices in range (see validate()).
template <int Dim>
[[nodiscard]] std::vector<CellQuality> evaluate_cells(const Mesh<Dim>& mesh, Metric metric, const QualityOptions& options = {}) {
  detail::check_cell_blocks(mesh, "evaluate_cells");
  std::vector<CellQuality> out(static_cast<std::size_t>(mesh.num_cells()));
  if (metric == Metric::scaled_jacobian) {
    // Only the certified minimum is used: refining the upper bound would be wasted work.
    ScaledJacobianOptions jacobian = options.jacobian;
    jacobian.sharp_max = false;
    const auto sj = scaled_jacobians(mesh, jacobian);
    for (std::size_t i = 0; i < sj.size(); ++i) out[i] = {sj[i].certified_min, sj[i].valid};
    return out;
  }
  const bool needs_size = metric == Metric::relative_size || metric == Metric::size_shape || metric == Metric::size_skew;
  const double reference = !needs_size ? 0.0 : options.reference_measure > 0 ? options.reference_measure : mean_cell_measure(mesh);
  Index offset = 0;
  for (const auto& block : mesh.cells) {
    const Index n = block.size();
    detail::RegionErrors errors;
#if defined(_OPENMP)
#pragma omp parallel for num_threads(::meshmotion::num_threads()) schedule(static)
#endif
    for (Index e = 0; e < n; ++e)
      errors.run([&] {
        const auto q = knupp_quality(block.type, detail::gather(mesh, block, e), reference);
        out[static_cast<std::size_t>(offset + e)] = {detail::select(q, metric), q.valid};
      });
    errors.rethrow();
    offset += n;
  }
  const bool curved = std::any_of(mesh.cells.begin(), mesh.cells.end(), [](const ElementBlock& b) { return order(b.type) > 1; });
  if (!curved) return out;
  ScaledJacobianOptions jacobian = options.jacobian;
  jacobian.sharp_max = false;
  jacobian.sharp = false;  // the verdict alone
  const std::vector<ScaledJacobian> certified = scaled_jacobians(mesh, jacobian);
  offset = 0;
  for (const auto& block : mesh.cells) {
    if (order(block.type) > 1)
      for (Index e = 0; e < block.size(); ++e) {
        CellQuality& c = out[static_cast<std::size_t>(offset + e)];
        c.valid = certified[static_cast<std::size_t>(offset + e)].valid;
        if (!c.valid) c.value = 0.0;
      }
    offset += block.size();
  }
  return out;
}

/// One value per cell, in cell order (see evaluate_cells()).
template <int Dim>
[[nodiscard]] std::vector<double> cell_quality(const Mesh<Dim>& mesh, Metric metric, const QualityOptions& options = {}) {
  const auto cells = evaluate_cells(mesh, metric, options);
  std::vector<double> v(cells.size());
  for (std::size_t i = 0; i < cells.size(); ++i) v[i] = cells[i].value;
  return v;
}

}  // namespace meshmotion

// The compiled library (target meshmotion::compiled, src/) holds these for Dim 2 and 3.
#ifdef MESHMOTION_COMPILED
namespace meshmotion {
extern template std::vector<CellQuality> evaluate_cells<2>(const Mesh<2>&, Metric, const QualityOptions&);
extern template std::vector<CellQuality> evaluate_cells<3>(const Mesh<3>&, Metric, const QualityOptions&);
}  // namespace meshmotion
#endif
