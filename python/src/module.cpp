// The Python module meshmotion._core: meshes as numpy views, movers by name with typed keyword
// options, boundaries by group, derivatives, curving and quality reports. The pure-Python
// package (python/meshmotion/) builds the user-facing API on it. One file per layer binds it
// (bindings.hpp lists them).

#include "bindings.hpp"

#include "meshmotion/core/threads.hpp"
#include "meshmotion/version.hpp"

PYBIND11_MODULE(_core, m) {
  using namespace meshmotion::python;
  m.doc() = "meshmotion's compiled core (use the meshmotion package)";
  m.attr("__version__") = MESHMOTION_VERSION_STRING;
  // As the programs do: an OMP_NUM_THREADS the OpenMP runtime would crash on is refused
  // (ImportError with the reason) before any parallel region opens.
  meshmotion::check_thread_environment();
  bind_errors(m);
  bind_catalogue(m);
  bind_mesh(m);
  bind_io(m);
  bind_boundary(m);
  bind_movers(m);
  bind_quality(m);
  bind_curving(m);
  bind_parallel(m);
}
