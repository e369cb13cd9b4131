// Movers by method name with typed keyword options, their moves into numpy arrays, derivatives and stats.

#include "bindings.hpp"

#include "meshmotion/movers/mover_options.hpp"

#include <string>
#include <vector>

namespace meshmotion::python {

void bind_movers(py::module_& m) {
  for_each_dimension([&]<int Dim>() {
    const std::string suffix = std::to_string(Dim);
    using M = Mesh<Dim>;
    using B = ResolvedBoundary<Dim>;
    using A = AnyMover<Dim>;
    py::class_<A>(m, ("Mover" + suffix).c_str())
        .def(py::init([](const std::string& method, const py::kwargs& options) {
               MoverConfig<Dim> c = mover_config<Dim>(method);
               const std::vector<OptionDoc> docs = c.docs();
               for (const auto& [key, value] : options) {
                 const std::string k = key.template cast<std::string>();
                 c.set(k, option_text(docs, k, value));
               }
               return make_mover(c);
             }),
             py::arg("method"))
        .def("setup", [](A& a, const M& mesh, const B& b) { a.setup(mesh, b); }, py::arg("mesh"), py::arg("boundary"),
             py::call_guard<py::gil_scoped_release>())
        .def("move",
             [](A& a, const py::array& d) {
               const Eigen::Map<const Points<Dim>> in = rows_of<Dim>(d, "move: displacements");  // read in place
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
        .def_property_readonly("stats", [](const A& a) { return to_py(a.stats()); })
        .def_property_readonly("has_derivatives", &A::has_derivatives)
        .def("derivative_forward",
             [](A& a, const py::array& w) {
               const Eigen::Map<const Points<Dim>> in = rows_of<Dim>(w, "derivative_forward: w");
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
  });
  m.def("mover_methods", [] {
    std::vector<std::string> out;
    for (const auto& method : mover_methods<3>()) out.emplace_back(method.name);
    return out;
  });
  m.def("mover_options", [](const std::string& method, int dim) {
    return dim == 2 ? mover_config<2>(method).values() : mover_config<3>(method).values();
  }, py::arg("method"), py::arg("dim") = 3, "the keys of a method with their default values (as text)");
}

}  // namespace meshmotion::python
