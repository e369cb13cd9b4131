// The element catalogue (types, reference nodes, VTK orders) and the thread count.

#include "bindings.hpp"

#include "meshmotion/core/shape_functions.hpp"
#include "meshmotion/core/threads.hpp"

#include <array>
#include <string>
#include <vector>

namespace meshmotion::python {

void bind_catalogue(py::module_& m) {
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

}  // namespace meshmotion::python
