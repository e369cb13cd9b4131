// curve_mesh with its keywords from the one description of its options, and its report as a dict.

#include "bindings.hpp"

#include "meshmotion/curving/curve_mesh.hpp"
#include "meshmotion/curving/geometry_text.hpp"
#include "meshmotion/curving/reports.hpp"
#include "meshmotion/io/mesh_summary.hpp"

#include <algorithm>
#include <string>
#include <vector>

namespace meshmotion::python {

namespace {

// curve_mesh's keywords: each through the library's one parser (set_curve_options), the
// pipeline's own keys and the method's alike; `geometry` is a dict {group: geometry text}.
template <int Dim>
CurveOptions<Dim> curve_options(const py::kwargs& kwargs) {
  CurveOptions<Dim> o;
  KeyValues given;
  const std::vector<OptionDoc> own = option_docs(o);
  for (const auto& [key_handle, value] : kwargs) {
    const auto key = py::cast<std::string>(key_handle);
    if (key == "geometry") {
      if (!py::isinstance<py::dict>(value))
        throw InputError("curve_mesh: option 'geometry' expects a dict {group: geometry text} (got " +
                         py::cast<std::string>(py::repr(value)) + ")");
      for (const auto& [group, spec] : py::cast<py::dict>(value)) {
        if (!py::isinstance<py::str>(group) || !py::isinstance<py::str>(spec))
          throw InputError("curve_mesh: option 'geometry' expects group names and geometry texts (got " +
                           py::cast<std::string>(py::repr(value)) + ")");
        o.geometry.insert_or_assign(py::cast<std::string>(group), geometry_from_text<Dim>(py::cast<std::string>(spec)));
      }
      continue;
    }
    given.emplace_back(key, option_text(own, key, value));
  }
  set_curve_options(o, given);
  return o;
}

}  // namespace

void bind_curving(py::module_& m) {
  for_each_dimension([&]<int Dim>() {
    using M = Mesh<Dim>;
    m.def(
        "curve_mesh",
        [](const M& mesh, const py::kwargs& kwargs) {
          const CurveOptions<Dim> options = curve_options<Dim>(kwargs);
          CurveResult<Dim> result;
          {
            py::gil_scoped_release release;
            result = curve_mesh(mesh, options);
          }
          py::object report = to_py(result);
          return py::make_tuple(py::cast(std::move(result.curved)), report);
        },
        py::arg("mesh"));
  });
  m.def(
      "curve_options",
      [](const std::string& method) {
        py::list out;
        for (const OptionDoc& d : curve_option_docs<3>(method))
          out.append(py::dict(py::arg("key") = d.key, py::arg("type") = d.type, py::arg("default") = d.value, py::arg("doc") = d.doc));
        return out;
      },
      py::arg("method") = "blend", "curve_mesh's keywords with method `method`: key, type, default (as text) and doc");
  m.def(
      "report_fields",
      [](const std::string& report) { return report_fields(report); },
      py::arg("report"), "the keys of a report's dict, from its one description");
}

}  // namespace meshmotion::python
