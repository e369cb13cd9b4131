// The Python module meshmotion._core: meshes as numpy views, movers by name with typed keyword
// options, boundaries by group, derivatives, quality reports. The pure-Python package
// (python/meshmotion/) builds the user-facing API on it.
//
// Layout: a Mesh<Dim> stores its points Dim × n column-major, which is the memory of a C-order
// (n, Dim) array: `points` is that array, a view on the mesh (no copy), kept alive by it.
// Arrays from Python are taken without a copy when they are C-contiguous float64 of the right
// shape; anything else is refused with the shape and dtype expected.

#include "meshmotion/core/json.hpp"
#include "meshmotion/core/mesh.hpp"
#include "meshmotion/core/option_text.hpp"
#include "meshmotion/core/orientation.hpp"
#include "meshmotion/core/threads.hpp"
#include "meshmotion/curving/curve_mesh.hpp"
#include "meshmotion/curving/geometry_text.hpp"
#include "meshmotion/io/mesh_io.hpp"
#include "meshmotion/movers/any_mover.hpp"
#include "meshmotion/movers/boundary.hpp"
#include "meshmotion/movers/mover_options.hpp"
#include "meshmotion/quality/cell_quality.hpp"
#include "meshmotion/quality/quality_report.hpp"
#include "meshmotion/version.hpp"

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <cmath>
#include <map>
#include <string>
#include <vector>

namespace py = pybind11;
using namespace meshmotion;

namespace {

using Float = py::array_t<double, py::array::c_style | py::array::forcecast>;

// Python's repr of a float is its shortest round-trip text, which the library's parser reads
// back exactly; sequences become comma-separated lists.
std::string option_text(const std::string& key, const py::handle& value) {
  if (py::isinstance<py::bool_>(value)) return value.cast<bool>() ? "true" : "false";
  if (py::isinstance<py::str>(value)) return value.cast<std::string>();
  if (py::isinstance<py::int_>(value) || py::isinstance<py::float_>(value)) return py::repr(value).cast<std::string>();
  if (value.is_none()) return "none";
  if (py::isinstance<py::sequence>(value) || py::isinstance<py::array>(value)) {
    std::string out;
    for (const py::handle item : value) {
      if (!out.empty()) out += ',';
      out += py::repr(py::float_(py::reinterpret_borrow<py::object>(item))).cast<std::string>();
    }
    return out;
  }
  throw InputError("option '" + key + "': expected a number, a string, a bool or a sequence of numbers (got " +
                   py::repr(py::type::of(value)).cast<std::string>() + ")");
}

// A C-contiguous float64 array of shape (rows, Dim), without a copy; refused otherwise.
template <int Dim>
Eigen::Map<const Points<Dim>> rows_of(const py::array& a, const char* what, Index rows = -1) {
  const bool float64 = py::isinstance<py::array_t<double>>(a);
  const bool contiguous = (a.flags() & py::array::c_style) != 0;
  if (!float64 || !contiguous || a.ndim() != 2 || a.shape(1) != Dim || (rows >= 0 && a.shape(0) != rows)) {
    std::string shape = "(";
    for (py::ssize_t k = 0; k < a.ndim(); ++k) {
      if (k > 0) shape += ", ";
      shape += std::to_string(a.shape(k));
    }
    throw InputError(std::string(what) + ": expected a C-contiguous float64 array of shape (" +
                     (rows >= 0 ? std::to_string(rows) : std::string("n")) + ", " + std::to_string(Dim) + ") (got " +
                     py::str(a.dtype()).cast<std::string>() + ", shape " + shape + ")" +
                     (contiguous ? "" : ", not C-contiguous") + ")");
  }
  return {static_cast<const double*>(a.data()), Dim, static_cast<Index>(a.shape(0))};
}

template <int Dim>
py::array_t<double> to_rows(Points<Dim> p) {
  auto* owner = new Points<Dim>(std::move(p));
  py::capsule free_when_done(owner, [](void* q) { delete static_cast<Points<Dim>*>(q); });
  return py::array_t<double>({static_cast<py::ssize_t>(owner->cols()), static_cast<py::ssize_t>(Dim)},
                             {static_cast<py::ssize_t>(Dim * sizeof(double)), static_cast<py::ssize_t>(sizeof(double))},
                             owner->data(), free_when_done);
}

py::dict report_dict(const QualityReport& r);

// The per-cell values and validity (cell order) beside the report's summary.
template <int Dim>
py::dict quality_dict(const Mesh<Dim>& mesh, Metric metric) {
  const std::vector<CellQuality> cells = evaluate_cells(mesh, metric);
  py::dict d = report_dict(make_report(mesh, metric, cells));
  py::array_t<double> values(static_cast<py::ssize_t>(cells.size()));
  py::array_t<bool> valid(static_cast<py::ssize_t>(cells.size()));
  auto v = values.mutable_unchecked<1>();
  auto ok = valid.mutable_unchecked<1>();
  for (std::size_t c = 0; c < cells.size(); ++c) {
    v(static_cast<py::ssize_t>(c)) = cells[c].value;
    ok(static_cast<py::ssize_t>(c)) = cells[c].valid;
  }
  d["values"] = values;
  d["valid"] = valid;
  return d;
}

py::dict report_dict(const QualityReport& r) {
  py::dict d;
  d["metric"] = std::string(metric_name(r.metric));
  d["elements"] = r.num_elements;
  d["min"] = r.min;
  d["max"] = r.max;
  d["mean"] = r.mean;
  d["invalid"] = r.num_invalid;
  d["histogram"] = r.histogram;
  py::list worst;
  for (const auto& w : r.worst) {
    py::dict e;
    e["id"] = w.id;
    e["file_id"] = w.file_id;
    e["type"] = std::string(name(w.type));
    e["value"] = w.value;
    worst.append(e);
  }
  d["worst"] = worst;
  return d;
}

py::dict stats_dict(const MoverStats& s) {
  py::dict d;
  d["setup_seconds"] = s.setup_seconds;
  d["move_seconds"] = s.move_seconds;
  d["moves"] = s.moves;
  d["factorizations"] = s.factorizations;
  d["iterations"] = s.iterations;
  d["residual"] = s.residual;
  d["fell_back"] = s.fell_back;
  d["boundary_nodes"] = s.boundary_nodes;
  d["evaluated_nodes"] = s.evaluated_nodes;
  d["nonzeros"] = s.nonzeros;
  return d;
}

ElementType element_type_named(const std::string& type_name) {
  std::string known;
  for (int t = 0; t < num_element_types; ++t) {
    const auto type = static_cast<ElementType>(t);
    if (name(type) == type_name) return type;
    if (!known.empty()) known += ", ";
    known += name(type);
  }
  throw InputError("unknown element type '" + type_name + "' (expected one of " + known + ")");
}

// The connectivity of a block as an (n_cells, nodes_per_cell) int64 view kept alive by `owner`.
py::array_t<Index> connectivity_view(ElementBlock& b, const py::object& owner) {
  const auto npc = static_cast<py::ssize_t>(b.nodes_per_element());
  return py::array_t<Index>({static_cast<py::ssize_t>(b.size()), npc},
                            {static_cast<py::ssize_t>(npc * sizeof(Index)), static_cast<py::ssize_t>(sizeof(Index))},
                            b.connectivity.data(), owner);
}

// {name: value(group)} over the named groups of a mesh.
template <int Dim, class Value>
py::dict by_group(const Mesh<Dim>& mesh, Value&& value) {
  py::dict out;
  for (const auto& g : mesh.groups)
    if (!g.name.empty()) out[py::str(g.name)] = value(g);
  return out;
}

// Python number → double, refusing anything else (a bool, a string) with the key's name.
double number_option(const std::string& key, const py::handle& value) {
  if (py::isinstance<py::bool_>(value) || !(py::isinstance<py::int_>(value) || py::isinstance<py::float_>(value)))
    throw InputError("curve_mesh: option '" + key + "' expects a number (got " + py::repr(value).cast<std::string>() + ")");
  return value.cast<double>();
}

std::string text_option(const std::string& key, const py::handle& value) {
  if (!py::isinstance<py::str>(value))
    throw InputError("curve_mesh: option '" + key + "' expects a string (got " + py::repr(value).cast<std::string>() + ")");
  return value.cast<std::string>();
}

bool bool_option(const std::string& key, const py::handle& value) {
  if (!py::isinstance<py::bool_>(value))
    throw InputError("curve_mesh: option '" + key + "' expects True or False (got " + py::repr(value).cast<std::string>() + ")");
  return value.cast<bool>();
}

// curve_mesh's keywords: the pipeline's own (CurveOptions) by name, every other one a typed
// option of the mover, checked by the library's parser.
template <int Dim>
CurveOptions<Dim> curve_options(const py::kwargs& kwargs) {
  CurveOptions<Dim> o;
  KeyValues mover;
  const std::map<std::string, double*> numbers{
      {"support_radius", &o.support_radius},         {"support_radius_factor", &o.support_radius_factor},
      {"active_radius_factor", &o.active_radius_factor}, {"max_support_nodes", &o.max_support_nodes},
      {"centre_reach", &o.centre_reach},             {"blending_length", &o.blending_length},
      {"blending_factor", &o.blending_factor},       {"corner_angle", &o.snap.corner_angle},
      {"untangle_threshold", &o.untangle.threshold}};
  const std::map<std::string, bool*> flags{{"per_wall_radius", &o.per_wall_radius},
                                           {"spline_by_default", &o.spline_by_default},
                                           {"strict", &o.strict},
                                           {"untangle", &o.untangle.enabled},
                                           {"inner_nodes", &o.inner_nodes}};
  for (const auto& [key_handle, value] : kwargs) {
    const auto key = py::cast<std::string>(key_handle);
    if (const auto n = numbers.find(key); n != numbers.end()) {
      *n->second = number_option(key, value);
    } else if (const auto f = flags.find(key); f != flags.end()) {
      *f->second = bool_option(key, value);
    } else if (key == "method") {
      o.method = text_option(key, value);
    } else if (key == "order") {
      const double order = number_option(key, value);
      if (order != std::floor(order) || order < 2 || order > max_element_order)
        throw InputError("curve_mesh: option 'order' expects 2, 3 or 4 (got " + py::cast<std::string>(py::repr(value)) + ")");
      o.order = static_cast<int>(order);
    } else if (key == "steps") {
      const double steps = number_option(key, value);
      if (!(steps >= 1.0) || steps != std::floor(steps) || steps > 1e6)
        throw InputError("curve_mesh: option 'steps' expects a positive integer (got " + py::cast<std::string>(py::repr(value)) + ")");
      o.steps = static_cast<int>(steps);
    } else if (key == "raise_rounds") {
      const double rounds = number_option(key, value);
      if (!(rounds >= 0.0) || rounds != std::floor(rounds) || rounds > 1e6)
        throw InputError("curve_mesh: option 'raise_rounds' expects an integer >= 0 (got " + py::cast<std::string>(py::repr(value)) + ")");
      o.untangle.raise_rounds = static_cast<int>(rounds);
    } else if (key == "sliding") {
      if (py::isinstance<py::str>(value) || !py::isinstance<py::sequence>(value))
        throw InputError("curve_mesh: option 'sliding' expects a list of group names (got " +
                         py::cast<std::string>(py::repr(value)) + ")");
      for (const auto group : py::cast<py::sequence>(value)) o.sliding.push_back(text_option("sliding", group));
    } else if (key == "geometry") {
      if (!py::isinstance<py::dict>(value))
        throw InputError("curve_mesh: option 'geometry' expects a dict {group: geometry text} (got " +
                         py::cast<std::string>(py::repr(value)) + ")");
      for (const auto& [group, spec] : py::cast<py::dict>(value))
        o.geometry.insert_or_assign(text_option("geometry", group), geometry_from_text<Dim>(text_option("geometry", spec)));
    } else {
      mover.emplace_back(key, option_text(key, value));
    }
  }
  if (o.method == "blend" || o.method == "none") {
    if (!mover.empty()) {
      std::vector<std::string> known{"method", "order", "steps", "raise_rounds", "sliding", "geometry"};
      for (const auto& entry : numbers) known.push_back(entry.first);
      for (const auto& entry : flags) known.push_back(entry.first);
      throw InputError("curve_mesh: " + unknown_key_message("method '" + o.method + "' (it takes no mover option)", mover.front().first, known));
    }
  } else {
    o.mover_options = mover_config<Dim>(o.method, mover).options;
  }
  return o;
}

template <int Dim>
py::dict curve_report(const CurveResult<Dim>& r) {
  py::dict d;
  d["method"] = r.method;
  d["num_linear_nodes"] = r.num_linear_nodes;
  d["support_radius"] = r.support_radius;
  d["wall_support_radii"] = r.wall_support_radii;
  d["snapped_nodes"] = r.snapped_nodes;
  d["moved_vertices"] = r.moved_vertices;
  d["max_boundary_displacement"] = r.max_boundary_displacement;
  d["moved_nodes"] = r.moved_nodes;
  d["solver_iterations"] = r.solver_iterations;
  d["invalid"] = r.invalid();
  d["quality"] = report_dict(r.quality);
  py::dict seconds;
  seconds["quadratic"] = r.seconds.quadratic;
  seconds["snap"] = r.seconds.snap;
  seconds["layer"] = r.seconds.layer;
  seconds["regularize"] = r.seconds.regularize;
  seconds["certify"] = r.seconds.certify;
  seconds["untangle"] = r.seconds.untangle;
  seconds["total"] = r.seconds.total;
  d["seconds"] = seconds;
  py::dict untangled;
  untangled["cells_below"] = r.untangle.cells_below;
  untangled["invalid_before"] = r.untangle.invalid_before;
  untangled["invalid_after"] = r.untangle.invalid_after;
  untangled["min_before"] = r.untangle.min_before;
  untangled["min_after"] = r.untangle.min_after;
  untangled["patch_cells"] = r.untangle.patch_cells;
  untangled["free_nodes"] = r.untangle.free_nodes;
  untangled["sweeps"] = r.untangle.sweeps;
  untangled["raise_rounds"] = r.untangle.raise_rounds;
  d["untangle"] = untangled;
  return d;
}

template <int Dim>
void bind_dimension(py::module_& m) {
  const std::string suffix = std::to_string(Dim);
  using M = Mesh<Dim>;
  py::class_<M>(m, ("Mesh" + suffix).c_str(), "An unstructured mixed-element mesh (points as an (n, dim) view)")
      .def_property_readonly_static("dim", [](const py::object&) { return Dim; })
      .def_property(
          "points",
          [](py::object self) {
            M& mesh = self.cast<M&>();
            return py::array_t<double>({static_cast<py::ssize_t>(mesh.num_nodes()), static_cast<py::ssize_t>(Dim)},
                                       {static_cast<py::ssize_t>(Dim * sizeof(double)), static_cast<py::ssize_t>(sizeof(double))},
                                       mesh.points.data(), self);
          },
          [](M& mesh, const py::array& a) {
            mesh.points = rows_of<Dim>(a, "Mesh.points", mesh.num_nodes());
            if (!mesh.points.allFinite()) throw InputError("Mesh.points: a coordinate is not finite");
          },
          "(n, dim) float64 view of the coordinates (no copy; writing into it moves the mesh)")
      .def_property_readonly("num_nodes", &M::num_nodes)
      .def_property_readonly("num_cells", &M::num_cells)
      .def_property_readonly(
          "cells",
          [](py::object self) {
            py::list out;
            for (auto& b : self.cast<M&>().cells) out.append(py::make_tuple(std::string(name(b.type)), connectivity_view(b, self)));
            return out;
          },
          "cell blocks as (type name, (n_cells, nodes_per_cell) int64 view) pairs")
      .def_property_readonly(
          "facets",
          [](py::object self) {
            py::list out;
            for (auto& b : self.cast<M&>().facets)
              out.append(py::make_tuple(std::string(name(b.type)), connectivity_view(b, self), py::array(py::cast(b.tags))));
            return out;
          },
          "boundary facet blocks as (type name, (n_facets, nodes_per_facet) int64 view, group tag per facet)")
      .def_property_readonly(
          "group_tags", [](const M& mesh) { return by_group(mesh, [](const PhysicalGroup& g) { return py::make_tuple(g.dim, g.tag); }); },
          "named groups: name → (dimension, tag) of the blocks' tags")
      .def_property_readonly(
          "groups", [](const M& mesh) { return by_group(mesh, [&](const PhysicalGroup& g) { return py::cast(mesh.group_nodes(g.name)); }); },
          "named groups: name → sorted node indices (0-based)")
      .def("group_nodes", [](const M& mesh, const std::string& g) { return mesh.group_nodes(g); }, py::arg("group"))
      .def("node_indices", [](const M& mesh, const std::vector<std::int64_t>& ids) { return mesh.node_indices(ids); },
           py::arg("file_ids"), "node indices of the file's node ids")
      .def("orient", [](M& mesh) { return std::string(name(orient_consistently(mesh).found)); },
           "mirror a consistently reversed mesh; returns what was found: positive, reversed or mixed")
      .def("copy", [](const M& mesh) { return M(mesh); })
      .def("__repr__", [suffix](const M& mesh) {
        return "<meshmotion.Mesh" + suffix + ": " + std::to_string(mesh.num_nodes()) + " nodes, " +
               std::to_string(mesh.num_cells()) + " cells>";
      });

  m.def(("_from_arrays" + suffix).c_str(),
        [](const py::array& points, const std::vector<std::pair<std::string, py::array_t<Index, py::array::c_style | py::array::forcecast>>>& cells,
           const std::vector<std::tuple<std::string, std::string, py::array_t<Index, py::array::c_style | py::array::forcecast>>>& groups) {
          M mesh;
          mesh.points = rows_of<Dim>(points, "from_arrays: points");
          const auto add = [&](const std::string& type_name, const py::array_t<Index, py::array::c_style | py::array::forcecast>& a,
                               int tag, const char* what) {
            const ElementType type = element_type_named(type_name);
            if (a.ndim() != 2 || a.shape(1) != num_nodes(type))
              throw InputError(std::string("from_arrays: ") + what + " block " + type_name + ": expected shape (n, " +
                               std::to_string(num_nodes(type)) + ")");
            ElementBlock& b = mesh.block(type);
            b.connectivity.insert(b.connectivity.end(), a.data(), a.data() + a.size());
            b.tags.insert(b.tags.end(), static_cast<std::size_t>(a.shape(0)), tag);
          };
          for (const auto& [type_name, a] : cells) add(type_name, a, 0, "cell");
          // A group given as several facet blocks (triangles and quadrilaterals) keeps one tag.
          std::map<std::string, int> tag_of;
          for (const auto& [group, type_name, a] : groups) {
            if (dimension(element_type_named(type_name)) != Dim - 1)
              throw InputError("from_arrays: group '" + group + "': " + type_name + " is not a facet type of a " +
                               std::to_string(Dim) + "D mesh");
            const auto [it, added] = tag_of.try_emplace(group, static_cast<int>(tag_of.size()) + 1);
            add(type_name, a, it->second, "group");
            if (added) mesh.groups.push_back({Dim - 1, it->second, group});
          }
          validate(mesh);
          return mesh;
        });

  using B = ResolvedBoundary<Dim>;
  py::class_<B>(m, ("ResolvedBoundary" + suffix).c_str(), "a boundary resolved to nodes: move()'s input has one row per node")
      .def_property_readonly("nodes", [](const B& b) { return b.nodes; })
      .def_property_readonly("size", &B::size)
      .def_property_readonly("kinds",
                             [](const B& b) {
                               std::vector<std::string> out;
                               for (const auto k : b.kinds)
                                 out.emplace_back(k == BoundaryKind::prescribed ? "prescribed"
                                                  : k == BoundaryKind::fixed    ? "fixed"
                                                                                : "sliding");
                               return out;
                             })
      .def_property_readonly("displacements", [](const B& b) { return to_rows<Dim>(b.displacements); })
      .def("column", &B::column, py::arg("node"))
      .def(
          "scatter",
          [](const B& b, const std::vector<Index>& nodes, const py::array& values, py::array& d) {
            Points<Dim> out = rows_of<Dim>(d, "scatter: d", b.size());
            b.scatter(nodes, Points<Dim>(rows_of<Dim>(values, "scatter: values", static_cast<Index>(nodes.size()))), out);
            std::copy(out.data(), out.data() + out.size(), static_cast<double*>(d.mutable_data()));
          },
          py::arg("nodes"), py::arg("values"), py::arg("d"), "write values (one row per node) into d's rows of those nodes");

  using S = BoundarySpec<Dim>;
  py::class_<S>(m, ("BoundarySpec" + suffix).c_str())
      .def(py::init<>())
      .def("moving",
           [](S& s, const std::string& g, const std::vector<Index>& nodes, const py::array& d) -> S& {
             return s.moving(g, nodes, Points<Dim>(rows_of<Dim>(d, "moving: displacements", static_cast<Index>(nodes.size()))));
           },
           py::arg("group"), py::arg("nodes"), py::arg("displacements"), py::return_value_policy::reference_internal)
      .def("translating",
           [](S& s, const std::string& g, const std::vector<double>& t) -> S& {
             if (static_cast<int>(t.size()) != Dim) throw InputError("translating: expected " + std::to_string(Dim) + " numbers");
             return s.moving(g, Translation<Dim>{Eigen::Map<const Vec<Dim>>(t.data())});
           },
           py::arg("group"), py::arg("translation"), py::return_value_policy::reference_internal)
      .def("prescribed", &S::prescribed, py::arg("group"), py::return_value_policy::reference_internal)
      .def("fixed", &S::fixed, py::arg("group"), py::return_value_policy::reference_internal)
      .def("sliding", [](S& s, const std::string& g) -> S& { return s.sliding(g); }, py::arg("group"),
           py::return_value_policy::reference_internal)
      .def("resolve", [](const S& s, const M& mesh) { return s.resolve(mesh); }, py::arg("mesh"))
      .def("resolve_nodes",
           [](const S& s, const py::array& points, const std::map<std::string, std::vector<Index>>& groups) {
             GroupNodes nodes(groups.begin(), groups.end());
             return s.resolve(Points<Dim>(rows_of<Dim>(points, "resolve_nodes: points")), nodes);
           },
           py::arg("points"), py::arg("groups"));

  using A = AnyMover<Dim>;
  py::class_<A>(m, ("Mover" + suffix).c_str())
      .def(py::init([](const std::string& method, const py::kwargs& options) {
             MoverConfig<Dim> c = mover_config<Dim>(method);
             for (const auto& [key, value] : options) {
               const std::string k = key.template cast<std::string>();
               c.set(k, option_text(k, value));
             }
             return make_mover(c);
           }),
           py::arg("method"))
      .def("setup", [](A& a, const M& mesh, const B& b) { a.setup(mesh, b); }, py::arg("mesh"), py::arg("boundary"),
           py::call_guard<py::gil_scoped_release>())
      .def("move",
           [](A& a, const py::array& d) {
             const Points<Dim> in = rows_of<Dim>(d, "move: displacements");
             Points<Dim> out;
             {
               py::gil_scoped_release release;
               a.move_into(in, out);
             }
             return to_rows<Dim>(std::move(out));
           },
           py::arg("displacements"), "node displacements (n, dim) for boundary displacements (boundary size, dim)")
      .def("move_into",
           [](A& a, const py::array& d, py::array& out) {
             const Points<Dim> in = rows_of<Dim>(d, "move_into: displacements");
             (void)rows_of<Dim>(out, "move_into: out");
             if (!out.writeable()) throw InputError("move_into: out is read-only");
             Eigen::Map<Points<Dim>> target(static_cast<double*>(out.mutable_data()), Dim, static_cast<Index>(out.shape(0)));
             py::gil_scoped_release release;
             a.move_into(in, target);
           },
           py::arg("displacements"), py::arg("out"), "move() into a caller's (n, dim) C-contiguous float64 array")
      .def_property_readonly("stats", [](const A& a) { return stats_dict(a.stats()); })
      .def_property_readonly("has_derivatives", &A::has_derivatives)
      .def("derivative_forward",
           [](A& a, const py::array& w) {
             const Points<Dim> in = rows_of<Dim>(w, "derivative_forward: w");
             Points<Dim> out;
             {
               py::gil_scoped_release release;
               out = a.derivative_forward(in);
             }
             return to_rows<Dim>(std::move(out));
           },
           py::arg("w"), "J w: node displacement changes (n, dim) for boundary changes w (boundary size, dim)")
      .def("derivative_reverse",
           [](A& a, const py::array& v) {
             // v is read in place (no copy of the (n, dim) seed).
             const Eigen::Map<const Points<Dim>> seed = rows_of<Dim>(v, "derivative_reverse: v");
             Points<Dim> out;
             {
               py::gil_scoped_release release;
               out = a.derivative_reverse(seed);
             }
             return to_rows<Dim>(std::move(out));
           },
           py::arg("v"), "Jᵀ v: the gradient (boundary size, dim) of <v, move(d)> for v (n, dim)");

  m.def("quality_report", [](const M& mesh, const std::string& metric) { return quality_dict(mesh, metric_from_name(metric)); },
        py::arg("mesh"), py::arg("metric") = "jacobian");
  m.def(
      "curve_mesh",
      [](const M& mesh, const py::kwargs& kwargs) {
        const CurveOptions<Dim> options = curve_options<Dim>(kwargs);
        CurveResult<Dim> result;
        {
          py::gil_scoped_release release;
          result = curve_mesh(mesh, options);
        }
        py::dict report = curve_report(result);
        return py::make_tuple(py::cast(std::move(result.curved)), report);
      },
      py::arg("mesh"));
  m.def("write_mesh", [](const std::filesystem::path& file, const M& mesh) { write_mesh(file, mesh); }, py::arg("file"),
        py::arg("mesh"));
}

}  // namespace

PYBIND11_MODULE(_core, m) {
  m.doc() = "meshmotion's compiled core (use the meshmotion package)";
  m.attr("__version__") = MESHMOTION_VERSION_STRING;
  m.attr("have_cgns") = have_cgns;  // read_mesh/write_mesh take .cgns

  // The C++ hierarchy as Python exceptions with the same messages.
  static py::exception<Error> error(m, "Error", PyExc_RuntimeError);
  static py::exception<InputError> input_error(m, "InputError", PyExc_ValueError);
  static py::exception<IoError> io_error(m, "IoError", PyExc_OSError);
  static py::exception<SolverError> solver_error(m, "SolverError", PyExc_RuntimeError);
  static py::exception<InvalidMeshError> invalid_mesh_error(m, "InvalidMeshError", PyExc_RuntimeError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const InputError& e) {
      input_error(e.what());
    } catch (const IoError& e) {
      io_error(e.what());
    } catch (const SolverError& e) {
      solver_error(e.what());
    } catch (const InvalidMeshError& e) {
      invalid_mesh_error(e.what());
    } catch (const Error& e) {
      error(e.what());
    }
  });

  bind_dimension<2>(m);
  bind_dimension<3>(m);

  m.def(
      "read_mesh",
      [](const std::filesystem::path& file, const std::string& orientation) -> py::object {
        ReadOptions o;
        if (orientation == "fix_reversed") o.orientation = ReadOrientation::fix_reversed;
        else if (orientation == "require_positive") o.orientation = ReadOrientation::require_positive;
        else if (orientation != "keep")
          throw InputError("read_mesh: orientation must be keep, fix_reversed or require_positive (got '" + orientation + "')");
        AnyMesh mesh = read_mesh(file, o);
        if (auto* m2 = std::get_if<Mesh<2>>(&mesh)) return py::cast(std::move(*m2));
        return py::cast(std::move(std::get<Mesh<3>>(mesh)));
      },
      py::arg("file"), py::arg("orientation") = "keep");
  m.def("mover_methods", [] {
    std::vector<std::string> out;
    for (const auto& method : mover_methods<3>()) out.emplace_back(method.name);
    return out;
  });
  m.def("mover_options", [](const std::string& method, int dim) {
    return dim == 2 ? mover_config<2>(method).values() : mover_config<3>(method).values();
  }, py::arg("method"), py::arg("dim") = 3, "the keys of a method with their default values (as text)");
  m.def(
      "vtk_order",
      [](const std::string& type_name, bool lagrange) {
        const auto order = vtk_order(element_type_named(type_name), lagrange);
        return std::vector<int>(order.begin(), order.end());
      },
      py::arg("type"), py::arg("lagrange") = false,
      "VTK's node i is our local node order[i] (classic VTK cells, or VTK's Lagrange cells with lagrange=True "
      "and past order 2); empty: the same order");
  m.def(
      "reference_nodes",
      [](const std::string& type_name) {
        const auto nodes = reference_nodes(element_type_named(type_name));
        py::array_t<double> out({static_cast<py::ssize_t>(nodes.size()), py::ssize_t{3}});
        auto view = out.mutable_unchecked<2>();
        for (std::size_t i = 0; i < nodes.size(); ++i)
          for (std::size_t d = 0; d < 3; ++d) view(static_cast<py::ssize_t>(i), static_cast<py::ssize_t>(d)) = nodes[i][d];
        return out;
      },
      py::arg("type"), "reference coordinates of the nodes of an element type, in the library's (Gmsh's) order: (n, 3)");
  m.def("element_types", [] {
    std::vector<std::string> out;
    for (int t = 0; t < num_element_types; ++t) out.emplace_back(name(static_cast<ElementType>(t)));
    return out;
  });
  m.def("set_num_threads", &set_num_threads, py::arg("n"));
  m.def("num_threads", &num_threads);
}
