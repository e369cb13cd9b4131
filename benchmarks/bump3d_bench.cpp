// bump3d_bench: thesis table 4.3, the NASA Turbulence Modeling Resource 3D bump-in-channel
// curved to P2. The linear hex grids (bump_channel_3d levels 0, 1, 2: 5×45×21, 9×89×41,
// 17×177×81) are generated in code; their P2 meshes have the thesis's 32,841 / 243,729 /
// 1,875,489 points. The bump wall is projected onto the analytic surface (closest point),
// the interior regularized by RBF (Wendland C2) at the thesis's support radii, the sides
// slide in their planes, every other boundary is fixed. Each level runs in its own process
// (fork) so its peak memory (getrusage ru_maxrss) is its own.
//
// Rows per level: snapping alone (method none: the same-run baseline of the ratio column),
// RBF at the thesis radius, RBF at the pipeline's default radius. Prints a table and one
// JSON line per case. Usage: bump3d_bench [level ...] (levels 0, 1, 2; default all three)

#include "bench_memory.hpp"
#include "meshmotion/core/generators.hpp"
#include "meshmotion/curving/curve_mesh.hpp"
#include "meshmotion/curving/function_graph.hpp"
#include "meshmotion/solvers/detail/stopwatch.hpp"

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

using namespace meshmotion;

namespace {

struct Thesis {
  long points, boundary_points;
  double radius, min_quality, seconds;
};
constexpr std::array<Thesis, 3> thesis{{{32841, 2304, 0.06, 0.714, 0.68},
                                        {243729, 8704, 0.06, 0.852, 12.6},
                                        {1875489, 33792, 0.04, 0.926, 338.0}}};
constexpr std::array<const char*, 3> level_names{"coarse", "medium", "fine"};

// The thesis's boundary-point count: nodes on the bottom, top, inflow and outflow faces (its
// RBF centres; the side planes were not among them).
Index thesis_style_boundary_points(const Mesh<3>& curved) {
  std::vector<char> on(static_cast<std::size_t>(curved.num_nodes()), 0);
  for (const char* g : {"bump", "symmetry_lower", "top", "inflow", "outflow"})
    for (const Index v : curved.group_nodes(g)) on[static_cast<std::size_t>(v)] = 1;
  return static_cast<Index>(std::count(on.begin(), on.end(), 1));
}

void run_level(int level, bool all_centres) {
  const Thesis& t = thesis[static_cast<std::size_t>(level)];
  const char* name = level_names[static_cast<std::size_t>(level)];
  const detail::Stopwatch generate_clock;
  const Mesh<3> linear = bump_channel_3d(level);
  const double generate_seconds = generate_clock.seconds();
  double baseline = 0.0;
  struct Case {
    const char* label;
    const char* method;
    double radius;  // 0: the pipeline's default
    double reach;   // CurveOptions::centre_reach; 0: every boundary node a centre (the thesis)
  };
  const double reach = CurveOptions<3>{}.centre_reach;
  // ru_maxrss only grows: the all-centres case runs last so that it does not hide the others' peak.
  for (const Case& c : {Case{"snap only", "none", 0.0, reach}, Case{"rbf thesis r", "rbf", t.radius, reach},
                        Case{"rbf default r", "rbf", 0.0, reach}, Case{"rbf th r all c", "rbf", t.radius, 0.0}}) {
    if (c.reach == 0.0 && !all_centres) continue;
    CurveOptions<3> options;
    options.method = c.method;
    options.support_radius = c.radius;
    options.centre_reach = c.reach;
    options.geometry.emplace("bump", BoundaryGeometry<3>::project(nasa_bump_3d()));
    options.sliding = {"side_y0", "side_y1"};
    // A coarse run takes tens of milliseconds, within the noise of a shared machine: it is
    // repeated and the run of median total time reported.
    // Each run's mesh is freed before the next, so that every run reuses the same memory (fresh
    // pages cost page faults that a single run would not pay).
    const int repeats = level == 0 ? 5 : 1;
    std::vector<CurveResult<3>> runs;
    Index points = 0, boundary_points = 0;
    for (int k = 0; k < repeats; ++k) {
      runs.push_back(curve_mesh(linear, options));
      points = runs.back().curved.num_nodes();
      boundary_points = thesis_style_boundary_points(runs.back().curved);
      runs.back().curved = Mesh<3>{};
    }
    std::sort(runs.begin(), runs.end(), [](const auto& a, const auto& b) { return a.seconds.total < b.seconds.total; });
    const CurveResult<3>& r = runs[runs.size() / 2];
    const double seconds = r.seconds.total;
    if (baseline == 0.0) baseline = seconds;
    const Index centres = r.mover_steps.empty() ? 0 : r.mover_steps.back().boundary_nodes;
    const QualityReport& q = r.quality;
    std::printf("%-6s %-14s %8lld %6lld %6lld %7.4f %8.4f %8.5f %5lld | %6.3f %6.3f %6.3f %6.3f %6.3f %7.3f %6.2f %7.0f | %7ld %6ld %5.2f %6.3f %6.2f\n",
                name, c.label, static_cast<long long>(points), static_cast<long long>(centres),
                static_cast<long long>(boundary_points), r.support_radius, q.min, q.mean,
                static_cast<long long>(q.num_invalid), generate_seconds, r.seconds.quadratic, r.seconds.snap,
                r.seconds.layer + r.seconds.regularize, r.seconds.certify, seconds, seconds / baseline, bench::peak_memory_mb(),
                t.points, t.boundary_points, t.radius, t.min_quality, t.seconds);
    std::printf("{\"bench\":\"bump3d\",\"level\":\"%s\",\"case\":\"%s\",\"points\":%lld,\"rbf_centres\":%lld,"
                "\"boundary_points\":%lld,\"support_radius\":%.6g,\"min\":%.6f,\"mean\":%.6f,\"invalid\":%lld,"
                "\"generate_seconds\":%.6f,\"quadratic_seconds\":%.6f,\"snap_seconds\":%.6f,\"layer_seconds\":%.6f,"
                "\"regularize_seconds\":%.6f,\"certify_seconds\":%.6f,\"seconds\":%.6f,\"ratio_to_snap_only\":%.4f,"
                "\"peak_mb\":%.1f,\"thesis_points\":%ld,\"thesis_boundary_points\":%ld,\"thesis_radius\":%g,"
                "\"thesis_min\":%g,\"thesis_seconds\":%g}\n",
                name, c.label, static_cast<long long>(points), static_cast<long long>(centres),
                static_cast<long long>(boundary_points), r.support_radius, q.min, q.mean,
                static_cast<long long>(q.num_invalid), generate_seconds, r.seconds.quadratic, r.seconds.snap,
                r.seconds.layer, r.seconds.regularize, r.seconds.certify, seconds, seconds / baseline, bench::peak_memory_mb(),
                t.points, t.boundary_points, t.radius, t.min_quality, t.seconds);
    std::fflush(stdout);
  }
}

}  // namespace

int main(int argc, char** argv) {
  bench::tune_memory(argc, argv);
  std::vector<int> levels;
  bool fine_all_centres = false;
  for (int a = 1; a < argc; ++a) {
    const std::string arg = argv[a];
    if (arg == "--fine-all-centres") {
      fine_all_centres = true;
      continue;
    }
    if (arg != "0" && arg != "1" && arg != "2") {
      std::fprintf(stderr,
                   "bump3d_bench: levels are 0 (coarse), 1 (medium), 2 (fine); --fine-all-centres also runs the fine "
                   "level with every boundary node a centre (111 s, 4.2 GB) (got '%s')\n",
                   argv[a]);
      return 1;
    }
    levels.push_back(std::stoi(arg));
  }
  if (levels.empty()) levels = {0, 1, 2};
  std::printf("3D bump-in-channel (thesis table 4.3): P2 from the linear TMR-family hex grids, RBF Wendland C2\n");
  std::printf("%-6s %-14s %8s %6s %6s %7s %8s %8s %5s | %6s %6s %6s %6s %6s %7s %6s %7s | %7s %6s %5s %6s %6s\n", "level",
              "case", "points", "rbf_c", "bnd", "radius", "min", "mean", "inv", "gen_s", "p2_s", "snap_s", "reg_s",
              "cert_s", "total_s", "ratio", "peak_MB", "th_pts", "th_bnd", "th_r", "th_min", "th_s");
  for (const int level : levels) {
    std::fflush(stdout);
    const pid_t child = fork();
    if (child < 0) {
      std::perror("bump3d_bench: fork");
      return 1;
    }
    if (child == 0) {
      run_level(level, level < 2 || fine_all_centres);
      std::fflush(stdout);
      std::_Exit(0);
    }
    int status = 0;
    waitpid(child, &status, 0);
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
      std::fprintf(stderr, "bump3d_bench: level %d failed\n", level);
      return 1;
    }
  }
  std::printf("\nrbf_c: RBF centres (boundary nodes within 2 radii of the motion; 'all c': every boundary node); bnd: the thesis's count (nodes of the\n"
              "bottom, top, inflow and outflow faces); reg_s: layer estimate + regularization; total_s: the whole pipeline\n"
              "(P2 conversion, snapping, regularization, certification; generation excluded; coarse: the run of median\n"
              "total of 5); ratio: total to snap only\n"
              "in the same run; peak_MB: ru_maxrss of the level's process; th_*: thesis table 4.3 (its hardware).\n");
  return 0;
}
