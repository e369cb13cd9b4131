#pragma once
// Helpers of the parallel tests: every check compares a value reduced over the ranks, so all
// ranks take the same branch.
#include <mpi.h>

#include <algorithm>
#include <cstddef>
#include <vector>

namespace test {

inline MPI_Comm world() { return MPI_COMM_WORLD; }

inline double global_max(double x) {
  double out = x;
  MPI_Allreduce(&x, &out, 1, MPI_DOUBLE, MPI_MAX, world());
  return out;
}

/// Cell ranks of an nx × ny rectangle_mesh (cells row by row) in bands of rows: rank 0 the two
/// rows on the bottom, rank 1 the middle rows (it owns no node of the bottom or top groups:
/// its boundary rows are owned by ranks 0 and 2), rank 2 the two top rows; a fourth rank gets
/// nothing. Fewer ranks merge the upper bands.
inline std::vector<int> row_bands(std::ptrdiff_t nx, std::ptrdiff_t ny) {
  int p = 1;
  MPI_Comm_size(world(), &p);
  std::vector<int> ranks(static_cast<std::size_t>(nx * ny));
  for (std::ptrdiff_t j = 0; j < ny; ++j)
    for (std::ptrdiff_t i = 0; i < nx; ++i)
      ranks[static_cast<std::size_t>(i + nx * j)] = std::min(j < 2 ? 0 : j < ny - 2 ? 1 : 2, p - 1);
  return ranks;
}

}  // namespace test
