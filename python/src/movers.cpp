// Movers by method name with typed keyword options, their moves into numpy arrays, derivatives and stats.

#include "bindings.hpp"

#include "mover_keywords.hpp"

#include "meshmotion/core/extrusion.hpp"
#include "meshmotion/movers/section_mover.hpp"

#include <optional>
#include <string>
#include <vector>

namespace meshmotion::python {

void bind_movers(py::module_& m) {
  for_each_dimension([&]<int Dim>() {
    const std::string suffix = std::to_string(Dim);
    using M = Mesh<Dim>;
    using B = ResolvedBoundary<Dim>;
    using A = AnyMover<Dim>;
    py::class_<A> c(m, ("Mover" + suffix).c_str());
    c.def(py::init([](const std::string& method, const py::kwargs& options) {
               return make_mover(mover_config_from<Dim>(method, options));
             }),
             py::arg("method"))
        .def("setup", [](A& a, const M& mesh, const B& b) { a.setup(mesh, b); }, py::arg("mesh"), py::arg("boundary"),
             py::call_guard<py::gil_scoped_release>())
        .def("derivative_forward",
             array_call<Dim, A>([](A& a, PointsView<Dim> w) { return a.derivative_forward(w); }, "derivative_forward: w"),
             py::arg("w"), "J w: node displacement changes (n, dim) for boundary changes w (boundary size, dim)");
    bind_move_calls<Dim>(c);
  });
  // A 2D case stored in 3D moved as its section (movers/section_mover.hpp): a Mover3.
  m.def("_section_mover", [](const std::string& method, const py::kwargs& options) {
    return AnyMover<3>(SectionMover(make_mover(mover_config_from<2>(method, options))));
  }, py::arg("method"));
  m.def("find_extrusion", [](const Mesh<3>& mesh) -> py::object {
    const std::optional<Extrusion> ext = find_extrusion(mesh);
    if (!ext) return py::none();
    py::dict out;
    out["axis"] = ext->axis;
    out["front"] = ext->front;
    out["back"] = ext->back;
    out["plane_groups"] = ext->plane_groups;
    return out;
  }, py::arg("mesh"),
        "None, or the axis (0, 1, 2), the two planes' coordinates and the groups lying in them of a mesh one cell thick "
        "between two planes normal to a coordinate axis (a 2D case stored in 3D)");
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
