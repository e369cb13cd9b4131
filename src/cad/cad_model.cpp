// The CAD component (meshmotion::cad); see include/meshmotion/cad/cad_model.hpp. The
// OpenCASCADE side is a module loaded on first use (cad_shape.hpp).

#include "meshmotion/cad/cad_model.hpp"

#include "cad_shape.hpp"
#include "meshmotion/core/error.hpp"
#include "meshmotion/curving/detail/curving_groups.hpp"
#include "meshmotion/io/detail/read_file.hpp"

#include <dlfcn.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <sstream>
#include <unordered_map>
#include <unordered_set>
#include <utility>

namespace meshmotion {

struct CadModel::Impl {
  std::filesystem::path file;
  std::unique_ptr<detail::CadShape> shape;
};

namespace {

using ReadShape = detail::CadShape* (*)(const std::filesystem::path*);

// $MESHMOTION_CAD_MODULE, else the build tree's module while it exists, else the installed one
// (CMake passes both paths).
std::string cad_module_path() {
  if (const char* given = std::getenv("MESHMOTION_CAD_MODULE"); given != nullptr && *given != '\0') return given;
  std::error_code ec;
  return std::filesystem::is_regular_file(MESHMOTION_CAD_MODULE_BUILD, ec) ? MESHMOTION_CAD_MODULE_BUILD
                                                                           : MESHMOTION_CAD_MODULE_INSTALL;
}

// The module's reader, loaded once and kept for the life of the process.
ReadShape cad_reader() {
  static const ReadShape reader = [] {
    const std::string path = cad_module_path();
    void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (handle == nullptr) {
      const char* reason = dlerror();
      throw IoError("cannot load the CAD module " + path + " (" + (reason != nullptr ? reason : "unknown reason") +
                    "; set MESHMOTION_CAD_MODULE to the installed libmeshmotion_cad_occt.so, and check that "
                    "OpenCASCADE's libraries are installed)");
    }
    const auto version = reinterpret_cast<int (*)()>(dlsym(handle, "meshmotion_cad_module_version"));
    const auto read = reinterpret_cast<ReadShape>(dlsym(handle, "meshmotion_cad_read"));
    if (version == nullptr || read == nullptr || version() != detail::cad_module_version)
      throw IoError("the CAD module " + path + " is not the one this program was built with (version " +
                    (version != nullptr ? std::to_string(version()) : std::string("none")) + ", expected " +
                    std::to_string(detail::cad_module_version) + ")");
    return read;
  }();
  return reader;
}

void check_entity(const CadModel& m, int dim, int index) {
  const int count = dim == 2 ? m.num_faces() : dim == 1 ? m.num_edges() : 0;
  if (index < 1 || index > count)
    throw InputError("CadModel: no " + std::string(dim == 2 ? "face " : dim == 1 ? "edge " : "entity ") + std::to_string(index) +
                     " of dimension " + std::to_string(dim) + " (the model has " + std::to_string(count) + ")");
}

}  // namespace

CadModel::CadModel(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
CadModel::CadModel(CadModel&&) noexcept = default;
CadModel& CadModel::operator=(CadModel&&) noexcept = default;
CadModel::~CadModel() = default;

CadModel CadModel::read(const std::filesystem::path& file) {
  // What needs no OpenCASCADE is checked before loading it.
  const std::string ext = detail::lower_extension(file);
  if (ext != ".step" && ext != ".stp" && ext != ".iges" && ext != ".igs" && ext != ".brep")
    throw InputError(file.string() + ": unknown CAD format '" + ext + "' (expected .step, .stp, .iges, .igs or .brep)");
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec)) throw IoError(file.string() + ": no such file");
  auto impl = std::make_unique<Impl>();
  impl->file = file;
  impl->shape.reset(cad_reader()(&file));
  return CadModel(std::move(impl));
}

const std::filesystem::path& CadModel::file() const { return impl_->file; }
int CadModel::num_faces() const { return impl_->shape->num_faces(); }
int CadModel::num_edges() const { return impl_->shape->num_edges(); }
double CadModel::diagonal() const { return impl_->shape->diagonal(); }

std::vector<int> CadModel::face_edges(int index) const {
  if (index < 1 || index > num_faces())
    throw InputError("CadModel: no face " + std::to_string(index) + " (the model has " + std::to_string(num_faces()) + ")");
  return impl_->shape->face_edges(index);
}

CadPoint CadModel::closest_point(int dim, int index, const Vec<3>& x) const {
  check_entity(*this, dim, index);
  return impl_->shape->closest_point(dim, index, x);
}

CadPoint CadModel::closest_point_near(int dim, int index, const Vec<3>& x, double u0, double v0) const {
  check_entity(*this, dim, index);
  if (dim == 2)
    if (const std::optional<CadPoint> found = impl_->shape->closest_point_near(index, x, u0, v0)) return *found;
  return impl_->shape->closest_point(dim, index, x);
}

Vec<3> CadModel::point_at(int dim, int index, double u, double v) const {
  check_entity(*this, dim, index);
  return impl_->shape->point_at(dim, index, u, v);
}

std::array<double, 2> CadModel::periods(int dim, int index) const {
  check_entity(*this, dim, index);
  return impl_->shape->periods(dim, index);
}

bool CadModel::flat(int dim, int index) const {
  check_entity(*this, dim, index);
  return impl_->shape->flat(dim, index);
}

double CadModel::arc_length_parameter(int index, double a, double b, double fraction) const {
  check_entity(*this, 1, index);
  return impl_->shape->arc_length_parameter(index, a, b, fraction);
}

double CadModel::isoline_arc_length_parameter(int index, int fixed, double at, double a, double b, double fraction) const {
  check_entity(*this, 2, index);
  if (fixed != 0 && fixed != 1)
    throw InputError("CadModel::isoline_arc_length_parameter: the fixed parameter is 0 (u) or 1 (v), got " + std::to_string(fixed));
  return impl_->shape->isoline_arc_length_parameter(index, fixed, at, a, b, fraction);
}

double default_cad_tolerance(const CadModel& model) { return 1e-6 * model.diagonal(); }

namespace {

std::vector<int> all_entities(int count) {
  std::vector<int> out(static_cast<std::size_t>(count));
  for (int k = 0; k < count; ++k) out[static_cast<std::size_t>(k)] = k + 1;
  return out;
}

}  // namespace

std::vector<CadPoint> CadModel::entities_within(int dim, const std::vector<int>& candidates, const Vec<3>& x, double distance) const {
  const std::vector<int> all = candidates.empty() ? all_entities(dim == 2 ? num_faces() : num_edges()) : std::vector<int>{};
  std::vector<CadPoint> out;
  for (const int e : candidates.empty() ? all : candidates) {
    check_entity(*this, dim, e);
    if (impl_->shape->box_distance(dim, e, x) > distance) continue;
    const CadPoint c = closest_point(dim, e, x);
    if (c.distance <= distance) out.push_back(c);
  }
  std::sort(out.begin(), out.end(), [](const CadPoint& a, const CadPoint& b) { return a.distance < b.distance; });
  return out;
}

CadPoint CadModel::nearest(int dim, const std::vector<int>& candidates, const Vec<3>& x) const {
  const std::vector<int> all = candidates.empty() ? all_entities(dim == 2 ? num_faces() : num_edges()) : std::vector<int>{};
  std::vector<std::pair<double, int>> order;
  for (const int e : candidates.empty() ? all : candidates) {
    check_entity(*this, dim, e);
    order.emplace_back(impl_->shape->box_distance(dim, e, x), e);
  }
  std::sort(order.begin(), order.end());
  CadPoint best;
  best.distance = std::numeric_limits<double>::infinity();
  for (const auto& [lower_bound, e] : order) {
    if (lower_bound > best.distance) break;  // boxes hold their entity: nothing nearer beyond
    const CadPoint c = closest_point(dim, e, x);
    if (c.distance < best.distance) best = c;
  }
  return best;
}

namespace {

template <int Dim>
Vec<3> embed(const Vec<Dim>& x) {
  Vec<3> y = Vec<3>::Zero();
  for (int d = 0; d < Dim; ++d) y[d] = x[d];
  return y;
}

template <int Dim>
Vec<Dim> restrict_to(const Vec<3>& x) {
  return x.template head<Dim>();
}

// A vertex of a matched group on the CAD: the entities of the group within the tolerance, and
// in 3D the edges of those faces within it (seams, ridges, the borders with other groups).
struct VertexOnCad {
  std::vector<CadPoint> entities;
  std::vector<CadPoint> edges;
};

struct PointKey {
  std::array<double, 3> x;
  friend bool operator==(const PointKey& a, const PointKey& b) { return a.x == b.x; }
};
struct PointKeyHash {
  std::size_t operator()(const PointKey& k) const noexcept {
    std::size_t h = 0;
    for (const double v : k.x) {
      std::uint64_t bits = 0;
      std::memcpy(&bits, &v, sizeof bits);
      h ^= std::hash<std::uint64_t>{}(bits) + 0x9e3779b97f4a7c15ULL + (h << 6) + (h >> 2);
    }
    return h;
  }
};

VertexOnCad locate(const CadModel& model, const CadGroupMatch& match, const Vec<3>& x, double tolerance) {
  VertexOnCad v;
  v.entities = model.entities_within(match.dim, match.entities, x, tolerance);
  if (match.dim == 2) {
    std::vector<int> edges;
    for (const CadPoint& f : v.entities)
      for (const int e : model.face_edges(f.index))
        if (std::find(edges.begin(), edges.end(), e) == edges.end()) edges.push_back(e);
    if (!edges.empty()) v.edges = model.entities_within(1, edges, x, tolerance);
  }
  return v;
}

// Parameter `value` moved by whole periods next to `reference`.
double unwrap(double value, double reference, double period) {
  if (!(period > 0.0)) return value;
  return value + period * std::round((reference - value) / period);
}

// The point at fraction `t` of the arc length between two vertices along an edge of the
// model they share (their parameter range on it, unwrapped on a closed edge), or none.
bool along_common_edge(const CadModel& model, const std::vector<const std::vector<CadPoint>*>& ends, double t, Vec<3>& out) {
  for (const CadPoint& a : *ends[0]) {
    const auto b = std::find_if(ends[1]->begin(), ends[1]->end(), [&](const CadPoint& c) { return c.index == a.index; });
    if (b == ends[1]->end()) continue;
    // At equal lengths, not at equal parameters, which a CAD parametrization need not make
    // equal (Gmsh places them the same way).
    const double period = model.periods(1, a.index)[0];
    out = model.point_at(1, a.index, model.arc_length_parameter(a.index, a.u, unwrap(b->u, a.u, period), t));
    return true;
  }
  return false;
}

// The point at fraction `t` of the arc length between two vertices along an isoline of a face
// they share (one parameter equal once the other is unwrapped), when that point is within
// 1e-3 of their distance of `near` (the isoline is then the edge `near` lies on), or none.
std::optional<Vec<3>> along_common_isoline(const CadModel& model, const std::vector<const std::vector<CadPoint>*>& ends, double t,
                                           const Vec<3>& near) {
  for (const CadPoint& a : *ends[0]) {
    const auto b = std::find_if(ends[1]->begin(), ends[1]->end(), [&](const CadPoint& c) { return c.index == a.index; });
    if (b == ends[1]->end()) continue;
    const std::array<double, 2> period = model.periods(2, a.index);
    const std::array<double, 2> from{a.u, a.v}, to{unwrap(b->u, a.u, period[0]), unwrap(b->v, a.v, period[1])};
    for (int fixed = 0; fixed < 2; ++fixed) {
      const int moving = 1 - fixed;
      if (std::abs(to[fixed] - from[fixed]) > 1e-9 * (1.0 + std::abs(from[fixed])) || to[moving] == from[moving]) continue;
      std::array<double, 2> uv = from;
      uv[moving] = model.isoline_arc_length_parameter(a.index, fixed, from[fixed], from[moving], to[moving], t);
      const Vec<3> x = model.point_at(2, a.index, uv[0], uv[1]);
      if ((x - near).norm() <= 1e-3 * (b->point - a.point).norm()) return x;
    }
  }
  return std::nullopt;
}

// A vertex's place from the mesh file (an entity tag and parameters): the model's point there
// when the model has that entity and the point is within the tolerance of the vertex.
std::optional<CadPoint> from_file(const CadModel& model, const NodeParametrization& p, const Vec<3>& x, double tolerance) {
  if (p.entity_tag < 1 || p.entity_tag > (p.entity_dim == 2 ? model.num_faces() : model.num_edges())) return std::nullopt;
  CadPoint c;
  c.dim = p.entity_dim;
  c.index = p.entity_tag;
  c.u = p.u;
  c.v = p.v;
  c.point = model.point_at(c.dim, c.index, c.u, c.v);
  c.distance = (c.point - x).norm();
  if (!(c.distance <= tolerance)) return std::nullopt;
  return c;
}

// The closest point to x of a face every vertex lies on, searched from the vertices' weighted
// parameters there (unwrapped across a seam next to the first vertex's), or none.
std::optional<CadPoint> near_common_face(const CadModel& model, const std::vector<const std::vector<CadPoint>*>& vertices,
                                         const std::vector<double>& weights, const Vec<3>& x) {
  if (vertices.empty()) return std::nullopt;
  for (const CadPoint& first : *vertices[0]) {
    const std::array<double, 2> period = model.periods(2, first.index);
    double u = 0.0, v = 0.0, total = 0.0;
    bool shared = true;
    for (std::size_t k = 0; k < vertices.size() && shared; ++k) {
      const auto on = std::find_if(vertices[k]->begin(), vertices[k]->end(), [&](const CadPoint& c) { return c.index == first.index; });
      shared = on != vertices[k]->end();
      if (!shared) break;
      u += weights[k] * unwrap(on->u, first.u, period[0]);
      v += weights[k] * unwrap(on->v, first.v, period[1]);
      total += weights[k];
    }
    if (shared && total > 0.0) return model.closest_point_near(2, first.index, x, u / total, v / total);
  }
  return std::nullopt;
}

// The closest point to x of a face one of `vertices` lies on, within the tolerance, searched
// from that vertex's parameters there (a local search), or none.
std::optional<CadPoint> on_a_face(const CadModel& model, const std::vector<const VertexOnCad*>& vertices, const Vec<3>& x,
                                  double tolerance) {
  for (const VertexOnCad* vertex : vertices)
    for (const CadPoint& f : vertex->entities)
      if (const CadPoint p = model.closest_point_near(2, f.index, x, f.u, f.v); p.distance <= tolerance) return p;
  return std::nullopt;
}

}  // namespace

template <int Dim>
std::vector<CadGroupMatch> match_cad_groups(const Mesh<Dim>& mesh, const CadModel& model, double tolerance,
                                            const std::vector<std::string>& groups) {
  if (!(tolerance > 0.0)) tolerance = default_cad_tolerance(model);
  const int dim = Dim - 1;
  if ((dim == 2 ? model.num_faces() : model.num_edges()) == 0)
    throw InputError(model.file().string() + ": the model has no " + (dim == 2 ? "faces" : "edges") + " to match a " +
                     std::to_string(Dim) + "D mesh's groups to");
  // Facet tags without a group are groups named by their number, as in curve_mesh().
  std::vector<PhysicalGroup> all = mesh.groups;
  for (const auto& block : mesh.facets)
    for (const int tag : block.tags)
      if (tag != 0 && std::none_of(all.begin(), all.end(), [&](const PhysicalGroup& g) { return g.dim == Dim - 1 && g.tag == tag; }))
        all.push_back({Dim - 1, tag, std::to_string(tag)});
  std::vector<const PhysicalGroup*> wanted;
  for (const auto& name : groups) {
    const auto it = std::find_if(all.begin(), all.end(), [&](const PhysicalGroup& g) { return g.name == name; });
    if (it == all.end()) {
      std::string known;
      for (const auto& g : all) known += (known.empty() ? "" : ", ") + g.name;
      throw InputError("match_cad_groups: no group named '" + name + "' (groups: " + known + ")");
    }
    wanted.push_back(&*it);
  }
  if (groups.empty())
    for (const auto& g : all)
      if (g.dim == Dim - 1) wanted.push_back(&g);
  std::unordered_map<Index, std::vector<CadPoint>> on_cad;  // vertex → entities within the tolerance
  std::unordered_set<Index> file_placed;                     // vertices on_cad has from the file
  const auto is_from_file = [&](Index v) { return file_placed.count(v) > 0; };
  std::vector<CadGroupMatch> out;
  for (const PhysicalGroup* g : wanted) {
    if (g->dim != Dim - 1)
      throw InputError("match_cad_groups: group '" + g->name + "' has dimension " + std::to_string(g->dim) + " (expected " +
                       std::to_string(Dim - 1) + ")");
    CadGroupMatch m;
    m.group = g->name;
    m.dim = dim;
    std::set<int> entities;
    std::set<Index> counted;
    bool all_on = true;
    for (const auto& block : mesh.facets) {
      const int nv = num_vertices(block.type);
      for (Index e = 0; e < block.size() && all_on; ++e) {
        if (block.tags[static_cast<std::size_t>(e)] != g->tag) continue;
        const auto el = block.element(e);
        std::vector<int> common;
        for (int k = 0; k < nv && all_on; ++k) {
          const Index v = el[static_cast<std::size_t>(k)];
          auto it = on_cad.find(v);
          if (it == on_cad.end()) {
            const Vec<3> x = embed<Dim>(mesh.points.col(v));
            std::vector<CadPoint> near;
            if (!mesh.node_params.empty() && mesh.node_params[static_cast<std::size_t>(v)].entity_dim == dim) {
              if (const auto p = from_file(model, mesh.node_params[static_cast<std::size_t>(v)], x, tolerance)) {
                near.push_back(*p);
                file_placed.insert(v);
              } else {
                ++m.file_mismatches;
              }
            }
            if (near.empty()) near = model.entities_within(dim, {}, x, tolerance);
            it = on_cad.emplace(v, std::move(near)).first;
          }
          const std::vector<CadPoint>& near = it->second;
          if (near.empty()) {
            const CadPoint nearest = model.nearest(dim, {}, embed<Dim>(mesh.points.col(v)));
            m.max_distance = nearest.distance;
            m.farthest_node = v;
            all_on = false;
            break;
          }
          if (near.front().distance > m.max_distance) m.max_distance = near.front().distance, m.farthest_node = v;
          if (counted.insert(v).second) {
            ++m.vertices;
            if (is_from_file(v)) {
              ++m.by_file;
              m.located.emplace_back(embed<Dim>(mesh.points.col(v)), near.front());
            }
          }
          std::vector<int> ids;
          for (const CadPoint& c : near) ids.push_back(c.index);
          if (k == 0) {
            common = ids;
          } else {
            std::erase_if(common, [&](int id) { return std::find(ids.begin(), ids.end(), id) == ids.end(); });
          }
        }
        if (!all_on) break;
        if (!common.empty()) {
          entities.insert(common.begin(), common.end());
        } else {  // a facet across an edge of the model: each vertex's nearest entity
          for (int k = 0; k < nv; ++k) entities.insert(on_cad[el[static_cast<std::size_t>(k)]].front().index);
        }
      }
    }
    if (all_on) m.entities.assign(entities.begin(), entities.end());
    if (!m.matched() && !groups.empty()) {
      std::ostringstream msg;
      msg << model.file().string() << " does not fit group '" << g->name << "': ";
      if (m.farthest_node < 0) {
        msg << "the group has no facets";
      } else {
        const Vec<Dim> x = mesh.points.col(m.farthest_node);
        msg << "node " << m.farthest_node << " (file id " << mesh.node_id(m.farthest_node) << ") at (";
        for (int d = 0; d < Dim; ++d) msg << (d ? ", " : "") << x[d];
        msg << ") is " << m.max_distance << " from the model's nearest " << (dim == 2 ? "face" : "edge") << " (tolerance "
            << tolerance << ")";
      }
      throw InputError(msg.str());
    }
    out.push_back(std::move(m));
  }
  return out;
}

template <int Dim>
BoundaryGeometry<Dim> cad_boundary(const CadModel& model, const CadGroupMatch& match, double tolerance) {
  if (!match.matched()) throw InputError("cad_boundary: group '" + match.group + "' matched no CAD entity");
  if (!(tolerance > 0.0)) tolerance = default_cad_tolerance(model);
  const CadModel* cad = &model;
  auto project = [cad, match](const Vec<Dim>& x) { return restrict_to<Dim>(cad->nearest(match.dim, match.entities, embed<Dim>(x)).point); };
  auto cache = std::make_shared<std::unordered_map<PointKey, VertexOnCad, PointKeyHash>>();
  // A vertex the file places inside an entity is on that entity alone, and on none of its
  // edges (Gmsh gives a vertex on an edge the edge's tag).
  for (const auto& [x, on] : match.located) cache->emplace(PointKey{{x[0], x[1], x[2]}}, VertexOnCad{{on}, {}});
  // The places on the model of the vertices of nonzero weight (cached), and their weights.
  struct Located {
    std::vector<const std::vector<CadPoint>*> entities, edges;
    std::vector<double> weights;
  };
  auto locate_vertices = [cad, match, tolerance, cache](std::span<const Vec<Dim>> vertices, std::span<const double> weights) {
    Located out;
    for (std::size_t k = 0; k < vertices.size(); ++k) {
      if (std::abs(weights[k]) < 1e-12) continue;
      const Vec<3> x = embed<Dim>(vertices[k]);
      const PointKey key{{x[0], x[1], x[2]}};
      auto it = cache->find(key);
      if (it == cache->end()) it = cache->emplace(key, locate(*cad, match, x, tolerance)).first;
      out.entities.push_back(&it->second.entities);
      out.edges.push_back(&it->second.edges);
      out.weights.push_back(weights[k]);
    }
    return out;
  };
  // Inside a facet whose vertices share a face: the closest point of that face, searched from
  // their weighted parameters (a global search over the group's entities costs ~40 times more:
  // the sphere's geometric certificate took 6.2 s that way, 0.15 s this way).
  const int dim = match.dim;
  auto on_face = [cad, dim, project](const Located& on, const Vec<Dim>& x) {
    if (dim == 2)
      if (const auto p = near_common_face(*cad, on.entities, on.weights, embed<Dim>(x))) return restrict_to<Dim>(p->point);
    return project(x);
  };
  auto nearby = [locate_vertices, on_face](std::span<const Vec<Dim>> vertices, std::span<const double> weights, const Vec<Dim>& x) {
    return on_face(locate_vertices(vertices, weights), x);
  };
  auto place = [cad, dim, locate_vertices, on_face](std::span<const Vec<Dim>> vertices, std::span<const double> weights) {
    Vec<Dim> straight = Vec<Dim>::Zero();
    for (std::size_t k = 0; k < vertices.size(); ++k) straight += weights[k] * vertices[k];
    // Between two vertices on one edge of the model: along that edge (in 2D the group's own
    // entities are edges).
    const Located on = locate_vertices(vertices, weights);
    Vec<3> at;
    if (on.weights.size() == 2 && along_common_edge(*cad, dim == 1 ? on.entities : on.edges, on.weights[1], at)) {
      // On a face group, onto the face: an edge's curve may lie only within the model's
      // tolerance of it (IGES trims faces by curves in their parameters, and OpenCASCADE builds
      // the edge's 3D curve from them: a torus's seam nodes were 2e-6 off the torus). A point
      // already on the face to round-off stays as it is. Along an isoline of the face (a seam
      // is one), the node is where the exact edge would put it: the closest point of the face
      // to the rebuilt curve's point was 3e-7 along the seam from it.
      if (dim == 2)
        if (const auto p = near_common_face(*cad, on.entities, on.weights, at); p && (p->point - at).norm() > 1e-12 * cad->diagonal())
          at = along_common_isoline(*cad, on.entities, on.weights[1], at).value_or(p->point);
      return restrict_to<Dim>(at);
    }
    // Across a face (and inside one): the projection of the straight place, on the nearest
    // curve of the surface to the straight edge. A parameter line would follow the face's
    // parametrization instead: two vertices on one latitude of a sphere would be joined along
    // the latitude, not the great circle (0.21 against 0.30 at P2 on the sphere's STEP file).
    return on_face(on, straight);
  };
  return BoundaryGeometry<Dim>::project(project, place, nearby);
}

template <int Dim>
void place_on_cad(Mesh<Dim>& mesh, const CadModel& model, const std::vector<CadGroupMatch>& matches, double tolerance) {
  if (!(tolerance > 0.0)) tolerance = default_cad_tolerance(model);
  std::vector<NodeParametrization> out(static_cast<std::size_t>(mesh.num_nodes()), NodeParametrization{Dim, 1, 0.0, 0.0});
  for (auto& block : mesh.cells) {
    if (block.entities.empty()) block.entities.assign(static_cast<std::size_t>(block.size()), 1);
    for (Index e = 0; e < block.size(); ++e)
      if (const int entity = block.entities[static_cast<std::size_t>(e)]; entity != 0)
        for (const Index v : block.element(e)) out[static_cast<std::size_t>(v)].entity_tag = entity;
  }
  name_unnamed_facet_groups(mesh);  // the names match_cad_groups() gave them
  std::map<int, const CadGroupMatch*> match_of_tag;
  for (const CadGroupMatch& m : matches) {
    const auto group = std::find_if(mesh.groups.begin(), mesh.groups.end(),
                                    [&](const PhysicalGroup& g) { return g.dim == Dim - 1 && g.name == m.group; });
    if (m.matched() && group != mesh.groups.end()) match_of_tag[group->tag] = &m;
  }
  // A located node's entity: the model edge it lies on, else its face (in 2D, its edge).
  const auto set = [&](Index v, const VertexOnCad& on) {
    if (on.edges.empty() && on.entities.empty()) return;
    const CadPoint& at = !on.edges.empty() ? on.edges.front() : on.entities.front();
    out[static_cast<std::size_t>(v)] = NodeParametrization{at.dim, at.index, at.u, at.dim == 2 ? at.v : 0.0};
  };
  // The vertices are located by a global search, or a local one from a vertex of the same facet;
  // the other nodes of a facet from its vertices: on a model edge one of them lies on, else on
  // a face of theirs by a local search (the global search for every node took twice the
  // curving's time on the sphere at P3).
  std::unordered_map<Index, VertexOnCad> vertices;
  std::vector<char> done(static_cast<std::size_t>(mesh.num_nodes()), 0);
  for (auto& block : mesh.facets) {
    const auto nv = static_cast<std::size_t>(num_vertices(block.type));
    for (Index e = 0; e < block.size(); ++e) {
      const auto m = match_of_tag.find(block.tags[static_cast<std::size_t>(e)]);
      if (m == match_of_tag.end()) continue;
      const CadGroupMatch& match = *m->second;
      const auto el = block.element(e);
      // The vertices found before first: a face of theirs is searched locally for the others.
      std::vector<const VertexOnCad*> corner(nv, nullptr), found;
      for (std::size_t k = 0; k < nv; ++k)
        if (const auto it = vertices.find(el[k]); it != vertices.end()) found.push_back(corner[k] = &it->second);
      for (std::size_t k = 0; k < nv; ++k) {
        if (corner[k] != nullptr) continue;
        const Vec<3> x = embed<Dim>(mesh.points.col(el[k]));
        VertexOnCad on;
        if (const auto f = match.dim == 2 ? on_a_face(model, found, x, tolerance) : std::nullopt) {
          on.entities = {*f};
          on.edges = model.entities_within(1, model.face_edges(f->index), x, tolerance);
        } else {
          on = locate(model, match, x, tolerance);
        }
        found.push_back(corner[k] = &vertices.emplace(el[k], std::move(on)).first->second);
        set(el[k], *corner[k]);
      }
      // Model edges a vertex lies on (in 2D the group's own entities are edges). Not only those
      // two vertices share: a vertex at a model corner, located from one face, lists that
      // face's edges only.
      std::vector<int> edges;
      for (const VertexOnCad* c : corner)
        for (const CadPoint& p : match.dim == 1 ? c->entities : c->edges)
          if (std::find(edges.begin(), edges.end(), p.index) == edges.end()) edges.push_back(p.index);
      // The facet's entity: the face (2D: the edge) a node inside it, or all its vertices, lie on.
      int entity = 0;
      for (const CadPoint& f : corner[0]->entities)
        if (std::all_of(corner.begin(), corner.end(), [&](const VertexOnCad* c) {
              return std::any_of(c->entities.begin(), c->entities.end(), [&](const CadPoint& g) { return g.index == f.index; });
            }))
          entity = f.index;
      for (std::size_t k = nv; k < el.size(); ++k) {
        const Index v = el[k];
        if (std::exchange(done[static_cast<std::size_t>(v)], 1) == 0) {
          const Vec<3> x = embed<Dim>(mesh.points.col(v));
          VertexOnCad on;
          for (const int edge : edges)
            if (const CadPoint c = model.closest_point(1, edge, x); c.distance <= tolerance && (on.edges.empty() || c.distance < on.edges[0].distance))
              on.edges = {c};
          if (on.edges.empty() && match.dim == 2)
            if (const auto f = on_a_face(model, corner, x, tolerance)) on.entities = {*f};
          set(v, on.edges.empty() && on.entities.empty() ? locate(model, match, x, tolerance) : on);
        }
        if (const NodeParametrization& p = out[static_cast<std::size_t>(v)]; p.entity_dim == match.dim) entity = p.entity_tag;
      }
      if (entity != 0) {
        if (block.entities.empty()) block.entities.assign(static_cast<std::size_t>(block.size()), 0);
        block.entities[static_cast<std::size_t>(e)] = entity;
      }
    }
  }
  mesh.node_params = std::move(out);
}

template <int Dim>
void require_cad_fit(const Mesh<Dim>& mesh, const CadModel& model, const std::vector<CadGroupMatch>& matches) {
  if (std::any_of(matches.begin(), matches.end(), [](const CadGroupMatch& m) { return m.matched(); })) return;
  std::ostringstream msg;
  msg << model.file().string() << " fits no group of the mesh";
  const CadGroupMatch* closest = nullptr;
  for (const CadGroupMatch& m : matches)
    if (m.farthest_node >= 0 && (closest == nullptr || m.max_distance < closest->max_distance)) closest = &m;
  if (closest != nullptr)
    msg << " (closest: group '" << closest->group << "', whose node " << closest->farthest_node << " (file id "
        << mesh.node_id(closest->farthest_node) << ") is " << closest->max_distance << " from it)";
  if (mesh.num_nodes() > 0 && model.diagonal() > 0.0) {
    const double size = (mesh.points.rowwise().maxCoeff() - mesh.points.rowwise().minCoeff()).norm() / model.diagonal();
    msg << "; the mesh is " << size << " times the model's size";
    if (size > 10.0 || size < 0.1) msg << " (another unit of length?)";
  }
  msg << "; expected the vertices of at least one group on the model";
  throw InputError(msg.str());
}

std::string describe_cad_matches(const std::vector<CadGroupMatch>& matches) {
  std::ostringstream out;
  for (const CadGroupMatch& m : matches) {
    out << "group '" << m.group << "': ";
    if (m.matched()) {
      out << (m.dim == 2 ? "face" : "edge") << (m.entities.size() > 1 ? "s " : " ");
      for (std::size_t k = 0; k < m.entities.size(); ++k) out << (k ? ", " : "") << m.entities[k];
      out << " (vertices within " << m.max_distance;
      if (m.by_file > 0) out << "; " << m.by_file << " of " << m.vertices << " located by the file's entity tags and parameters";
      if (m.file_mismatches > 0)
        out << "; " << m.file_mismatches << " whose entity tag and parameters in the file do not fit the model, located by distance";
      out << ")\n";
    } else if (m.farthest_node >= 0) {
      out << "not on the model (node " << m.farthest_node << " is " << m.max_distance << " from it)\n";
    } else {
      out << "no facets\n";
    }
  }
  return out.str();
}

template <int Dim>
CadCurving geometry_on_cad(Mesh<Dim>& mesh, const CadModel& model, CurveOptions<Dim>& options, double tolerance,
                           const std::vector<std::string>& groups) {
  name_unnamed_facet_groups(mesh);  // the matches name groups by their tags
  CadCurving out{match_cad_groups(mesh, model, tolerance, groups), {}, {}};
  require_cad_fit(mesh, model, out.matches);
  // Snapping onto a plane moves nothing; projecting a far field's nodes and measuring its
  // facets took a third of a wing's run (benchmarks/wing_mesh.py) for no change.
  const std::set<int> planar = groups.empty() && options.slide_planar_groups ? planar_group_tags(mesh) : std::set<int>{};
  const auto flat = [&](const CadGroupMatch& m) {
    return std::all_of(m.entities.begin(), m.entities.end(), [&](int e) { return model.flat(m.dim, e); });
  };
  for (const CadGroupMatch& m : out.matches) {
    if (!m.matched() || planar.count(mesh.group(m.group).tag)) continue;
    if (groups.empty() && flat(m)) {
      options.geometry.insert_or_assign(m.group, BoundaryGeometry<Dim>::straight());
      continue;
    }
    options.geometry.insert_or_assign(m.group, cad_boundary<Dim>(model, m, tolerance));
    out.on_model.push_back(m.group);
  }
  out.report = describe_cad_matches(out.matches);
  return out;
}

template CadCurving geometry_on_cad<2>(Mesh<2>&, const CadModel&, CurveOptions<2>&, double, const std::vector<std::string>&);
template CadCurving geometry_on_cad<3>(Mesh<3>&, const CadModel&, CurveOptions<3>&, double, const std::vector<std::string>&);
template void require_cad_fit<2>(const Mesh<2>&, const CadModel&, const std::vector<CadGroupMatch>&);
template void require_cad_fit<3>(const Mesh<3>&, const CadModel&, const std::vector<CadGroupMatch>&);
template std::vector<CadGroupMatch> match_cad_groups<2>(const Mesh<2>&, const CadModel&, double, const std::vector<std::string>&);
template std::vector<CadGroupMatch> match_cad_groups<3>(const Mesh<3>&, const CadModel&, double, const std::vector<std::string>&);
template BoundaryGeometry<2> cad_boundary<2>(const CadModel&, const CadGroupMatch&, double);
template BoundaryGeometry<3> cad_boundary<3>(const CadModel&, const CadGroupMatch&, double);
template void place_on_cad<2>(Mesh<2>&, const CadModel&, const std::vector<CadGroupMatch>&, double);
template void place_on_cad<3>(Mesh<3>&, const CadModel&, const std::vector<CadGroupMatch>&, double);

}  // namespace meshmotion
