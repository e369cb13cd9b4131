#pragma once
/// \file
/// An SVG picture of a 2D mesh with its cells coloured by a per-cell value (quality), a
/// colour bar, P2 edges drawn curved (the quadratic Bézier through the edge's mid node) and an
/// optional zoom box (near-wall cells of boundary-layer meshes are 1e-5 thin). Invalid cells
/// (value ≤ 0) get a red ring of fixed pixel size at their centroid, drawn over the cells, and
/// a legend line with their count: at any zoom that shows the body, a 1e-5 thin inverted cell
/// is narrower than a pixel.

#include "meshmotion/core/element.hpp"
#include "meshmotion/core/detail/atomic_file.hpp"
#include "meshmotion/core/error.hpp"
#include "meshmotion/core/mesh.hpp"
#include "meshmotion/core/types.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace meshmotion {

/// Options of svg_picture().
struct SvgOptions {
  std::optional<std::array<double, 4>> zoom;  ///< xmin, xmax, ymin, ymax; default: the whole mesh
  int width = 1000;                           ///< picture width in pixels (height follows the aspect ratio)
  double value_min = 0.0;                     ///< value at the bottom of the colour scale
  double value_max = 1.0;                     ///< value at the top of the colour scale
  std::string title;                          ///< shown in a band above the picture
  bool draw_edges = true;
  bool mark_invalid = true;                   ///< ring each cell with value ≤ 0 (or NaN) and count them
  double marker_radius = 5.0;                 ///< ring radius in pixels, whatever the cell's size
};

namespace detail {

/// Appends printf-style text of any length: a picture is never silently truncated.
template <class... Args>
void append_format(std::string& out, const char* format, Args... args) {
  const int n = std::snprintf(nullptr, 0, format, args...);
  if (n <= 0) return;
  const std::size_t old = out.size();
  out.resize(old + static_cast<std::size_t>(n) + 1);
  std::snprintf(out.data() + old, static_cast<std::size_t>(n) + 1, format, args...);
  out.resize(old + static_cast<std::size_t>(n));
}

// A perceptually ordered scale (dark blue → teal → yellow), close to viridis.
inline std::string colour(double t) {
  static constexpr std::array<std::array<double, 3>, 5> stops{{
      {68, 1, 84}, {59, 82, 139}, {33, 145, 140}, {94, 201, 98}, {253, 231, 37}}};
  t = std::clamp(std::isfinite(t) ? t : 0.0, 0.0, 1.0) * (stops.size() - 1);
  const auto k = std::min<std::size_t>(static_cast<std::size_t>(t), stops.size() - 2);
  const double f = t - static_cast<double>(k);
  char buf[8];
  std::snprintf(buf, sizeof buf, "#%02x%02x%02x", static_cast<int>(stops[k][0] + f * (stops[k + 1][0] - stops[k][0])),
                static_cast<int>(stops[k][1] + f * (stops[k + 1][1] - stops[k][1])),
                static_cast<int>(stops[k][2] + f * (stops[k + 1][2] - stops[k][2])));
  return buf;
}

}  // namespace detail

/// The SVG text of `mesh` with cell i coloured by values[i] (cell order); only the cells that
/// reach into the zoom box are written. Cells whose value is ≤ 0 or NaN (invalid) are magenta
/// whatever the scale, drawn translucent over the valid ones, and with options.mark_invalid
/// each one drawn also gets a `<circle class="invalid" .../>` ring and the colour-bar column a
/// line "N invalid" (N: the rings drawn). Throws InputError when values.size() !=
/// num_cells() or the zoom box is empty.
[[nodiscard]] inline std::string svg_picture(const Mesh<2>& mesh, const std::vector<double>& values,
                                             const SvgOptions& options = {}) {
  if (static_cast<Index>(values.size()) != mesh.num_cells())
    throw InputError("svg_picture: " + std::to_string(values.size()) + " values for " +
                     std::to_string(mesh.num_cells()) + " cells");
  std::array<double, 4> box{0, 1, 0, 1};
  if (options.zoom) {
    box = *options.zoom;
  } else if (mesh.num_nodes() > 0) {
    box = {mesh.points.row(0).minCoeff(), mesh.points.row(0).maxCoeff(), mesh.points.row(1).minCoeff(),
           mesh.points.row(1).maxCoeff()};
  }
  if (!(box[1] > box[0]) || !(box[3] > box[2]))
    throw InputError("svg_picture: empty zoom box (got x " + std::to_string(box[0]) + ".." + std::to_string(box[1]) +
                     ", y " + std::to_string(box[2]) + ".." + std::to_string(box[3]) + ")");
  const double w = options.width, h = std::clamp(w * (box[3] - box[2]) / (box[1] - box[0]), 100.0, 4.0 * w);
  const double bar = 100;
  // The title gets a band of its own above the picture: in the colour-bar column a long one
  // ran off the right edge.
  const double band = options.title.empty() ? 0.0 : 22.0;
  const auto px = [&](double x) { return (x - box[0]) / (box[1] - box[0]) * w; };
  const auto py = [&](double y) { return (box[3] - y) / (box[3] - box[2]) * h; };
  std::string out;
  detail::append_format(out,
                "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%.0f\" height=\"%.0f\" viewBox=\"0 0 %.0f %.0f\">\n"
                "<rect width=\"100%%\" height=\"100%%\" fill=\"white\"/>\n<g transform=\"translate(0 %.0f)\">\n"
                "<clipPath id=\"box\"><rect width=\"%.0f\" height=\"%.0f\"/></clipPath>\n"
                "<g clip-path=\"url(#box)\" stroke=\"%s\" stroke-width=\"0.4\">\n",
                w + bar, h + band, w + bar, h + band, band, w, h, options.draw_edges ? "black" : "none");
  const double span = options.value_max - options.value_min;
  std::vector<std::array<double, 2>> markers;  // pixel centroids of the invalid cells drawn
  // Invalid cells go on top of the valid ones: a folded cell overlaps its neighbours, and
  // drawn in turn it would hide under the layers it folds across.
  std::string invalid_paths;
  Index cell = 0;
  for (const auto& block : mesh.cells) {
    const int nv = num_vertices(block.type);
    const int p_order = order(block.type);
    for (Index e = 0; e < block.size(); ++e, ++cell) {
      const auto nodes = block.element(e);
      const auto p = [&](int local) { return mesh.points.col(nodes[static_cast<std::size_t>(local)]); };
      double xmin = p(0).x(), xmax = xmin, ymin = p(0).y(), ymax = ymin;
      for (std::size_t k = 0; k < nodes.size(); ++k) {
        const auto q = mesh.points.col(nodes[k]);
        xmin = std::min(xmin, q.x()), xmax = std::max(xmax, q.x()), ymin = std::min(ymin, q.y()), ymax = std::max(ymax, q.y());
      }
      if (!(xmax >= box[0] && xmin <= box[1] && ymax >= box[2] && ymin <= box[3])) continue;  // also skips NaN
      const double v = values[static_cast<std::size_t>(cell)];
      const bool invalid = v <= 0 || !std::isfinite(v);
      const std::string fill = invalid ? std::string("#ff00ff")
                                       : detail::colour(span > 0 ? (v - options.value_min) / span : 1.0);
      if (invalid && options.mark_invalid) {
        std::array<double, 2> c{0.0, 0.0};
        for (int k = 0; k < nv; ++k) c[0] += px(p(k).x()) / nv, c[1] += py(p(k).y()) / nv;
        markers.push_back(c);
      }
      std::string& path = invalid ? invalid_paths : out;
      detail::append_format(path, "<path fill=\"%s\" d=\"M%.3f %.3f", fill.c_str(), px(p(0).x()), py(p(0).y()));
      for (int k = 0; k < nv; ++k) {
        const auto b = p((k + 1) % nv);
        if (p_order == 2) {
          // The quadratic through a, m (at t = 1/2) and b has control point 2m - (a + b)/2.
          const Eigen::Vector2d c = 2.0 * p(nv + k) - 0.5 * (p(k) + b);
          detail::append_format(path, " Q%.3f %.3f %.3f %.3f", px(c.x()), py(c.y()), px(b.x()), py(b.y()));
        } else if (p_order > 2) {
          // SVG has no curves past cubics: 4 segments per edge node interval, on the edge's
          // Lagrange polynomial through its p + 1 nodes (at t = j/p, from vertex k).
          const auto edge_node = [&](int j) { return j == 0 ? p(k) : j == p_order ? b : p(nv + k * (p_order - 1) + j - 1); };
          const int segments = 4 * p_order;
          for (int s = 1; s <= segments; ++s) {
            const double t = static_cast<double>(s) / segments;
            Eigen::Vector2d x = Eigen::Vector2d::Zero();
            for (int j = 0; j <= p_order; ++j) {
              double l = 1.0;
              for (int m = 0; m <= p_order; ++m)
                if (m != j) l *= (t * p_order - m) / (j - m);
              x += l * edge_node(j);
            }
            detail::append_format(path, " L%.3f %.3f", px(x.x()), py(x.y()));
          }
        } else {
          detail::append_format(path, " L%.3f %.3f", px(b.x()), py(b.y()));
        }
      }
      path += "Z\"/>\n";
    }
  }
  // Translucent, so that the layers a folded cell lies across still show.
  if (!invalid_paths.empty()) {
    out += "<g fill-opacity=\"0.6\">\n";
    out += invalid_paths;
    out += "</g>\n";
  }
  out += "</g>\n";
  if (!markers.empty()) {
    // Over the cells, so that neighbours drawn later do not hide them.
    out += "<g clip-path=\"url(#box)\" fill=\"none\" stroke=\"red\" stroke-width=\"1.5\">\n";
    for (const auto& m : markers)
      detail::append_format(out, "<circle class=\"invalid\" cx=\"%.2f\" cy=\"%.2f\" r=\"%.1f\"/>\n", m[0], m[1],
                            options.marker_radius);
    out += "</g>\n";
  }
  // Colour bar: 20 steps from value_max (top) to value_min (bottom).
  const double bx = w + 15, bh = std::min(h - 70, 400.0), by = 25;  // room for the legend below
  for (int k = 0; k < 20; ++k) {
    detail::append_format(out, "<rect x=\"%.1f\" y=\"%.2f\" width=\"20\" height=\"%.2f\" fill=\"%s\"/>\n", bx,
                          by + k * bh / 20, bh / 20 + 0.5, detail::colour(1.0 - (k + 0.5) / 20).c_str());
  }
  for (int k = 0; k <= 4; ++k) {
    detail::append_format(out, "<text x=\"%.1f\" y=\"%.1f\" font-size=\"11\" font-family=\"sans-serif\">%.3g</text>\n",
                          bx + 24, by + bh * (1.0 - k / 4.0) + 4, options.value_min + span * k / 4.0);
  }
  if (options.mark_invalid) {
    const double ly = by + bh + 25;
    detail::append_format(out,
                          "<circle cx=\"%.1f\" cy=\"%.1f\" r=\"5\" fill=\"#ff00ff\" stroke=\"red\" stroke-width=\"1.5\"/>\n"
                          "<text x=\"%.1f\" y=\"%.1f\" font-size=\"11\" font-family=\"sans-serif\">%zu invalid</text>\n"
                          "<text x=\"%.1f\" y=\"%.1f\" font-size=\"11\" font-family=\"sans-serif\">(≤ 0, ringed)</text>\n",
                          bx + 5, ly - 4, bx + 14, ly, markers.size(), bx, ly + 14);
  }
  out += "</g>\n";
  if (!options.title.empty()) {
    out += "<text x=\"5\" y=\"15\" font-size=\"12\" font-family=\"sans-serif\">";
    for (const char ch : options.title) out += ch == '<' ? std::string("&lt;") : ch == '&' ? std::string("&amp;") : std::string(1, ch);
    out += "</text>\n";
  }
  out += "</svg>\n";
  return out;
}

/// Writes svg_picture() to `file`, atomically (a temporary file in the same folder, then a
/// rename). Throws IoError when the file cannot be written, InputError as svg_picture().
inline void write_svg(const std::filesystem::path& file, const Mesh<2>& mesh, const std::vector<double>& values,
                      const SvgOptions& options = {}) {
  detail::write_file_atomically(file, svg_picture(mesh, values, options));
}

}  // namespace meshmotion
