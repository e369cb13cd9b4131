// io_bench: writes and reads a >= 1M-node tetrahedral mesh (a structured box split into six
// tets per cube) as msh 4.1 binary, 4.1 ASCII, 2.2 ASCII, SU2 and CGNS (when built with it;
// medians of 3 rounds); prints MB/s and nodes/s, each format's times as ratios to the msh 4.1
// binary row of the same run, and compares binary reading against Gmsh's own reader
// (`gmsh FILE -0`) when gmsh is installed. OpenFOAM rows: the same box as hexahedra in a
// polyMesh (ASCII and binary); "read" is the whole case, "write" the points replaced in place.
// Usage: io_bench [cells_per_side = 100]

#include "bench_memory.hpp"
#include "meshmotion/io.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

using namespace meshmotion;
using Clock = std::chrono::steady_clock;

namespace {

Mesh<3> box_mesh(int n) {
  Mesh<3> mesh;
  const int m = n + 1;
  mesh.points.resize(3, static_cast<Index>(m) * m * m);
  const auto id = [m](int i, int j, int k) { return static_cast<Index>(i + m * (j + m * k)); };
  for (int k = 0; k < m; ++k)
    for (int j = 0; j < m; ++j)
      for (int i = 0; i < m; ++i) mesh.points.col(id(i, j, k)) << double(i) / n, double(j) / n, double(k) / n;
  auto& tets = mesh.block(ElementType::tet4);
  tets.reserve(6 * static_cast<Index>(n) * n * n);
  // Kuhn split of each cube along the 0-6 diagonal: six positively oriented tets.
  const int paths[6][2] = {{1, 3}, {1, 5}, {2, 3}, {2, 6}, {4, 5}, {4, 6}};
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const auto corner = [&](int bits) { return id(i + (bits & 1), j + ((bits >> 1) & 1), k + ((bits >> 2) & 1)); };
        for (const auto& p : paths) {
          Index v[4] = {corner(0), corner(p[0]), corner(p[1]), corner(7)};
          if (signed_measure(mesh, ElementType::tet4, std::span<const Index>(v, 4)) < 0) std::swap(v[1], v[2]);
          tets.add(std::span<const Index>(v, 4), 1);
        }
      }
  mesh.groups.push_back({3, 1, "volume"});
  return mesh;
}

// The box as n^3 hexahedra in a polyMesh, faces ordered and oriented as OpenFOAM wants them.
PolyMesh box_polymesh(int n) {
  PolyMesh poly;
  const int m = n + 1;
  const auto p = [m](int i, int j, int k) { return static_cast<Index>(i + m * (j + m * k)); };
  const auto c = [n](int i, int j, int k) { return static_cast<Index>(i + n * (j + n * k)); };
  poly.points.resize(3, static_cast<Index>(m) * m * m);
  for (int k = 0; k < m; ++k)
    for (int j = 0; j < m; ++j)
      for (int i = 0; i < m; ++i) poly.points.col(p(i, j, k)) << double(i) / n, double(j) / n, double(k) / n;
  using Quad = std::array<Index, 4>;
  const auto face = [&](const Quad& v, Index owner) {
    poly.face_nodes.insert(poly.face_nodes.end(), v.begin(), v.end());
    poly.face_offsets.push_back(static_cast<Index>(poly.face_nodes.size()));
    poly.owner.push_back(owner);
  };
  // Outward from the owner: the +x, +y and +z sides of a cell.
  const auto plus_x = [&](int i, int j, int k) { return Quad{p(i, j, k), p(i, j + 1, k), p(i, j + 1, k + 1), p(i, j, k + 1)}; };
  const auto plus_y = [&](int i, int j, int k) { return Quad{p(i, j, k), p(i, j, k + 1), p(i + 1, j, k + 1), p(i + 1, j, k)}; };
  const auto plus_z = [&](int i, int j, int k) { return Quad{p(i, j, k), p(i + 1, j, k), p(i + 1, j + 1, k), p(i, j + 1, k)}; };
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        if (i + 1 < n) face(plus_x(i + 1, j, k), c(i, j, k)), poly.neighbour.push_back(c(i + 1, j, k));
        if (j + 1 < n) face(plus_y(i, j + 1, k), c(i, j, k)), poly.neighbour.push_back(c(i, j + 1, k));
        if (k + 1 < n) face(plus_z(i, j, k + 1), c(i, j, k)), poly.neighbour.push_back(c(i, j, k + 1));
      }
  const Index start = poly.num_faces();
  for (int a = 0; a < n; ++a)
    for (int b = 0; b < n; ++b) {
      face(plus_x(n, a, b), c(n - 1, a, b));
      face(plus_y(a, n, b), c(a, n - 1, b));
      face(plus_z(a, b, n), c(a, b, n - 1));
      face(Quad{p(0, a, b), p(0, a, b + 1), p(0, a + 1, b + 1), p(0, a + 1, b)}, c(0, a, b));  // -x
      face(Quad{p(a, 0, b), p(a + 1, 0, b), p(a + 1, 0, b + 1), p(a, 0, b + 1)}, c(a, 0, b));  // -y
      face(Quad{p(a, b, 0), p(a, b + 1, 0), p(a + 1, b + 1, 0), p(a + 1, b, 0)}, c(a, b, 0));  // -z
    }
  poly.patches.push_back({"walls", "wall", start, poly.num_faces() - start});
  poly.num_cells = static_cast<Index>(n) * n * n;
  return poly;
}

std::uintmax_t folder_size(const std::filesystem::path& dir) {
  std::uintmax_t bytes = 0;
  for (const auto& e : std::filesystem::recursive_directory_iterator(dir))
    if (e.is_regular_file()) bytes += e.file_size();
  return bytes;
}

double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

}  // namespace

int main(int argc, char** argv) {
  bench::tune_memory(argc, argv);
  const int n = argc > 1 ? std::atoi(argv[1]) : 100;
  const auto mesh = box_mesh(n);
  const auto dir = std::filesystem::temp_directory_path() / "meshmotion_io_bench";
  std::filesystem::create_directories(dir);
  std::printf("mesh: %lld nodes, %lld tets\n", static_cast<long long>(mesh.num_nodes()), static_cast<long long>(mesh.num_cells()));
  std::printf("%-15s %9s %10s %10s %12s %10s %10s %12s %11s %11s\n", "case", "MB", "write s", "write MB/s", "write nodes/s",
              "read s", "read MB/s", "read nodes/s", "write/msh-b", "read/msh-b");
  struct Case {
    const char* name;
    const char* extension;
    WriteOptions options;
  };
  std::vector<Case> cases{{"msh4.1-binary", ".msh", {MshVersion::v4_1, true, false}},
                          {"msh4.1-ascii", ".msh", {MshVersion::v4_1, false, false}},
                          {"msh2.2-ascii", ".msh", {MshVersion::v2_2, false, false}},
                          {"su2-ascii", ".su2", {}}};
  if (have_cgns) cases.push_back({"cgns-hdf5", ".cgns", {}});
  else std::printf("cgns: meshmotion was built without the CGNS library (libcgns-dev): no CGNS row\n");
  double binary_read_seconds = 0, binary_write_seconds = 0;
  std::vector<std::string> json;
  // One table row and one JSON line: `read_mb` read in read_s, `write_mb` written in write_s.
  const auto row = [&](const char* name, double read_mb, double write_mb, double write_s, double read_s, Index nodes, Index cells,
                       const char* written) {
    const double n_nodes = static_cast<double>(nodes);
    std::printf("%-15s %9.1f %10.3f %10.1f %12.3g %10.3f %10.1f %12.3g %11.2f %11.2f\n", name, read_mb, write_s, write_mb / write_s,
                n_nodes / write_s, read_s, read_mb / read_s, n_nodes / read_s, write_s / binary_write_seconds,
                read_s / binary_read_seconds);
    char line[640];
    std::snprintf(line, sizeof line,
                  "{\"bench\":\"io\",\"case\":\"%s\",\"nodes\":%lld,\"cells\":%lld,\"mb\":%.3f,\"write\":\"%s\",\"write_mb\":%.3f,"
                  "\"write_s\":%.4f,\"write_mb_s\":%.1f,\"read_s\":%.4f,\"read_mb_s\":%.1f,\"read_nodes_s\":%.4g,"
                  "\"write_ratio_msh_binary\":%.3f,\"read_ratio_msh_binary\":%.3f}",
                  name, static_cast<long long>(nodes), static_cast<long long>(cells), read_mb, written, write_mb, write_s,
                  write_mb / write_s, read_s, read_mb / read_s, n_nodes / read_s, write_s / binary_write_seconds,
                  read_s / binary_read_seconds);
    json.emplace_back(line);
  };
  for (const auto& c : cases) {
    const auto file = dir / (std::string(c.name) + c.extension);
    // Medians of three write-read rounds: single runs on this VM vary up to 3x.
    std::vector<double> writes, reads;
    for (int round = 0; round < 3; ++round) {
      auto t = Clock::now();
      write_mesh(file, mesh, c.options);
      writes.push_back(seconds_since(t));
      t = Clock::now();
      const auto back = read_mesh_as<3>(file);
      reads.push_back(seconds_since(t));
      if (back.num_nodes() != mesh.num_nodes() || back.num_cells() != mesh.num_cells()) {
        std::fprintf(stderr, "io_bench: %s read back a different mesh\n", c.name);
        return 1;
      }
    }
    std::sort(writes.begin(), writes.end());
    std::sort(reads.begin(), reads.end());
    const double write_s = writes[1], read_s = reads[1];
    const double mb = static_cast<double>(std::filesystem::file_size(file)) / 1e6;
    if (c.options.binary) {
      binary_read_seconds = read_s;
      binary_write_seconds = write_s;
    }
    row(c.name, mb, mb, write_s, read_s, mesh.num_nodes(), mesh.num_cells(), "file");
  }
  {
    const PolyMesh poly = box_polymesh(n);
    for (const bool binary : {false, true}) {
      const char* name = binary ? "openfoam-binary" : "openfoam-ascii";
      const auto case_dir = dir / name;
      write_polymesh(case_dir, poly, PolyMeshWriteOptions{binary, false});
      std::vector<double> writes, reads;
      for (int round = 0; round < 3; ++round) {
        auto t = Clock::now();
        const Mesh<3> back = read_openfoam(case_dir);
        reads.push_back(seconds_since(t));
        if (back.num_cells() != poly.num_cells || back.num_auxiliary_nodes != 0) {
          std::fprintf(stderr, "io_bench: %s read back a different mesh\n", name);
          return 1;
        }
        t = Clock::now();
        write_mesh(case_dir, back);
        writes.push_back(seconds_since(t));
      }
      std::sort(writes.begin(), writes.end());
      std::sort(reads.begin(), reads.end());
      const double write_s = writes[1], read_s = reads[1];
      const double read_mb = static_cast<double>(folder_size(case_dir)) / 1e6;
      const double write_mb = static_cast<double>(std::filesystem::file_size(case_dir / "constant" / "polyMesh" / "points")) / 1e6;
      row(name, read_mb, write_mb, write_s, read_s, poly.points.cols(), poly.num_cells, "points");
    }
  }
  // Baseline: Gmsh reading the same binary file (process start included).
  const auto binary_file = dir / "msh4.1-binary.msh";
  if (std::system("gmsh --version > /dev/null 2>&1") == 0) {
    const std::string command = "gmsh " + binary_file.string() + " -0 -o " + (dir / "gmsh_out.msh").string() + " > /dev/null 2>&1";
    const auto t = Clock::now();
    const int rc = std::system(command.c_str());
    const double gmsh_s = seconds_since(t);
    if (rc == 0) {
      std::printf("gmsh: read+rewrite of msh4.1-binary %.3f s; ours (read only) %.3f s; ratio ours/gmsh %.3f\n", gmsh_s,
                  binary_read_seconds, binary_read_seconds / gmsh_s);
      char line[256];
      std::snprintf(line, sizeof line, "{\"bench\":\"io\",\"case\":\"gmsh-baseline\",\"gmsh_s\":%.4f,\"ours_s\":%.4f,\"ratio\":%.4f}",
                    gmsh_s, binary_read_seconds, binary_read_seconds / gmsh_s);
      json.emplace_back(line);
    } else {
      std::printf("gmsh: failed to read the file (exit %d)\n", rc);
    }
  } else {
    std::printf("gmsh: not installed\n");
  }
  for (const auto& j : json) std::printf("%s\n", j.c_str());
  std::filesystem::remove_all(dir);
  return 0;
}
