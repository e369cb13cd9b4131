// The library's exception hierarchy as Python exceptions with the same messages.

#include "bindings.hpp"

#include <exception>

namespace meshmotion::python {

void bind_errors(py::module_& m) {
  // The C++ hierarchy as Python exceptions with the same messages.
  static py::exception<Error> error(m, "Error", PyExc_RuntimeError);
  static py::exception<InputError> input_error(m, "InputError", PyExc_ValueError);
  static py::exception<IoError> io_error(m, "IoError", PyExc_OSError);
  static py::exception<SolverError> solver_error(m, "SolverError", PyExc_RuntimeError);
  static py::exception<InvalidMeshError> invalid_mesh_error(m, "InvalidMeshError", PyExc_RuntimeError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const InputError& e) {
      input_error(e.what());
    } catch (const IoError& e) {
      io_error(e.what());
    } catch (const SolverError& e) {
      solver_error(e.what());
    } catch (const InvalidMeshError& e) {
      invalid_mesh_error(e.what());
    } catch (const Error& e) {
      error(e.what());
    }
  });
}

}  // namespace meshmotion::python
