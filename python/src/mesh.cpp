// Meshes: points as an (n, dim) numpy view, cell and facet blocks, named groups, from a solver's arrays.

#include "bindings.hpp"

#include "meshmotion/core/orientation.hpp"
#include "meshmotion/io/mesh_summary.hpp"

#include <map>
#include <string>
#include <tuple>
#include <vector>

namespace meshmotion::python {

// {name: value(group)} over the named groups of a mesh.
template <int Dim, class Value>
py::dict by_group(const Mesh<Dim>& mesh, Value&& value) {
  py::dict out;
  for (const auto& g : mesh.groups)
    if (!g.name.empty()) out[py::str(g.name)] = value(g);
  return out;
}

void bind_mesh(py::module_& m) {
  for_each_dimension([&]<int Dim>() {
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
        .def("summary", [](const M& mesh) { return to_py(summarize(mesh)); },
             "mesh_info's summary as a dict: counts per element type, groups, bounding box, edge lengths, orientation")
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
            mesh.first_node_id = 0;  // numpy's indices: node_indices() takes them as they are
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
  });
}

}  // namespace meshmotion::python
