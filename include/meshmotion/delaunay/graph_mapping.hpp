#pragma once
/// \file
/// The core mathematics of the Delaunay graph mapping (DGM: Liu, Qin and Xia, JCP 2006;
/// thesis section 2.2.1): every query point (mesh node) is located once in a Delaunay
/// triangulation of the graph points (boundary nodes) and keeps its barycentric coordinates;
/// after the graph points move, it is placed at the same barycentric combination of its
/// simplex's moved vertices. The map is linear in the graph positions, so displacements map
/// the same way. It is only valid while no graph simplex inverts: inverted_simplices() says
/// which did (exact orientation test), and the caller refuses or rebuilds the graph.
/// Setup costs one hinted walk per query (queries visited in Hilbert order); mapping costs
/// (Dim + 1) × Dim multiply-adds per query and allocates nothing in its non-allocating form.

#include "meshmotion/core/error.hpp"
#include "meshmotion/core/types.hpp"
#include "meshmotion/delaunay/delaunay_triangulation.hpp"
#include "meshmotion/delaunay/detail/bowyer_watson_kernel.hpp"
#include "meshmotion/delaunay/detail/spatial_sort.hpp"

#include <Eigen/Core>

#include <string>
#include <vector>

namespace meshmotion {

/// Barycentric coordinates of query points in a Delaunay graph, mapped through moved graph
/// vertices.
template <int Dim>
class GraphMapping {
 public:
  static constexpr int corners = Dim + 1;

  /// Locates every column of `queries` (Dim × n_queries) in `graph`. Queries outside the
  /// graph's convex hull get the nearest hull simplex and extrapolating coordinates, and are
  /// counted in num_outside(). Keeps a copy of the graph's simplices (the graph itself may
  /// be discarded). Throws InputError for non-finite query coordinates.
  GraphMapping(const DelaunayTriangulation<Dim>& graph, const Points<Dim>& queries)
      : simplices_(graph.simplices()),
        n_graph_points_(graph.points().cols()),
        query_simplex_(static_cast<std::size_t>(queries.cols())),
        barycentric_(corners, queries.cols()) {
    const std::vector<Index> order =
        detail::brio_order<Dim>(queries, 1, static_cast<std::size_t>(queries.cols()));
    Index hint = -1;
    for (Index q : order) {
      if (!queries.col(q).allFinite()) {
        throw InputError("GraphMapping: query point " + std::to_string(q) +
                         " has a non-finite coordinate (expected finite coordinates)");
      }
      const LocateResult<Dim> where = graph.locate(queries.col(q), hint);
      hint = where.simplex;
      query_simplex_[static_cast<std::size_t>(q)] = where.simplex;
      barycentric_.col(q) = where.barycentric;
      num_outside_ += where.outside;
    }
  }

  [[nodiscard]] Index num_queries() const noexcept { return barycentric_.cols(); }
  /// Number of queries outside the graph's convex hull (mapped by extrapolation).
  [[nodiscard]] Index num_outside() const noexcept { return num_outside_; }
  /// The graph simplex of query q.
  [[nodiscard]] Index simplex(Index q) const { return query_simplex_[static_cast<std::size_t>(q)]; }
  /// Barycentric coordinates, (Dim+1) × n_queries, in the order of the simplex's vertices.
  [[nodiscard]] const Eigen::Matrix<double, Dim + 1, Eigen::Dynamic>& barycentric() const noexcept {
    return barycentric_;
  }

  /// Positions (or displacements: the map is linear) of the queries for graph point values
  /// `graph_values` (Dim × n_graph_points, indexed like the graph's input points), written
  /// into `out` (resized to Dim × n_queries). Throws InputError on a size mismatch.
  void map(const Points<Dim>& graph_values, Points<Dim>& out) const {
    check_size(graph_values, "GraphMapping::map");
    out.resize(Dim, num_queries());
    for (Index q = 0; q < num_queries(); ++q) {
      const Index s = query_simplex_[static_cast<std::size_t>(q)];
      Vec<Dim> x = Vec<Dim>::Zero();
      for (int j = 0; j < corners; ++j)
        x += barycentric_(j, q) * graph_values.col(simplices_(j, s));
      out.col(q) = x;
    }
  }

  /// Allocating form of map().
  [[nodiscard]] Points<Dim> map(const Points<Dim>& graph_values) const {
    Points<Dim> out;
    map(graph_values, out);
    return out;
  }

  /// Graph simplices that are inverted or degenerate (orientation <= 0, exact test) when the
  /// graph points are at `moved_graph_points` (Dim × n_graph_points). Empty when the mapping
  /// is valid. Throws InputError on a size mismatch.
  [[nodiscard]] std::vector<Index> inverted_simplices(const Points<Dim>& moved_graph_points) const {
    check_size(moved_graph_points, "GraphMapping::inverted_simplices");
    std::vector<Index> inverted;
    for (Index s = 0; s < simplices_.cols(); ++s) {
      const double* p[corners];
      for (int j = 0; j < corners; ++j) p[j] = moved_graph_points.col(simplices_(j, s)).data();
      if (detail::orientation<Dim>(p) <= 0) inverted.push_back(s);
    }
    return inverted;
  }

 private:
  void check_size(const Points<Dim>& values, const char* where) const {
    if (values.cols() != n_graph_points_) {
      throw InputError(std::string(where) + ": wrong number of graph points (got " +
                       std::to_string(values.cols()) + ", expected " +
                       std::to_string(n_graph_points_) + ")");
    }
    if (!values.allFinite()) {
      throw InputError(std::string(where) + ": graph values have a non-finite coordinate");
    }
  }

  typename DelaunayTriangulation<Dim>::SimplexArray simplices_;
  Index n_graph_points_;
  std::vector<Index> query_simplex_;
  Eigen::Matrix<double, Dim + 1, Eigen::Dynamic> barycentric_;
  Index num_outside_ = 0;
};

}  // namespace meshmotion
