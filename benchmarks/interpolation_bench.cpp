// Interpolation movers on the rotating-object case (thesis section 4.1.3, fig. 4.11, table 4.1):
// an ellipse in a circular farfield (boundary-layer graded quads) rotated in one step by
// DGM, improved DGM, DGRBF, DGRBF2 and RBF, all measured in the same run.
// Per method and angle (60°, 120°): setup + move seconds, ratio to RBF, min and mean Knupp
// skew, invalid cells (a refused DGM move counts as invalid), and the largest valid
// one-step angle scanned in steps of 10°. Thesis: RBF 1.926 s, DGRBF2 0.08 s at 60°; only
// DGRBF2 valid at 120°; RBF valid to ~110°.
// Prints a table and one JSON line per case. Usage: interpolation_bench [n_around=128] [n_radial=64]

#include "bench_memory.hpp"
#include "meshmotion/core/generators.hpp"
#include "meshmotion/movers.hpp"
#include "meshmotion/movers/dgm.hpp"
#include "meshmotion/movers/dgrbf.hpp"
#include "meshmotion/movers/dgrbf2.hpp"
#include "meshmotion/movers/improved_dgm.hpp"
#include "meshmotion/quality.hpp"
#include "meshmotion/solvers/detail/stopwatch.hpp"

#include <cstdio>
#include <cstdlib>
#include <functional>
#include <string>
#include <vector>

using namespace meshmotion;

namespace {

struct Outcome {
  double seconds = 0.0;
  double min = 0.0, mean = 0.0;
  Index invalid = 0;
  bool refused = false;  ///< the mover threw InvalidMeshError (DGM's inverted graph)
};

struct Method {
  const char* name;
  std::function<AnyMover<2>()> make;
  double thesis_seconds;  ///< < 0: no thesis figure
};

Outcome rotate(const Method& method, const Mesh<2>& mesh, double degrees) {
  BoundarySpec<2> spec;
  spec.moving("wall", Rotation2D{Vec<2>::Zero(), radians(degrees)}).fixed("farfield");
  const ResolvedBoundary<2> b = spec.resolve(mesh);
  AnyMover<2> mover = method.make();
  Outcome o;
  const detail::Stopwatch watch;
  Points<2> u;
  try {
    mover.setup(mesh, b);
    mover.move_into(b.displacements, u);
  } catch (const InvalidMeshError&) {
    o.seconds = watch.seconds();
    o.refused = true;
    o.invalid = -1;
    return o;
  }
  o.seconds = watch.seconds();
  Mesh<2> moved = mesh;
  moved.points += u;
  const QualityReport q = quality_report(moved, Metric::skew);
  o.min = q.min;
  o.mean = q.mean;
  o.invalid = q.num_invalid;
  return o;
}

bool valid(const Outcome& o) { return !o.refused && o.invalid == 0; }

}  // namespace

int main(int argc, char** argv) {
  bench::tune_memory(argc, argv);
  OMeshOptions options;
  options.semi_axis_x = 0.5;
  options.semi_axis_y = 0.25;
  if (argc > 1) options.n_around = std::atol(argv[1]);
  if (argc > 2) options.n_radial = std::atol(argv[2]);
  const Mesh<2> mesh = o_mesh(options);
  const double rbf_radius = 8.0;  // as rbf_bench: the rotating case needs a wide support
  const ImprovedDgmOptions idgm;
  const std::vector<Method> methods{
      {"RBF", [&] { RbfOptions o; o.support_radius = rbf_radius; return AnyMover<2>(RbfMover<2>(o)); }, 1.926},
      {"DGM", [] { return AnyMover<2>(DgmMover<2>()); }, -1.0},
      {"IDGM", [&] { return AnyMover<2>(ImprovedDgmMover<2>(idgm)); }, -1.0},
      {"DGRBF", [] { return AnyMover<2>(DgrbfMover<2>()); }, -1.0},
      {"DGRBF2", [] { return AnyMover<2>(Dgrbf2Mover<2>(dgrbf2_options(Rotation2D{}))); }, 0.08},
  };
  std::printf("rotating ellipse: %ld nodes, %ld cells; RBF support radius %.1f; IDGM layer offset %.1f wall spacings\n",
              static_cast<long>(mesh.num_nodes()), static_cast<long>(mesh.num_cells()), rbf_radius, idgm.layer_offset);
  std::printf("%-8s %6s %10s %9s %10s %10s %8s %10s %12s\n", "method", "deg", "seconds", "vs_RBF", "min_skew", "mean_skew",
              "invalid", "thesis_s", "largest_deg");
  for (const double degrees : {60.0, 120.0}) {
    const Outcome rbf = rotate(methods.front(), mesh, degrees);
    for (const Method& m : methods) {
      const Outcome o = &m == &methods.front() ? rbf : rotate(m, mesh, degrees);
      double largest = 0.0;
      if (degrees == 60.0)
        for (double angle = 10.0; angle <= 180.0; angle += 10.0) {
          if (!valid(rotate(m, mesh, angle))) break;
          largest = angle;
        }
      const double thesis = degrees == 60.0 ? m.thesis_seconds : -1.0;
      char thesis_text[32] = "-", largest_text[32] = "-";
      if (thesis > 0.0) std::snprintf(thesis_text, sizeof thesis_text, "%.3f", thesis);
      if (degrees == 60.0) std::snprintf(largest_text, sizeof largest_text, "%.0f", largest);
      std::printf("%-8s %6.0f %10.4f %9.3f %10.4f %10.4f %8s %10s %12s\n", m.name, degrees, o.seconds, o.seconds / rbf.seconds,
                  o.min, o.mean, o.refused ? "refused" : std::to_string(o.invalid).c_str(), thesis_text, largest_text);
      std::printf("{\"case\":\"rotate\",\"method\":\"%s\",\"degrees\":%.0f,\"nodes\":%ld,\"seconds\":%.6f,\"ratio_to_rbf\":%.4f,"
                  "\"min_skew\":%.6f,\"mean_skew\":%.6f,\"invalid\":%ld,\"refused\":%s",
                  m.name, degrees, static_cast<long>(mesh.num_nodes()), o.seconds, o.seconds / rbf.seconds, o.min, o.mean,
                  static_cast<long>(o.invalid), o.refused ? "true" : "false");
      if (thesis > 0.0) std::printf(",\"thesis_seconds\":%.3f", thesis);
      if (degrees == 60.0) std::printf(",\"largest_valid_degrees\":%.0f", largest);
      std::printf("}\n");
    }
  }
  std::printf("thesis (table 4.1, own hardware): RBF 1.926 s, DGRBF2 0.08 s at 60 deg; only DGRBF2 valid at 120 deg;"
              " RBF valid to ~110 deg\n");
  return 0;
}
