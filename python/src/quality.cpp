// Quality reports with per-cell numpy arrays.

#include "bindings.hpp"

#include "meshmotion/quality/cell_quality.hpp"
#include "meshmotion/quality/quality_report.hpp"

#include <string>
#include <vector>

namespace meshmotion::python {

// The per-cell values and validity (cell order) beside the report's summary.
template <int Dim>
py::dict quality_dict(const Mesh<Dim>& mesh, Metric metric) {
  std::vector<CellQuality> cells;
  QualityReport report;
  {
    py::gil_scoped_release release;
    cells = evaluate_cells(mesh, metric);
    report = make_report(mesh, metric, cells);
  }
  py::dict d(to_py(report));
  py::array_t<double> values(static_cast<py::ssize_t>(cells.size()));
  py::array_t<bool> valid(static_cast<py::ssize_t>(cells.size()));
  auto v = values.mutable_unchecked<1>();
  auto ok = valid.mutable_unchecked<1>();
  for (std::size_t c = 0; c < cells.size(); ++c) {
    v(static_cast<py::ssize_t>(c)) = cells[c].value;
    ok(static_cast<py::ssize_t>(c)) = cells[c].valid;
  }
  d["values"] = values;
  d["valid"] = valid;
  return d;
}

void bind_quality(py::module_& m) {
  for_each_dimension([&]<int Dim>() {
    using M = Mesh<Dim>;
    m.def("quality_report", [](const M& mesh, const std::string& metric) { return quality_dict(mesh, metric_from_name(metric)); },
          py::arg("mesh"), py::arg("metric") = "jacobian");
  });
}

}  // namespace meshmotion::python
