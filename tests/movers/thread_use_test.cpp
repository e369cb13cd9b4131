// One mover, two threads: a call made while another thread is inside the mover is refused
// with SolverError (AnyMover's contract), never run on shared scratch into a wrong mesh.

#include "meshmotion/core/generators.hpp"
#include "meshmotion/movers/any_mover.hpp"
#include "meshmotion/movers/boundary.hpp"

#include <catch2/catch.hpp>

#include <atomic>
#include <chrono>
#include <thread>

using namespace meshmotion;

namespace {

// A mover whose move() waits, inside the call, until the test lets it go.
struct HeldMover {
  static constexpr int dim = 2;
  std::atomic<bool>* inside = nullptr;
  std::atomic<bool>* release = nullptr;
  Index nodes = 0;
  void setup(const Mesh<2>& mesh, const ResolvedBoundary<2>&) { nodes = mesh.num_nodes(); }
  [[nodiscard]] Points<2> move(const Points<2>& d) {
    Points<2> out;
    move_into(d, out);
    return out;
  }
  void move_into(PointsView<2>, Points<2>& out) {
    inside->store(true);
    const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(20);
    while (!release->load() && std::chrono::steady_clock::now() < give_up) std::this_thread::yield();
    out.setZero(2, nodes);
  }
  [[nodiscard]] MoverStats stats() const { return {}; }
};

}  // namespace

TEST_CASE("a mover used by a second thread while the first is inside it refuses, and serves again after", "[movers]") {
  const Mesh<2> mesh = rectangle_mesh({});
  const ResolvedBoundary<2> b = BoundarySpec<2>().fixed("bottom").resolve(mesh);
  std::atomic<bool> inside{false}, release{false};
  AnyMover<2> mover(HeldMover{&inside, &release});
  mover.setup(mesh, b);
  const Points<2> d = Points<2>::Zero(2, b.size());
  std::thread first([&] { (void)mover.move(d); });
  while (!inside.load()) std::this_thread::yield();
  AnyMover<2> copy = mover;  // copies share the mover
  CHECK_THROWS_AS((void)copy.move(d), SolverError);
  CHECK_THROWS_WITH((void)mover.move(d), Catch::Contains("in use by another thread"));
  release.store(true);
  first.join();
  CHECK(mover.move(d).cols() == mesh.num_nodes());  // free again once the first call returned
}
