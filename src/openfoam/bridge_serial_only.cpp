// The plugin built without meshmotion's parallel layer (MPI, PETSc, METIS): decomposed cases
// are refused (serving.hpp; bridge_parallel.cpp where the layer is built).

#include "serving.hpp"

namespace meshmotion::foam {

bool decomposed_needs_cells(const std::string&) { return false; }

std::unique_ptr<Serving> serve_decomposed(const BridgeInput&, const MoverConfig<3>&, const parallel::ParallelOptions&) {
  throw InputError("this plugin was built without meshmotion's parallel layer (MPI, PETSc, METIS): run the motion serially");
}

}  // namespace meshmotion::foam
