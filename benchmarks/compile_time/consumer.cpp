// A program as a solver or a script would write it: reads a mesh, moves it with RBF, reports
// its quality and curves it. benchmarks/compile_time.sh times its compilation against the
// headers alone and against meshmotion::compiled.

#include <meshmotion/meshmotion.hpp>

#include <iostream>

int main(int argc, char** argv) {
  using namespace meshmotion;
  if (argc < 2) return 1;
  const Mesh<3> mesh = read_mesh_as<3>(argv[1]);
  const ResolvedBoundary<3> boundary = BoundarySpec<3>().moving("wall", Translation<3>{Vec<3>(0.0, 0.0, 0.01)}).resolve(mesh);
  RbfMover<3> mover(RbfOptions{});
  mover.setup(mesh, boundary);
  const Points<3> u = mover.move(boundary.displacements);
  const QualityReport q = quality_report(mesh, Metric::scaled_jacobian);
  const CurveResult<3> curved = curve_mesh(mesh, CurveOptions<3>{});
  std::cout << u.cols() << " " << q.min << " " << curved.quality.min << "\n";
  return 0;
}
