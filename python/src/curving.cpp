// curve_mesh with its keywords from the one description of its options, and its report as a dict.

#include "bindings.hpp"

#include "meshmotion/curving/curve_mesh.hpp"
#include "meshmotion/curving/geometry_text.hpp"
#include "meshmotion/curving/reports.hpp"
#include "meshmotion/io/mesh_summary.hpp"

#ifdef MESHMOTION_PYTHON_CAD
#include "meshmotion/cad/cad_model.hpp"
#endif

#include <algorithm>
#include <optional>
#include <string>
#include <vector>

namespace meshmotion::python {

namespace {

// A CAD model named by curve_mesh's `geometry`, with the groups it is for (none: every group
// it fits) and the matching tolerance (0: 1e-6 of its diagonal).
struct CadRequest {
  std::string file;
  std::vector<std::string> groups;
  double tolerance = 0.0;
};

// curve_mesh's keywords: each through the library's one parser (set_curve_options), the
// pipeline's own keys and the method's alike; `geometry` is a dict {group: geometry text} or
// a CAD file's name (with cad_groups and cad_tolerance), which goes into `cad`.
template <int Dim>
CurveOptions<Dim> curve_options(const py::kwargs& kwargs, std::optional<CadRequest>& cad) {
  CurveOptions<Dim> o;
  KeyValues given;
  const std::vector<OptionDoc> own = option_docs(o);
  std::optional<py::object> cad_groups, cad_tolerance;
  for (const auto& [key_handle, value] : kwargs) {
    const auto key = py::cast<std::string>(key_handle);
    if (key == "cad_groups" || key == "cad_tolerance") {
      (key == "cad_groups" ? cad_groups : cad_tolerance) = py::reinterpret_borrow<py::object>(value);
      continue;
    }
    if (key == "geometry" && py::isinstance<py::str>(value) && is_cad_file(py::cast<std::string>(value))) {
      cad.emplace().file = py::cast<std::string>(value);
      continue;
    }
    if (key == "geometry") {
      if (!py::isinstance<py::dict>(value))
        throw InputError("curve_mesh: option 'geometry' expects a dict {group: geometry text} or a CAD file "
                         "(.step, .stp, .iges, .igs, .brep) (got " + py::cast<std::string>(py::repr(value)) + ")");
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
  if ((cad_groups || cad_tolerance) && !cad)
    throw InputError("curve_mesh: cad_groups and cad_tolerance go with geometry=\"MODEL.step\" (a CAD file)");
  if (cad_groups) cad->groups = py::cast<std::vector<std::string>>(*cad_groups);
  if (cad_tolerance) cad->tolerance = py::cast<double>(*cad_tolerance);
  set_curve_options(o, given);
  return o;
}

// curve_mesh() of `mesh`, on the CAD model `cad` names when given: the groups the model's
// policy chooses (geometry_on_cad()) curved onto it, the curved mesh tied to it (place_on_cad()).
template <int Dim>
py::tuple curve(const Mesh<Dim>& mesh, CurveOptions<Dim> options, const std::optional<CadRequest>& cad) {
  CurveResult<Dim> result;
  if (!cad) {
    {
      py::gil_scoped_release release;
      result = curve_mesh(mesh, options);
    }
    py::object report = to_py(result);
    return py::make_tuple(py::cast(std::move(result.curved)), report);
  }
#ifdef MESHMOTION_PYTHON_CAD
  const CadModel model = CadModel::read(cad->file);
  Mesh<Dim> linear = mesh;
  CadCurving chosen;
  {
    py::gil_scoped_release release;
    chosen = geometry_on_cad(linear, model, options, cad->tolerance, cad->groups);
    result = curve_mesh(linear, options);
    place_on_cad(result.curved, model, chosen.matches, cad->tolerance);
  }
  py::dict report = to_py(result);
  report["cad_groups"] = chosen.report;
  report["on_model"] = chosen.on_model;
  return py::make_tuple(py::cast(std::move(result.curved)), report);
#else
  throw InputError("curve_mesh: geometry '" + cad->file + "' is a CAD file, and this module was built without the CAD "
                   "component (install libocct-modeling-algorithms-dev libocct-data-exchange-dev and reconfigure)");
#endif
}

}  // namespace

void bind_curving(py::module_& m) {
#ifdef MESHMOTION_PYTHON_CAD
  m.attr("have_cad") = true;
#else
  m.attr("have_cad") = false;
#endif
  for_each_dimension([&]<int Dim>() {
    using M = Mesh<Dim>;
    m.def(
        "curve_mesh",
        [](const M& mesh, const py::kwargs& kwargs) {
          std::optional<CadRequest> cad;
          CurveOptions<Dim> options = curve_options<Dim>(kwargs, cad);
          return curve<Dim>(mesh, std::move(options), cad);
        },
        py::arg("mesh"));
  });
  m.def(
      "curve_options",
      [](const std::string& method) {
        py::list out;
        for (const OptionDoc& d : curve_option_docs<3>(method))
          out.append(py::dict(py::arg("key") = d.key, py::arg("type") = d.type, py::arg("default") = d.value, py::arg("doc") = d.doc,
                              py::arg("details") = d.details));
        return out;
      },
      py::arg("method") = "blend", "curve_mesh's keywords with method `method`: key, type, default (as text), doc (a line) and details (the rest of its description, or empty)");
  m.def(
      "report_fields",
      [](const std::string& report) { return report_fields(report); },
      py::arg("report"), "the keys of a report's dict, from its one description");
}

}  // namespace meshmotion::python
