// Boundaries: groups moving, fixed or sliding, resolved to nodes.

#include "bindings.hpp"

#include "meshmotion/movers/boundary.hpp"
#include "meshmotion/movers/motion.hpp"

#include <map>
#include <optional>
#include <string>
#include <vector>

namespace meshmotion::python {

void bind_boundary(py::module_& m) {
  for_each_dimension([&]<int Dim>() {
    const std::string suffix = std::to_string(Dim);
    using M = Mesh<Dim>;
    using B = ResolvedBoundary<Dim>;
    py::class_<B>(m, ("ResolvedBoundary" + suffix).c_str(), "a boundary resolved to nodes: move()'s input has one row per node")
        .def_property_readonly("nodes", [](const B& b) { return b.nodes; })
        .def_property_readonly("size", &B::size)
        .def_property_readonly("kinds",
                               [](const B& b) {
                                 std::vector<std::string> out;
                                 for (const auto k : b.kinds) out.emplace_back(name(k));
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
        .def(
            "sliding",
            [](S& s, const std::string& g, std::optional<std::vector<double>> normal) -> S& {
              if (!normal) return s.sliding(g);
              if (static_cast<int>(normal->size()) != Dim)
                throw InputError("sliding: the normal of '" + g + "' needs " + std::to_string(Dim) + " numbers (got " +
                                 std::to_string(normal->size()) + ")");
              return s.sliding(g, Vec<Dim>(Eigen::Map<const Vec<Dim>>(normal->data())));
            },
            py::arg("group"), py::arg("normal") = std::nullopt, py::return_value_policy::reference_internal,
            "the group slides in its plane: the normal given, or fitted to the group's nodes")
        .def("resolve", [](const S& s, const M& mesh) { return s.resolve(mesh); }, py::arg("mesh"))
        .def("resolve_nodes",
             [](const S& s, const py::array& points, const std::map<std::string, std::vector<Index>>& groups) {
               GroupNodes nodes(groups.begin(), groups.end());
               return s.resolve(Points<Dim>(rows_of<Dim>(points, "resolve_nodes: points")), nodes);
             },
             py::arg("points"), py::arg("groups"));
  });
}

}  // namespace meshmotion::python
