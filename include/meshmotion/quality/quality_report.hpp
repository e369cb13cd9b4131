#pragma once
/// \file
/// Mesh-level quality report: min, max, mean, a histogram on [0, 1], the invalid count, the
/// worst elements (id, type, value, centroid) and a breakdown per element type; printed as a
/// table or written as JSON.

#include "meshmotion/core/element.hpp"
#include "meshmotion/core/fields.hpp"
#include "meshmotion/core/mesh.hpp"
#include "meshmotion/core/mesh_like.hpp"
#include "meshmotion/core/option_text.hpp"
#include "meshmotion/core/types.hpp"
#include "meshmotion/quality/cell_quality.hpp"

#include <concepts>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <ostream>
#include <sstream>
#include <string>
#include <vector>

namespace meshmotion {

/// One of the worst cells of a report.
struct WorstElement {
  Index id = 0;                       ///< position in cell order
  std::int64_t file_id = 0;           ///< the element id the file gave, else the one a written .msh gives it (msh_element_id)
  ElementType type = ElementType::tri3;
  double value = 0.0;
  bool valid = false;
  std::array<double, 3> centroid{};   ///< mean of the vertices (z = 0 in 2D)
};

/// Statistics of the cells of one element type.
struct TypeQuality {
  ElementType type = ElementType::tri3;
  Index num_elements = 0;
  Index num_invalid = 0;
  double min = 0.0, max = 0.0, mean = 0.0;
};

/// The report of one metric over a mesh. Never holds NaN: invalid cells count with their
/// (finite) value, 0 for Knupp metrics, the signed bound for the scaled Jacobian.
struct QualityReport {
  Metric metric = Metric::shape;
  Index num_elements = 0;
  Index num_invalid = 0;
  double min = 0.0, max = 0.0, mean = 0.0;   ///< 0 for a mesh without cells
  std::vector<Index> histogram;              ///< equal bins on [0, 1]; values outside go to the end bins
  std::vector<WorstElement> worst;           ///< lowest values first
  std::vector<TypeQuality> per_type;         ///< in the order of mesh.cells
};

template <class F>
void visit_fields(const WorstElement& e, F&& f) {
  f("id", e.id, "position in cell order");
  f("file_id", e.file_id, "the element id of the file (or of a written .msh)");
  f("type", e.type, "element type");
  f("value", e.value, "the metric's value");
  f("valid", e.valid, "not inverted, not degenerate");
  f("centroid", e.centroid, "mean of the vertices (z = 0 in 2D)");
}

template <class F>
void visit_fields(const TypeQuality& t, F&& f) {
  f("type", t.type, "element type");
  f("elements", t.num_elements, "cells of the type");
  f("invalid", t.num_invalid, "invalid cells of the type");
  f("min", t.min, "lowest value");
  f("max", t.max, "highest value");
  f("mean", t.mean, "mean value");
}

template <class F>
void visit_fields(const QualityReport& r, F&& f) {
  f("metric", r.metric, "quality metric");
  f("elements", r.num_elements, "cells");
  f("invalid", r.num_invalid, "invalid cells (inverted or degenerate)");
  f("min", r.min, "lowest value");
  f("max", r.max, "highest value");
  f("mean", r.mean, "mean value");
  f("histogram", r.histogram, "cells per equal bin of [0, 1] (values outside in the end bins)");
  f("worst", r.worst, "the lowest cells, lowest first");
  f("per_type", r.per_type, "statistics per element type, in the order of the mesh's blocks");
}

/// Options of quality_report().
struct ReportOptions {
  int histogram_bins = 10;
  int num_worst = 10;
  QualityOptions quality{};
};

template <class F>
void visit_options(ScaledJacobianOptions& o, F&& f, const std::string& prefix = {}) {
  f(prefix + "certify", o.certify, "certified Bezier bounds (false: sampled extremes only, a fast screening)");
  f(prefix + "sharp", o.sharp, "refine both bounds to the tolerance (false: stop once validity is decided)");
  f(prefix + "sharp_max", o.sharp_max, "with sharp: refine the upper bound too (false when only the minimum is used)");
  f(prefix + "tolerance", o.tolerance, OptionHelp{"wanted gap between a Bezier bound and the sampled extreme (scaled units)", range::positive});
  f(prefix + "max_depth", o.max_depth, OptionHelp{"deepest subdivision level", range::non_negative});
  f(prefix + "max_leaves", o.max_leaves, OptionHelp{"subdomains per cell at most (the bound stays a bound when hit)", range::at_least(1)});
}

template <class F>
void visit_options(ReportOptions& o, F&& f, const std::string& prefix = {}) {
  f(prefix + "histogram_bins", o.histogram_bins, OptionHelp{"bins of the quality histogram", range::at_least(1)});
  f(prefix + "num_worst", o.num_worst, OptionHelp{"worst cells listed", range::non_negative});
  f(prefix + "reference_measure", o.quality.reference_measure, OptionHelp{"size metrics: the measure of relative size 1 (0: the mean)", range::non_negative});
  visit_options(o.quality.jacobian, f, prefix + "jacobian_");
}

/// Builds the report from per-cell results already computed (cell order).
template <int Dim>
[[nodiscard]] QualityReport make_report(const Mesh<Dim>& mesh, Metric metric, const std::vector<CellQuality>& cells,
                                        const ReportOptions& options = {}) {
  QualityReport r;
  r.metric = metric;
  r.num_elements = static_cast<Index>(cells.size());
  r.histogram.assign(static_cast<std::size_t>(std::max(1, options.histogram_bins)), 0);
  const auto finite = [](double v) { return std::isfinite(v) ? v : 0.0; };
  double sum = 0.0;
  r.min = cells.empty() ? 0.0 : std::numeric_limits<double>::infinity();
  r.max = cells.empty() ? 0.0 : -std::numeric_limits<double>::infinity();
  std::vector<Index> order;
  Index offset = 0;
  for (const auto& block : mesh.cells) {
    TypeQuality t{block.type, block.size(), 0, std::numeric_limits<double>::infinity(),
                  -std::numeric_limits<double>::infinity(), 0.0};
    for (Index e = 0; e < block.size(); ++e) {
      const auto& c = cells[static_cast<std::size_t>(offset + e)];
      const double v = finite(c.value);
      t.num_invalid += c.valid ? 0 : 1;
      t.min = std::min(t.min, v);
      t.max = std::max(t.max, v);
      t.mean += v;
      const auto bins = static_cast<double>(r.histogram.size());
      const auto bin = static_cast<std::size_t>(std::clamp(std::floor(v * bins), 0.0, bins - 1));
      ++r.histogram[bin];
    }
    if (t.num_elements > 0) {
      r.min = std::min(r.min, t.min);
      r.max = std::max(r.max, t.max);
      sum += t.mean;
      t.mean /= static_cast<double>(t.num_elements);
    } else {
      t.min = t.max = 0.0;
    }
    r.num_invalid += t.num_invalid;
    r.per_type.push_back(t);
    offset += block.size();
  }
  if (r.num_elements > 0) r.mean = sum / static_cast<double>(r.num_elements);

  order.resize(cells.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = static_cast<Index>(i);
  const auto k = std::min<std::size_t>(order.size(), static_cast<std::size_t>(std::max(0, options.num_worst)));
  std::partial_sort(order.begin(), order.begin() + static_cast<std::ptrdiff_t>(k), order.end(), [&](Index a, Index b) {
    return finite(cells[static_cast<std::size_t>(a)].value) < finite(cells[static_cast<std::size_t>(b)].value);
  });
  for (std::size_t i = 0; i < k; ++i) {
    Index id = order[i], local = id;
    const ElementBlock* block = nullptr;
    for (const auto& b : mesh.cells) {
      if (local < b.size()) {
        block = &b;
        break;
      }
      local -= b.size();
    }
    WorstElement w;
    w.id = id;
    w.type = block->type;
    w.file_id = msh_element_id(mesh, *block, local);
    w.value = finite(cells[static_cast<std::size_t>(id)].value);
    w.valid = cells[static_cast<std::size_t>(id)].valid;
    const auto nodes = block->element(local);
    const int nv = num_vertices(block->type);
    for (int v = 0; v < nv; ++v)
      for (int d = 0; d < Dim; ++d)
        w.centroid[static_cast<std::size_t>(d)] += mesh.points(d, nodes[static_cast<std::size_t>(v)]) / nv;
    r.worst.push_back(w);
  }
  return r;
}

/// Report of `metric` over the cells of `mesh`. Throws as evaluate_cells().
template <int Dim>
[[nodiscard]] QualityReport quality_report(const Mesh<Dim>& mesh, Metric metric, const ReportOptions& options = {}) {
  return make_report(mesh, metric, evaluate_cells(mesh, metric, options.quality), options);
}

/// The report of a solver's own mesh type (any MeshLike): its cells are copied into a
/// Mesh<Dim> first.
template <MeshLike M>
  requires(!std::same_as<M, Mesh<mesh_dim<M>>>)
[[nodiscard]] QualityReport quality_report(const M& mesh, Metric metric, const ReportOptions& options = {}) {
  return quality_report(to_mesh(mesh), metric, options);
}

/// The report as a JSON string.
[[nodiscard]] inline std::string to_json(const QualityReport& r) {
  std::ostringstream s;
  JsonWriter w(s);
  write_json(w, r);
  return s.str();
}

/// Prints the report as a readable table.
inline void print_report(std::ostream& out, const QualityReport& r) {
  char line[256];
  std::snprintf(line, sizeof line, "%-16s elements %10lld  invalid %8lld  min %10.4g  mean %10.4g  max %10.4g\n",
                std::string(metric_name(r.metric)).c_str(), static_cast<long long>(r.num_elements),
                static_cast<long long>(r.num_invalid), r.min, r.mean, r.max);
  out << line;
  for (const auto& t : r.per_type) {
    std::snprintf(line, sizeof line, "  %-14s elements %10lld  invalid %8lld  min %10.4g  mean %10.4g  max %10.4g\n",
                  std::string(name(t.type)).c_str(), static_cast<long long>(t.num_elements),
                  static_cast<long long>(t.num_invalid), t.min, t.mean, t.max);
    out << line;
  }
  out << "  histogram:";
  for (const Index h : r.histogram) out << ' ' << h;
  out << '\n';
  for (const auto& e : r.worst) {
    std::snprintf(line, sizeof line, "  worst: cell %lld (id %lld, %s) %.6g%s at (%.6g, %.6g, %.6g)\n",
                  static_cast<long long>(e.id), static_cast<long long>(e.file_id), std::string(name(e.type)).c_str(),
                  e.value, e.valid ? "" : " INVALID", e.centroid[0], e.centroid[1], e.centroid[2]);
    out << line;
  }
}

}  // namespace meshmotion

// The compiled library (target meshmotion::compiled, src/) holds these for Dim 2 and 3.
#ifdef MESHMOTION_COMPILED
namespace meshmotion {
extern template QualityReport make_report<2>(const Mesh<2>&, Metric, const std::vector<CellQuality>&, const ReportOptions&);
extern template QualityReport make_report<3>(const Mesh<3>&, Metric, const std::vector<CellQuality>&, const ReportOptions&);
extern template QualityReport quality_report<2>(const Mesh<2>&, Metric, const ReportOptions&);
extern template QualityReport quality_report<3>(const Mesh<3>&, Metric, const ReportOptions&);
}  // namespace meshmotion
#endif
