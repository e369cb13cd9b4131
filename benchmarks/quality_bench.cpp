// Scaled-Jacobian throughput on ≥1M-element curved meshes (tri6 and tet10 generated here, with
// slightly perturbed mid-edge nodes): sampled minimum versus certified Bézier bound, single
// thread and OpenMP. The baseline of each row is the sampled check of the same mesh and thread
// count; the target is certified ≤ 5× sampled on valid meshes. The thesis gives no timing for
// this step (it ran Gmsh's plugin).
//
// Then the cost per element by order: every shape at P2 to P8, curved by moving every node past the vertices; each row's ratio is to the same shape's
// P2 row of the same run.
//
//   quality_bench [--quick]     (--quick: ~100k elements)

#include "bench_memory.hpp"
#include "meshmotion/core/generators.hpp"
#include "meshmotion/core/json.hpp"
#include "meshmotion/core/mesh.hpp"
#include "meshmotion/curving/order_conversion.hpp"
#include "meshmotion/quality/scaled_jacobian.hpp"

#if defined(_OPENMP)
#include <omp.h>
#endif

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <numbers>
#include <string>
#include <vector>

using namespace meshmotion;

namespace {

// Deterministic offset in [-1, 1] for node i, axis d.
double jitter(Index i, int d) {
  std::uint64_t h = static_cast<std::uint64_t>(i) * 0x9E3779B97F4A7C15ull + static_cast<std::uint64_t>(d) * 0xBF58476D1CE4E5B9ull;
  h ^= h >> 31;
  h *= 0x94D049BB133111EBull;
  h ^= h >> 29;
  return static_cast<double>(h % 2000001) / 1000000.0 - 1.0;
}

// P2 nodes on the doubled lattice: even indices are vertices, the others mid-edge nodes,
// moved by up to `amplitude` × (half the spacing) to make the elements curved.
template <int Dim>
Points<Dim> lattice(int m, double amplitude) {
  Index n = 1;
  for (int d = 0; d < Dim; ++d) n *= (2 * m + 1);
  Points<Dim> p(Dim, n);
  const double h = 0.5 / m;
  for (Index id = 0; id < n; ++id) {
    Index rest = id;
    bool vertex = true;
    for (int d = 0; d < Dim; ++d) {
      const Index c = rest % (2 * m + 1);
      rest /= (2 * m + 1);
      p(d, id) = static_cast<double>(c) * h;
      vertex = vertex && c % 2 == 0;
    }
    if (!vertex)
      for (int d = 0; d < Dim; ++d) p(d, id) += amplitude * h * jitter(id, d);
  }
  return p;
}

Mesh<2> tri6_mesh(int m, double amplitude) {
  Mesh<2> mesh;
  mesh.points = lattice<2>(m, amplitude);
  const Index s = 2 * m + 1;
  const auto id = [s](Index i, Index j) { return i + s * j; };
  auto& b = mesh.block(ElementType::tri6);
  b.reserve(2 * static_cast<Index>(m) * m);
  for (Index j = 0; j < 2 * m; j += 2)
    for (Index i = 0; i < 2 * m; i += 2) {
      b.add({id(i, j), id(i + 2, j), id(i + 2, j + 2), id(i + 1, j), id(i + 2, j + 1), id(i + 1, j + 1)});
      b.add({id(i, j), id(i + 2, j + 2), id(i, j + 2), id(i + 1, j + 1), id(i + 1, j + 2), id(i, j + 1)});
    }
  return mesh;
}

// Kuhn's six tetrahedra per cube, all positively oriented.
Mesh<3> tet10_mesh(int m, double amplitude) {
  Mesh<3> mesh;
  mesh.points = lattice<3>(m, amplitude);
  const Index s = 2 * m + 1;
  using C = std::array<Index, 3>;
  const auto id = [s](const C& c) { return c[0] + s * (c[1] + s * c[2]); };
  const auto mid = [](const C& a, const C& b) { return C{(a[0] + b[0]) / 2, (a[1] + b[1]) / 2, (a[2] + b[2]) / 2}; };
  const std::array<std::array<int, 3>, 6> perms{{{0, 1, 2}, {1, 2, 0}, {2, 0, 1}, {0, 2, 1}, {2, 1, 0}, {1, 0, 2}}};
  auto& b = mesh.block(ElementType::tet10);
  b.reserve(6 * static_cast<Index>(m) * m * m);
  for (Index k = 0; k < 2 * m; k += 2)
    for (Index j = 0; j < 2 * m; j += 2)
      for (Index i = 0; i < 2 * m; i += 2)
        for (std::size_t p = 0; p < perms.size(); ++p) {
          std::array<C, 4> v;
          v[0] = {i, j, k};
          v[1] = v[0];
          v[1][static_cast<std::size_t>(perms[p][0])] += 2;
          v[2] = v[1];
          v[2][static_cast<std::size_t>(perms[p][1])] += 2;
          v[3] = {i + 2, j + 2, k + 2};
          if (p >= 3) std::swap(v[1], v[2]);  // odd permutations
          b.add({id(v[0]), id(v[1]), id(v[2]), id(v[3]), id(mid(v[0], v[1])), id(mid(v[1], v[2])), id(mid(v[2], v[0])),
                 id(mid(v[3], v[0])), id(mid(v[3], v[2])), id(mid(v[3], v[1]))});
        }
  return mesh;
}

struct Mode {
  const char* name;
  ScaledJacobianOptions options;
};

template <int Dim>
void run_cases(const char* mesh_name, const Mesh<Dim>& mesh) {
  ScaledJacobianOptions sampled, validity, sharp;
  sampled.certify = false;
  validity.sharp = false;
  const std::array<Mode, 3> modes{{{"sampled", sampled}, {"certified_validity", validity}, {"certified_sharp", sharp}}};
#if defined(_OPENMP)
  const int max_threads = omp_get_num_procs();
#else
  const int max_threads = 1;
#endif
  for (int threads : {1, max_threads}) {
#if defined(_OPENMP)
    omp_set_num_threads(threads);
#endif
    double baseline = 0.0;
    for (const auto& mode : modes) {
      // Best of three runs (the first also builds the tables and touches the output pages).
      std::vector<ScaledJacobian> r;
      double sec = 1e300;
      for (int repeat = 0; repeat < 3; ++repeat) {
        const auto t0 = std::chrono::steady_clock::now();
        r = scaled_jacobians(mesh, mode.options);
        sec = std::min(sec, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
      }
      Index invalid = 0;
      double min = 1e300;
      for (const auto& s : r) {
        invalid += s.valid ? 0 : 1;
        min = std::min(min, s.certified_min);
      }
      if (baseline == 0.0) baseline = sec;
      const double per_s = static_cast<double>(r.size()) / sec;
      std::printf("%-6s %9lld  %-19s %2d thr  %8.3f s  %10.3g el/s  ratio %5.2f  min %.4f  invalid %lld\n", mesh_name,
                  static_cast<long long>(r.size()), mode.name, threads, sec, per_s, sec / baseline, min,
                  static_cast<long long>(invalid));
      JsonWriter w(std::cout);
      w.begin_object().key("benchmark").value("quality").key("mesh").value(mesh_name).key("elements").value(r.size());
      w.key("mode").value(mode.name).key("threads").value(threads).key("seconds").value(sec);
      w.key("elements_per_second").value(per_s).key("ratio_to_sampled").value(sec / baseline);
      w.key("min_scaled_jacobian").value(min).key("invalid").value(invalid).end_object();
      std::cout << std::endl;
    }
  }
}

// Seconds per element of the certified validity check (single thread, best of three) on
// `linear` raised to each order, then every node moved by a smooth field of amplitude 0.3
// spacings and wavelength 8 (gradient about 0.24): curved cells, valid at every order, as a
// curved mesh's are. (A random offset per node made most cells past P4 invalid: high-order
// equispaced nodes turn rough data into wild edges.)
template <int Dim>
void run_orders(const char* shape_name, const Mesh<Dim>& linear, double spacing) {
#if defined(_OPENMP)
  omp_set_num_threads(1);
#endif
  ScaledJacobianOptions validity;
  validity.sharp = false;
  double p2 = 0.0;
  for (int p = 2; p <= max_order(shape(linear.cells.front().type)); ++p) {
    OrderConversion<Dim> conversion = convert_to_order(linear, p);
    Mesh<Dim>& mesh = conversion.mesh;
    const double wave = 2.0 * std::numbers::pi / (8.0 * spacing);
    for (Index i = 0; i < mesh.num_nodes(); ++i) {
      const Vec<Dim> x = mesh.points.col(i);
      for (int d = 0; d < Dim; ++d) mesh.points(d, i) += 0.3 * spacing * std::sin(wave * x((d + 1) % Dim) + d);
    }
    double sec = 1e300;
    std::vector<ScaledJacobian> r;
    for (int repeat = 0; repeat < 3; ++repeat) {
      const auto t0 = std::chrono::steady_clock::now();
      r = scaled_jacobians(mesh, validity);
      sec = std::min(sec, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    }
    Index invalid = 0;
    for (const auto& s : r) invalid += s.valid ? 0 : 1;
    const double per_element = sec / static_cast<double>(r.size());
    if (p == 2) p2 = per_element;
    std::printf("%-14s P%d %8lld el  %9.3f us/el  ratio to P2 %6.2f  invalid %lld\n", shape_name, p,
                static_cast<long long>(r.size()), 1e6 * per_element, per_element / p2, static_cast<long long>(invalid));
    JsonWriter w(std::cout);
    w.begin_object().key("benchmark").value("quality_order").key("shape").value(shape_name).key("order").value(p);
    w.key("elements").value(r.size()).key("seconds_per_element").value(per_element);
    w.key("ratio_to_p2").value(per_element / p2).key("invalid").value(invalid).end_object();
    std::cout << std::endl;
  }
}

}  // namespace

int main(int argc, char** argv) {
  bench::tune_memory(argc, argv);
  const bool quick = argc > 1 && std::strcmp(argv[1], "--quick") == 0;
  // Mid-edge nodes moved by up to 15% (tri6) and 5% (tet10) of half the spacing: curved, valid.
  const Mesh<2> tri = tri6_mesh(quick ? 224 : 708, 0.15);  // 2 m^2 ≥ 1M
  run_cases("tri6", tri);
  const Mesh<3> tet = tet10_mesh(quick ? 26 : 56, 0.05);   // 6 m^3 ≥ 1M
  run_cases("tet10", tet);
  const Index n2 = quick ? 40 : 120, n3 = quick ? 6 : 12;
  run_orders("triangle", rectangle_mesh({.nx = n2, .ny = n2, .cells = RectangleCells::tri3}), 1.0 / static_cast<double>(n2));
  run_orders("quadrilateral", rectangle_mesh({.nx = n2, .ny = n2}), 1.0 / static_cast<double>(n2));
  run_orders("tetrahedron", box_mesh({.nx = n3, .ny = n3, .nz = n3, .cells = BoxCells::tet4}), 1.0 / static_cast<double>(n3));
  // Hexahedra past P3 keep their det J lattice (1,728 to 13,824 points) on the heap.
  const Index nh = quick ? 4 : 8;
  run_orders("hexahedron", box_mesh({.nx = nh, .ny = nh, .nz = nh, .cells = BoxCells::hex8}), 1.0 / static_cast<double>(nh));
  // Prisms: det J of degree 3p - 2 on the triangle times 3p - 1 along the axis (6,624 points
  // at P8); pyramids: sampled on a lattice of order 2p, not certified (their det J is rational).
  run_orders("prism", box_mesh({.nx = nh, .ny = nh, .nz = nh, .cells = BoxCells::prism6}), 1.0 / static_cast<double>(nh));
  run_orders("pyramid", box_mesh({.nx = nh, .ny = nh, .nz = nh, .cells = BoxCells::pyramid5}), 1.0 / static_cast<double>(nh));
}
