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
#include "meshmotion/io/mesh_io.hpp"
#include "meshmotion/movers/any_mover.hpp"
#include "meshmotion/movers/boundary.hpp"
#include "meshmotion/movers/mover_options.hpp"
#include "meshmotion/quality/quality_report.hpp"
#include "meshmotion/version.hpp"

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <cmath>
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
    for (py::ssize_t k = 0; k < a.ndim(); ++k) shape += (k ? ", " : "") + std::to_string(a.shape(k));
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
    known += (known.empty() ? "" : ", ") + std::string(name(type));
  }
  throw InputError("unknown element type '" + type_name + "' (expected one of " + known + ")");
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
            M& mesh = self.cast<M&>();
            py::list out;
            for (auto& b : mesh.cells) {
              const auto npc = static_cast<py::ssize_t>(b.nodes_per_element());
              out.append(py::make_tuple(std::string(name(b.type)),
                                        py::array_t<Index>({static_cast<py::ssize_t>(b.size()), npc},
                                                           {static_cast<py::ssize_t>(npc * sizeof(Index)),
                                                            static_cast<py::ssize_t>(sizeof(Index))},
                                                           b.connectivity.data(), self)));
            }
            return out;
          },
          "cell blocks as (type name, (n_cells, nodes_per_cell) int64 view) pairs")
      .def_property_readonly("groups",
                             [](const M& mesh) {
                               py::dict out;
                               for (const auto& g : mesh.groups)
                                 if (!g.name.empty()) out[py::str(g.name)] = py::cast(mesh.group_nodes(g.name));
                               return out;
                             },
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
          int tag = 0;
          for (const auto& [group, type_name, a] : groups) {
            if (dimension(element_type_named(type_name)) != Dim - 1)
              throw InputError("from_arrays: group '" + group + "': " + type_name + " is not a facet type of a " +
                               std::to_string(Dim) + "D mesh");
            add(type_name, a, ++tag, "group");
            mesh.groups.push_back({Dim - 1, tag, group});
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
           [](A& a, const py::array& w) { return to_rows<Dim>(a.derivative_forward(Points<Dim>(rows_of<Dim>(w, "derivative_forward: w")))); },
           py::arg("w"))
      .def("derivative_reverse",
           [](A& a, const py::array& v) { return to_rows<Dim>(a.derivative_reverse(Points<Dim>(rows_of<Dim>(v, "derivative_reverse: v")))); },
           py::arg("v"));

  m.def("quality_report",
        [](const M& mesh, const std::string& metric) { return report_dict(quality_report(mesh, metric_from_name(metric))); },
        py::arg("mesh"), py::arg("metric") = "jacobian");
  m.def("write_mesh", [](const std::filesystem::path& file, const M& mesh) { write_mesh(file, mesh); }, py::arg("file"),
        py::arg("mesh"));
}

}  // namespace

PYBIND11_MODULE(_core, m) {
  m.doc() = "meshmotion's compiled core (use the meshmotion package)";
  m.attr("__version__") = MESHMOTION_VERSION_STRING;

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
  m.def("set_num_threads", &set_num_threads, py::arg("n"));
  m.def("num_threads", &num_threads);
}
