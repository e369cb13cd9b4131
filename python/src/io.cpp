// Reading and writing meshes in every format of io/mesh_io.hpp.

#include "bindings.hpp"

#include "meshmotion/io/mesh_io.hpp"

#include <pybind11/stl/filesystem.h>

#include <filesystem>
#include <string>
#include <variant>

namespace meshmotion::python {

void bind_io(py::module_& m) {
  m.attr("have_cgns") = have_cgns;  // read_mesh/write_mesh take .cgns
  m.def(
      "read_mesh",
      [](const std::filesystem::path& file, const std::string& orientation) -> py::object {
        ReadOptions o;
        if (orientation == "fix_reversed") o.orientation = ReadOrientation::fix_reversed;
        else if (orientation == "require_positive") o.orientation = ReadOrientation::require_positive;
        else if (orientation != "keep")
          throw InputError("read_mesh: orientation must be keep, fix_reversed or require_positive (got '" + orientation + "')");
        AnyMesh mesh = [&] {
          py::gil_scoped_release release;
          return read_mesh(file, o);
        }();
        if (auto* m2 = std::get_if<Mesh<2>>(&mesh)) return py::cast(std::move(*m2));
        return py::cast(std::move(std::get<Mesh<3>>(mesh)));
      },
      py::arg("file"), py::arg("orientation") = "keep");
  for_each_dimension([&]<int Dim>() {
    m.def("write_mesh", [](const std::filesystem::path& file, const Mesh<Dim>& mesh) { write_mesh(file, mesh); },
          py::arg("file"), py::arg("mesh"), py::call_guard<py::gil_scoped_release>());
    m.def("write_cgns_coordinates",
          [](const std::filesystem::path& source, const std::filesystem::path& file, const Mesh<Dim>& mesh) {
            write_cgns_coordinates(source, file, mesh);
          },
          py::arg("source"), py::arg("file"), py::arg("mesh"), py::call_guard<py::gil_scoped_release>(),
          "the CGNS file source again as file, with the mesh's coordinates (structured zones stay blocks)");
  });
}

}  // namespace meshmotion::python
