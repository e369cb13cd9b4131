// An allocation failing inside a parallel region reaches the caller as std::bad_alloc. An
// exception leaving an OpenMP region ends the program instead ("terminate called after
// throwing std::bad_alloc", rc 134, no JSON error): what a large case under `ulimit -v` did.
//
// This executable's operator new fails, while `fail_in_workers` is set, on every OpenMP worker
// thread (thread number > 0), the way a process out of memory fails wherever it allocates.

#include "meshmotion/core/generators.hpp"
#include "meshmotion/core/threads.hpp"
#include "meshmotion/movers.hpp"

#include <catch2/catch.hpp>

#include <atomic>
#include <cstdlib>
#include <new>

#ifdef _OPENMP
#include <omp.h>
#endif

namespace {
std::atomic<bool> fail_in_workers{false};
}  // namespace

void* operator new(std::size_t size) {
#ifdef _OPENMP
  if (fail_in_workers.load(std::memory_order_relaxed) && omp_in_parallel() && omp_get_thread_num() > 0) throw std::bad_alloc();
#endif
  if (void* p = std::malloc(size > 0 ? size : 1)) return p;
  throw std::bad_alloc();
}
// GCC pairs its built-in knowledge of operator new with the free() here and warns of a
// mismatch; this operator new is malloc, so the pair is right.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
#endif
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif

using namespace meshmotion;

namespace {

// Sets up `mover` with allocations failing in the worker threads; the mover must throw
// bad_alloc, and set up again once memory is back.
template <class Mover>
void check_setup_fails_cleanly(Mover mover, const Mesh<2>& mesh, const ResolvedBoundary<2>& b) {
  set_num_threads(2);
  fail_in_workers = true;
  CHECK_THROWS_AS(mover.setup(mesh, b), std::bad_alloc);
  fail_in_workers = false;
  mover.setup(mesh, b);
  CHECK(mover.move(b.displacements).allFinite());
  set_num_threads(0);
}

}  // namespace

TEST_CASE("an allocation failing in a parallel region is thrown to the caller, not the end of the program",
          "[movers][memory]") {
#ifndef _OPENMP
  SUCCEED("built without OpenMP: no parallel region");
#else
  const Mesh<2> mesh = rectangle_mesh({.nx = 40, .ny = 40});
  BoundarySpec<2> spec;
  spec.moving("bottom", Translation<2>{Vec<2>(0.0, 0.01)}).fixed("top").fixed("left").fixed("right");
  const ResolvedBoundary<2> b = spec.resolve(mesh);
  SECTION("compact RBF: the neighbour search") {
    RbfOptions o;
    o.support_radius = 0.3;
    check_setup_fails_cleanly(RbfMover<2>(o), mesh, b);
  }
  SECTION("partition-of-unity RBF: the blended evaluation") {
    RbfOptions o;
    o.support_radius = 0.3;
    o.partition_of_unity = true;
    o.patch_centres = 40;
    check_setup_fails_cleanly(RbfMover<2>(o), mesh, b);
  }
  SECTION("wall-distance blending: the operator's rows") {
    check_setup_fails_cleanly(BlendMover<2>(BlendOptions{0.5, {}, 1.0}), mesh, b);
  }
#endif
}
