// The library's exception hierarchy as Python exceptions with the same messages.

#include "bindings.hpp"

#include <exception>

namespace meshmotion::python {

void bind_errors(py::module_& m) {
  // The C++ hierarchy as Python exceptions with the same messages. Each derives from Error,
  // so that `except meshmotion.Error` catches them all, and from the built-in exception a
  // Python caller expects (a bad value is a ValueError, an unreadable file an OSError).
  static py::exception<Error> error(m, "Error", PyExc_RuntimeError);
  const auto bases = [&](PyObject* builtin) { return py::make_tuple(error, py::handle(builtin)); };
  static py::exception<InputError> input_error(m, "InputError", bases(PyExc_ValueError));
  static py::exception<IoError> io_error(m, "IoError", bases(PyExc_OSError));
  static py::exception<SolverError> solver_error(m, "SolverError", error);
  static py::exception<InvalidMeshError> invalid_mesh_error(m, "InvalidMeshError", error);
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
