#pragma once
/// \file
/// CAD geometry for curving (the optional component meshmotion::cad, on OpenCASCADE: Debian
/// libocct-modeling-algorithms-dev and libocct-data-exchange-dev; CMake builds it when it finds
/// them, and defines MESHMOTION_HAVE_CAD for what links it).
///
/// A CadModel is a STEP, IGES or BREP file's shape, its faces and edges numbered from 1 in
/// OpenCASCADE's exploration order. match_cad_groups() finds, for each facet group of a mesh,
/// the CAD entities its vertices lie on (faces in 3D, edges in 2D: a 2D mesh lies in z = 0),
/// within a tolerance; cad_boundary() turns a match into the BoundaryGeometry curve_mesh()
/// takes. Its placement puts a node between two vertices on a common CAD edge (an edge of a
/// 2D model, a seam or ridge of a 3D one) along that edge at its fraction of the arc length
/// between them (the parameters of a periodic or closed curve unwrapped across its seam, the
/// short way round), as Gmsh does; any other edge
/// node goes to the closest point of the group's entities to its straight place (a curve of
/// the surface close to the geodesic, where a parameter line need not be), and the nodes
/// inside a facet to the closest point of their place on the facet curved by its edges.
///
/// The header holds no OpenCASCADE type: a program includes it and links meshmotion::cad.

#include "meshmotion/core/mesh.hpp"
#include "meshmotion/core/types.hpp"
#include "meshmotion/curving/boundary_snapping.hpp"
#include "meshmotion/curving/curve_options.hpp"

#include <array>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace meshmotion {

/// The closest point of one CAD entity to a point.
struct CadPoint {
  Vec<3> point = Vec<3>::Zero();
  double distance = 0.0;
  int dim = 0;      ///< 1: edge, 2: face
  int index = 0;    ///< the entity, from 1
  double u = 0.0;   ///< curve parameter, or surface parameters (u, v)
  double v = 0.0;
};

/// A STEP, IGES or BREP model.
class CadModel {
 public:
  /// Reads .step/.stp, .iges/.igs or .brep (by extension, any case). Throws IoError for a file
  /// that cannot be read and InputError for another extension or a file without faces or edges.
  [[nodiscard]] static CadModel read(const std::filesystem::path& file);

  CadModel(CadModel&&) noexcept;
  CadModel& operator=(CadModel&&) noexcept;
  ~CadModel();

  [[nodiscard]] const std::filesystem::path& file() const;
  [[nodiscard]] int num_faces() const;
  [[nodiscard]] int num_edges() const;
  /// Diagonal of the model's bounding box: the scale of the default tolerance.
  [[nodiscard]] double diagonal() const;

  /// The closest point of entity (dim, index) to x. Throws InputError for an entity the model
  /// does not have.
  [[nodiscard]] CadPoint closest_point(int dim, int index, const Vec<3>& x) const;
  /// The closest point of face `index` to x found by a local search from parameters (u0, v0),
  /// for a point next to known points of the face (much cheaper than closest_point()'s global
  /// search). Falls back to closest_point() when the search fails or ends outside the face's
  /// boundary. Edges (dim 1) take closest_point().
  [[nodiscard]] CadPoint closest_point_near(int dim, int index, const Vec<3>& x, double u0, double v0) const;
  /// The point of entity (dim, index) at parameters (u, v) (v unused on edges); on a closed
  /// entity a parameter is taken modulo its period.
  [[nodiscard]] Vec<3> point_at(int dim, int index, double u, double v = 0.0) const;
  /// The period of each parameter of entity (dim, index): a periodic one's, the parameter range
  /// of one that closes without being periodic (IGES's closed B-splines), 0 elsewhere.
  [[nodiscard]] std::array<double, 2> periods(int dim, int index) const;
  /// Whether entity (dim, index) is a plane (a face) or a straight line (an edge): nothing on it
  /// needs curving.
  [[nodiscard]] bool flat(int dim, int index) const;
  /// The parameter of edge `index` between parameters a and b where the arc length from a
  /// reaches `fraction` of the length from a to b, to round-off. On a closed edge b may lie
  /// past the seam (a parameter unwrapped by whole periods): the way goes across it.
  [[nodiscard]] double arc_length_parameter(int index, double a, double b, double fraction) const;
  /// The same along an isoline of face `index`: its parameter `fixed` (0: u, 1: v) held at
  /// `at`, a and b values of the other parameter (unwrapped across a seam like b above).
  [[nodiscard]] double isoline_arc_length_parameter(int index, int fixed, double at, double a, double b, double fraction) const;
  /// The edges bounding face `index`.
  [[nodiscard]] std::vector<int> face_edges(int index) const;
  /// The closest points of the entities of dimension `dim` among `candidates` (empty: all)
  /// that lie within `distance` of x, nearest first (bounding boxes screen the others out).
  [[nodiscard]] std::vector<CadPoint> entities_within(int dim, const std::vector<int>& candidates, const Vec<3>& x,
                                                      double distance) const;
  /// The closest point of the nearest entity of dimension `dim` among `candidates` (empty: all).
  [[nodiscard]] CadPoint nearest(int dim, const std::vector<int>& candidates, const Vec<3>& x) const;

 private:
  struct Impl;
  explicit CadModel(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

/// What a facet group of a mesh matched on a CAD model.
struct CadGroupMatch {
  std::string group;
  int dim = 0;                 ///< entity dimension: 1 (edges) for 2D meshes, 2 (faces) for 3D
  std::vector<int> entities;   ///< the entities holding its vertices (empty: not matched)
  double max_distance = 0.0;   ///< largest distance of a vertex to its nearest entity
  Index farthest_node = -1;    ///< that vertex (mesh index)
  Index vertices = 0;          ///< vertices of the group's facets
  /// Of them, those the mesh file places inside an entity of the model (Gmsh's entity tag and
  /// parameters, Mesh::node_params) within the tolerance: located without a search.
  Index by_file = 0;
  /// Those the file places inside an entity of the group's dimension that the model does not
  /// have there (another numbering, or another model): located by distance instead.
  Index file_mismatches = 0;
  /// The vertices located by the file, with their place on the model (cad_boundary() starts
  /// from them).
  std::vector<std::pair<Vec<3>, CadPoint>> located;
  [[nodiscard]] bool matched() const noexcept { return !entities.empty(); }
};

/// The default tolerance of match_cad_groups(): 1e-6 of the model's diagonal.
[[nodiscard]] double default_cad_tolerance(const CadModel& model);

/// Matches every facet group of `mesh` (or only `groups` when given) to the CAD entities its
/// vertices lie on within `tolerance` (≤ 0: default_cad_tolerance()). A vertex the mesh file
/// puts inside an entity (Gmsh's `$ParametricNodes` or parametric node blocks: the entity's tag
/// and the node's parameters) is on that entity of the model when the model's point at those
/// parameters is within the tolerance (Gmsh numbers a STEP file's entities as OpenCASCADE
/// explores them, as CadModel does); any other vertex is located by distance. A group with a vertex
/// farther than the tolerance from every entity is not matched (its farthest vertex and
/// distance say why); a group named in `groups` that does not match throws InputError naming
/// the vertex (index and file id), its position and its distance.
template <int Dim>
[[nodiscard]] std::vector<CadGroupMatch> match_cad_groups(const Mesh<Dim>& mesh, const CadModel& model, double tolerance = 0.0,
                                                          const std::vector<std::string>& groups = {});

/// The boundary geometry of a matched group: closest-point projection onto its entities and
/// the parametric placement of the file comment. `model` must outlive the result.
template <int Dim>
[[nodiscard]] BoundaryGeometry<Dim> cad_boundary(const CadModel& model, const CadGroupMatch& match, double tolerance = 0.0);

/// Ties `mesh` (a mesh curved on `model`) to the model's entities, as a .msh file keeps them
/// (Gmsh's $ParametricNodes and elementary tags), so that it goes back into Gmsh with the model:
/// - Mesh::node_params: a node of a facet of a matched group lies within `tolerance` (≤ 0:
///   default_cad_tolerance()) of the group's entities and, in 3D, on an edge of them when one
///   is within it (a seam, a ridge, a border with another face); it is given that entity and
///   its parameters there. Every other node lies in the domain: the entity of a cell holding it.
/// - ElementBlock::entities of the facets of matched groups: the face (in 2D, the edge) their
///   nodes lie on; of cells without entities: 1 (the model's one volume, or surface in 2D).
/// Facet tags without a group get one named by their number, as match_cad_groups() names them.
template <int Dim>
void place_on_cad(Mesh<Dim>& mesh, const CadModel& model, const std::vector<CadGroupMatch>& matches, double tolerance = 0.0);

/// Throws InputError when `matches` (match_cad_groups() of `mesh`) matched no group: a user who
/// gives a model wants it used, not a silent fallback. The message names the group that came
/// closest and how far its farthest vertex is, and the ratio of the mesh's size to the
/// model's (1000: a mesh in millimetres on a model in metres).
template <int Dim>
void require_cad_fit(const Mesh<Dim>& mesh, const CadModel& model, const std::vector<CadGroupMatch>& matches);

/// One line per group: what it matched (or why not), for the programs' reports.
[[nodiscard]] std::string describe_cad_matches(const std::vector<CadGroupMatch>& matches);

/// The groups curve_mesh() curves on a model, as geometry_on_cad() chose them.
struct CadCurving {
  std::vector<CadGroupMatch> matches;  ///< match_cad_groups()'s, for place_on_cad() after curving
  std::vector<std::string> on_model;   ///< the groups given the model's geometry
  std::string report;                  ///< describe_cad_matches(): one line per group
};

/// Which groups of `mesh` go onto `model` (the policy every front end shares: curve_mesh
/// --geometry FILE, Python's curve_mesh(geometry="FILE")): the groups `groups` names, or every
/// facet group the model fits (match_cad_groups(), within `tolerance`; require_cad_fit()
/// refuses a model that fits none). Each gets cad_boundary() in `options.geometry`, except,
/// unless named, a planar group where `options.slide_planar_groups` (left to curve_mesh(),
/// which keeps it straight and lets it slide where it meets a curved group: a symmetry plane)
/// and a group on the model's planes alone (a box's far field: kept straight, nothing to
/// curve). Names unnamed facet groups by their tags first, as curve_mesh() does. `model` must
/// outlive the options.
template <int Dim>
[[nodiscard]] CadCurving geometry_on_cad(Mesh<Dim>& mesh, const CadModel& model, CurveOptions<Dim>& options,
                                         double tolerance = 0.0, const std::vector<std::string>& groups = {});

}  // namespace meshmotion
