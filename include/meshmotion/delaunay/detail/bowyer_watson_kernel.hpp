#pragma once
/// \file
/// The Bowyer–Watson "Delaunay kernel" of thesis appendix A, for triangles (Dim = 2) and
/// tetrahedra (Dim = 3), on vertices given in insertion order.
///
/// Departures from appendix A, and why:
/// - The super simplex has its vertices at infinity: one symbolic vertex `infinite()` joined
///   to every convex-hull facet ("ghost" simplices, as in CGAL and Shewchuk's Triangle). A
///   finite super simplex loses hull simplices and can leave the hull non-Delaunay; the
///   symbolic one gives exactly the Delaunay triangulation of the input, and removing it at
///   the end is dropping the ghosts.
/// - Predicates are exact (predicates.hpp) and evaluated on the input coordinates, so
///   co-circular and co-spherical points cannot corrupt the cavity: a simplex is in conflict
///   only when the new point is strictly inside its circumsphere, and then every cavity
///   boundary facet is strictly visible from the point (the cavity is star-shaped).
/// - Replacing the vertex opposite each cavity boundary facet by the new point keeps the
///   positive orientation of every simplex (note 4 of the appendix) without bookkeeping.

#include "meshmotion/core/error.hpp"
#include "meshmotion/delaunay/predicates.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace meshmotion::detail {

/// Sign of the orientation of Dim + 1 points (positive = counterclockwise / Gmsh-positive).
template <int Dim>
[[nodiscard]] inline int orientation(const double* const* p) {
  if constexpr (Dim == 2) {
    return orient2d(p[0], p[1], p[2]);
  } else {
    return orient3d(p[0], p[1], p[2], p[3]);
  }
}

/// > 0 when q is strictly inside the circumsphere of the positively oriented simplex p.
template <int Dim>
[[nodiscard]] inline int in_sphere(const double* const* p, const double* q) {
  if constexpr (Dim == 2) {
    return incircle(p[0], p[1], p[2], q);
  } else {
    return insphere(p[0], p[1], p[2], p[3], q);
  }
}

/// True when the coplanar points a, b, c, q (3D) have q strictly inside the circle through
/// a, b, c. The circle is the plane's section of any sphere through a, b, c and a fourth
/// point off the plane, so an exact insphere test with such a point decides it.
[[nodiscard]] inline bool coplanar_in_circle(const double* a, const double* b, const double* c,
                                             const double* q) {
  for (int axis = 0; axis < 3; ++axis) {
    double lifted[3] = {a[0], a[1], a[2]};
    lifted[axis] += std::max(1.0, std::abs(a[axis]));
    const int side = orient3d(a, b, c, lifted);
    if (side != 0) return side * insphere(a, b, c, lifted, q) > 0;
  }
  return false;  // a, b, c collinear: no circle (does not happen for hull facets)
}

/// True when collinear q lies strictly between a and b.
template <int Dim>
[[nodiscard]] inline bool strictly_between(const double* a, const double* b, const double* q) {
  for (int d = 0; d < Dim; ++d) {
    if (a[d] != b[d]) {
      return std::min(a[d], b[d]) < q[d] && q[d] < std::max(a[d], b[d]);
    }
  }
  return false;
}

/// Incremental Delaunay triangulation with ghost simplices. Vertices are 0..n-1 (the caller's
/// insertion order); `coordinates` is Dim × n column-major and must outlive the kernel.
template <int Dim>
class BowyerWatsonKernel {
 public:
  static constexpr int corners = Dim + 1;
  using Id = std::int32_t;

  BowyerWatsonKernel(const double* coordinates, Id n_vertices, std::uint64_t seed)
      : xyz_(coordinates), n_(n_vertices), rng_state_(seed | 1u), representative_(n_vertices) {
    cells_.reserve((Dim == 2 ? 2 : 7) * static_cast<std::size_t>(n_) + 16);
    if constexpr (Dim == 2) vertex_ridges_.resize(static_cast<std::size_t>(n_) + 1);
    for (Id v = 0; v < n_; ++v) representative_[v] = v;
  }

  /// The symbolic vertex at infinity shared by all ghost simplices.
  [[nodiscard]] Id infinite() const noexcept { return n_; }

  /// Builds the first simplex from vertices 0..Dim (which must be affinely independent) and
  /// its ghosts, then inserts vertices Dim+1..n-1.
  void run() {
    make_first_simplex();
    for (Id v = corners; v < n_; ++v) insert(v);
  }

  [[nodiscard]] Id num_slots() const noexcept { return static_cast<Id>(cells_.size()); }
  [[nodiscard]] bool is_dead(Id s) const noexcept { return vertex(s, 0) < 0; }
  [[nodiscard]] bool is_ghost(Id s) const noexcept {
    for (int i = 0; i < corners; ++i) {
      if (vertex(s, i) == n_) return true;
    }
    return false;
  }
  [[nodiscard]] Id vertex(Id s, int i) const noexcept { return cells_[s].vertices[i]; }
  [[nodiscard]] Id neighbour(Id s, int i) const noexcept { return cells_[s].neighbours[i]; }
  /// The vertex that vertex v duplicates (v itself when unique).
  [[nodiscard]] Id representative(Id v) const noexcept { return representative_[v]; }

 private:
  /// A simplex: vertices, neighbour opposite each vertex, and the cavity-search mark, packed
  /// so that visiting a simplex touches one cache line.
  struct Cell {
    std::array<Id, corners> vertices;
    std::array<Id, corners> neighbours;
    std::uint32_t mark;
  };
  struct BoundaryFacet {
    std::array<Id, corners> vertices;  // the new simplex: old one with the point at `facet`
    Id outside;                        // simplex across the facet, not in the cavity
    int facet;
    int outside_facet;  // index of the facet in `outside`
  };
  struct RidgeEntry {
    Id low = -1;
    Id high = -1;
    Id simplex = -1;
    int facet = -1;
  };

  [[nodiscard]] const double* point(Id v) const noexcept {
    return xyz_ + static_cast<std::size_t>(v) * Dim;
  }
  Id& vertex_ref(Id s, int i) noexcept { return cells_[s].vertices[i]; }
  Id& neighbour_ref(Id s, int i) noexcept { return cells_[s].neighbours[i]; }

  std::uint64_t random() noexcept {
    rng_state_ ^= rng_state_ << 13;
    rng_state_ ^= rng_state_ >> 7;
    rng_state_ ^= rng_state_ << 17;
    return rng_state_;
  }

  Id allocate() {
    if (!free_.empty()) {
      const Id s = free_.back();
      free_.pop_back();
      return s;
    }
    const auto s = static_cast<Id>(cells_.size());
    if (s == std::numeric_limits<Id>::max()) {
      throw InputError("delaunay: too many simplices for 32-bit indices (got " +
                       std::to_string(n_) + " points)");
    }
    cells_.push_back(Cell{{}, {}, 0});
    return s;
  }

  /// Orientation of simplex s with vertex i replaced by q (s finite).
  [[nodiscard]] int orientation_with(Id s, int i, const double* q) const {
    const double* p[corners];
    for (int k = 0; k < corners; ++k) p[k] = k == i ? q : point(vertex(s, k));
    return orientation<Dim>(p);
  }

  /// True when q is strictly inside the circumsphere of s. For a ghost, "inside" is the open
  /// half-space beyond its hull facet plus, on the facet's plane, the open circumdisk of the
  /// facet (the limit of the spheres through the facet and a vertex receding to infinity).
  [[nodiscard]] bool in_conflict(Id s, const double* q) const {
    int infinite_at = -1;
    const double* p[corners];
    for (int k = 0; k < corners; ++k) {
      const Id v = vertex(s, k);
      if (v == n_) {
        infinite_at = k;
        p[k] = q;
      } else {
        p[k] = point(v);
      }
    }
    if (infinite_at < 0) return in_sphere<Dim>(p, q) > 0;
    const int side = orientation<Dim>(p);
    if (side != 0) return side > 0;
    const double* facet[Dim];
    for (int k = 0, m = 0; k < corners; ++k) {
      if (k != infinite_at) facet[m++] = p[k];
    }
    if constexpr (Dim == 2) {
      return strictly_between<Dim>(facet[0], facet[1], q);
    } else {
      return coplanar_in_circle(facet[0], facet[1], facet[2], q);
    }
  }

  void make_first_simplex() {
    std::array<Id, corners> first{};
    for (int i = 0; i < corners; ++i) first[i] = i;
    const Id s = allocate();
    for (int i = 0; i < corners; ++i) vertex_ref(s, i) = first[i];
    if (orientation_with(s, 0, point(0)) < 0) std::swap(vertex_ref(s, 0), vertex_ref(s, 1));
    // Ghost i replaces vertex i by infinity, with two finite vertices swapped so that
    // substituting a point beyond the facet gives a positive simplex.
    std::array<Id, corners> ghosts{};
    for (int i = 0; i < corners; ++i) {
      ghosts[i] = allocate();
      const int a = i == 0 ? 1 : 0;
      const int b = i == corners - 1 ? corners - 2 : corners - 1;
      for (int k = 0; k < corners; ++k) vertex_ref(ghosts[i], k) = vertex(s, k);
      vertex_ref(ghosts[i], i) = n_;
      std::swap(vertex_ref(ghosts[i], a), vertex_ref(ghosts[i], b));
      neighbour_ref(s, i) = ghosts[i];
    }
    for (int i = 0; i < corners; ++i) {
      for (int k = 0; k < corners; ++k) {
        const Id v = vertex(ghosts[i], k);
        if (v == n_) {
          neighbour_ref(ghosts[i], k) = s;
        } else {
          for (int m = 0; m < corners; ++m) {
            if (vertex(s, m) == v) neighbour_ref(ghosts[i], k) = ghosts[m];
          }
        }
      }
    }
    last_ = s;
  }

  /// A simplex in conflict with q: a finite simplex whose closure contains q, or a ghost whose
  /// hull facet q is strictly beyond. Remembering stochastic visibility walk (Devillers, Pion
  /// and Teillaud 2002) from the last created simplex, exhaustive search as a safety net.
  [[nodiscard]] Id locate(const double* q) {
    Id s = last_;
    Id previous = -1;
    const std::size_t max_steps = 64 + 4 * cells_.size();
    for (std::size_t step = 0; step < max_steps; ++step) {
      if (is_ghost(s)) return s;
      const int start = static_cast<int>(random() % corners);
      Id next = -1;
      for (int k = 0; k < corners; ++k) {
        const int i = (start + k) % corners;
        const Id across = neighbour(s, i);
        if (across == previous) continue;
        if (orientation_with(s, i, q) < 0) {
          next = across;
          break;
        }
      }
      if (next < 0) return s;
      previous = s;
      s = next;
    }
    return locate_exhaustively(q);
  }

  [[nodiscard]] Id locate_exhaustively(const double* q) const {
    Id beyond = -1;
    for (Id s = 0; s < num_slots(); ++s) {
      if (is_dead(s)) continue;
      if (is_ghost(s)) {
        if (beyond < 0 && in_conflict(s, q)) beyond = s;
        continue;
      }
      bool inside = true;
      for (int i = 0; i < corners && inside; ++i) inside = orientation_with(s, i, q) >= 0;
      if (inside) return s;
    }
    return beyond;
  }

  void insert(Id v) {
    const double* q = point(v);
    const Id host = locate(q);
    if (!is_ghost(host)) {
      for (int i = 0; i < corners; ++i) {
        const double* w = point(vertex(host, i));
        if (std::equal(q, q + Dim, w)) {
          representative_[v] = vertex(host, i);
          return;
        }
      }
    }
    find_cavity(host, q);
    retriangulate(v);
  }

  /// Breadth of in-sphere violations from the host (appendix A, "badElements"); records the
  /// cavity's boundary facets.
  void find_cavity(Id host, const double* q) {
    epoch_ += 2;
    const std::uint32_t in_cavity = epoch_;
    const std::uint32_t rejected = epoch_ + 1;
    cavity_.clear();
    boundary_.clear();
    cavity_.push_back(host);
    cells_[host].mark = in_cavity;
    for (std::size_t c = 0; c < cavity_.size(); ++c) {
      const Id s = cavity_[c];
      for (int i = 0; i < corners; ++i) {
        const Id t = neighbour(s, i);
        std::uint32_t& mark = cells_[t].mark;
        if (mark == in_cavity) continue;
        if (mark != rejected && in_conflict(t, q)) {
          mark = in_cavity;
          cavity_.push_back(t);
          continue;
        }
        mark = rejected;
        BoundaryFacet f;
        for (int k = 0; k < corners; ++k) f.vertices[k] = vertex(s, k);
        f.facet = i;
        f.outside = t;
        f.outside_facet = 0;
        while (neighbour(t, f.outside_facet) != s) ++f.outside_facet;
        boundary_.push_back(f);
      }
    }
  }

  /// Joins every cavity boundary facet to the new vertex and links the new simplices to each
  /// other through their shared ridges (the new facets minus the new vertex).
  void retriangulate(Id v) {
    for (Id s : cavity_) {
      vertex_ref(s, 0) = -1;
      free_.push_back(s);
    }
    if constexpr (Dim == 3) {
      std::size_t table_size = 16;
      while (table_size < 4 * Dim * boundary_.size()) table_size *= 2;
      if (ridges_.size() < table_size) ridges_.resize(table_size);
      ridge_mask_ = table_size - 1;
    }
    Id finite_new = -1;
    for (BoundaryFacet& f : boundary_) {
      f.vertices[f.facet] = v;
      const Id s = allocate();
      bool ghost = false;
      for (int k = 0; k < corners; ++k) {
        vertex_ref(s, k) = f.vertices[k];
        ghost = ghost || f.vertices[k] == n_;
      }
      if (!ghost) finite_new = s;
      neighbour_ref(s, f.facet) = f.outside;
      neighbour_ref(f.outside, f.outside_facet) = s;
      for (int j = 0; j < corners; ++j) {
        if (j != f.facet) link_ridge(s, j, f);
      }
    }
    if constexpr (Dim == 3) {
      for (std::size_t slot : touched_) ridges_[slot] = RidgeEntry{};
      touched_.clear();
    }
    last_ = finite_new;
  }

  /// Links the facet opposite vertex j of new simplex s to the other new simplex sharing its
  /// ridge, or records it for that simplex.
  void link_ridge(Id s, int j, const BoundaryFacet& f) {
    RidgeEntry* entry = nullptr;
    if constexpr (Dim == 2) {
      // The ridge is one vertex: a vertex-indexed table stamped by insertion (in `low`).
      entry = &vertex_ridges_[f.vertices[3 - j - f.facet]];
      if (entry->low != static_cast<Id>(epoch_)) {
        *entry = RidgeEntry{static_cast<Id>(epoch_), 0, s, j};
        return;
      }
    } else {
      // The ridge is an edge: a small open-addressing hash table, cleared after each insertion.
      Id low = std::numeric_limits<Id>::max();
      Id high = -1;
      for (int k = 0; k < corners; ++k) {
        if (k == j || k == f.facet) continue;
        low = std::min(low, f.vertices[k]);
        high = std::max(high, f.vertices[k]);
      }
      std::size_t slot =
          (static_cast<std::size_t>(low) * 0x9E3779B97F4A7C15ull ^ static_cast<std::size_t>(high)) &
          ridge_mask_;
      while (ridges_[slot].simplex >= 0 &&
             (ridges_[slot].low != low || ridges_[slot].high != high)) {
        slot = (slot + 1) & ridge_mask_;
      }
      entry = &ridges_[slot];
      if (entry->simplex < 0) {
        *entry = RidgeEntry{low, high, s, j};
        touched_.push_back(slot);
        return;
      }
    }
    neighbour_ref(s, j) = entry->simplex;
    neighbour_ref(entry->simplex, entry->facet) = s;
  }

  const double* xyz_;
  Id n_;
  std::uint64_t rng_state_;
  std::vector<Id> representative_;
  std::vector<Cell> cells_;
  std::uint32_t epoch_ = 0;
  std::vector<Id> free_;
  Id last_ = 0;
  std::vector<Id> cavity_;
  std::vector<BoundaryFacet> boundary_;
  std::vector<RidgeEntry> ridges_;         // 3D
  std::size_t ridge_mask_ = 0;             // 3D: ridges_ size - 1 for this insertion
  std::vector<RidgeEntry> vertex_ridges_;  // 2D: per vertex, `low` holds the insertion stamp
  std::vector<std::size_t> touched_;
};

}  // namespace meshmotion::detail
