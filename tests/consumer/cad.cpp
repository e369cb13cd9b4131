// Links the CAD component of an installed (or added) meshmotion: a file that does not exist is
// refused with the reason, and a model given as the argument is read through the module the
// component loads (the installed one when MESHMOTION_CAD_MODULE names it).
#include <meshmotion/cad/cad_model.hpp>
#include <meshmotion/core/error.hpp>

#include <iostream>

int main(int argc, char** argv) {
  try {
    (void)meshmotion::CadModel::read("no_such_model.step");
    return 1;
  } catch (const meshmotion::IoError& e) {
    std::cout << "consumer: cad refuses " << e.what() << "\n";
  }
  if (argc > 1) {
    const meshmotion::CadModel model = meshmotion::CadModel::read(argv[1]);
    std::cout << "consumer: cad reads " << argv[1] << ": " << model.num_faces() << " faces, " << model.num_edges() << " edges\n";
    if (model.num_faces() + model.num_edges() == 0) return 1;
  }
  return 0;
}
