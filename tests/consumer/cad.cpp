// Links the CAD component of an installed (or added) meshmotion and calls into OpenCASCADE
// through it: a file that does not exist is refused with the reason.
#include <meshmotion/cad/cad_model.hpp>
#include <meshmotion/core/error.hpp>

#include <iostream>

int main() {
  try {
    (void)meshmotion::CadModel::read("no_such_model.step");
  } catch (const meshmotion::IoError& e) {
    std::cout << "consumer: cad refuses " << e.what() << "\n";
    return 0;
  }
  return 1;
}
