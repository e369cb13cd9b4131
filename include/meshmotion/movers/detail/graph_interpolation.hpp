#pragma once
/// \file
/// GraphInterpolation: the Delaunay graph of some points and, for each query point, its graph
/// simplex and Dim+1 interpolation weights (barycentric for DGM, per-simplex RBF cardinal
/// weights for DGRBF), so that any per-graph-node quantity is interpolated by one weighted
/// sum per query. Location and the inversion test are delaunay/graph_mapping.hpp's.

#include "meshmotion/core/error.hpp"
#include "meshmotion/core/threads.hpp"
#include "meshmotion/core/types.hpp"
#include "meshmotion/delaunay/bowyer_watson.hpp"
#include "meshmotion/delaunay/delaunay_triangulation.hpp"
#include "meshmotion/delaunay/graph_mapping.hpp"
#include "meshmotion/movers/delaunay_graph_options.hpp"
#include "meshmotion/movers/rbf_kernels.hpp"

#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

namespace meshmotion::detail {

template <int Dim>
class GraphInterpolation {
 public:
  static constexpr int corners = Dim + 1;
  using Weights = Eigen::Matrix<double, corners, Eigen::Dynamic>;
  using Vertices = Eigen::Matrix<Index, corners, Eigen::Dynamic>;

  /// Triangulates `graph_points` (Dim × m) and computes the weights of every column of
  /// `queries` (Dim × q). `rbf` empty: barycentric weights (DGM); otherwise per-simplex RBF
  /// weights (DGRBF). Throws InputError (prefixed by `who`) when the graph points span no
  /// simplex (fewer than Dim+1, collinear, coplanar) or a coordinate is not finite.
  void build(const Points<Dim>& graph_points, const Points<Dim>& queries, const std::optional<SimplexRbfOptions>& rbf,
             OutsideGraph outside, const std::string& who) {
    if (rbf && (!(rbf->simplex_support_radius >= 0.0) || (rbf->simplex_support_radius == 0.0 && !(rbf->simplex_support > 0.0))))
      throw InputError(who + ": simplex RBF support must be positive (got simplex_support_radius " +
                       std::to_string(rbf->simplex_support_radius) + ", simplex_support " + std::to_string(rbf->simplex_support) + ")");
    if (graph_points.cols() < corners)
      throw InputError(who + ": the Delaunay graph needs at least " + std::to_string(corners) + " boundary nodes (got " +
                       std::to_string(graph_points.cols()) + ")");
    std::optional<DelaunayTriangulation<Dim>> graph;
    try {
      graph.emplace(delaunay<Dim>(graph_points));
    } catch (const InputError& e) {
      throw InputError(who + ": cannot build the Delaunay graph of the boundary nodes: " + e.what());
    }
    mapping_.emplace(*graph, queries);
    simplices_ = graph->simplices();
    const Index q = queries.cols();
    vertices_.resize(corners, q);
    weights_ = mapping_->barycentric();
    num_outside_ = 0;
    num_fallback_ = 0;
    std::vector<std::optional<Eigen::Matrix<double, corners, corners>>> inverse;
    std::vector<double> radius;
    if (rbf) prepare_simplices(*graph, *rbf, inverse, radius);
    for (Index k = 0; k < q; ++k) {
      const Index s = mapping_->simplex(k);
      vertices_.col(k) = graph->simplices().col(s);
      auto w = weights_.col(k);
      if (w.minCoeff() < -1e-12) {
        ++num_outside_;
        if (outside == OutsideGraph::clamp) {
          w = w.cwiseMax(0.0);
          w /= w.sum();
        }
      }
      if (!rbf) continue;
      const auto& a_inverse = inverse[static_cast<std::size_t>(s)];
      if (!a_inverse) {
        ++num_fallback_;
        continue;
      }
      // Outside the hull the RBF is evaluated at the point the barycentric weights place.
      const Eigen::Matrix<double, Dim, corners> c = graph->corner_points(s);
      const Vec<Dim> x = c * w;
      Eigen::Matrix<double, corners, 1> phi;
      for (int j = 0; j < corners; ++j) phi(j) = rbf_value(rbf->kernel, (x - c.col(j)).norm(), radius[static_cast<std::size_t>(s)]);
      Eigen::Matrix<double, corners, 1> cardinal = *a_inverse * phi;
      if (rbf->normalize) {
        const double sum = cardinal.sum();
        // No vertex reaches the point (an absolute radius smaller than the simplex): keep the
        // barycentric weights rather than divide by zero.
        if (!(std::abs(sum) > 1e-12)) {
          ++num_fallback_;
          continue;
        }
        cardinal /= sum;
      }
      w = cardinal;
    }
  }

  [[nodiscard]] Index num_queries() const noexcept { return weights_.cols(); }
  /// Queries outside the graph's convex hull.
  [[nodiscard]] Index num_outside() const noexcept { return num_outside_; }
  /// Queries that kept barycentric weights because their simplex's RBF system was singular or
  /// no vertex's support reached them.
  [[nodiscard]] Index num_fallback() const noexcept { return num_fallback_; }
  /// Graph-point indices of each graph simplex, (Dim+1) × n_simplices.
  [[nodiscard]] const typename DelaunayTriangulation<Dim>::SimplexArray& simplices() const noexcept { return simplices_; }
  /// Graph-point indices of query k's simplex, (Dim+1) × q.
  [[nodiscard]] const Vertices& vertices() const noexcept { return vertices_; }

  /// out.col(k) = Σ_j w_jk values.col(vertex_jk): `values` Rows × m (graph-point order),
  /// `out` resized to Rows × q.
  template <int Rows>
  void interpolate(const Eigen::Matrix<double, Rows, Eigen::Dynamic>& values,
                   Eigen::Matrix<double, Rows, Eigen::Dynamic>& out) const {
    const Index q = num_queries();
    out.resize(values.rows(), q);
#pragma omp parallel for num_threads(::meshmotion::num_threads()) schedule(static)
    for (Index k = 0; k < q; ++k) {
      Eigen::Matrix<double, Rows, 1> sum = weights_(0, k) * values.col(vertices_(0, k));
      for (int j = 1; j < corners; ++j) sum += weights_(j, k) * values.col(vertices_(j, k));
      out.col(k) = sum;
    }
  }

  /// The transpose of interpolate(): values_bar.col(vertex_jk) += w_jk out_bar.col(k) for every
  /// query k (`out_bar` Rows × q, `values_bar` Rows × m, accumulated into).
  template <int Rows>
  void interpolate_transpose(const Eigen::Matrix<double, Rows, Eigen::Dynamic>& out_bar,
                             Eigen::Matrix<double, Rows, Eigen::Dynamic>& values_bar) const {
    // Serial: queries share vertices, and a scatter per query is a few flops.
    for (Index k = 0; k < num_queries(); ++k)
      for (int j = 0; j < corners; ++j) values_bar.col(vertices_(j, k)) += weights_(j, k) * out_bar.col(k);
  }

  /// Graph simplices inverted or flattened with the graph points at `moved` (Dim × m).
  [[nodiscard]] std::vector<Index> inverted_simplices(const Points<Dim>& moved) const {
    return mapping_->inverted_simplices(moved);
  }

 private:
  /// Inverse of each simplex's RBF matrix (eq. 2.16), empty when singular, and its radius.
  static void prepare_simplices(const DelaunayTriangulation<Dim>& graph, const SimplexRbfOptions& rbf,
                                std::vector<std::optional<Eigen::Matrix<double, corners, corners>>>& inverse,
                                std::vector<double>& radius) {
    const auto n = static_cast<std::size_t>(graph.num_simplices());
    inverse.assign(n, std::nullopt);
    radius.assign(n, rbf.simplex_support_radius);
    for (std::size_t s = 0; s < n; ++s) {
      const Eigen::Matrix<double, Dim, corners> c = graph.corner_points(static_cast<Index>(s));
      double longest = 0.0;
      Eigen::Matrix<double, corners, corners> distance;
      for (int i = 0; i < corners; ++i)
        for (int j = 0; j < corners; ++j) {
          distance(i, j) = (c.col(i) - c.col(j)).norm();
          longest = std::max(longest, distance(i, j));
        }
      if (rbf.simplex_support_radius == 0.0) radius[s] = rbf.simplex_support * longest;
      Eigen::Matrix<double, corners, corners> a;
      for (int i = 0; i < corners; ++i)
        for (int j = 0; j < corners; ++j) a(i, j) = rbf_value(rbf.kernel, distance(i, j), radius[s]);
      const Eigen::FullPivLU<Eigen::Matrix<double, corners, corners>> lu(a);
      if (lu.isInvertible()) inverse[s] = lu.inverse();
    }
  }

  std::optional<GraphMapping<Dim>> mapping_;
  typename DelaunayTriangulation<Dim>::SimplexArray simplices_;
  Vertices vertices_;
  Weights weights_;
  Index num_outside_ = 0;
  Index num_fallback_ = 0;
};

}  // namespace meshmotion::detail
