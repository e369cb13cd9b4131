// The OpenCASCADE module of the CAD component: the toolkits behind detail::CadShape, loaded by
// CadModel::read() on first use (src/cad/cad_shape.hpp says why).

#include "cad_shape.hpp"

#include "meshmotion/core/error.hpp"
#include "meshmotion/io/detail/read_file.hpp"
#include "meshmotion/spatial/kd_tree.hpp"

#include <Adaptor3d_IsoCurve.hxx>
#include <BRepAdaptor_Curve.hxx>
#include <BRepAdaptor_Surface.hxx>
#include <BRepBndLib.hxx>
#include <BRepTools.hxx>
#include <BRepTopAdaptor_FClass2d.hxx>
#include <BRep_Builder.hxx>
#include <BRep_Tool.hxx>
#include <Bnd_Box.hxx>
#include <Extrema_ExtPS.hxx>
#include <GeomAPI_ProjectPointOnCurve.hxx>
#include <GCPnts_AbscissaPoint.hxx>
#include <Geom_Curve.hxx>
#include <IFSelect_ReturnStatus.hxx>
#include <IGESControl_Reader.hxx>
#include <Message.hxx>
#include <Message_Messenger.hxx>
#include <STEPControl_Reader.hxx>
#include <Precision.hxx>
#include <ShapeAnalysis_Surface.hxx>
#include <Standard_Failure.hxx>
#include <TopExp.hxx>
#include <TopExp_Explorer.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Edge.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Shape.hxx>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

namespace meshmotion::detail {
namespace {

// OpenCASCADE's translators print their progress to stdout: a program's JSON output must stay
// clean, and failures reach the caller as exceptions.
void quiet_occt() {
  static const bool done = [] {
    Message::DefaultMessenger()->ChangePrinters().Clear();
    return true;
  }();
  (void)done;
}

TopoDS_Shape read_shape(const std::filesystem::path& file) {
  quiet_occt();
  const std::string ext = detail::lower_extension(file);
  if (ext == ".step" || ext == ".stp") {
    STEPControl_Reader reader;
    if (reader.ReadFile(file.c_str()) != IFSelect_RetDone) throw IoError(file.string() + ": OpenCASCADE cannot read this STEP file");
    reader.TransferRoots();
    return reader.OneShape();
  }
  if (ext == ".iges" || ext == ".igs") {
    IGESControl_Reader reader;
    if (reader.ReadFile(file.c_str()) != IFSelect_RetDone) throw IoError(file.string() + ": OpenCASCADE cannot read this IGES file");
    reader.TransferRoots();
    return reader.OneShape();
  }
  if (ext == ".brep") {
    TopoDS_Shape shape;
    BRep_Builder builder;
    if (!BRepTools::Read(shape, file.c_str(), builder)) throw IoError(file.string() + ": OpenCASCADE cannot read this BREP file");
    return shape;
  }
  throw InputError(file.string() + ": unknown CAD format '" + ext + "' (expected .step, .stp, .iges, .igs or .brep)");
}

gp_Pnt to_gp(const Vec<3>& x) { return gp_Pnt(x[0], x[1], x[2]); }
Vec<3> from_gp(const gp_Pnt& p) { return Vec<3>(p.X(), p.Y(), p.Z()); }

double distance_to_box(const Bnd_Box& box, const gp_Pnt& p) {
  if (box.IsVoid()) return std::numeric_limits<double>::infinity();
  double x0, y0, z0, x1, y1, z1;
  box.Get(x0, y0, z0, x1, y1, z1);
  const double dx = std::max({x0 - p.X(), 0.0, p.X() - x1});
  const double dy = std::max({y0 - p.Y(), 0.0, p.Y() - y1});
  const double dz = std::max({z0 - p.Z(), 0.0, p.Z() - z1});
  return std::sqrt(dx * dx + dy * dy + dz * dz);
}

class OcctShape final : public CadShape {
 public:
  explicit OcctShape(const std::filesystem::path& file);

  int num_faces() const override { return faces_.Extent(); }
  int num_edges() const override { return edges_.Extent(); }
  double diagonal() const override { return diagonal_; }
  std::vector<int> face_edges(int face) const override { return face_edges_[static_cast<std::size_t>(face - 1)]; }
  double box_distance(int dim, int index, const Vec<3>& x) const override {
    return distance_to_box((dim == 2 ? face_boxes_ : edge_boxes_)[static_cast<std::size_t>(index - 1)], to_gp(x));
  }
  CadPoint closest_point(int dim, int index, const Vec<3>& x) const override;
  std::optional<CadPoint> closest_point_near(int face, const Vec<3>& x, double u0, double v0) const override;
  Vec<3> point_at(int dim, int index, double u, double v) const override;
  std::array<double, 2> periods(int dim, int index) const override;
  bool flat(int dim, int index) const override {
    if (dim == 1) return BRepAdaptor_Curve(TopoDS::Edge(edges_(index))).GetType() == GeomAbs_Line;
    return queries(index).surface.GetType() == GeomAbs_Plane;
  }
  double arc_length_parameter(int edge, double a, double b, double fraction) const override;
  double isoline_arc_length_parameter(int face, int fixed, double at, double a, double b, double fraction) const override;

 private:
  std::filesystem::path file_;
  TopoDS_Shape shape_;
  TopTools_IndexedMapOfShape faces_, edges_;
  std::vector<Bnd_Box> face_boxes_, edge_boxes_;
  std::vector<std::vector<int>> face_edges_;
  double diagonal_ = 0.0;
  // What the queries on a face need, built on its first use and kept: its surface (a
  // BRepAdaptor_Surface takes its parameter bounds from the face's edges, and on a plane
  // projects each edge to get them: rebuilt per query, that was a tenth of curving the sphere),
  // the global search with its grid of samples, and the classifier of parameter points (built
  // per query by BRepExtrema, they were a third of it). Queries evaluate the surface through
  // shallow copies, which keep their own B-spline caches, and use the search and the
  // classifier under the face's mutex: the model's const methods stay safe to call from
  // several threads.
  // A grid of the surface's points over the face's parameter box gives Newton's method its
  // start for points on the face (seeded_closest_point).
  struct FaceQueries {
    FaceQueries(const TopoDS_Face& face, double tolerance);
    BRepAdaptor_Surface surface;
    Handle(Adaptor3d_Surface) searched;  // the search's own copy
    Extrema_ExtPS search;
    BRepTopAdaptor_FClass2d classifier;
    std::mutex mutex;
    static constexpr int samples = 24;  // per parameter direction
    Points<3> sample_points;
    std::vector<std::array<double, 2>> sample_parameters;
    KdTree<3> sample_tree;  // over sample_points
  };
  std::optional<CadPoint> seeded_closest_point(FaceQueries& q, int face, const Vec<3>& x) const;
  FaceQueries& queries(int face) const;
  mutable std::vector<std::unique_ptr<FaceQueries>> queries_;
  mutable std::mutex queries_mutex_;
};

OcctShape::FaceQueries::FaceQueries(const TopoDS_Face& face, double tolerance)
    : surface(face), searched(surface.ShallowCopy()), classifier(face, tolerance) {
  // The tolerances BRepExtrema gives the same search: the face's, in parameters.
  const double face_tolerance = BRep_Tool::Tolerance(face);
  search.Initialize(*searched, surface.FirstUParameter(), surface.LastUParameter(), surface.FirstVParameter(),
                    surface.LastVParameter(), std::max(surface.UResolution(face_tolerance), Precision::PConfusion()),
                    std::max(surface.VResolution(face_tolerance), Precision::PConfusion()));
  sample_points.resize(3, samples * samples);
  for (int i = 0; i < samples; ++i)
    for (int j = 0; j < samples; ++j) {
      const double u = surface.FirstUParameter() + (surface.LastUParameter() - surface.FirstUParameter()) * (i + 0.5) / samples;
      const double v = surface.FirstVParameter() + (surface.LastVParameter() - surface.FirstVParameter()) * (j + 0.5) / samples;
      const Vec<3> at = from_gp(surface.Value(u, v));
      if (!at.allFinite()) continue;  // a face unbounded in its parameters: the global search serves it
      sample_points.col(static_cast<Index>(sample_parameters.size())) = at;
      sample_parameters.push_back({u, v});
    }
  sample_points.conservativeResize(3, static_cast<Index>(sample_parameters.size()));
  if (!sample_parameters.empty()) sample_tree.build(sample_points);
}

// A point on the face, or within a tenth of its distance to the nearest grid sample (a mesh
// vertex made on the face, off by the file's tolerance), is found by Newton's method from that
// sample. The global search it replaces was a third of curving the sphere with its far field
// (whole P2 run 0.91 -> 0.36 s). Another part of the face nearer still would have to pass
// within twice the distance found, a fifth of the sample's, of this one. Points farther off
// (a vertex of a neighbouring face, tried against this one) get none and take the global
// search.
std::optional<CadPoint> OcctShape::seeded_closest_point(FaceQueries& q, int face, const Vec<3>& x) const {
  if (q.sample_parameters.empty()) return std::nullopt;
  const Neighbor nearest = q.sample_tree.nearest(x);
  const auto& [u0, v0] = q.sample_parameters[nearest.first];
  const std::optional<CadPoint> found = closest_point_near(face, x, u0, v0);
  if (found && found->distance <= 0.1 * std::sqrt(nearest.second)) return found;
  return std::nullopt;
}

OcctShape::FaceQueries& OcctShape::queries(int face) const {
  const std::lock_guard<std::mutex> lock(queries_mutex_);
  auto& q = queries_[static_cast<std::size_t>(face - 1)];
  if (!q) q = std::make_unique<FaceQueries>(TopoDS::Face(faces_(face)), 1e-9 * std::max(diagonal_, 1e-300));
  return *q;
}

OcctShape::OcctShape(const std::filesystem::path& file) : file_(file) {
  shape_ = read_shape(file);
  if (shape_.IsNull()) throw InputError(file.string() + ": the file holds no shape");
  TopExp::MapShapes(shape_, TopAbs_FACE, faces_);
  TopExp::MapShapes(shape_, TopAbs_EDGE, edges_);
  if (faces_.Extent() == 0 && edges_.Extent() == 0)
    throw InputError(file.string() + ": the shape has no faces or edges to curve a mesh onto");
  for (int f = 1; f <= faces_.Extent(); ++f) {
    Bnd_Box box;
    BRepBndLib::Add(faces_(f), box);
    face_boxes_.push_back(box);
    TopTools_IndexedMapOfShape bounding;
    TopExp::MapShapes(faces_(f), TopAbs_EDGE, bounding);
    std::vector<int> ids;
    for (int e = 1; e <= bounding.Extent(); ++e) ids.push_back(edges_.FindIndex(bounding(e)));
    face_edges_.push_back(std::move(ids));
  }
  queries_.resize(static_cast<std::size_t>(faces_.Extent()));
  for (int e = 1; e <= edges_.Extent(); ++e) {
    Bnd_Box box;
    BRepBndLib::Add(edges_(e), box);
    edge_boxes_.push_back(box);
  }
  Bnd_Box all;
  BRepBndLib::Add(shape_, all);
  if (!all.IsVoid()) {
    double x0, y0, z0, x1, y1, z1;
    all.Get(x0, y0, z0, x1, y1, z1);
    diagonal_ = std::sqrt((x1 - x0) * (x1 - x0) + (y1 - y0) * (y1 - y0) + (z1 - z0) * (z1 - z0));
  }
}

CadPoint OcctShape::closest_point(int dim, int index, const Vec<3>& x) const {
  CadPoint out;
  out.dim = dim;
  out.index = index;
  const gp_Pnt p = to_gp(x);
  if (dim == 1) {
    // The edge's own curve on its parameter range, and its ends.
    const TopoDS_Edge& edge = TopoDS::Edge(edges_(index));
    double first = 0, last = 0;
    const Handle(Geom_Curve) curve = BRep_Tool::Curve(edge, first, last);
    if (curve.IsNull()) {  // a degenerate edge (a sphere's pole): its one point
      const gp_Pnt q = BRep_Tool::Pnt(TopExp::FirstVertex(edge));
      out.u = first;
      out.point = from_gp(q);
      out.distance = q.Distance(p);
      return out;
    }
    double best = std::numeric_limits<double>::infinity(), t_best = first;
    for (const double t : {first, last}) {
      const double d = curve->Value(t).Distance(p);
      if (d < best) best = d, t_best = t;
    }
    GeomAPI_ProjectPointOnCurve projection(p, curve, first, last);
    if (projection.NbPoints() > 0 && projection.LowerDistance() < best) best = projection.LowerDistance(), t_best = projection.LowerDistanceParameter();
    out.u = t_best;
    out.point = from_gp(curve->Value(t_best));
    out.distance = best;
    return out;
  }
  // The nearest extremum of the surface inside the face, or the nearest point of its boundary
  // (what BRepExtrema_DistShapeShape finds between a vertex and a face).
  out.distance = std::numeric_limits<double>::infinity();
  FaceQueries& q = queries(index);
  if (const std::optional<CadPoint> seeded = seeded_closest_point(q, index, x)) {
    out = *seeded;
  } else {
    const std::lock_guard<std::mutex> lock(q.mutex);
    q.search.Perform(p);
    for (int i = 1; q.search.IsDone() && i <= q.search.NbExt(); ++i) {
      const double d = std::sqrt(q.search.SquareDistance(i));
      if (d >= out.distance) continue;
      double u = 0, v = 0;
      q.search.Point(i).Parameter(u, v);
      if (const TopAbs_State state = q.classifier.Perform(gp_Pnt2d(u, v)); state == TopAbs_IN || state == TopAbs_ON) {
        out.distance = d;
        out.u = u;
        out.v = v;
        out.point = from_gp(q.search.Point(i).Value());
      }
    }
  }
  bool on_boundary = false;
  for (const int edge : face_edges_[static_cast<std::size_t>(index - 1)]) {
    if (box_distance(1, edge, x) >= out.distance) continue;
    if (const CadPoint c = closest_point(1, edge, x); c.distance < out.distance) {
      out.distance = c.distance;
      out.point = c.point;
      on_boundary = true;
    }
  }
  if (!std::isfinite(out.distance)) throw InputError(file_.string() + ": no closest point on face " + std::to_string(index));
  if (on_boundary) {  // its surface parameters there
    const TopoDS_Face& face = TopoDS::Face(faces_(index));
    ShapeAnalysis_Surface surface(BRep_Tool::Surface(face));
    const gp_Pnt2d uv = surface.ValueOfUV(to_gp(out.point), 1e-9 * std::max(diagonal_, 1e-300));
    out.u = uv.X();
    out.v = uv.Y();
  }
  // OpenCASCADE's extremum stops at its precision (a torus stored as a surface of revolution,
  // as IGES has it, came out 3e-6 off its closest point): Newton's method takes it to round-off.
  if (const std::optional<CadPoint> polished = closest_point_near(index, x, out.u, out.v))
    if (polished->distance <= out.distance) return *polished;
  return out;
}

std::optional<CadPoint> OcctShape::closest_point_near(int index, const Vec<3>& x, double u0, double v0) const {
  FaceQueries& q = queries(index);
  const Handle(Adaptor3d_Surface) surface = q.surface.ShallowCopy();
  // Newton's method on the squared distance, to round-off: from a start next to the answer it
  // converges in a few steps (OpenCASCADE's local extremum stops at its parameter tolerance,
  // 1e-9, which moved a sphere's edge nodes 5e-7 off their great circles).
  const gp_Pnt p = to_gp(x);
  double u = u0, v = v0;
  bool converged = false;
  for (int iteration = 0; iteration < 30 && !converged; ++iteration) {
    gp_Pnt s;
    gp_Vec su, sv, suu, svv, suv;
    surface->D2(u, v, s, su, sv, suu, svv, suv);
    const gp_Vec r(p, s);
    const double gu = r.Dot(su), gv = r.Dot(sv);
    const double huu = su.Dot(su) + r.Dot(suu), hvv = sv.Dot(sv) + r.Dot(svv), huv = su.Dot(sv) + r.Dot(suv);
    const double det = huu * hvv - huv * huv;
    if (!(det > 1e-14 * (su.SquareMagnitude() * sv.SquareMagnitude())) || !(huu > 0.0)) break;  // not a minimum, or degenerate
    const double du = (hvv * gu - huv * gv) / det, dv = (huu * gv - huv * gu) / det;
    u -= du;
    v -= dv;
    converged = std::abs(du) * su.Magnitude() + std::abs(dv) * sv.Magnitude() < 1e-14 * std::max(diagonal_, 1e-300);
  }
  if (converged) {
    // Back into the face's range by whole periods: the search may end past a periodic face's
    // seam (and IGES's trimming closes 2e-10 short of the period).
    const auto into_range = [](double t, bool periodic, double period, double first) {
      return periodic && period > 0.0 ? first + std::fmod(std::fmod(t - first, period) + period, period) : t;
    };
    u = into_range(u, surface->IsUPeriodic(), surface->IsUPeriodic() ? surface->UPeriod() : 0.0, surface->FirstUParameter());
    v = into_range(v, surface->IsVPeriodic(), surface->IsVPeriodic() ? surface->VPeriod() : 0.0, surface->FirstVParameter());
    CadPoint out;
    out.dim = 2;
    out.index = index;
    out.u = u;
    out.v = v;
    TopAbs_State state;
    {
      const std::lock_guard<std::mutex> lock(q.mutex);
      state = q.classifier.Perform(gp_Pnt2d(out.u, out.v));
    }
    if (state == TopAbs_IN || state == TopAbs_ON) {
      out.point = from_gp(surface->Value(u, v));
      out.distance = (out.point - x).norm();
      return out;
    }
  }
  return std::nullopt;
}

// A curve or surface that closes on itself without being periodic (IGES stores a circle or an
// ellipse as a closed, non-periodic B-spline; OpenCASCADE's STEP reader makes it a periodic
// circle) still has a seam, and its parameter range is one period: the placement unwraps
// across it as across a periodic one's (else the node between the seam vertex and its
// neighbour went the long way round, to the far side of the body), and a parameter beyond the
// range is wrapped back before evaluating, where a non-periodic curve would extrapolate.
double period_of(bool periodic, double period, bool closed, double first, double last) {
  return periodic ? period : closed ? last - first : 0.0;
}

double wrap(double t, bool periodic, bool closed, double first, double last) {
  if (periodic || !closed || !(last > first)) return t;
  t = first + std::fmod(t - first, last - first);
  return t < first ? t + (last - first) : t;
}

Vec<3> OcctShape::point_at(int dim, int index, double u, double v) const {
  if (dim == 1) {
    const BRepAdaptor_Curve c(TopoDS::Edge(edges_(index)));
    return from_gp(c.Value(wrap(u, c.IsPeriodic(), c.IsClosed(), c.FirstParameter(), c.LastParameter())));
  }
  const Handle(Adaptor3d_Surface) copy = queries(index).surface.ShallowCopy();
  const Adaptor3d_Surface& s = *copy;
  return from_gp(s.Value(wrap(u, s.IsUPeriodic(), s.IsUClosed(), s.FirstUParameter(), s.LastUParameter()),
                         wrap(v, s.IsVPeriodic(), s.IsVClosed(), s.FirstVParameter(), s.LastVParameter())));
}

std::array<double, 2> OcctShape::periods(int dim, int index) const {
  if (dim == 1) {
    const BRepAdaptor_Curve c(TopoDS::Edge(edges_(index)));
    return {period_of(c.IsPeriodic(), c.IsPeriodic() ? c.Period() : 0.0, c.IsClosed(), c.FirstParameter(), c.LastParameter()), 0.0};
  }
  const BRepAdaptor_Surface& s = queries(index).surface;  // its constant properties only
  return {period_of(s.IsUPeriodic(), s.IsUPeriodic() ? s.UPeriod() : 0.0, s.IsUClosed(), s.FirstUParameter(), s.LastUParameter()),
          period_of(s.IsVPeriodic(), s.IsVPeriodic() ? s.VPeriod() : 0.0, s.IsVClosed(), s.FirstVParameter(), s.LastVParameter())};
}

// OpenCASCADE integrates the length piecewise between the curve's breaks of continuity (a
// B-spline circle's speed jumps at its knots) and inverts it by Newton's method, both to
// round-off here: a circle stored as a periodic circle (STEP) or a closed B-spline (IGES) then
// gets the same nodes to 1e-12, where a polyline of chords left the B-spline's 1e-5 apart.
double arc_length_on(const Adaptor3d_Curve& c, double a, double b, double fraction) {
  const double first = c.FirstParameter(), last = c.LastParameter();
  // Pieces of the way from a to b in the curve's own range: a closed, non-periodic curve
  // cannot be evaluated past its seam, so a way across it continues from the other end.
  struct Piece {
    double from, to, shift;  // curve parameters, and what unwraps them
  };
  std::vector<Piece> pieces;
  if (!c.IsPeriodic() && c.IsClosed() && last > first) {
    const double period = last - first;
    const double shift = a - wrap(a, false, true, first, last), from = a - shift, to = b - shift;
    if (to > last)
      pieces = {{from, last, shift}, {first, to - period, shift + period}};
    else if (to < first)
      pieces = {{from, first, shift}, {last, to + period, shift - period}};
    else
      pieces = {{from, to, shift}};
  } else {
    pieces = {{a, b, 0.0}};
  }
  constexpr double tolerance = 1e-13;
  std::vector<double> lengths;
  double total = 0.0;
  for (const Piece& p : pieces) {
    lengths.push_back(GCPnts_AbscissaPoint::Length(c, std::min(p.from, p.to), std::max(p.from, p.to), tolerance));
    total += lengths.back();
  }
  if (!(total > 0.0)) return a + fraction * (b - a);
  double remaining = fraction * total;
  for (std::size_t k = 0; k < pieces.size(); ++k) {
    const Piece& p = pieces[k];
    if (remaining > lengths[k] && k + 1 < pieces.size()) {
      remaining -= lengths[k];
      continue;
    }
    const double direction = p.to >= p.from ? 1.0 : -1.0;
    const double guess = p.from + (p.to - p.from) * std::clamp(remaining / std::max(lengths[k], 1e-300), 0.0, 1.0);
    const GCPnts_AbscissaPoint at(c, direction * remaining, p.from, guess, tolerance);
    return (at.IsDone() ? at.Parameter() : guess) + p.shift;
  }
  return b;
}

double OcctShape::arc_length_parameter(int edge, double a, double b, double fraction) const {
  return arc_length_on(BRepAdaptor_Curve(TopoDS::Edge(edges_(edge))), a, b, fraction);
}

double OcctShape::isoline_arc_length_parameter(int face, int fixed, double at, double a, double b, double fraction) const {
  return arc_length_on(Adaptor3d_IsoCurve(queries(face).surface.ShallowCopy(), fixed == 0 ? GeomAbs_IsoU : GeomAbs_IsoV, at), a, b, fraction);
}

}  // namespace
}  // namespace meshmotion::detail

extern "C" {

int meshmotion_cad_module_version() { return meshmotion::detail::cad_module_version; }

meshmotion::detail::CadShape* meshmotion_cad_read(const std::filesystem::path* file) {
  // OpenCASCADE's own exceptions stay in the module: the caller knows meshmotion's.
  try {
    return new meshmotion::detail::OcctShape(*file);
  } catch (const Standard_Failure& e) {
    throw meshmotion::IoError(file->string() + ": OpenCASCADE failed reading it (" + std::string(e.GetMessageString()) + ")");
  }
}

}
