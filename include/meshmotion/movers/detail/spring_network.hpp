#pragma once
/// \file
/// The lineal springs of a mesh (thesis eqs. 2.1–2.2): one spring per edge of a linear cell,
/// and on quadratic cells one per half edge of the element's natural sub-division (vertex to
/// edge node, and between high-order nodes half an edge apart, e.g. the four sub-triangles of
/// a tri6 or the eight sub-hexahedra of a hex27), so every node of any type is connected.
/// Springs shared by neighbouring cells are counted once.

#include "meshmotion/core/element.hpp"
#include "meshmotion/core/error.hpp"
#include "meshmotion/core/mesh.hpp"
#include "meshmotion/core/shape_functions.hpp"
#include "meshmotion/core/types.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include <Eigen/SparseCore>

namespace meshmotion::detail {

/// Local node pairs of `type` joined by a spring: pairs whose reference offset is ±1/order
/// of a reference edge vector (for linear types exactly the edges).
[[nodiscard]] inline const std::vector<std::array<int, 2>>& spring_pairs(ElementType type) {
  static PerTypeCache<std::vector<std::array<int, 2>>> table;
  return table.get(type, [](ElementType type_t) {
    std::vector<std::array<int, 2>> pairs;
    if (dimension(type_t) < 1) return pairs;
    const auto x = reference_nodes(type_t);
    const double p = order(type_t);
    const auto offset_matches = [&](int i, int j, const std::array<int, 2>& e) {
      double plus = 0.0, minus = 0.0;
      for (std::size_t d = 0; d < 3; ++d) {
        const double edge = (x[static_cast<std::size_t>(e[1])][d] - x[static_cast<std::size_t>(e[0])][d]) / p;
        const double offset = x[static_cast<std::size_t>(j)][d] - x[static_cast<std::size_t>(i)][d];
        plus = std::max(plus, std::abs(offset - edge));
        minus = std::max(minus, std::abs(offset + edge));
      }
      return std::min(plus, minus) < 1e-12;
    };
    const int n = num_nodes(type_t);
    for (int i = 0; i < n; ++i)
      for (int j = i + 1; j < n; ++j)
        for (const auto& e : edges(type_t))
          if (offset_matches(i, j, e)) {
            pairs.push_back({i, j});
            break;
          }
    return pairs;
  });
}

/// Unique springs (node pairs, smaller index first) of the cells of `mesh`, sorted.
template <int Dim>
[[nodiscard]] std::vector<std::array<Index, 2>> mesh_springs(const Mesh<Dim>& mesh) {
  std::vector<std::array<Index, 2>> springs;
  Index count = 0;
  for (const auto& block : mesh.cells) count += block.size() * static_cast<Index>(spring_pairs(block.type).size());
  springs.reserve(static_cast<std::size_t>(count));
  for (const auto& block : mesh.cells) {
    const auto& pairs = spring_pairs(block.type);
    for (Index e = 0; e < block.size(); ++e) {
      const auto nodes = block.element(e);
      for (const auto& [i, j] : pairs) {
        const Index a = nodes[static_cast<std::size_t>(i)], b = nodes[static_cast<std::size_t>(j)];
        if (a != b) springs.push_back({std::min(a, b), std::max(a, b)});
      }
    }
  }
  std::sort(springs.begin(), springs.end());
  springs.erase(std::unique(springs.begin(), springs.end()), springs.end());
  return springs;
}

/// Triplets of the springs of `mesh`, k = ‖r_b − r_a‖^−exponent, on node-major dofs with
/// `components` per node. Uncoupled (Batina): the same spring k in each direction. Coupled
/// (the truss springs of Farhat et al. 1998; components must be Dim): the spring resists only
/// the change of its length, so its blocks are ±k e eᵀ with e the unit direction a → b, and it
/// stores no energy in an infinitesimal rigid rotation. Throws InputError, prefixed by
/// `where`, when a spring joins two distinct nodes at the same position.
template <int Dim>
[[nodiscard]] std::vector<Eigen::Triplet<double, int>> spring_triplets(const Mesh<Dim>& mesh, int components, double exponent,
                                                                       bool coupled, const std::string& where) {
  const auto springs = mesh_springs(mesh);
  std::vector<Eigen::Triplet<double, int>> triplets;
  const auto c = static_cast<std::size_t>(components);
  triplets.reserve(springs.size() * 4 * (coupled ? c * c : c));
  for (const auto& [a, b] : springs) {
    const Vec<Dim> d = mesh.points.col(b) - mesh.points.col(a);
    const double length = d.norm();
    if (!(length > 0.0))
      throw InputError(where + ": nodes " + std::to_string(a) + " and " + std::to_string(b) +
                       " share an edge but coincide (got length 0, expected > 0)");
    const double k = std::pow(length, -exponent);
    for (int i = 0; i < components; ++i)
      for (int j = coupled ? 0 : i; j < (coupled ? components : i + 1); ++j) {
        const double kij = coupled ? k * d(i) * d(j) / (length * length) : k;
        const auto ai = static_cast<int>(a * components + i), aj = static_cast<int>(a * components + j);
        const auto bi = static_cast<int>(b * components + i), bj = static_cast<int>(b * components + j);
        triplets.emplace_back(ai, aj, kij);
        triplets.emplace_back(bi, bj, kij);
        triplets.emplace_back(ai, bj, -kij);
        triplets.emplace_back(bi, aj, -kij);
      }
  }
  return triplets;
}

/// Batina's uncoupled lineal springs (spring_triplets with coupled = false).
template <int Dim>
[[nodiscard]] std::vector<Eigen::Triplet<double, int>> lineal_spring_triplets(const Mesh<Dim>& mesh, int components,
                                                                              double exponent, const std::string& where) {
  return spring_triplets(mesh, components, exponent, false, where);
}

}  // namespace meshmotion::detail
