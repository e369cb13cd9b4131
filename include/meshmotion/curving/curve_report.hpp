#pragma once
/// \file
/// What curve_mesh() produced and measured (CurveResult, CurveTimes), with their one
/// description (visit_fields: the JSON and Python report keys).

#include "meshmotion/curving/curve_options.hpp"

namespace meshmotion {

/// Wall-clock seconds of each stage.
struct CurveTimes {
  double cad = 0.0;  ///< reading a CAD file and matching it to the groups (by the caller: curve_mesh's --geometry FILE)
  double quadratic = 0.0;
  double snap = 0.0;
  double layer = 0.0;  ///< boundary-layer estimate for the default radius
  double regularize = 0.0;
  double untangle = 0.0;
  double certify = 0.0;
  double distance = 0.0;  ///< the geometric certificate
  double total = 0.0;
};

template <class F>
void visit_fields(const CurveTimes& t, F&& f) {
  f("cad", t.cad, "reading the CAD file, matching its entities to the groups and placing the curved nodes on them (the program's --geometry FILE)");
  f("quadratic", t.quadratic, "conversion to the curved order");
  f("snap", t.snap, "snapping the boundary to the geometry");
  f("layer", t.layer, "estimating the walls' boundary layers");
  f("regularize", t.regularize, "the mover's setup and moves");
  f("untangle", t.untangle, "optimizing the cells below the threshold");
  f("certify", t.certify, "certifying the scaled Jacobian");
  f("distance", t.distance, "measuring the curved walls' distance to their geometry");
  f("total", t.total, "the whole pipeline, with the CAD stage");
}

/// What curve_mesh() produced and measured.
template <int Dim>
struct CurveResult {
  Mesh<Dim> curved;                 ///< the curved mesh; nodes 0..num_linear_nodes-1 are the input's
  Index num_linear_nodes = 0;
  int order = 2;
  CurveTimes seconds;
  std::string method;
  double support_radius = 0.0;      ///< support radius given to the mover, the largest when per wall (0 for movers without one)
  std::vector<double> wall_support_radii;  ///< per wall of `layers` when each has its own radius (rbf default)
  bool support_radius_limited = false;  ///< the default radius was shrunk to max_support_nodes
  std::vector<std::string> curved_groups;  ///< the groups given a curved boundary (not straight)
  std::vector<std::string> sliding_groups;  ///< the groups that slid in their plane (given or planar)
  std::vector<WallLayer> layers;    ///< estimated layers of the curved walls (when estimated)
  Index snapped_nodes = 0;          ///< boundary nodes given a position on the true boundary
  Index moved_vertices = 0;         ///< linear vertices that were off the geometry
  /// Cells whose straight shape (their vertices) the snapping's vertex moves turned over: the
  /// validity certificate measures each cell against its orientation in the input, which such a
  /// cell no longer has even where its scaled Jacobian is positive.
  Index reversed_cells = 0;
  double max_boundary_displacement = 0.0;
  Index moved_nodes = 0;            ///< nodes not on the boundary that the regularization moved
  Index solver_iterations = 0;      ///< summed over steps
  std::vector<MoverStats> mover_steps;  ///< the mover's stats per step
  UntangleReport untangle;          ///< what the untangling did (cells_below = 0: nothing to do)
  QualityReport quality;            ///< certified scaled Jacobian
  std::vector<double> cell_quality;  ///< the certified scaled Jacobian of each cell, in cell order
  std::vector<GeometryDistance> geometry_distance;  ///< per curved group, the distance of its facets to its geometry
  [[nodiscard]] Index invalid() const noexcept { return quality.num_invalid; }
  /// Curved facets farther than CurveOptions::geometry_tolerance from their geometry.
  [[nodiscard]] Index off_geometry() const noexcept {
    Index n = 0;
    for (const GeometryDistance& w : geometry_distance) n += w.facets_off;
    return n;
  }
};

/// The report of CurveResult: every field but the mesh and the per-cell values.
template <int Dim, class F>
void visit_fields(const CurveResult<Dim>& r, F&& f) {
  f("method", r.method, "the mover that regularized the interior");
  f("order", r.order, "order of the curved mesh");
  f("num_linear_nodes", r.num_linear_nodes, "nodes of the input (numbered first in the curved mesh)");
  f("curved_groups", r.curved_groups, "groups given a curved boundary");
  f("sliding_groups", r.sliding_groups, "groups that slid in their plane: those given, and planar ones meeting a curved group");
  f("support_radius", r.support_radius, "support radius given to the mover (the largest when per wall; 0 without one)");
  f("wall_support_radii", r.wall_support_radii, "per wall of layers, when each has its own radius");
  f("support_radius_limited", r.support_radius_limited, "the default radius was shrunk to max_support_nodes");
  f("layers", r.layers, "estimated boundary layers of the curved walls");
  f("snapped_nodes", r.snapped_nodes, "boundary nodes given their place on the geometry");
  f("moved_vertices", r.moved_vertices, "linear vertices that were off the geometry");
  f("reversed_cells", r.reversed_cells, "cells whose straight shape the snapping's vertex moves turned over");
  f("max_boundary_displacement", r.max_boundary_displacement, "largest move of a boundary node");
  f("moved_nodes", r.moved_nodes, "nodes off the boundary that the regularization moved");
  f("solver_iterations", r.solver_iterations, "iterative solver iterations, summed over the steps");
  f("mover_steps", r.mover_steps, "the mover's stats per step");
  f("untangle", r.untangle, "what the untangling did");
  f("invalid", r.invalid(), "cells whose certified scaled Jacobian is not positive");
  f("quality", r.quality, "certified scaled Jacobian of the curved mesh");
  f("geometry_distance", r.geometry_distance, "per curved group: its facets' distance to the geometry it was curved onto");
  f("off_geometry", r.off_geometry(), "curved facets farther than geometry_tolerance x their size from their geometry");
  f("seconds", r.seconds, "wall-clock seconds per stage");
}

}  // namespace meshmotion
