#pragma once
// Helpers of the parallel tests: every check compares a value reduced over the ranks, so all
// ranks take the same branch.
#include <mpi.h>

#include <algorithm>

namespace test {

inline MPI_Comm world() { return MPI_COMM_WORLD; }

inline double global_max(double x) {
  double out = x;
  MPI_Allreduce(&x, &out, 1, MPI_DOUBLE, MPI_MAX, world());
  return out;
}

}  // namespace test
