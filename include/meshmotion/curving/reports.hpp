#pragma once
/// \file
/// Every report the library writes, listed once: its key (Python's report_fields(key)), its
/// heading and one line for docs/options.md, and its type, whose visit_fields description
/// gives the keys of its JSON object and Python dict. The programs' docs and Python's
/// report_fields() both read this list.

#include "meshmotion/core/error.hpp"
#include "meshmotion/core/fields.hpp"
#include "meshmotion/curving/curve_mesh.hpp"
#include "meshmotion/curving/geometry_distance.hpp"
#include "meshmotion/curving/untangle.hpp"
#include "meshmotion/io/foam_case_summary.hpp"
#include "meshmotion/io/mesh_summary.hpp"
#include "meshmotion/movers/boundary_layer.hpp"
#include "meshmotion/movers/mover.hpp"
#include "meshmotion/movers/step_driver.hpp"
#include "meshmotion/parallel/parallel_options.hpp"
#include "meshmotion/quality/quality_report.hpp"

#include <string>
#include <string_view>
#include <vector>

namespace meshmotion {

/// Calls f.template operator()<Report>(key, heading, what) for every report, in the order of
/// docs/options.md.
template <class F>
void for_each_report(F&& f) {
  f.template operator()<CurveResult<3>>(
      "curve", "curve_mesh's report",
      "`curve_mesh --json` (beside input, output, vtu, dim, nodes, cells, options) and Python's report dict.");
  f.template operator()<CurveTimes>("seconds", "seconds", "Seconds per stage of the pipeline.");
  f.template operator()<WallLayer>("layers", "layers", "One per curved wall whose layer was estimated.");
  f.template operator()<GeometryDistance>("geometry_distance", "geometry_distance",
                                          "One per curved group: how far its facets are from its geometry.");
  f.template operator()<UntangleReport>("untangle", "untangle", "What the untangling did.");
  f.template operator()<QualityReport>("quality", "quality",
                                       "A quality report (`mesh_quality --json`, Python's quality_report).");
  f.template operator()<WorstElement>("worst", "worst", "One of the lowest cells.");
  f.template operator()<TypeQuality>("per_type", "per_type", "The cells of one element type.");
  f.template operator()<MoverStats>("mover_stats", "mover_steps", "A mover's stats (Python's Mover.stats).");
  f.template operator()<MoveReport>("move", "move_mesh's report",
                                    "`move_mesh --json` (beside input, output, support_radius, options).");
  f.template operator()<parallel::DistributedChoices>("distributed", "move_mesh_mpi's choices",
                                                     "`move_mesh_mpi --json` (beside ranks, threads_per_rank and move_mesh's report).");
  f.template operator()<MeshSummary>("summary", "summary", "What a mesh holds (`mesh_info --json`, Python's Mesh.summary).");
  f.template operator()<FoamCaseSummary>("openfoam_case", "openfoam",
                                         "An OpenFOAM case as checkMesh counts it (`mesh_info --json` of a case).");
  f.template operator()<FoamPatchSummary>("openfoam_patch", "patches", "One patch of the case's boundary file.");
  f.template operator()<FoamZoneSummary>("openfoam_zone", "zones", "One cell, face or point zone of the case.");
}

/// The keys of report `key`'s JSON object and Python dict. Throws InputError naming the known
/// reports for another key.
[[nodiscard]] inline std::vector<std::string> report_fields(std::string_view key) {
  std::vector<std::string> out;
  std::string known;
  bool found = false;
  for_each_report([&]<class Report>(std::string_view k, std::string_view, std::string_view) {
    known += (known.empty() ? "" : ", ") + std::string(k);
    if (k != key) return;
    out = field_keys(Report{});
    found = true;
  });
  if (!found) throw InputError("report_fields: unknown report '" + std::string(key) + "' (expected one of " + known + ")");
  return out;
}

}  // namespace meshmotion
