#pragma once
/// \file
/// The plane of a sliding group whose nodes are spread over the ranks: fit_plane() of the
/// whole group, its sums reduced over the communicator, so that a partitioned mesh finds the
/// normal (and refuses a group that is not planar, with the same message) as one mesh does.

#include "meshmotion/core/types.hpp"
#include "meshmotion/movers/boundary.hpp"

#include <mpi.h>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <span>
#include <string>

namespace meshmotion::parallel {

/// Collective. fit_plane() of the nodes `list` of `points` on every rank together (each node
/// listed by one rank only: its owner).
template <int Dim>
[[nodiscard]] PlaneFit<Dim> fit_plane(MPI_Comm comm, const Points<Dim>& points, std::span<const Index> list, Index* count = nullptr) {
  double local[Dim + 1] = {}, total[Dim + 1] = {};
  for (const Index v : list)
    for (int a = 0; a < Dim; ++a) local[a] += points(a, v);
  local[Dim] = static_cast<double>(list.size());
  MPI_Allreduce(local, total, Dim + 1, MPI_DOUBLE, MPI_SUM, comm);
  PlaneFit<Dim> fit;
  for (int a = 0; a < Dim; ++a) fit.centroid(a) = total[a] / std::max(total[Dim], 1.0);
  if (count != nullptr) *count = static_cast<Index>(total[Dim]);
  Eigen::Matrix<double, Dim, Dim> scatter = Eigen::Matrix<double, Dim, Dim>::Zero(), all;
  double extent = 0.0;
  for (const Index v : list) {
    const Vec<Dim> r = points.col(v) - fit.centroid;
    scatter += r * r.transpose();
    extent = std::max(extent, r.norm());
  }
  MPI_Allreduce(scatter.data(), all.data(), Dim * Dim, MPI_DOUBLE, MPI_SUM, comm);
  MPI_Allreduce(&extent, &fit.extent, 1, MPI_DOUBLE, MPI_MAX, comm);
  fit.normal = Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, Dim, Dim>>(all).eigenvectors().col(0);
  double off = 0.0;
  for (const Index v : list) off = std::max(off, std::abs(fit.normal.dot(points.col(v) - fit.centroid)));
  MPI_Allreduce(&off, &fit.off_plane, 1, MPI_DOUBLE, MPI_MAX, comm);
  return fit;
}

/// Collective. The normal of sliding group `group` from its nodes `owned` (this rank's, each
/// node on one rank), as BoundarySpec::resolve finds it on one mesh: sliding_plane_normal()'s
/// InputError on every rank when the group is too small or not planar.
template <int Dim>
[[nodiscard]] Vec<Dim> sliding_plane_normal(MPI_Comm comm, const std::string& group, const Points<Dim>& points,
                                            std::span<const Index> owned) {
  Index count = 0;
  const PlaneFit<Dim> fit = fit_plane(comm, points, owned, &count);
  return meshmotion::sliding_plane_normal<Dim>(group, count, fit);
}

}  // namespace meshmotion::parallel
