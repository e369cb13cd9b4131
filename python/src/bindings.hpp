#pragma once
// What every file of the Python module shares: numpy arrays without a copy, option values as
// the library's text, reports as dicts, and the bind_* function of each file.
//
// Layout: a Mesh<Dim> stores its points Dim × n column-major, which is the memory of a C-order
// (n, Dim) array: `points` is that array, a view on the mesh (no copy), kept alive by it.
// Arrays from Python are taken without a copy when they are C-contiguous float64 of the right
// shape; anything else is refused with the shape and dtype expected.

#include "meshmotion/core/element.hpp"
#include "meshmotion/core/error.hpp"
#include "meshmotion/core/fields.hpp"
#include "meshmotion/core/mesh.hpp"
#include "meshmotion/core/option_text.hpp"
#include "meshmotion/core/types.hpp"

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace meshmotion::python {

namespace py = pybind11;

// Python's repr of a float is its shortest round-trip text, which the library's parser reads
// back exactly; sequences become comma-separated lists.
inline std::string option_text(const std::string& key, const py::handle& value) {
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

// A sequence of names as the parser's comma-separated text.
inline std::string names_text(const py::handle& value) {
  std::string out;
  for (const py::handle item : value) {
    if (!py::isinstance<py::str>(item))
      throw InputError("expected a list of names (got " + py::repr(value).cast<std::string>() + ")");
    if (!out.empty()) out += ',';
    out += item.cast<std::string>();
  }
  return out;
}

// A keyword's value as option text, by the type its description gives (`docs`, the keys the
// receiver takes): a list of names must be a sequence of str (a lone str is a mistake, not a
// list of one), integers a sequence of int, a choice or a text a str; a key without a
// description goes as it is and the parser names the known keys.
inline std::string option_text(const std::vector<OptionDoc>& docs, const std::string& key, const py::handle& value) {
  const auto doc = std::find_if(docs.begin(), docs.end(), [&](const OptionDoc& d) { return d.key == key; });
  if (doc == docs.end()) return option_text(key, value);
  const std::string& type = doc->type;
  const auto refuse = [&](const std::string& expected) {
    throw InputError("option '" + key + "': expected " + expected + " (got " + py::repr(value).cast<std::string>() + ")");
  };
  if (type == "names") {
    if (py::isinstance<py::str>(value) || !py::isinstance<py::sequence>(value)) refuse("a list of names");
    return names_text(value);
  }
  if (type == "integers") {
    if (py::isinstance<py::str>(value) || !py::isinstance<py::sequence>(value)) refuse("a list of integers");
    std::string out;
    for (const py::handle item : value) {
      if (!py::isinstance<py::int_>(item) || py::isinstance<py::bool_>(item)) refuse("a list of integers");
      if (!out.empty()) out += ',';
      out += py::repr(item).cast<std::string>();
    }
    return out;
  }
  if ((type == "text" || type.find('|') != std::string::npos) && !py::isinstance<py::str>(value))
    refuse(type == "text" ? std::string("a string") : "one of " + type + " as a string");
  return option_text(key, value);
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

// A described report as Python objects: reports and keyed lists as dicts, lists as lists,
// enums by name.
template <class V>
py::object to_py(const V& v) {
  if constexpr (DescribedFields<V>) {
    py::dict d;
    visit_fields(v, [&](std::string_view key, const auto& x, std::string_view) { d[py::str(std::string(key))] = to_py(x); });
    return d;
  } else if constexpr (detail::is_keyed_list<V>::value) {
    py::dict d;
    for (const auto& [key, x] : v) d[py::str(key)] = to_py(x);
    return d;
  } else if constexpr (detail::is_field_list<V>::value) {
    py::list items;
    for (const auto& x : v) items.append(to_py(x));
    return items;
  } else if constexpr (std::is_enum_v<V>) {
    return py::str(std::string(name(v)));
  } else {
    return py::cast(v);
  }
}

inline ElementType element_type_named(const std::string& type_name) {
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
inline py::array_t<Index> connectivity_view(ElementBlock& b, const py::object& owner) {
  const auto npc = static_cast<py::ssize_t>(b.nodes_per_element());
  py::array_t<Index> view({static_cast<py::ssize_t>(b.size()), npc},
                          {static_cast<py::ssize_t>(npc * sizeof(Index)), static_cast<py::ssize_t>(sizeof(Index))},
                          b.connectivity.data(), owner);
  // Read-only: an index written here would reach the library's loops unchecked (a node out
  // of range crashed quality_report). A new connectivity goes through from_arrays().
  view.attr("setflags")(py::arg("write") = false);
  return view;
}

// A mover's call `call(a, x)` of one (rows, dim) array to another, as a Python method: the
// input read in place, the GIL released while the library works. `what` names the input in errors.
template <int Dim, class A, class Call>
auto array_call(Call call, const char* what) {
  return [call, what](A& a, const py::array& x) {
    const Eigen::Map<const Points<Dim>> in = rows_of<Dim>(x, what);
    Points<Dim> out;
    {
      py::gil_scoped_release release;
      out = call(a, in);
    }
    return to_rows<Dim>(std::move(out));
  };
}

// What every mover class of the module offers (the serial AnyMover and the distributed one):
// move, move into the caller's array, the reverse derivative, its figures. Inputs are read in
// place and the GIL is released while the library works.
template <int Dim, class A, class... Extra>
void bind_move_calls(py::class_<A, Extra...>& c) {
  c.def("move",
        [](A& a, const py::array& d) {
          const Eigen::Map<const Points<Dim>> in = rows_of<Dim>(d, "move: displacements");
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
             const Eigen::Map<const Points<Dim>> in = rows_of<Dim>(d, "move_into: displacements");
             (void)rows_of<Dim>(out, "move_into: out");
             if (!out.writeable()) throw InputError("move_into: out is read-only");
             Eigen::Map<Points<Dim>> target(static_cast<double*>(out.mutable_data()), Dim, static_cast<Index>(out.shape(0)));
             py::gil_scoped_release release;
             a.move_into(in, target);
           },
           py::arg("displacements"), py::arg("out"), "move() into a caller's (n, dim) C-contiguous float64 array")
      .def("velocity",
           array_call<Dim, A>([](A& a, PointsView<Dim> v) { return a.velocity(v); }, "velocity: boundary velocities"),
           py::arg("boundary_velocities"),
           "grid velocities (n, dim) for boundary velocities (boundary size, dim): J v through the current move's map")
      .def_property_readonly("stats", [](const A& a) { return to_py(a.stats()); })
      .def_property_readonly("has_derivatives", &A::has_derivatives)
      .def("derivative_reverse",
           array_call<Dim, A>([](A& a, PointsView<Dim> v) { return a.derivative_reverse(v); }, "derivative_reverse: v"),
           py::arg("v"), "Jᵀ v: the gradient (boundary size, dim) of <v, move(d)> for v (n, dim)");
}

/// Runs f.template operator()<Dim>() for Dim 2 and 3: each class and function is bound once
/// per dimension, with the dimension in its Python name (Mesh2, Mesh3).
template <class F>
void for_each_dimension(F&& f) {
  f.template operator()<2>();
  f.template operator()<3>();
}

void bind_errors(py::module_& m);
void bind_catalogue(py::module_& m);
void bind_mesh(py::module_& m);
void bind_io(py::module_& m);
void bind_boundary(py::module_& m);
void bind_movers(py::module_& m);
void bind_quality(py::module_& m);
void bind_curving(py::module_& m);
// Where the parallel layer is built (MESHMOTION_PYTHON_PARALLEL); otherwise parallel.cpp says why not.
void bind_parallel(py::module_& m);

}  // namespace meshmotion::python
