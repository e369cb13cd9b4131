// Reading and writing meshes in every format of io/mesh_io.hpp.

#include "bindings.hpp"

#include "meshmotion/io/mesh_io.hpp"
#include "meshmotion/io/openfoam.hpp"

#include <pybind11/stl/filesystem.h>

#include <filesystem>
#include <string>
#include <variant>
#include <vector>

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
  m.def(
      "read_foam_processor",
      [](const std::filesystem::path& folder) {
        PolyMesh poly;
        std::vector<Index> ids;
        {
          py::gil_scoped_release release;
          poly = read_polymesh(folder);
          const std::filesystem::path addressing = detail::polymesh_folder(folder) / "pointProcAddressing";
          ids = detail::read_foam_labels(addressing, "pointProcAddressing", 0);
          if (static_cast<Index>(ids.size()) != poly.points.cols())
            throw InputError(addressing.string() + ": " + std::to_string(ids.size()) + " labels for " +
                             std::to_string(poly.points.cols()) + " points (expected one each)");
          for (std::size_t k = 0; k < ids.size(); ++k)
            if (ids[k] < 0)
              throw InputError(addressing.string() + ": label " + std::to_string(k) + " is " + std::to_string(ids[k]) +
                               " (expected a point of the whole mesh, from 0)");
        }
        py::list patches;
        for (const PolyMesh::Patch& patch : poly.patches) {
          std::vector<Index> conn, sizes;
          for (Index f = patch.start; f < patch.start + patch.size; ++f) {
            const auto face = poly.face(f);
            conn.insert(conn.end(), face.begin(), face.end());
            sizes.push_back(static_cast<Index>(face.size()));
          }
          py::dict d;
          d["name"] = patch.name;
          d["type"] = patch.type;
          d["groups"] = patch.groups;
          d["conn"] = py::array_t<Index>(static_cast<py::ssize_t>(conn.size()), conn.data());
          d["sizes"] = py::array_t<Index>(static_cast<py::ssize_t>(sizes.size()), sizes.data());
          patches.append(d);
        }
        py::dict out;
        out["points"] = to_rows<3>(std::move(poly.points));
        out["global_ids"] = py::array_t<Index>(static_cast<py::ssize_t>(ids.size()), ids.data());
        out["patches"] = patches;
        return out;
      },
      py::arg("folder"),
      "a processor folder of a decomposed OpenFOAM case as its solver holds it: points (n, 3) in its order, their "
      "global ids (constant/polyMesh/pointProcAddressing), and per patch its name, type, groups and faces (conn flat, "
      "sizes; indices into points)");
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
